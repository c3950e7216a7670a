# Linux x86-64 (FMI 2.0 linux64, FMI 3.0 x86_64-linux) from another machine: Debian's cross gcc
# (apt-get install gcc-x86-64-linux-gnu); with LINUX_GLIBC, from any machine: zig's C compiler
# against that glibc (cmake/linux.cmake).
set(CMAKE_SYSTEM_PROCESSOR x86_64)
include("${CMAKE_CURRENT_LIST_DIR}/linux.cmake")
