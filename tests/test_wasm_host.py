"""The FMU's WebAssembly binary (wasm32-wasip2, FMI-LS-WASM) run by the package through wasmtime:
the numbers of its native FMI 3.0 binary, Co-Simulation and Model Exchange, on the seed case and the
quick start's jump; the reference's; the same commands; one-line refusals.
"""

import sys
import zipfile

import numpy as np
import pytest
from fmpy import simulate_fmu

from pendulum_fmu._errors import InvalidInput, MissingDependency
from pendulum_fmu.cli import main
from pendulum_fmu.comparing._compare_tools import parse_tools
from pendulum_fmu.fmu import WASM_PLATFORM
from pendulum_fmu.fmu._instance import FmuError, initialize, instantiated
from pendulum_fmu.fmu._model import FmuFileError, fmu_model
from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.oracle._reference import reference_schedule
from pendulum_fmu.signals._torque_schedule import schedule

wasm = pytest.importorskip("pendulum_fmu.fmu._wasm")
pytest.importorskip("wasmtime", reason="the wasm extra (wasmtime) is not installed")

BINARY = f"binaries/{WASM_PLATFORM}/Pendulum.wasm"
# The quick start's signal (README): 20 N.m, then -20 N.m from t = 1 s.
JUMP_CSV = "time,torque\n0,20\n1,20\n1,-20\n3,-20\n"


def jump_torque(time):
    """The quick start's signal as a callable of time."""
    return 20.0 if time < 1.0 else -20.0


@pytest.fixture(scope="module")
def wasm_fmu(fmu3):
    """The FMI 3.0 FMU of this checkout, which carries the wasm binary beside the native ones."""
    with zipfile.ZipFile(fmu3) as archive:
        if BINARY not in archive.namelist():
            pytest.skip(f"{fmu3.name} carries no {BINARY} (built without the wasm toolchain)")
    return fmu3


@pytest.fixture
def jump(tmp_path):
    path = tmp_path / "torque.csv"
    path.write_text(JUMP_CSV)
    return path


def _copy_without(fmu, tmp_path, leave_out, add=None):
    """A copy of an FMU without the entries leave_out(name) is true of, plus add {name: bytes}."""
    copy = tmp_path / "copy.fmu"
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(copy, "w") as target:
        for item in source.infolist():
            if not leave_out(item.filename):
                target.writestr(item, source.read(item))
        for name, data in (add or {}).items():
            target.writestr(name, data)
    return copy


@pytest.mark.parametrize("signal", ["seed", "jump"])
def test_co_simulation_is_the_native_binary_to_1e_12(wasm_fmu, jump, signal):
    torque = 20.0 if signal == "seed" else jump
    native = simulate(torque, stop_time=3.0, step_size=1e-3, fmu_path=wasm_fmu)
    ours = simulate(torque, stop_time=3.0, step_size=1e-3, fmu_path=wasm_fmu, platform=WASM_PLATFORM)
    assert ours.dtype == native.dtype and len(ours) == 3001
    assert np.array_equal(ours["time"], native["time"]) and np.array_equal(ours["torque"], native["torque"])
    assert np.max(np.abs(ours["theta"] - native["theta"])) <= 1e-12
    assert np.max(np.abs(ours["omega"] - native["omega"])) <= 1e-12
    # And the independent reference, as the native binary is held to it (test_fmi3.py).
    plan = schedule(torque, stop_time=3.0, step_size=1e-3)
    assert np.max(np.abs(ours["theta"] - reference_schedule(plan)["theta"])) < 1e-9


def test_model_exchange_is_the_native_binary_to_1e_12(wasm_fmu):
    model = fmu_model(wasm_fmu)
    signal = np.array([(0.0, 20.0), (1.0, 20.0), (1.0, -20.0), (3.0, -20.0)], dtype=[("time", "f8"), ("torque", "f8")])
    settings = dict(
        fmi_type="ModelExchange",
        solver="CVode",
        relative_tolerance=1e-10,
        stop_time=3.0,
        output_interval=1e-3,
        input=signal,
        output=["theta", "omega"],
    )
    native = simulate_fmu(str(wasm_fmu), **settings)
    ours = simulate_fmu(
        model.folder, model_description=model.description, fmu_instance=wasm.WasmModelExchange(model), **settings
    )
    assert np.array_equal(ours["time"], native["time"])
    assert np.max(np.abs(ours["theta"] - native["theta"])) <= 1e-12
    # CVode's theta at 1 ms points against the reference at its tolerance.
    plan = schedule(jump_torque, stop_time=3.0, step_size=1e-3)
    expected = reference_schedule(plan)["theta"]
    assert np.max(np.abs(ours["theta"][np.searchsorted(ours["time"], plan.time)] - expected)) < 1e-8


def test_simulate_command_runs_the_wasm_binary(wasm_fmu, tmp_path, capsys):
    output = tmp_path / "out.csv"
    status = main(
        ["simulate", "--torque", "20", "--fmu", str(wasm_fmu), "--platform", WASM_PLATFORM, "--output", str(output)]
    )
    assert status == 0
    written = np.genfromtxt(output, delimiter=",", names=True)
    native = simulate(20.0, fmu_path=wasm_fmu)
    assert np.max(np.abs(written["theta"] - native["theta"])) <= 1e-12
    assert "3000 steps to t = 3 s" in capsys.readouterr().out


def test_compare_runs_the_wasm_binary_as_a_tool(wasm_fmu):
    fmu, wasm_tool = parse_tools("fmu,wasm", fmu_path=wasm_fmu)
    plan = schedule(jump_torque, stop_time=3.0, step_size=1e-3)
    assert wasm_tool.label == "wasm"
    gap = np.max(np.abs(wasm_tool.run(plan)["theta"] - fmu.run(plan)["theta"]))
    assert gap <= 1e-12


def test_the_binary_logs_its_refusals_as_the_native_one(wasm_fmu):
    model = fmu_model(wasm_fmu)
    refusals = []
    for slave in (instantiated(model, "pendulum"), wasm.instantiated(model, "pendulum")):
        with pytest.raises(FmuError) as refused:
            initialize(slave, parameters={"mass": -1.0})
        refusals.append(str(refused.value))
        slave.freeInstance()
    assert "mass must be > 0" in refusals[0]
    assert refusals[1] == refusals[0]


def test_the_binary_imports_only_the_fmi_callbacks(wasm_fmu):
    import wasmtime

    model = fmu_model(wasm_fmu)
    component = wasmtime.component.Component.from_file(wasmtime.Engine(), f"{model.folder}/{BINARY}")
    imports = set(component.type.imports(wasmtime.Engine()))
    assert imports <= {"fmi:fmi3/types@3.0.0", wasm.CALLBACKS}


def test_a_missing_wasm_binary_is_one_line(wasm_fmu, tmp_path):
    native_only = _copy_without(wasm_fmu, tmp_path, lambda name: name == BINARY)
    with pytest.raises(FmuFileError, match=f"has no binary for {WASM_PLATFORM} \\({BINARY}\\)") as refused:
        simulate(20.0, stop_time=0.1, fmu_path=native_only, platform=WASM_PLATFORM)
    assert "\n" not in str(refused.value)


def test_an_fmi2_fmu_has_no_wasm_binary(fmu):
    with pytest.raises(FmuFileError, match=r"FMI 3\.0 only"):
        simulate(20.0, stop_time=0.1, fmu_path=fmu, platform=WASM_PLATFORM)


def test_a_wasm_only_fmu_names_the_platform_to_run_it(wasm_fmu, tmp_path, capsys):
    wasm_only = _copy_without(wasm_fmu, tmp_path, lambda name: name.startswith("binaries/") and name != BINARY)
    with pytest.raises(FmuFileError, match=f"--platform {WASM_PLATFORM}"):
        simulate(20.0, stop_time=0.1, fmu_path=wasm_only)
    run = simulate(20.0, stop_time=3.0, fmu_path=wasm_only, platform=WASM_PLATFORM)
    assert np.max(np.abs(run["theta"] - simulate(20.0, fmu_path=wasm_fmu)["theta"])) <= 1e-12
    with pytest.raises(InvalidInput, match=r"^the FMU refuses the parameters: mass must be > 0$"):
        simulate(20.0, stop_time=0.1, parameters={"mass": -1.0}, fmu_path=wasm_only, platform=WASM_PLATFORM)
    assert main(["simulate", "--torque", "20", "--fmu", str(wasm_only)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "run its WebAssembly binary instead" in line


def test_a_binary_that_is_no_component_is_one_line(wasm_fmu, tmp_path):
    broken = _copy_without(wasm_fmu, tmp_path, lambda name: name == BINARY, add={BINARY: b"\0asm not a component"})
    with pytest.raises(FmuFileError, match="is no WebAssembly component wasmtime can load") as refused:
        simulate(20.0, stop_time=0.1, fmu_path=broken, platform=WASM_PLATFORM)
    assert "\n" not in str(refused.value)


def test_an_unknown_platform_is_refused():
    with pytest.raises(InvalidInput, match="platform 'wasm64' is none the package runs"):
        simulate(20.0, stop_time=0.1, platform="wasm64")


def test_without_wasmtime_the_refusal_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "wasmtime", None)  # import wasmtime raises ImportError
    with pytest.raises(MissingDependency, match=r'needs the wasmtime package: pip install "\.\[wasm\]"'):
        wasm.wasmtime_module()


def test_a_held_torque_only(wasm_fmu, tmp_path):
    ramp = tmp_path / "ramp.csv"
    ramp.write_text("time,torque\n0,0\n3,30\n")
    with pytest.raises(InvalidInput, match=r"FMI 3\.0 has no input derivatives"):
        simulate(ramp, ramp=True, fmu_path=wasm_fmu, platform=WASM_PLATFORM)


def test_a_trap_in_a_step_is_one_line_naming_the_step(wasm_fmu):
    import wasmtime

    model = fmu_model(wasm_fmu)
    slave = wasm.instantiated(model, "pendulum")
    initialize(slave)
    name = "[method]co-simulation-instance.do-step"
    step = slave.function(name)
    calls = []

    def trapping(store, resource, t, h, rollback):
        calls.append(t)
        if len(calls) == 3:  # as the binary's own trap would arrive: a WasmtimeError out of the call
            raise wasmtime.WasmtimeError("error while executing at wasm backtrace:\n    0: 0x1234 - <unknown>!do_step")
        return step(store, resource, t, h, rollback)

    slave._functions[name] = trapping
    with pytest.raises(FmuError) as stopped:
        wasm.run_schedule(slave, schedule(20.0, stop_time=0.01, step_size=1e-3))
    assert str(stopped.value) == (
        f"the step from t = 0.002: the {WASM_PLATFORM} binary stopped: error while executing at wasm backtrace:"
    )
    slave.freeInstance()


def test_compare_without_an_fmu_runs_the_packages_fmi3_wasm_binary(tmp_path):
    from pendulum_fmu import compare, default_fmu

    with zipfile.ZipFile(default_fmu(3)) as archive:
        if BINARY not in archive.namelist():
            pytest.skip(f"{default_fmu(3)} carries no {BINARY} (built without the wasm toolchain)")
    comparison = compare(20.0, "fmu,wasm", output_dir=tmp_path, stop_time=1.0)
    assert np.max(np.abs(comparison.runs["fmu"]["theta"] - comparison.runs["wasm"]["theta"])) <= 1e-12


def test_a_log_message_is_kept_on_one_line_and_bounded(wasm_fmu):
    slave = wasm.instantiated(fmu_model(wasm_fmu), "pendulum")
    slave._log(None, "pendulum", "error", "logStatusError", "two\nlines")
    slave._log(None, "pendulum", "warning", "logStatusWarning", "x" * 5000)
    assert slave.messages.lines == ["[ERROR] 'two\\nlines'", f"[WARNING] {'x' * 1000}... (5,000 characters)"]
    slave.freeInstance()
