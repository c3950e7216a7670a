# The project's C flags, link-time optimization and export rule, for every C binary it builds:
# included by CMakeLists.txt and by the benchmarks' null FMU (benchmarks/null_fmu/).

# Without FMA contraction (clang contracts a*b+c by default, on arm64 for instance; gcc's
# -std=c99 does not) every compiler rounds alike, so a binary built by one gives the numbers of a
# binary built by another.
set(CMAKE_C_STANDARD 99)
set(CMAKE_C_STANDARD_REQUIRED ON)
set(CMAKE_C_EXTENSIONS OFF)
set(CMAKE_C_VISIBILITY_PRESET hidden)
# -O3 unrolls the Taylor integrator's loops (bounded by the states and the series' order): a 1 ms
# step takes fewer instructions than at -O2 (benchmarks/callgrind.py).
if(MSVC)
    add_compile_options(/O2 /W3)
else()
    add_compile_options(-O3 -Wall -Wextra -Werror -ffp-contract=off)
endif()

# Link-time optimization lets the integrator inline the model's right-hand side across files,
# where the toolchain links with it (zig's Mach-O linker does not, a gcc without its LTO plug-in
# does not).
include(CheckIPOSupported)
check_ipo_supported(RESULT LTO LANGUAGES C)
if(LTO)
    set(CMAKE_INTERPROCEDURAL_OPTIMIZATION ON)
else()
    message(STATUS "no link-time optimization: the toolchain does not link with it")
endif()

# Makes target a library that exports the functions named <prefix>* and nothing else: on
# Windows the ones marked __declspec(dllexport), elsewhere the ones of default visibility, and
# on ELF a version script says so to the linker too. Its file name has no "lib" prefix; on macOS
# its install name is its own file name, as in the Reference FMUs.
function(export_only target prefix)
    if(APPLE)
        set_target_properties(${target} PROPERTIES NO_SONAME ON)
        target_link_options(${target} PRIVATE "LINKER:-install_name,$<TARGET_FILE_NAME:${target}>")
        # Without the debug map (stabs naming each object file and source by its absolute path,
        # which differ from build folder to build folder), so one commit gives the same bytes.
        target_link_options(${target} PRIVATE -s)
    elseif(MINGW)
        # No dependency on the mingw runtime DLLs: the binary loads on any Windows.
        target_link_options(${target} PRIVATE -static-libgcc -s)
        # No link time in the PE header, so one commit gives the same bytes: GNU ld's option, or
        # for zig's linker (LLD, which refuses GNU ld's) -Brepro, a hash of the content in its place.
        if(CMAKE_C_COMPILER_ID STREQUAL "GNU")
            target_link_options(${target} PRIVATE "LINKER:--no-insert-timestamp")
        else()
            target_link_options(${target} PRIVATE "LINKER:-Brepro")
        endif()
    elseif(UNIX AND NOT APPLE)
        set(script "${CMAKE_CURRENT_BINARY_DIR}/${target}.exports.map")
        file(WRITE "${script}" "{ global: ${prefix}*; local: *; };\n")
        target_link_options(${target} PRIVATE "LINKER:--version-script=${script}")
        # zig's without debug sections: it links in its glibc stubs (libc_nonshared) with their
        # DWARF, which names zig's install folder and the build folder; so one commit gives the
        # same bytes. (gcc links none: its builds, and their records, stay as they are.)
        if(NOT CMAKE_C_COMPILER_ID STREQUAL "GNU")
            target_link_options(${target} PRIVATE "LINKER:--strip-debug")
        endif()
        set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS "${script}")
        target_link_libraries(${target} PRIVATE m)
    endif()
    set_target_properties(${target} PROPERTIES PREFIX "")
endfunction()
