# zig's C compiler (PyPI ziglang: pip install ziglang) for the target ZIG_TARGET, a zig target
# triple such as aarch64-macos.11.0 (the minimum OS version is part of it) or aarch64-linux-gnu.
# zig brings each target's libc headers and link stubs, so no SDK or sysroot is needed for plain C.
# ZIG is the zig executable (fmu_build/ passes the one in the ziglang package).
# The project's try_compile checks (CheckIPOSupported) read this file again without the cache:
# the environment carries ZIG and ZIG_TARGET to them.
foreach(variable ZIG_TARGET ZIG)
    if(${variable})
        set(ENV{${variable}} "${${variable}}")
    elseif(DEFINED ENV{${variable}})
        set(${variable} "$ENV{${variable}}")
    endif()
endforeach()
if(NOT ZIG_TARGET)
    message(FATAL_ERROR "cmake/zig.cmake needs ZIG_TARGET, a zig target such as aarch64-macos.11.0")
endif()
if(NOT ZIG)
    find_program(ZIG zig REQUIRED)
endif()

if(ZIG_TARGET MATCHES "-macos")
    set(CMAKE_SYSTEM_NAME Darwin)
elseif(ZIG_TARGET MATCHES "-windows")
    set(CMAKE_SYSTEM_NAME Windows)
elseif(ZIG_TARGET MATCHES "^wasm32-")
    # No operating system (CMake 3.25 knows none called WASI): executables only, no suffix.
    set(CMAKE_SYSTEM_NAME Generic)
else()
    set(CMAKE_SYSTEM_NAME Linux)
endif()
string(REGEX MATCH "^[^-]+" CMAKE_SYSTEM_PROCESSOR "${ZIG_TARGET}")
set(CMAKE_C_COMPILER "${ZIG}" cc -target "${ZIG_TARGET}")
