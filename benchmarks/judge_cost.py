"""The judge beside the run it judges (issue 42), each as a user runs it: a new process, end to end.

The README quick start's run, `fmpy simulate` of the FMU under the jump torque file (3 s, 1 ms),
beside `pendulum-fmu judge` of the result it wrote (with --fmu naming the FMU fmpy ran), taking
turns; then 100 results of that run
(the result with rounding-sized and with failing changes to theta) judged in one call beside one
result; and the least any judge in Python takes, an interpreter importing numpy. Each figure is
the median of the repeats; the load average is printed with them.

    .venv/bin/python -m benchmarks.judge_cost [--repeats 5] [--before CHECKOUT]

--before CHECKOUT measures the judge of another checkout too (main's before a change), taking
turns with this one: its package on PYTHONPATH, the FMU, the signal and the results made here. A
judge that takes one result per call (before issue 42) is given the 100 results through its
judge() in one Python process, the fastest it offers. It prints TEMPLATE, the block
docs/judging.md holds. Also part of `python -m benchmarks --only judge` (this checkout alone).
"""

from __future__ import annotations

import argparse
import datetime
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .report import Row, cpu_model
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

TEMPLATE = """Measured by `.venv/bin/python -m benchmarks.judge_cost --before CHECKOUT` on {date}, {before}
against this version, taking turns, on {machine} (python {python}, load average {load} before);
the README quick start's run (3 s, 1 ms steps), each command a new process, end to end, medians
of {repetitions}:

| measure | before | now | target |
| --- | --- | --- | --- |
| `fmpy simulate` of the run (the same command for both) | {fmpy} | |
| `pendulum-fmu judge` of its result | {one} | |
| judge / fmpy's run | {one_ratio} | <= 1.5: {one_held} |
| {results} results of that run, judged {how} | {many} | |
| {results} results / one | {many_ratio} | <= 10: {many_held} |
| an interpreter importing numpy, the least a judge in Python takes | {numpy} | |
"""


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


def measure(repeats: int, checkouts: dict[str, Path]) -> dict:
    """Seconds per repeat of fmpy's run, numpy's import, and of each checkout's judge of one
    result and of RESULTS results; {version: whether it took them in one call}.
    """
    with tempfile.TemporaryDirectory(prefix="pendulum-judge-cost-") as scratch:
        folder = Path(scratch)
        names = _prepare(folder)
        python = [sys.executable, "-m", "pendulum_fmu"]
        here = checkouts["now"]
        contenders = {
            "fmpy": lambda: _command(folder, [str(Path(sys.executable).parent / "fmpy"), *FMPY_RUN], here),
            "numpy": lambda: _command(folder, [sys.executable, "-c", "import numpy"], here),
        }
        many = {}
        for version, checkout in checkouts.items():
            many[version] = _takes_many(folder, checkout, names)
            hundred = [*python, JUDGE[0], *names, *JUDGE[2:]] if many[version] else [sys.executable, "-c", JUDGE_LOOP]
            hundred += [] if many[version] else names
            contenders[f"one {version}"] = lambda c=checkout: _command(folder, [*python, *JUDGE], c)
            contenders[f"many {version}"] = lambda c=checkout, argv=hundred: _command(folder, argv, c)
        load = os.getloadavg()[0]
        seconds = interleaved(contenders, repeats)
    medians = {name: median(values) for name, values in seconds.items()}
    return {"medians": medians, "many": many, "load": (load, os.getloadavg()[0]), "repetitions": repeats}


def _ratios(medians: dict[str, float], version: str) -> tuple[float, float]:
    """A version's ratios: its judge over fmpy's run, and RESULTS results over one."""
    return medians[f"one {version}"] / medians["fmpy"], medians[f"many {version}"] / medians[f"one {version}"]


def judge_cost_rows(repeats: int) -> list[Row]:
    """The rows of python -m benchmarks: this checkout's medians and both ratios against their targets."""
    measured = measure(repeats, {"now": HERE})
    seconds = measured["medians"]
    one_ratio, many_ratio = _ratios(seconds, "now")
    return [
        Row(PART, "fmpy simulate of the quick start's run (3 s, 1 ms), end to end", f"{seconds['fmpy']:.2f} s"),
        Row(PART, "pendulum-fmu judge of its result, end to end", f"{seconds['one now']:.2f} s"),
        Row(PART, "  judge / fmpy's run", f"{one_ratio:.2f}", f"<= {ONE_TARGET}", one_ratio <= ONE_TARGET),
        Row(PART, f"{RESULTS} results of that run judged in one call", f"{seconds['many now']:.2f} s"),
        Row(PART, f"  {RESULTS} results / one", f"{many_ratio:.2f}", f"<= {MANY_TARGET}", many_ratio <= MANY_TARGET),
        Row(PART, "python importing numpy alone", f"{seconds['numpy']:.2f} s"),
        Row(PART, "load average before, after", "{:.1f}, {:.1f}".format(*measured["load"])),
    ]


def _revision(checkout: Path) -> str:
    found = subprocess.run(["git", "-C", str(checkout), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    return f"the checkout {checkout.name} ({found.stdout.strip() or 'no git revision'})"


def template_figures(measured: dict, before: Path | None) -> dict[str, str]:
    """The figures of TEMPLATE from measure()'s; "-" in the before column without a checkout."""
    medians, versions = measured["medians"], ["before", "now"]

    def pair(text) -> str:
        return " | ".join(text(version) if f"one {version}" in medians else "-" for version in versions)

    one_ratio, many_ratio = _ratios(medians, "now")
    hows = {True: "in one call", False: "through judge() in one process"}
    how = " / ".join(f"{version}: {hows[many]}" for version, many in measured["many"].items())
    return {
        "date": datetime.date.today().isoformat(),
        "before": "no other version" if before is None else _revision(before),
        "machine": f"{cpu_model()}, {os.cpu_count()} cores",
        "python": sys.version.split()[0],
        "load": f"{measured['load'][0]:.1f}",
        "repetitions": str(measured["repetitions"]),
        "fmpy": pair(lambda version: f"{medians['fmpy']:.2f} s"),
        "one": pair(lambda version: f"{medians[f'one {version}']:.2f} s"),
        "one_ratio": pair(lambda version: f"{_ratios(medians, version)[0]:.2f}"),
        "one_held": "met" if one_ratio <= ONE_TARGET else "missed",
        "results": str(RESULTS),
        "how": f"({how})",
        "many": pair(lambda version: f"{medians[f'many {version}']:.2f} s"),
        "many_ratio": pair(lambda version: f"{_ratios(medians, version)[1]:.2f}"),
        "many_held": "met" if many_ratio <= MANY_TARGET else "missed",
        "numpy": pair(lambda version: f"{medians['numpy']:.2f} s"),
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.judge_cost", description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs of each command, taking turns (default: 5)")
    parser.add_argument("--before", type=Path, help="another checkout, measured taking turns with this one")
    args = parser.parse_args(argv)
    before = None if args.before is None else args.before.resolve()
    checkouts = {"now": HERE} if before is None else {"before": before, "now": HERE}
    print(TEMPLATE.format(**template_figures(measure(args.repeats, checkouts), before)), end="")


if __name__ == "__main__":
    main()
