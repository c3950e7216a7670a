# What the two Linux toolchain files share; each sets CMAKE_SYSTEM_PROCESSOR, then includes this.
# LINUX_GLIBC empty (the default): Debian's cross gcc, <processor>-linux-gnu-gcc, which links
# against the build machine's glibc, so the binary needs the glibc symbol versions that glibc
# has (GLIBC_2.29 for pow on Debian 12). LINUX_GLIBC a glibc version such as 2.17: zig's C
# compiler for the target <processor>-linux-gnu.<LINUX_GLIBC>, which links against that glibc's
# own symbol versions, so the binary loads on that glibc and every later one (the manylinux
# rule: manylinux2014 is glibc 2.17). It runs on any machine, this processor's or not.
# The project's try_compile checks read this file again without the cache: the environment
# carries LINUX_GLIBC to them, as cmake/zig.cmake does ZIG_TARGET.
set(LINUX_GLIBC "" CACHE STRING "the oldest glibc the Linux binaries load on, such as 2.17 (built by zig); empty: the build machine's (built by gcc)")
if(LINUX_GLIBC)
    set(ENV{LINUX_GLIBC} "${LINUX_GLIBC}")
elseif(DEFINED ENV{LINUX_GLIBC})
    set(LINUX_GLIBC "$ENV{LINUX_GLIBC}")
endif()
if(LINUX_GLIBC)
    if(NOT LINUX_GLIBC MATCHES "^2\\.[0-9]+$")
        message(FATAL_ERROR "LINUX_GLIBC=${LINUX_GLIBC}: a glibc version such as 2.17")
    endif()
    set(ZIG_TARGET "${CMAKE_SYSTEM_PROCESSOR}-linux-gnu.${LINUX_GLIBC}")
    include("${CMAKE_CURRENT_LIST_DIR}/zig.cmake")
else()
    set(CMAKE_SYSTEM_NAME Linux)
    set(CMAKE_C_COMPILER "${CMAKE_SYSTEM_PROCESSOR}-linux-gnu-gcc")
endif()
