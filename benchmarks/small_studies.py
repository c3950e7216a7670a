"""Small studies (issue 42): what a user waits for a study of 1 and of 10 cases, against the same
cases through a simulate() loop, and where running a study in the calling process stops paying.

    .venv/bin/python -m benchmarks.small_studies [--before CHECKOUT] [--quick]
    .venv/bin/python -m benchmarks --only small-studies [--before CHECKOUT]

Every figure is a fresh process's, end to end, or a process's that already ran a study (as a
notebook would): 3-s cases at 1 ms steps, all outputs written as Parquet, the figure drawn.
- the command: `pendulum-fmu sweep` of 1 and of 10 cases, from the interpreter's start to its exit;
- the API: run_sweep of 1 and of 10 cases in a process that has run one study already;
- the loop: the same 10 cases through simulate(), in a fresh process (nothing written) and in a
  warm one;
- the local cluster of two workers alone, TLS included: started and closed, in a warm process.
With --before, a checkout of another version (its package on PYTHONPATH, the same interpreter)
runs the same commands and scripts, taking turns with this one, and the two columns are printed
side by side. Last, this checkout's break-even: studies of SMALL and LARGE cases run in the
process and on a local cluster of two workers, taking turns; where the two straight lines cross
is the number of cases (and steps) below which the process is quicker: what BREAK_EVEN_STEPS
(signals/_time_grid.py) is set from. Medians; the load average is printed.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .builds import build_pendulum_fmu
from .report import Row
from .timing import interleaved, median

PART = "small studies"
REPOSITORY = Path(__file__).resolve().parent.parent
STOP_TIME = 3.0
TORQUES = [float(torque) for torque in range(1, 11)]
STUDY_TARGET = 1.5  # s, a 1-case study by the command, end to end
LOOP_TARGET = 2.0  # a 10-case study by the command over the same cases' simulate() loop, end to end
SMALL, LARGE = 16, 8192  # cases of the break-even's two studies

# Run in a process of its own with a checkout's package on PYTHONPATH: prints, as JSON, the
# seconds of a 1-case and a 10-case run_sweep, of the 10 cases' simulate() loop and of the local
# cluster's start and close, after a first study and simulate() (imports, the FMU read).
WARM_PROCESS = """
import json, os, sys, tempfile, time
from pendulum_fmu import simulate
from pendulum_fmu.sweep import Study, run_sweep, sweep_grid
from pendulum_fmu.sweep.client import dask_client

fmu, torques, stop_time = sys.argv[1], json.loads(sys.argv[2]), float(sys.argv[3])
folder = tempfile.mkdtemp(prefix="pendulum-small-studies-")

def study(cases, name, **options):
    started = time.perf_counter()
    run_sweep(Study(sweep_grid(torques[:cases]), stop_time=stop_time, fmu_path=fmu),
              output_dir=os.path.join(folder, name), progress=False, **options)
    return time.perf_counter() - started

study(1, "warm")
with dask_client(None, 2, 30.0):  # dask's imports, in a checkout whose small studies need none
    pass
seconds = {"api 1": study(1, "one"), "api 10": study(10, "ten")}
if sys.argv[4] == "this":  # a version with the option
    seconds["api 10 no figure"] = study(10, "ten without", figure=False)
started = time.perf_counter()
for torque in torques:
    simulate(torque, stop_time=stop_time, fmu_path=fmu)
seconds["loop warm"] = time.perf_counter() - started
started = time.perf_counter()
with dask_client(None, 2, 30.0):
    pass
seconds["cluster"] = time.perf_counter() - started
print(json.dumps(seconds))
"""
LOOP = """
import json, sys
from pendulum_fmu import simulate
for torque in json.loads(sys.argv[2]):
    simulate(torque, stop_time=float(sys.argv[3]), fmu_path=sys.argv[1])
"""


def _wall(command: list[str], checkout: Path) -> tuple[float, str]:
    """(seconds, stdout) of a command run in the checkout, whose package is then the first on
    the path (python -m and -c put the working directory before PYTHONPATH).
    """
    started = time.perf_counter()
    run = subprocess.run(command, cwd=checkout, capture_output=True, text=True, timeout=600, check=False)
    seconds = time.perf_counter() - started
    if run.returncode != 0:
        raise RuntimeError(f"{' '.join(command[:4])} ... failed in {checkout}: {run.stderr.strip()[-400:]}")
    return seconds, run.stdout


def one_round(checkout: Path, fmu: Path, scratch: Path) -> dict[str, float]:
    """Seconds of every contender once, with the checkout's package (this one's: with --no-figure too)."""
    this = "this" if checkout == REPOSITORY else "other"
    arguments = [str(fmu), json.dumps(TORQUES), str(STOP_TIME)]
    seconds = json.loads(_wall([sys.executable, "-c", WARM_PROCESS, *arguments, this], checkout)[1])
    seconds["loop process"] = _wall([sys.executable, "-c", LOOP, *arguments], checkout)[0]
    studies = {"command 1": (1, []), "command 10": (10, [])}
    if this == "this":
        studies["command 10 no figure"] = (10, ["--no-figure"])
    for name, (cases, extra) in studies.items():
        folder = tempfile.mkdtemp(dir=scratch)
        command = [sys.executable, "-m", "pendulum_fmu", "sweep", "--torque", *map(str, TORQUES[:cases]), *extra]
        options = ["--stop-time", str(STOP_TIME), "--fmu", str(fmu), "--output-dir", f"{folder}/study"]
        seconds[name] = _wall(command + options, checkout)[0]
    return seconds


def side_by_side(checkouts: dict[str, Path], fmu: Path, scratch: Path, repetitions: int) -> dict[str, dict]:
    """{checkout's name: {contender: median seconds}}, the checkouts taking turns."""
    rounds = {name: [] for name in checkouts}

    def turn(name):
        def run() -> float:
            rounds[name].append(one_round(checkouts[name], fmu, scratch))
            return 0.0

        return run

    interleaved({name: turn(name) for name in checkouts}, repetitions)
    return {name: {key: median([r[key] for r in runs]) for key in runs[0]} for name, runs in rounds.items()}


def break_even(fmu: Path, scratch: Path, repetitions: int) -> tuple[float, float, dict[str, float]]:
    """(cases, steps) where a study in the process and one on a local cluster of two workers take
    as long, from the medians of studies of SMALL and LARGE cases each way (taking turns); and
    the medians. Infinite where the cluster is no quicker per case.
    """
    from pendulum_fmu.sweep import Study, run_sweep, sweep_grid

    def study(cases: int, run_in: str):
        torques = [1.0 + index * 1e-3 for index in range(cases)]

        def run() -> float:
            result = run_sweep(
                Study(sweep_grid(torques), stop_time=STOP_TIME, fmu_path=fmu),
                output_dir=tempfile.mkdtemp(dir=scratch),
                progress=False,
                run_in=run_in,
            )
            return result.seconds

        return run

    study(SMALL, "cluster")()  # the cluster's imports, the FMU read
    contenders = {
        f"{run_in} {cases}": study(cases, run_in) for cases in (SMALL, LARGE) for run_in in ("process", "cluster")
    }
    seconds = {name: median(values) for name, values in interleaved(contenders, repetitions).items()}
    slopes = {
        where: (seconds[f"{where} {LARGE}"] - seconds[f"{where} {SMALL}"]) / (LARGE - SMALL)
        for where in ("process", "cluster")
    }
    start = seconds[f"cluster {SMALL}"] - seconds[f"process {SMALL}"] - SMALL * (slopes["cluster"] - slopes["process"])
    saved = slopes["process"] - slopes["cluster"]
    cases = start / saved if saved > 0 else float("inf")
    return cases, cases * round(STOP_TIME / 1e-3), seconds


def _cell(seconds: float) -> str:
    return f"{seconds:.2f} s"


def small_study_rows(fmu: Path, quick: bool, before: Path | None = None) -> list[Row]:
    """The rows of the table: each contender's median, before and after where a checkout is
    given; the targets; the break-even.
    """
    repetitions = 3 if quick else 5
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="pendulum-small-studies-") as scratch:
        checkouts = {"after": REPOSITORY} if before is None else {"before": before, "after": REPOSITORY}
        medians = side_by_side(checkouts, fmu, Path(scratch), repetitions)
        cases, steps, studies = break_even(fmu, Path(scratch), 3)
    for seconds in medians.values():
        seconds["ratio"] = seconds["command 10"] / seconds["loop process"]
        if "command 10 no figure" in seconds:
            seconds["ratio no figure"] = seconds["command 10 no figure"] / seconds["loop process"]
    after = medians["after"]

    def value(key: str, unit: str = " s", scale: float = 1.0) -> str:
        return " -> ".join(
            f"{seconds[key] * scale:.2f}{unit}" if key in seconds else "-" for seconds in medians.values()
        )

    def held(measure: str, key: str, target: float, unit: str = "") -> Row:
        return Row(PART, measure, value(key, unit), f"<= {target:g}{unit}", after[key] <= target)

    def study(where: str, size: int) -> str:
        return _cell(studies[f"{where} {size}"])

    return [
        Row(PART, f"median of {repetitions}, load average {load:.1f} before", " -> ".join(medians)),
        held("1-case study, `pendulum-fmu sweep`, end to end", "command 1", STUDY_TARGET, " s"),
        Row(PART, "10-case study, `pendulum-fmu sweep`, end to end", value("command 10")),
        Row(PART, "the 10 cases' simulate() loop, a fresh process, end to end", value("loop process")),
        held("10-case study by the command / the loop's process", "ratio", LOOP_TARGET),
        Row(PART, "10-case study, `pendulum-fmu sweep --no-figure`, end to end", value("command 10 no figure")),
        held("the same / the loop's process", "ratio no figure", LOOP_TARGET),
        Row(PART, "1-case study, run_sweep in a process that ran one", value("api 1")),
        Row(PART, "10-case study, run_sweep in a process that ran one", value("api 10")),
        Row(PART, "the same, figure=False", value("api 10 no figure")),
        Row(PART, "the 10 cases' simulate() loop, in that process", value("loop warm", " ms", 1e3)),
        Row(PART, "the local cluster of 2 workers, TLS included: start and close", value("cluster")),
        Row(
            PART,
            f"break-even: studies of {SMALL} and {LARGE} 3-s cases in the process ({study('process', SMALL)}, "
            f"{study('process', LARGE)}) and on a local cluster of 2 ({study('cluster', SMALL)}, "
            f"{study('cluster', LARGE)}), medians of 3",
            f"{cases:,.0f} cases = {steps / 1e6:,.1f} million steps"
            if cases < float("inf")
            else "none: the cluster ran a case no faster than the process",
        ),
    ]


def main() -> None:
    from .report import as_text, main_table

    parser = argparse.ArgumentParser(prog="python -m benchmarks.small_studies", description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, metavar="CHECKOUT", help="a checkout to compare with (e.g. main's)")
    parser.add_argument("--quick", action="store_true", help="3 rounds instead of 5")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="pendulum-small-studies-fmu-") as scratch:
        fmu = build_pendulum_fmu(Path(scratch)).path
        print(as_text(main_table(small_study_rows(fmu, args.quick, args.before))))


if __name__ == "__main__":
    main()
