"""The FMU's wasm binary in Node (through jco) and in the docs page in headless Chromium, held to
the native FMI 3.0 binary on the same schedule: theta within 1e-12 rad at every point, through
Co-Simulation and (in Node) Model Exchange.

The native runs are pendulum_fmu.simulate() of the FMI 3.0 FMU's linux64 binary, an independent
host (fmpy's loader, ctypes) of an independent build (gcc) of the same C sources.
"""

import ctypes
import json
import os
import shutil
import struct
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
import wasm_page
from test_docs import _built_site

from fmu_build import wasm_page as wasm_page_build
from fmu_build.wasm_page import WEB, write_page_files
from pendulum_fmu import schedule, simulate
from pendulum_fmu._errors import BuildError
from pendulum_fmu.judging._result_file import read_result

ROOT = Path(__file__).resolve().parent.parent
SCREENSHOT = ROOT / "docs" / "images" / "wasm_page.png"
THETA_TOLERANCE = 1e-12  # rad, the bar for every host of the wasm binary
SEED = {"torque": 20.0, "stop_time": 3.0, "step_size": 1e-3}
JUMP_CSV = "time,torque\n0,20\n1,20\n1,-20\n3,-20\n"  # the README quick start's
BAD_CSV = b"time,torque\n0,1\n0.5,x\n"


def _need_node() -> None:
    if shutil.which("node") is None:
        pytest.skip("needs Node 20 (node on PATH)")
    if not (WEB / "node_modules" / ".bin" / "jco").is_file():
        pytest.skip("needs jco: npm ci --prefix web")


def _fake_npm(folder: Path, monkeypatch, script: str) -> Path:
    """A bin folder first on PATH holding node and an npm that runs script (bash), logging its arguments."""
    bin_folder = folder / "bin"
    bin_folder.mkdir()
    for name, body in {"node": "exit 0", "npm": f'echo "$@" >> {folder}/npm.log\n{script}'}.items():
        (bin_folder / name).write_text(f"#!/bin/bash\n{body}\n", encoding="utf-8")
        (bin_folder / name).chmod(0o755)
    monkeypatch.setenv("PATH", f"{bin_folder}:{os.environ['PATH']}")
    return folder / "npm.log"


def test_a_fresh_clone_s_jco_is_installed_by_npm_ci_from_the_lock_file(tmp_path, monkeypatch):
    web = tmp_path / "web"
    web.mkdir()
    log = _fake_npm(tmp_path, monkeypatch, 'mkdir -p "$3/node_modules/.bin" && touch "$3/node_modules/.bin/jco"')
    assert wasm_page_build._jco(web) == web / "node_modules" / ".bin" / "jco"
    assert log.read_text(encoding="utf-8").split() == ["ci", "--prefix", str(web), "--no-audit", "--no-fund"]
    wasm_page_build._jco(web)  # installed now: npm is not run again
    assert len(log.read_text(encoding="utf-8").splitlines()) == 1


def test_a_failed_jco_install_stops_the_page_in_one_line(tmp_path, monkeypatch):
    web = tmp_path / "web"
    web.mkdir()
    _fake_npm(tmp_path, monkeypatch, 'echo "npm error request to the registry failed" >&2; exit 1')
    with pytest.raises(BuildError) as failed:
        wasm_page_build._jco(web)
    assert str(failed.value) == (
        f"`npm ci --prefix {web}` failed (it needs the npm registry): npm error request to the registry failed"
    )


@pytest.fixture(scope="session")
def page_files(build_once, fmu3):
    """The page's files (jco's module, fmu.json, native.json, the scripts) from the session's FMI
    3.0 FMU, once per session.
    """
    _need_node()
    return build_once("wasm-page", lambda folder: (write_page_files(fmu3, folder), folder)[1])


@pytest.mark.node
def test_the_page_s_build_says_in_one_line_what_an_fmu_lacks(fmu, fmu3, tmp_path, capsys):
    _need_node()
    without_wasm = tmp_path / "no-wasm.fmu"
    with zipfile.ZipFile(fmu3) as source, zipfile.ZipFile(without_wasm, "w") as copy:
        for member in source.namelist():
            if not member.startswith("binaries/wasm32-wasip2/"):
                copy.writestr(member, source.read(member))
    expected = {
        without_wasm: f"error: {without_wasm}: no binaries/wasm32-wasip2/Pendulum.wasm; build the FMI 3.0 FMU "
        "with its wasm binary",
        Path(fmu): f"error: {fmu}: not an FMI 3.0 Co-Simulation FMU; give the FMI 3.0 one (Pendulum-fmi3.fmu)",
    }
    for given, message in expected.items():
        assert wasm_page_build.main([str(tmp_path / "out"), "--fmu", str(given)]) == 1
        assert capsys.readouterr().err == message + "\n"


def _native(torque, fmu3):
    return simulate(torque, stop_time=SEED["stop_time"], step_size=SEED["step_size"], fmu_path=fmu3)


def _node_run(page_files: Path, out: Path, *signal: str) -> dict:
    done = subprocess.run(
        ["node", str(WEB / "run_node.js"), str(page_files), *signal, "--output-file", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.mark.node
@pytest.mark.parametrize("case", ["seed", "jump"])
def test_node_runs_the_wasm_fmu_as_the_native_binary(page_files, fmu3, tmp_path, case):
    torque_file = tmp_path / "torque.csv"
    torque_file.write_text(JUMP_CSV)
    signal = ["--torque", "20"] if case == "seed" else ["--torque-file", str(torque_file)]
    printed = _node_run(page_files, tmp_path / "node.csv", *signal)
    native = _native(SEED["torque"] if case == "seed" else torque_file, fmu3)
    ran = read_result(tmp_path / "node.csv")
    # The same schedule (the JS host's grid and held torques are the package's), to the bit.
    assert np.array_equal(ran["time"], native["time"])
    torque = np.loadtxt(tmp_path / "node.csv", delimiter=",", skiprows=1, usecols=1)
    assert np.array_equal(torque, native["torque"])
    difference = np.max(np.abs(ran["theta"] - native["theta"]))
    print(f"{case}: theta(3 s) Node {printed['theta']!r}, native {native['theta'][-1]!r}, max |diff| {difference:.3g}")
    assert printed["theta"] == ran["theta"][-1]
    assert difference <= THETA_TOLERANCE
    assert not printed["messages"], printed["messages"]


def _native_model_exchange(fmu_path, plan, substeps: int, unzip_folder) -> np.ndarray:
    """Theta at every point of the native binary's Model Exchange interface under the JS host's
    integrator (fmu_host.js' rungeKuttaStep), the same operations in the same order through fmpy's
    ctypes bindings.
    """
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Model

    description = read_model_description(str(fmu_path))
    model = FMU3Model(
        guid=description.guid,
        unzipDirectory=extract(str(fmu_path), str(unzip_folder)),
        modelIdentifier=description.modelExchange.modelIdentifier,
        instanceName="pendulum",
    )
    references = {v.name: v.valueReference for v in description.modelVariables}
    count = description.numberOfContinuousStates
    buffer = (ctypes.c_double * count)()
    model.instantiate()
    model.enterInitializationMode(startTime=plan.time[0], stopTime=plan.time[-1])
    model.exitInitializationMode()
    model.updateDiscreteStates()
    model.enterContinuousTimeMode()
    model.getContinuousStates(buffer, count)
    state = np.array(buffer)

    def derivatives(t, x):
        model.setTime(t)
        model.setContinuousStates((ctypes.c_double * count)(*x), count)
        model.getContinuousStateDerivatives(buffer, count)
        return np.array(buffer)

    theta = []
    for k in range(len(plan.time) - 1):
        model.setFloat64([references["torque"]], [plan.torque[k]])
        derivatives(plan.time[k], state)
        theta.append(model.getFloat64([references["theta"]])[0])
        h = (plan.time[k + 1] - plan.time[k]) / substeps
        for j in range(substeps):
            t = plan.time[k] + j * h
            k1 = derivatives(t, state)
            k2 = derivatives(t + h / 2, state + (h / 2) * k1)
            k3 = derivatives(t + h / 2, state + (h / 2) * k2)
            k4 = derivatives(t + h, state + h * k3)
            state = state + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4)
            model.setContinuousStates((ctypes.c_double * count)(*state), count)
            model.completedIntegratorStep()
    derivatives(plan.time[-1], state)
    theta.append(model.getFloat64([references["theta"]])[0])
    model.terminate()
    model.freeInstance()
    return np.array(theta)


@pytest.mark.node
def test_node_runs_the_model_exchange_interface_as_the_native_binary(page_files, fmu3, tmp_path):
    """The component's model-exchange export under the host's Runge-Kutta (2 steps per 1 ms),
    against the native binary's Model Exchange under the same.
    """
    printed = _node_run(page_files, tmp_path / "node.csv", "--torque", "20", "--model-exchange", "2")
    plan = schedule(SEED["torque"], stop_time=SEED["stop_time"], step_size=SEED["step_size"])
    native = _native_model_exchange(fmu3, plan, 2, tmp_path / "unzipped")
    ran = read_result(tmp_path / "node.csv")
    difference = np.max(np.abs(ran["theta"] - native))
    print(f"Model Exchange: theta(3 s) Node {printed['theta']!r}, native {native[-1]!r}, max |diff| {difference:.3g}")
    assert difference <= THETA_TOLERANCE
    # And the integration itself is sound: within 1e-9 rad of the FMU's own Co-Simulation.
    assert abs(native[-1] - _native(SEED["torque"], fmu3)["theta"][-1]) < 1e-9


# Torque CSVs whose schedule the JS host must make as the package does: ramps, a jump between
# grid points (a point of its own) and a stop off the grid; a running-sum jump time within the
# event tolerance of a grid point (that point); a start off zero with a coarse step.
SCHEDULES = [
    ("time,torque\n0,0\n0.5,10\n1.00049,10\n1.00049,-3\n2,7\n", 0.0, 2.9995, 1e-3),
    ("time,torque\n0.1,5\n0.39100000000000029,5\n0.39100000000000029,-5\n1,2.5\n", 0.0, 1.0, 1e-3),
    ("time,torque\n0,1\n0.3,1\n0.3,2\n0.7,2\n0.7,0.25\n", 0.05, 1.3, 0.1),
]


@pytest.mark.node
@pytest.mark.parametrize(("csv", "start", "stop", "step"), SCHEDULES)
def test_the_js_host_s_schedule_is_the_package_s(tmp_path, csv, start, stop, step):
    if shutil.which("node") is None:
        pytest.skip("needs Node 20 (node on PATH)")
    torque_file = tmp_path / "torque.csv"
    torque_file.write_text(csv)
    script = (
        f"import {{ parseTorqueCsv, schedule }} from {json.dumps((WEB / 'fmu_host.js').as_uri())};"
        f"const rows = parseTorqueCsv({json.dumps(csv)});"
        f"console.log(JSON.stringify(schedule({{ kind: 'csv', rows }}, {start!r}, {stop!r}, {step!r})));"
    )
    done = subprocess.run(["node", "--input-type=module", "-e", script], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    made = json.loads(done.stdout)
    plan = schedule(torque_file, start_time=start, stop_time=stop, step_size=step)
    assert np.array_equal(made["time"], plan.time)
    assert np.array_equal(made["torque"], plan.torque)


@pytest.fixture(scope="module")
def chromium_runs(build_once, tmp_path_factory):
    """The built site's page in headless Chromium: what it showed after the seed case (then its
    CSV downloaded and a screenshot taken), after the quick start's jump (its step signal), after
    a bad torque CSV was dropped, and after the quick start's torque.csv was; and the folder
    holding the download and the screenshot.
    """
    pytest.importorskip("playwright", reason="needs Playwright's Python package (the [test] extra)")
    if not wasm_page.CHROMIUM.is_file():
        pytest.skip("needs Debian's chromium (apt-get install chromium)")
    _need_node()
    site = build_once("site", _built_site)
    folder = tmp_path_factory.mktemp("chromium")
    with wasm_page.served(site) as base_url, wasm_page.browser_page() as page:
        shown = {"seed": wasm_page.run_seed_case(page, base_url)}
        with page.expect_download() as download:
            page.click("#download")
        download.value.save_as(folder / "downloaded.csv")
        wasm_page.screenshot(page, folder / "page.png")
        shown["jump"] = wasm_page.run_case(page, "step")
        page.set_input_files("#torque-file", files=[{"name": "bad.csv", "mimeType": "text/csv", "buffer": BAD_CSV}])
        shown["bad csv"] = page.inner_text("#wasm-status.wasm-error")
        jump_file = {"name": "torque.csv", "mimeType": "text/csv", "buffer": JUMP_CSV.encode()}
        page.set_input_files("#torque-file", files=[jump_file])
        page.wait_for_selector("#wasm-status:not(.wasm-error)")
        shown["jump csv"] = wasm_page.run_case(page, "csv")
    return shown, folder


@pytest.mark.browser
def test_the_page_runs_the_seed_case_in_chromium_as_the_native_binary(chromium_runs, fmu3):
    shown = chromium_runs[0]["seed"]
    native = _native(SEED["torque"], fmu3)
    print(f"theta(3 s) Chromium {shown['theta']!r}, native {native['theta'][-1]!r}; page: {shown['status']}")
    assert not shown["errors"], shown["errors"]
    assert abs(shown["theta"] - native["theta"][-1]) <= THETA_TOLERANCE
    # The page found its shipped native run and drew the two together.
    assert shown["difference"] is not None and shown["difference"] <= THETA_TOLERANCE


@pytest.mark.browser
@pytest.mark.parametrize("given_as", ["jump", "jump csv"])
def test_the_page_runs_the_quick_start_s_jump_as_the_native_binary(chromium_runs, fmu3, tmp_path, given_as):
    """The jump as the page's step signal, and as the quick start's torque.csv dropped on it."""
    shown = chromium_runs[0][given_as]
    torque_file = tmp_path / "torque.csv"
    torque_file.write_text(JUMP_CSV)
    native = _native(torque_file, fmu3)
    assert abs(shown["theta"] - native["theta"][-1]) <= THETA_TOLERANCE
    assert shown["difference"] is not None and shown["difference"] <= THETA_TOLERANCE


@pytest.mark.browser
def test_the_page_says_in_one_line_what_is_wrong_with_a_dropped_csv(chromium_runs):
    assert chromium_runs[0]["bad csv"] == "bad.csv: line 3: '0.5,x' is not a time and a torque"


@pytest.mark.browser
def test_the_page_s_download_is_the_csv_judge_reads(chromium_runs, fmu3):
    downloaded = read_result(chromium_runs[1] / "downloaded.csv")
    native = _native(SEED["torque"], fmu3)
    assert np.array_equal(downloaded["time"], native["time"])
    assert np.max(np.abs(downloaded["theta"] - native["theta"])) <= THETA_TOLERANCE
    assert np.max(np.abs(downloaded["omega"] - native["omega"])) <= THETA_TOLERANCE


def _png_size(path: Path) -> tuple[int, int]:
    header = path.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    return struct.unpack(">II", header[16:24])


@pytest.mark.browser
def test_the_docs_screenshot_is_the_page_as_it_runs(chromium_runs):
    """The screenshot docs/browser.md shows is the page's app as tests/wasm_page.py takes it: the
    same size (its pixels differ with the fonts a machine has).
    """
    folder = chromium_runs[1]
    assert _png_size(SCREENSHOT) == _png_size(folder / "page.png"), (
        "docs/images/wasm_page.png is not the page as it runs now: remake it with "
        "`.venv/bin/python tests/wasm_page.py docs/_build/html docs/images/wasm_page.png`"
    )
