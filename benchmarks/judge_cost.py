"""The judge beside the run it judges (issue 42), each as a user runs it: a new process, end to end.

The README quick start's run, `fmpy simulate` of the FMU under the jump torque file (3 s, 1 ms),
beside `pendulum-fmu judge` of the result it wrote (with --fmu naming the FMU fmpy ran), taking
turns; then 100 results of that run
(the result with rounding-sized and with failing changes to theta) judged in one call beside one
result. Each figure is the median of the repeats; the load average is printed with them.

    .venv/bin/python -m benchmarks.judge_cost [--repeats 5] [--checkout DIR]

--checkout DIR measures the judge of another checkout (main's, for the figures before a change):
its package on PYTHONPATH, the FMU, the signal and the results made here. A judge that takes one
result per call (before issue 42) is given the 100 results through its judge() in one Python
process, the fastest it offers. Also part of `python -m benchmarks --only judge`.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .report import Row
from .timing import interleaved, median

PART = "judge"
HERE = Path(__file__).resolve().parent.parent
RESULTS = 100
# The quick start's run (README.md): 20 N.m for a second, then -20 N.m, 1 ms steps to 3 s.
TORQUE_CSV = "time,torque\n0,20\n1,20\n1,-20\n3,-20\n"
FMPY_RUN = ["simulate", "Pendulum.fmu", "--input-file", "torque.csv", "--stop-time", "3"]
FMPY_RUN += ["--output-interval", "0.001", "--output-file", "out.csv"]
# The FMU fmpy ran, named: the judge of a checkout would otherwise look its own build up.
JUDGE = ["judge", "out.csv", "--torque-file", "torque.csv", "--fmu", "Pendulum.fmu"]
# 100 results through judge() in one process, for a judge that takes one result per call.
JUDGE_LOOP = (
    "import sys; from pendulum_fmu import judge; "
    "[judge(path, 'torque.csv', fmu_path='Pendulum.fmu') for path in sys.argv[1:]]"
)
# Targets (issue 42): one result in at most 1.5 times fmpy's run of it; 100 in at most 10 times one.
ONE_TARGET, MANY_TARGET = 1.5, 10.0


def _command(folder: Path, argv: list[str], checkout: Path) -> float:
    """Seconds of one command run in folder, with checkout's package first on the path."""
    environment = {**os.environ, "PYTHONPATH": str(checkout)}
    started = time.perf_counter()
    done = subprocess.run(argv, cwd=folder, env=environment, capture_output=True, text=True)
    seconds = time.perf_counter() - started
    if done.returncode not in (0, 1):  # 1: a result that fails, as some of the 100 do
        raise RuntimeError(f"{' '.join(argv)} exited {done.returncode}: {done.stderr.strip()[-500:]}")
    return seconds


def _prepare(folder: Path) -> list[str]:
    """The quick start in folder (the FMU, its signal, fmpy's result) and RESULTS results of
    that run: rounding-sized changes to theta, every tenth one 1e-6 rad off (it fails).
    """
    python = [sys.executable, "-m", "pendulum_fmu"]
    subprocess.run(
        [*python, "export"], cwd=folder, check=True, capture_output=True, env={**os.environ, "PYTHONPATH": str(HERE)}
    )
    (folder / "torque.csv").write_text(TORQUE_CSV)
    subprocess.run([str(Path(sys.executable).parent / "fmpy"), *FMPY_RUN], cwd=folder, check=True, capture_output=True)
    header, *rows = (folder / "out.csv").read_text().splitlines()
    values = np.array([[float(cell) for cell in row.split(",")] for row in rows])
    names = []
    for number in range(RESULTS):
        changed = values.copy()
        changed[:, 1] += 1e-6 if number % 10 == 9 else number * 1e-13
        names.append(f"result_{number:03d}.csv")
        lines = [header, *(",".join(repr(float(cell)) for cell in row) for row in changed)]
        (folder / names[-1]).write_text("\n".join(lines) + "\n")
    return names


def _takes_many(folder: Path, checkout: Path, names: list[str]) -> bool:
    """Whether the checkout's judge takes several results in one call."""
    argv = [sys.executable, "-m", "pendulum_fmu", *JUDGE[:1], *names[:2], *JUDGE[2:]]
    environment = {**os.environ, "PYTHONPATH": str(checkout)}
    return subprocess.run(argv, cwd=folder, env=environment, capture_output=True).returncode in (0, 1)


def measure(repeats: int, checkout: Path) -> dict:
    """Seconds per repeat of: fmpy's run, the judge of its result, the judge of RESULTS results
    and the imports alone of numpy and scipy.integrate (the least a judge on solve_ivp takes).
    """
    with tempfile.TemporaryDirectory(prefix="pendulum-judge-cost-") as scratch:
        folder = Path(scratch)
        names = _prepare(folder)
        many = _takes_many(folder, checkout, names)
        python = [sys.executable, "-m", "pendulum_fmu"]
        hundred = [*python, JUDGE[0], *names, *JUDGE[2:]] if many else [sys.executable, "-c", JUDGE_LOOP, *names]
        contenders = {
            "fmpy simulate": lambda: _command(folder, [str(Path(sys.executable).parent / "fmpy"), *FMPY_RUN], checkout),
            "judge one": lambda: _command(folder, [*python, *JUDGE], checkout),
            "judge 100": lambda: _command(folder, hundred, checkout),
            "imports": lambda: _command(folder, [sys.executable, "-c", "import numpy, scipy.integrate"], checkout),
        }
        load = os.getloadavg()[0]
        seconds = interleaved(contenders, repeats)
    return {"seconds": seconds, "many": many, "load": (load, os.getloadavg()[0])}


def judge_cost_rows(repeats: int, checkout: Path = HERE) -> list[Row]:
    """The rows of python -m benchmarks: the medians and both ratios against their targets."""
    measured = measure(repeats, checkout)
    seconds = {name: median(values) for name, values in measured["seconds"].items()}
    how = "in one call" if measured["many"] else "through judge() in one process"
    one_ratio, many_ratio = seconds["judge one"] / seconds["fmpy simulate"], seconds["judge 100"] / seconds["judge one"]
    return [
        Row(
            PART, "fmpy simulate of the quick start's run (3 s, 1 ms), end to end", f"{seconds['fmpy simulate']:.2f} s"
        ),
        Row(PART, "pendulum-fmu judge of its result, end to end", f"{seconds['judge one']:.2f} s"),
        Row(PART, "  judge / fmpy's run", f"{one_ratio:.2f}", f"<= {ONE_TARGET}", one_ratio <= ONE_TARGET),
        Row(PART, f"{RESULTS} results of that run judged {how}", f"{seconds['judge 100']:.2f} s"),
        Row(PART, f"  {RESULTS} results / one", f"{many_ratio:.2f}", f"<= {MANY_TARGET}", many_ratio <= MANY_TARGET),
        Row(PART, "python importing numpy and scipy.integrate alone", f"{seconds['imports']:.2f} s"),
        Row(PART, "load average before, after", "{:.1f}, {:.1f}".format(*measured["load"])),
    ]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.judge_cost", description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs of each command, taking turns (default: 5)")
    parser.add_argument("--checkout", type=Path, default=HERE, help="the checkout whose judge is measured")
    args = parser.parse_args(argv)
    rows = judge_cost_rows(args.repeats, args.checkout.resolve())
    print(f"the judge of {args.checkout.resolve()}, median of {args.repeats} (python {sys.version.split()[0]}):")
    for row in rows:
        target = f"  (target {row.target}: {row.verdict})" if row.target else ""
        print(f"  {row.measure:<66} {row.value:>10}{target}")


if __name__ == "__main__":
    main()
