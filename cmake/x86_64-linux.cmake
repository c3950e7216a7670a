# Linux x86-64 (FMI 2.0 linux64, FMI 3.0 x86_64-linux) from another machine: Debian's cross gcc
# (apt-get install gcc-x86-64-linux-gnu).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CMAKE_C_COMPILER x86_64-linux-gnu-gcc)
