# Linux ARM64 (FMI 2.0 and 3.0 aarch64-linux) from another machine: Debian's cross gcc
# (apt-get install gcc-aarch64-linux-gnu); with LINUX_GLIBC, zig's C compiler against that glibc
# (cmake/linux.cmake).
set(CMAKE_SYSTEM_PROCESSOR aarch64)
include("${CMAKE_CURRENT_LIST_DIR}/linux.cmake")
