# The FMU's WebAssembly component (FMI-LS-WASM, binaries/wasm32-wasip2), on any machine: zig's C
# compiler builds its core module for wasm32-wasi (zig brings wasi-libc) and cmake/wasm.cmake
# makes the component of it with wasm-tools (WASM_TOOLS, or wasm-tools on PATH).
set(ZIG_TARGET wasm32-wasi)
include("${CMAKE_CURRENT_LIST_DIR}/zig.cmake")
