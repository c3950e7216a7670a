# Linux ARM64 (FMI 2.0 and 3.0 aarch64-linux) from another machine: Debian's cross gcc
# (apt-get install gcc-aarch64-linux-gnu).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
