"""The installed package's FMUs run by fmpy on this machine, each result judged against the
reference: what CI's platform jobs run on each runner after pip installs its wheel
(.github/workflows/platforms.yml).

    python .ci/platform_check.py [--output-dir platform-check]

Into output-dir it writes both FMUs (`pendulum-fmu export`, `--fmi-version 3`), the README quick
start's torque.csv, and for each case fmpy's result (`fmpy simulate`, 1 ms output) and the judge's
verdict on it (`pendulum-fmu judge --json`):

- FMI 2.0 Co-Simulation, as the quick start runs it;
- FMI 2.0 Model Exchange, under fmpy's CVode at a relative tolerance of 1e-12 (1e-10 leaves
  6e-9 rad, past the judge's 1e-9; 1e-12 left 2.2e-10 on Linux x86-64);
- FMI 3.0 Co-Simulation.

A case fmpy cannot run on this platform is not run, and says so: its Model Exchange where fmpy
ships no CVode for this platform, and FMI 2.0 on ARM64 Linux, where fmpy loads binaries/linux64
(x86-64's; docs/masters.md). Exit 0 when every case run passes, 1 when one fails.
The commands are the installed package's and fmpy's (this interpreter's scripts folder), run in
output-dir, so that the package under test is the installed wheel, not a checkout beside it.
"""

from __future__ import annotations

import argparse
import json
import platform
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

try:
    import fmpy
except ModuleNotFoundError:
    sys.exit("platform_check.py: no fmpy here: pip install the wheel first (it brings fmpy)")

TORQUE_CSV = "time,torque\n0,20\n1,20\n1,-20\n3,-20\n"
RUN_OPTIONS = ["--stop-time", "3", "--output-interval", "0.001"]
FMI2, FMI3 = "Pendulum.fmu", "Pendulum-fmi3.fmu"
ME_OPTIONS = ["--interface-type", "ModelExchange", "--solver", "CVode", "--relative-tolerance", "1e-12"]
CASES = {
    "fmi2-cs": ("FMI 2.0 Co-Simulation", FMI2, []),
    "fmi2-me": ("FMI 2.0 Model Exchange (CVode)", FMI2, ME_OPTIONS),
    "fmi3-cs": ("FMI 3.0 Co-Simulation", FMI3, []),
}


def script(name: str) -> str:
    """The installed console script of this interpreter (name.exe in Scripts on Windows)."""
    found = shutil.which(name, path=sysconfig.get_path("scripts"))
    if found is None:
        sys.exit(f"platform_check.py: no {name} in {sysconfig.get_path('scripts')}: pip install the wheel first")
    return found


def not_run_here(case: str) -> str | None:
    """Why fmpy cannot run the case on this platform, or None."""
    if fmpy.platform_tuple == "aarch64-linux" and case.startswith("fmi2"):
        return f"fmpy {fmpy.__version__} loads FMI 2.0 binaries from binaries/{fmpy.platform}, x86-64's, on ARM64 Linux"
    cvode = Path(fmpy.__file__).parent / "sundials" / fmpy.platform_tuple
    if case == "fmi2-me" and not cvode.is_dir():
        return f"fmpy {fmpy.__version__} ships no CVode for {fmpy.platform_tuple}"
    return None


def run(command: list[str], folder: Path) -> subprocess.CompletedProcess:
    """The command, shown as a shell line, run in folder, its output captured."""
    print("$", Path(command[0]).name, *command[1:], flush=True)
    return subprocess.run(command, cwd=folder, capture_output=True, text=True)


def check_case(case: str, folder: Path) -> str:
    """'pass', 'fail: why' or 'not run: why' for one case, its files in folder."""
    _, fmu, options = CASES[case]
    reason = not_run_here(case)
    if reason:
        return f"not run: {reason}"
    output = f"{case}.csv"
    simulate = [script("fmpy"), "simulate", fmu, *options, "--input-file", "torque.csv", *RUN_OPTIONS]
    simulated = run([*simulate, "--output-file", output], folder)
    if simulated.returncode:
        return f"fail: fmpy simulate exited {simulated.returncode}: {(simulated.stderr or simulated.stdout)[-1500:]}"
    judge = [script("pendulum-fmu"), "judge", output, "--torque-file", "torque.csv", "--json", f"{case}.json"]
    judged = run(judge, folder)
    print(judged.stdout, judged.stderr, sep="", end="", flush=True)
    if judged.returncode:
        return f"fail: the judge exited {judged.returncode}: {judged.stdout.splitlines()[0] if judged.stdout else ''}"
    return "pass"


def main(argv: list[str] | None = None) -> int:
    """Export, run and judge every case into --output-dir; 0 when every case run passed."""
    parser = argparse.ArgumentParser(prog="platform_check.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--output-dir", type=Path, default=Path("platform-check"), help="folder for the files")
    folder = parser.parse_args(argv).output_dir.resolve()
    folder.mkdir(parents=True, exist_ok=True)
    print(f"{platform.system()} {platform.machine()}, Python {platform.python_version()}, fmpy {fmpy.__version__}")
    (folder / "torque.csv").write_text(TORQUE_CSV, encoding="utf-8")
    for version in ("2", "3"):
        exported = run([script("pendulum-fmu"), "export", "--fmi-version", version, "--overwrite"], folder)
        print(exported.stdout, exported.stderr, sep="", end="", flush=True)
        if exported.returncode:
            print(f"platform_check.py: pendulum-fmu export --fmi-version {version} failed", file=sys.stderr)
            return 1
    verdicts = {case: check_case(case, folder) for case in CASES}
    (folder / "verdicts.json").write_text(json.dumps(verdicts, indent=1) + "\n", encoding="utf-8")
    for case, verdict in verdicts.items():
        print(f"{CASES[case][0]}: {verdict}")
    return 1 if any(verdict.startswith("fail") for verdict in verdicts.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
