# macOS on Intel (FMI 3.0 x86_64-darwin, the x86_64 slice of FMI 2.0 darwin64), from macOS 10.13.
# On a Mac the host's compiler builds it; elsewhere zig's C compiler.
set(CMAKE_OSX_ARCHITECTURES x86_64 CACHE STRING "")
set(CMAKE_OSX_DEPLOYMENT_TARGET 10.13 CACHE STRING "")
if(NOT CMAKE_HOST_SYSTEM_NAME STREQUAL "Darwin")
    set(ZIG_TARGET "x86_64-macos.${CMAKE_OSX_DEPLOYMENT_TARGET}")
    include("${CMAKE_CURRENT_LIST_DIR}/zig.cmake")
endif()
