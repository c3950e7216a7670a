"""Long runs (issue 48): a result of millions of rows written, judged and compared, each as a user
runs it: a new process, end to end, its peak memory read by /usr/bin/time -v.

Per length (rows of a 1-ms run), taking turns, once each: `pendulum-fmu simulate` writing the
result, `fmpy simulate` of the same run (the exported FMU, the torque as a file), `pendulum-fmu
judge` of the result against that file, and `pendulum-fmu compare` of the run (the FMU and the
reference); the load average is printed with them. The torque is 20 N.m held (a file of two
rows), or with --torque per-step a file of a row per step, as a master records it: 20 N.m
sin(pi t), each step's value held.

    .venv/bin/python -m benchmarks.long_runs [--rows 1000 100000 3000000 30000000] [--torque per-step]

It prints TEMPLATE, the block docs/judging.md holds. Targets (issue 48): the judge at most 2 times
`pendulum-fmu simulate` of the run; the judge's and compare's peak memory under 256 MB.
"""

from __future__ import annotations

import argparse
import datetime
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .report import cpu_model

HERE = Path(__file__).resolve().parent.parent
ROWS = (1_000, 100_000, 3_000_000, 30_000_000)
STEP = 0.001
# A run over 10 million steps is refused unless asked for (--max-steps); then the stop time.
MAX_STEPS = ["--max-steps", "100000000"]
# The torques: the words TEMPLATE says them in.
TORQUES = {"constant": "a run of 20 N.m", "per-step": "a run of 20 N.m sin(pi t), a torque file row per step,"}
# Rows of the per-step torque file written at a time.
TORQUE_ROWS = 1 << 20
FMPY_OPTIONS = [
    "--input-file",
    "torque.csv",
    "--output-interval",
    str(STEP),
    "--output-file",
    "fmpy.csv",
    "--stop-time",
]
# Targets (issue 48): the judge of a result against simulate's run of it; peak memory.
JUDGE_TARGET, MEMORY_TARGET_MB = 2.0, 256

TEMPLATE = """Measured by `.venv/bin/python -m benchmarks.long_runs{options}` on {date}, on {machine} (python
{python}, load average {load} before, {load_after} after); {torque_text} in 1-ms steps, each
command (`pendulum-fmu COMMAND` but fmpy's) a new process, end to end, taking turns, once each;
seconds and peak memory (MB):

| rows | `simulate` | `fmpy simulate` | `judge` | judge / simulate | `compare` | peak MB: simulate, judge, compare |
| --- | --- | --- | --- | --- | --- | --- |
{table}

Targets: judge / simulate <= {judge_target} ({judge_held}); judge and compare under {memory_target} MB ({memory_held}).
"""


def _timed(argv: list[str], folder: Path) -> tuple[float, float]:
    """(seconds, peak MB) of one command run in folder, this checkout's package first."""
    report = folder / "time.txt"
    environment = {**os.environ, "PYTHONPATH": str(HERE)}
    done = subprocess.run(
        ["/usr/bin/time", "-o", str(report), "-f", "%e %M", *argv], cwd=folder, env=environment, capture_output=True
    )
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} exited {done.returncode}: {done.stderr.decode()[-500:]}")
    seconds, kilobytes = report.read_text().split()[-2:]
    return float(seconds), float(kilobytes) / 1024


def write_torque(path: Path, rows: int, torque: str) -> None:
    """The run's torque file: 20 N.m at its two ends, or a row per step (TORQUES)."""
    stop = (rows - 1) * STEP
    if torque == "constant":
        path.write_text(f"time,torque\n0,20\n{stop:.3f},20\n")
        return
    with open(path, "w") as file:
        file.write("time,torque\n")
        for start in range(0, rows, TORQUE_ROWS):
            times = np.arange(start, min(start + TORQUE_ROWS, rows)) * STEP
            np.savetxt(file, np.c_[times, 20.0 * np.sin(np.pi * times)], fmt=("%.3f", "%.17g"), delimiter=",")


def measure(rows: int, folder: Path, torque: str = "constant") -> dict[str, tuple[float, float]]:
    """{command: (seconds, peak MB)} for a run of `rows` rows under a torque of TORQUES, taking
    turns in folder.
    """
    stop = f"{(rows - 1) * STEP:.3f}"
    python = [sys.executable, "-m", "pendulum_fmu"]
    subprocess.run(
        [*python, "export"], cwd=folder, check=True, capture_output=True, env={**os.environ, "PYTHONPATH": str(HERE)}
    )
    write_torque(folder / "torque.csv", rows, torque)
    # A held torque is given as a number, as a user gives it; the judge reads the file either way.
    given = ["--torque", "20"] if torque == "constant" else ["--torque-file", "torque.csv"]
    run = [*given, *MAX_STEPS, "--stop-time", stop]
    commands = {
        "simulate": [*python, "simulate", "--output", "result.csv", *run],
        "fmpy": [str(Path(sys.executable).parent / "fmpy"), "simulate", "Pendulum.fmu", *FMPY_OPTIONS, stop],
        "judge": [*python, "judge", "result.csv", "--torque-file", "torque.csv", *MAX_STEPS, "--json", "verdict.json"],
        "compare": [*python, "compare", "--tools", "fmu,reference", "--output-dir", "compared", *run],
    }
    return {name: _timed(argv, folder) for name, argv in commands.items()}


def template_figures(
    measured: dict[int, dict[str, tuple[float, float]]],
    load: tuple[float, float],
    options: str = "",
    torque: str = "constant",
) -> dict[str, str]:
    """The figures of TEMPLATE from measure()'s, a row per length; options, the command's;
    torque, the run's (TORQUES).
    """
    lines, ratios, peaks = [], [], []
    for rows, figures in measured.items():
        (simulate, simulate_mb), (fmpy, _), (judge, judge_mb), (compare, compare_mb) = (
            figures[name] for name in ("simulate", "fmpy", "judge", "compare")
        )
        ratios.append(judge / simulate)
        peaks += [judge_mb, compare_mb]
        lines.append(
            f"| {rows:,} | {simulate:.2f} s | {fmpy:.2f} s | {judge:.2f} s | {judge / simulate:.2f} | "
            f"{compare:.2f} s | {simulate_mb:.0f}, {judge_mb:.0f}, {compare_mb:.0f} |"
        )
    return {
        "options": options,
        "torque_text": TORQUES[torque],
        "date": datetime.date.today().isoformat(),
        "machine": f"{cpu_model()}, {os.cpu_count()} cores",
        "python": sys.version.split()[0],
        "load": f"{load[0]:.1f}",
        "load_after": f"{load[1]:.1f}",
        "table": "\n".join(lines),
        "judge_target": str(JUDGE_TARGET),
        "judge_held": "met" if max(ratios) <= JUDGE_TARGET else f"missed: up to {max(ratios):.2f}",
        "memory_target": str(MEMORY_TARGET_MB),
        "memory_held": "met" if max(peaks) < MEMORY_TARGET_MB else f"missed: up to {max(peaks):.0f} MB",
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.long_runs", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--rows", type=int, nargs="+", default=list(ROWS), help="the lengths, in rows (default: %(default)s)"
    )
    parser.add_argument(
        "--torque", choices=list(TORQUES), default="constant", help="the run's torque (default: %(default)s)"
    )
    args = parser.parse_args(argv)
    before = os.getloadavg()[0]
    measured = {}
    for rows in args.rows:
        with tempfile.TemporaryDirectory(prefix="pendulum-long-runs-") as scratch:
            measured[rows] = measure(rows, Path(scratch), args.torque)
    options = "" if tuple(args.rows) == ROWS else " --rows " + " ".join(map(str, args.rows))
    options += "" if args.torque == "constant" else f" --torque {args.torque}"
    load = (before, os.getloadavg()[0])
    print(TEMPLATE.format(**template_figures(measured, load, options, args.torque)), end="")


if __name__ == "__main__":
    main()
