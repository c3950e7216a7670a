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
import datetime
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .builds import build_pendulum_fmu
from .report import Row, cpu_model
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


def measured(fmu: Path, quick: bool, before: Path | None = None) -> dict:
    """Each checkout's medians ({"before": ..., "after": ...}, "after" alone without before), the
    break-even (cases, steps, the four studies' seconds), the rounds and the load average before.
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
    return {"medians": medians, "break even": (cases, steps, studies), "repetitions": repetitions, "load": load}


def _break_even_text(figures: dict) -> tuple[str, str]:
    """(the four studies' seconds, where the process stops paying) as the table gives them."""
    cases, steps, studies = figures["break even"]
    seconds = ", ".join(
        _cell(studies[f"{where} {size}"]) for where in ("process", "cluster") for size in (SMALL, LARGE)
    )
    crossing = (
        f"{cases:,.0f} cases = {steps / 1e6:,.1f} million steps"
        if cases < float("inf")
        else "none: the cluster ran a case no faster than the process"
    )
    return seconds, crossing


def small_study_rows(fmu: Path, quick: bool, before: Path | None = None) -> list[Row]:
    """The rows of `python -m benchmarks`' table: each contender's median, before and after where
    a checkout is given; the targets; the break-even.
    """
    figures = measured(fmu, quick, before)
    medians = figures["medians"]
    after = medians["after"]

    def value(key: str, unit: str = " s", scale: float = 1.0) -> str:
        return " -> ".join(
            f"{seconds[key] * scale:.2f}{unit}" if key in seconds else "-" for seconds in medians.values()
        )

    def held(measure: str, key: str, target: float, unit: str = "") -> Row:
        return Row(PART, measure, value(key, unit), f"<= {target:g}{unit}", after[key] <= target)

    seconds, crossing = _break_even_text(figures)
    return [
        Row(
            PART, f"median of {figures['repetitions']}, load average {figures['load']:.1f} before", " -> ".join(medians)
        ),
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
            PART, f"break-even: {SMALL} and {LARGE} cases in the process, then on a cluster of 2 ({seconds})", crossing
        ),
    ]


# What the command prints, and docs/sweeps.md holds (tests/readme_figures.py keeps the two in
# step): each cell pair is "before | now", "-" where a version has no such figure.
TEMPLATE = """Measured by `.venv/bin/python -m benchmarks.small_studies --before CHECKOUT` on {date}, {before}
against this version, taking turns, on {machine} (load average {load} before); 3-s cases at 1 ms
steps, all outputs written as Parquet, medians of {repetitions}:

| measure | before | now | target |
| --- | --- | --- | --- |
| 1-case study, `pendulum-fmu sweep`, end to end | {command_1} | <= 1.5 s: {command_1_held} |
| 10-case study, `pendulum-fmu sweep`, end to end | {command_10} | |
| the 10 cases' `simulate()` loop, a fresh process, end to end | {loop_process} | |
| 10-case study by the command / the loop's process | {ratio} | <= 2: {ratio_held} |
| 10-case study, `pendulum-fmu sweep --no-figure`, end to end | {command_10_no_figure} | |
| the same / the loop's process | {ratio_no_figure} | <= 2: {ratio_no_figure_held} |
| 1-case study, `run_sweep` in a process that ran one | {api_1} | |
| 10-case study, `run_sweep` in a process that ran one | {api_10} | |
| the same, `figure=False` | {api_10_no_figure} | |
| the 10 cases' `simulate()` loop, in that process | {loop_warm} | |
| the local cluster of 2 workers, TLS included: start and close (the same code) | {cluster} | |
| break-even ({small} and {large} cases in the process, then on a cluster: {break_even_seconds}) | - | {break_even} | |
"""


def _revision(checkout: Path) -> str:
    found = subprocess.run(["git", "-C", str(checkout), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    return f"the checkout {checkout} ({found.stdout.strip() or 'no git revision'})"


def template_figures(figures: dict, before: Path | None) -> dict[str, str]:
    """The figures of TEMPLATE from measured()'s."""
    medians = figures["medians"]
    after = medians["after"]
    earlier = medians.get("before", {})

    def pair(key: str, unit: str = " s", scale: float = 1.0, digits: int = 2) -> str:
        return " | ".join(
            f"{seconds[key] * scale:.{digits}f}{unit}" if key in seconds else "-" for seconds in (earlier, after)
        )

    def held(key: str, target: float) -> str:
        return "met" if after[key] <= target else "missed"

    seconds, crossing = _break_even_text(figures)
    return {
        "date": datetime.date.today().isoformat(),
        "before": "no other version" if before is None else _revision(before),
        "machine": f"{cpu_model()}, {os.cpu_count()} cores",
        "load": f"{figures['load']:.1f}",
        "repetitions": str(figures["repetitions"]),
        "command_1": pair("command 1"),
        "command_1_held": held("command 1", STUDY_TARGET),
        "command_10": pair("command 10"),
        "loop_process": pair("loop process"),
        "ratio": pair("ratio", ""),
        "ratio_held": held("ratio", LOOP_TARGET),
        "command_10_no_figure": pair("command 10 no figure"),
        "ratio_no_figure": pair("ratio no figure", ""),
        "ratio_no_figure_held": held("ratio no figure", LOOP_TARGET),
        "api_1": pair("api 1"),
        "api_10": pair("api 10"),
        "api_10_no_figure": pair("api 10 no figure"),
        "loop_warm": pair("loop warm", " ms", 1e3, 1),
        "cluster": pair("cluster"),
        "small": f"{SMALL:,}",
        "large": f"{LARGE:,}",
        "break_even_seconds": seconds,
        "break_even": crossing,
    }


def main() -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.small_studies", description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, metavar="CHECKOUT", help="a checkout to compare with (e.g. main's)")
    parser.add_argument("--quick", action="store_true", help="3 rounds instead of 5")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="pendulum-small-studies-fmu-") as scratch:
        fmu = build_pendulum_fmu(Path(scratch)).path
        print(TEMPLATE.format(**template_figures(measured(fmu, args.quick, args.before), args.before)), end="")


if __name__ == "__main__":
    main()
