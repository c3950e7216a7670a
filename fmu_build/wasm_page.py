"""The files of the docs page that runs the FMU's wasm binary in the browser, and of the Node host.

    python -m fmu_build.wasm_page OUT_DIR [--fmu Pendulum-fmi3.fmu]

From the FMI 3.0 FMU (default: the checkout's, pendulum_fmu.default_fmu(3)) it writes into OUT_DIR:

- fmu.js and its core wasm files: `jco transpile --instantiation async` of the FMU's
  binaries/wasm32-wasip2/<modelIdentifier>.wasm (FMI-LS-WASM), an ES module whose instantiate()
  takes the FMI callbacks from the host;
- fmu.json: the model identifier, the instantiation token and the value references of torque,
  theta, omega and alpha, from the FMU's modelDescription.xml;
- native.json: theta of the FMU's native binary on the signals the page compares against (the seed
  case and the quick start's jump), with the schedule each ran, so the page shows one only beside
  a run of the very same schedule;
- fmu_host.js, page.js and run_node.js from web/: the host (shared by the page and Node), the page's
  script, the Node command line.

jco comes from web/package-lock.json: where web/node_modules has no jco yet (a fresh clone), this
module runs `npm ci --prefix web` first, which needs Node 20's npm and the npm registry. The docs
build (docs/_ext/wasm_page.py) runs this module, so the README's one docs command is the whole of it.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

from pendulum_fmu._errors import BuildError

from .sources import ROOT

WEB = ROOT / "web"
# What the page and the Node command take from web/ as they are.
HOST_FILES = ("fmu_host.js", "page.js", "run_node.js")
RECORDED = ("torque", "theta", "omega", "alpha")
# The signals whose native result the page ships: the seed case and the README quick start's jump.
STOP_TIME, STEP_SIZE = 3.0, 1e-3
NATIVE_CASES = {
    "seed": {"kind": "constant", "value": 20.0},
    "quick start's jump": {"kind": "step", "before": 20.0, "after": -20.0, "at": 1.0},
}


def _jco(web: Path = WEB) -> Path:
    """The jco of the folder web, installed from its package-lock.json (`npm ci`) when missing."""
    jco = web / "node_modules" / ".bin" / "jco"
    if shutil.which("node") is None or shutil.which("npm") is None:
        raise BuildError("node or npm is not on PATH: install Node 20 and npm to build the wasm page")
    if not jco.is_file():
        print(f"installing jco: npm ci --prefix {web}", file=sys.stderr, flush=True)
        command = [shutil.which("npm"), "ci", "--prefix", str(web), "--no-audit", "--no-fund"]
        done = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
        if done.returncode or not jco.is_file():
            last = (done.stderr.strip() or done.stdout.strip() or "no jco after it").splitlines()[-1]
            raise BuildError(f"`npm ci --prefix {web}` failed (it needs the npm registry): {last}")
    return jco


def fmu_description(fmu: zipfile.ZipFile, fmu_name: str) -> dict:
    """The model identifier, instantiation token and value references the hosts need, from an
    FMI 3.0 FMU's modelDescription.xml.

    Parameters
    ----------
    fmu : zipfile.ZipFile
        The FMU, open.
    fmu_name : str
        Its path, for the messages.

    Returns
    -------
    dict
        modelIdentifier, instantiationToken and valueReferences (torque, theta, omega, alpha).

    Raises
    ------
    BuildError
        Not an FMI 3.0 Co-Simulation FMU with those variables.
    """
    root = ET.fromstring(fmu.read("modelDescription.xml"))
    co_simulation = root.find("CoSimulation")
    if root.get("fmiVersion") != "3.0" or co_simulation is None:
        raise BuildError(f"{fmu_name}: not an FMI 3.0 Co-Simulation FMU; give the FMI 3.0 one (Pendulum-fmi3.fmu)")
    references = {v.get("name"): int(v.get("valueReference", -1)) for v in root.find("ModelVariables") or ()}
    missing = [name for name in RECORDED if name not in references]
    if missing:
        raise BuildError(f"{fmu_name}: no variable {', '.join(missing)} in its modelDescription.xml")
    return {
        "modelIdentifier": co_simulation.get("modelIdentifier"),
        "instantiationToken": root.get("instantiationToken"),
        "valueReferences": {name: references[name] for name in RECORDED},
    }


def transpile(fmu_path: Path, out_dir: Path) -> dict:
    """Transpile the FMU's wasm component with jco: its ES module in out_dir (fmu.js, its core wasm files) and
    fmu.json beside it; returns what fmu.json holds (see fmu_description).

    Parameters
    ----------
    fmu_path : Path
        An FMI 3.0 FMU carrying binaries/wasm32-wasip2/<modelIdentifier>.wasm.
    out_dir : Path
        The folder to write into (made when missing).

    Returns
    -------
    dict
        The FMU's description, as fmu.json holds it.

    Raises
    ------
    BuildError
        No wasm binary in the FMU, Node or jco missing, or jco failing (its message included).
    """
    jco = _jco()
    with zipfile.ZipFile(fmu_path) as fmu:
        description = fmu_description(fmu, str(fmu_path))
        member = f"binaries/wasm32-wasip2/{description['modelIdentifier']}.wasm"
        if member not in fmu.namelist():
            raise BuildError(f"{fmu_path}: no {member}; build the FMI 3.0 FMU with its wasm binary")
        component = fmu.read(member)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        wasm = Path(scratch, "fmu.wasm")
        wasm.write_bytes(component)
        command = [str(jco), "transpile", str(wasm), "--name", "fmu", "--instantiation", "async"]
        # --minify: the page loads 381 kB of JavaScript instead of 861 kB.
        command += ["--no-typescript", "--minify", "--quiet", "-o", str(out_dir)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
    if done.returncode:
        raise BuildError(f"jco transpile of {member} failed: {done.stderr.strip()[-2000:]}")
    # Node reads the module as ES (import/export) only under a package.json saying so.
    (out_dir / "package.json").write_text('{"type": "module"}\n', encoding="utf-8")
    (out_dir / "fmu.json").write_text(json.dumps(description, indent=1) + "\n", encoding="utf-8")
    return description


def native_results(fmu_path: Path) -> dict:
    """The theta of the FMU's native binary on each of NATIVE_CASES, with the schedule it ran.

    Parameters
    ----------
    fmu_path : Path
        The FMI 3.0 FMU, whose binary for this machine runs.

    Returns
    -------
    dict
        name: {signal, stopTime, stepSize, time, torque (per step), theta}.
    """
    import numpy as np

    from pendulum_fmu import schedule, simulate
    from pendulum_fmu.signals._torque_csv import TorqueTable

    cases = {}
    for name, signal in NATIVE_CASES.items():
        if signal["kind"] == "constant":
            torque = signal["value"]
        else:
            times = np.array([signal["at"], signal["at"]])
            torque = TorqueTable(times, np.array([signal["before"], signal["after"]]))
        plan = schedule(torque, stop_time=STOP_TIME, step_size=STEP_SIZE)
        run = simulate(torque, stop_time=STOP_TIME, step_size=STEP_SIZE, fmu_path=fmu_path)
        cases[name] = {
            "signal": signal,
            "stopTime": STOP_TIME,
            "stepSize": STEP_SIZE,
            "time": plan.time.tolist(),
            "torque": plan.torque.tolist(),
            "theta": run["theta"].tolist(),
        }
    return cases


def write_page_files(fmu_path: str | Path, out_dir: str | Path) -> dict:
    """Every file of the wasm page and the Node host in out_dir (see the module's docstring).

    Parameters
    ----------
    fmu_path : str or Path
        The FMI 3.0 FMU with its wasm binary.
    out_dir : str or Path
        The folder to write into.

    Returns
    -------
    dict
        The FMU's description (fmu.json).

    Raises
    ------
    BuildError
        See transpile.
    """
    fmu_path, out_dir = Path(fmu_path), Path(out_dir)
    description = transpile(fmu_path, out_dir)
    (out_dir / "native.json").write_text(json.dumps(native_results(fmu_path)) + "\n", encoding="utf-8")
    for name in HOST_FILES:
        shutil.copyfile(WEB / name, out_dir / name)
    return description


def main(argv: list[str] | None = None) -> int:
    """The command line (see the module's docstring); a failure is one line on stderr, status 1."""
    parser = argparse.ArgumentParser(prog="python -m fmu_build.wasm_page", description=__doc__.split("\n")[0])
    parser.add_argument("out_dir", type=Path, help="the folder to write the page's files into")
    parser.add_argument("--fmu", type=Path, help="the FMI 3.0 FMU (default: the checkout's, built when stale)")
    arguments = parser.parse_args(argv)
    try:
        from pendulum_fmu import default_fmu

        fmu = arguments.fmu or Path(default_fmu(3))
        description = write_page_files(fmu, arguments.out_dir)
    except BuildError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    print(f"{arguments.out_dir}: the page's files for {description['modelIdentifier']} from {fmu}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
