# Windows x86-64 (FMI 2.0 win64, FMI 3.0 x86_64-windows) from Linux: Debian's mingw-w64 gcc
# (apt-get install gcc-mingw-w64-x86-64).
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR AMD64)
set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc)
