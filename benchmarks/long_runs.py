"""Long runs (issue 48): a result of millions of rows written, judged and compared, each as a user
runs it: a new process, end to end, its peak memory read by /usr/bin/time -v.

Per length (rows of a 1-ms run under 20 N.m), taking turns, once each: `pendulum-fmu simulate`
writing the result, `fmpy simulate` of the same run (the exported FMU, the torque as a file),
`pendulum-fmu judge` of the result against that file, and `pendulum-fmu compare` of the run
(the FMU and the reference); the load average is printed with them.

    .venv/bin/python -m benchmarks.long_runs [--rows 1000 100000 3000000 30000000]

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

from .report import cpu_model

HERE = Path(__file__).resolve().parent.parent
ROWS = (1_000, 100_000, 3_000_000, 30_000_000)
STEP = 0.001
# A run over 10 million steps is refused unless asked for (--max-steps); then the stop time.
RUN = ["--torque", "20", "--max-steps", "100000000", "--stop-time"]
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
{python}, load average {load} before, {load_after} after); a run of 20 N.m in 1-ms steps, each
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


def measure(rows: int, folder: Path) -> dict[str, tuple[float, float]]:
    """{command: (seconds, peak MB)} for a run of `rows` rows, taking turns in folder."""
    stop = f"{(rows - 1) * STEP:.3f}"
    python = [sys.executable, "-m", "pendulum_fmu"]
    subprocess.run(
        [*python, "export"], cwd=folder, check=True, capture_output=True, env={**os.environ, "PYTHONPATH": str(HERE)}
    )
    (folder / "torque.csv").write_text(f"time,torque\n0,20\n{stop},20\n")
    commands = {
        "simulate": [*python, "simulate", "--output", "result.csv", *RUN, stop],
        "fmpy": [str(Path(sys.executable).parent / "fmpy"), "simulate", "Pendulum.fmu", *FMPY_OPTIONS, stop],
        "judge": [*python, "judge", "result.csv", "--torque-file", "torque.csv", *RUN[2:4], "--json", "verdict.json"],
        "compare": [*python, "compare", "--tools", "fmu,reference", "--output-dir", "compared", *RUN, stop],
    }
    return {name: _timed(argv, folder) for name, argv in commands.items()}


def template_figures(
    measured: dict[int, dict[str, tuple[float, float]]], load: tuple[float, float], options: str = ""
) -> dict[str, str]:
    """The figures of TEMPLATE from measure()'s, a row per length; options, the command's."""
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
    args = parser.parse_args(argv)
    before = os.getloadavg()[0]
    measured = {}
    for rows in args.rows:
        with tempfile.TemporaryDirectory(prefix="pendulum-long-runs-") as scratch:
            measured[rows] = measure(rows, Path(scratch))
    options = "" if tuple(args.rows) == ROWS else " --rows " + " ".join(map(str, args.rows))
    print(TEMPLATE.format(**template_figures(measured, (before, os.getloadavg()[0]), options)), end="")


if __name__ == "__main__":
    main()
