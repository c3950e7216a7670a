"""The FMU from Python: its model description, an instance, a run, the result, the FMU handed on.

_model parses an FMU file once per version (FmuModel, fmu_model); _parameters reads its variables
and defaults; _instance is one FMI instance (opened, initialized, its messages kept); _simulate runs
a schedule through it, in Python or in the native loop (_native_loop loads _cs_loop.c, compiled
beside it, with ctypes); _results is the one result format every tool returns (its fields the
FMU's recorded variables). _export hands a user the FMU; _cross_check writes its results in the
FMI cross-check layout. _linearize asks an instance for its directional derivatives at an
operating point: A, B, C, D (linearize).
_build_record is what an FMU records of how it was made (its build.json), and its archive
written the same way every time.
_signing reads the Ed25519 keys an FMU's record is signed and checked with.
_wasm runs the FMU's WebAssembly binary (FMI-LS-WASM) through wasmtime where fmpy runs the native
one: Co-Simulation for simulate(platform=WASM_PLATFORM), Model Exchange through fmpy's solver.

May import: signals/, the basics and the top's own names (default_fmu, FMU_FILES, __version__).
Not the reference, nor any tool or job: they all run the FMU through here.
"""

# The binaries folder of FMI-LS-WASM's WebAssembly component, a platform beside the native ones;
# here, where the command line reads it without loading fmpy.
WASM_PLATFORM = "wasm32-wasip2"
