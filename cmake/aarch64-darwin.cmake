# macOS on Apple Silicon (FMI 3.0 aarch64-darwin, the arm64 slice of FMI 2.0 darwin64), from
# macOS 11.0 (the first on Apple Silicon). On a Mac the host's compiler builds it; elsewhere zig's
# C compiler, whose linker signs the binary ad hoc, as Apple Silicon requires of any code it runs.
set(CMAKE_OSX_ARCHITECTURES arm64 CACHE STRING "")
set(CMAKE_OSX_DEPLOYMENT_TARGET 11.0 CACHE STRING "")
if(NOT CMAKE_HOST_SYSTEM_NAME STREQUAL "Darwin")
    set(ZIG_TARGET "aarch64-macos.${CMAKE_OSX_DEPLOYMENT_TARGET}")
    include("${CMAKE_CURRENT_LIST_DIR}/zig.cmake")
endif()
