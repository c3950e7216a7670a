# What the two Linux toolchain files share; each sets CMAKE_SYSTEM_PROCESSOR, then includes this.
# LINUX_GLIBC empty (the default): Debian's cross gcc, <processor>-linux-gnu-gcc, which links
# against the glibc it comes with, so the binary needs that glibc's newest symbol versions of the
# functions it calls (on Debian 12 pow@GLIBC_2.29). LINUX_GLIBC a glibc version such as 2.17:
# zig's C compiler, from any machine, for the target <processor>-linux-gnu.<LINUX_GLIBC>, which
# links against that glibc's own symbol versions, so the binary loads on that glibc and every
# later one (manylinux2014 is glibc 2.17).
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
    # zig's C compiler writes debug information unless told not to, which gcc does not: without
    # it the pendulum's binary for x86-64 is 39 kB rather than 127 kB (gcc's is 56 kB).
    set(CMAKE_C_FLAGS_INIT -g0)
else()
    set(CMAKE_SYSTEM_NAME Linux)
    set(CMAKE_C_COMPILER "${CMAKE_SYSTEM_PROCESSOR}-linux-gnu-gcc")
endif()
