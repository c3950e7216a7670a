# Windows x86-64 (FMI 2.0 win64, FMI 3.0 x86_64-windows) from Linux: Debian's mingw-w64 gcc
# (apt-get install gcc-mingw-w64-x86-64); with ZIG (the zig executable, which fmu_build/ passes
# where that gcc is missing), zig's C compiler for x86_64-windows-gnu, which brings its own
# mingw-w64 headers and import libraries.
# The project's try_compile checks read this file again without the cache: cmake/zig.cmake
# carries ZIG to them in the environment.
if(ZIG OR DEFINED ENV{ZIG})
    set(ZIG_TARGET x86_64-windows-gnu)
    include("${CMAKE_CURRENT_LIST_DIR}/zig.cmake")
    # No debug information, as mingw's gcc writes none by default.
    set(CMAKE_C_FLAGS_INIT -g0)
else()
    set(CMAKE_SYSTEM_NAME Windows)
    set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc)
endif()
set(CMAKE_SYSTEM_PROCESSOR AMD64)
