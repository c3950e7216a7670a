"""Reference results in the FMI cross-check layout, for other tools to compare against.

    <output_dir>/fmus/2.0/cs/<platform>/pendulum_fmu/<version>/Pendulum/
        Pendulum.fmu  Pendulum_in.csv  Pendulum_ref.csv  Pendulum_ref.opt  ReadMe.md

one folder per platform the FMU carries a binary for. The input is a step-wise torque that jumps
at communication points; from a jump on, the value after it applies (fmpy's reading of a repeated
time in an input CSV, which reproduces these results to the last bit).
"""

from __future__ import annotations

import csv
import shutil
import zipfile
from pathlib import Path

import fmpy
import numpy as np

from .. import __version__
from .._atomic_files import check_writable, replacing, replacing_path
from ..signals._torque_csv import TorqueTable
from ._model import fmu_file
from ._parameters import model_description, pendulum_variables
from ._simulate import simulate

START_TIME, STOP_TIME, STEP_SIZE, RELATIVE_TOLERANCE = 0.0, 4.0, 1e-3, 1e-10
# The torque in N.m from the start, then (time of a jump, torque after it).
INITIAL_TORQUE = 10.0
JUMPS = ((1.0, 20.0), (2.0, -15.0), (3.0, 0.0))
OUTPUTS = ("theta", "omega")
TOOL = "pendulum_fmu"


def _input_rows() -> list[tuple[float, float]]:
    """The rows of the input CSV: a jump is a repeated time."""
    rows = [(START_TIME, INITIAL_TORQUE)]
    before = INITIAL_TORQUE
    for jump_time, after in JUMPS:
        rows += [(jump_time, before), (jump_time, after)]
        before = after
    return [*rows, (STOP_TIME, before)]


def _write_csv(path: Path, header, rows) -> None:
    with replacing(path, newline="") as file:
        writer = csv.writer(file)
        writer.writerow(header)
        writer.writerows(rows)


def _readme(computed_on: str, model_name: str) -> str:
    return f"""# {model_name}, exported by {TOOL} {__version__}

A rigid pendulum driven by a torque at its pivot (FMI 2.0 Co-Simulation).

- Input `{model_name}_in.csv`: the torque in N.m, {INITIAL_TORQUE:g} from t = 0, then
  {", ".join(f"{after:g} from t = {t:g} s" for t, after in JUMPS)}. Each jump is at a
  communication point (a repeated time in the CSV), and the value after it applies from there.
- Reference `{model_name}_ref.csv`: theta (rad) and omega (rad/s) at every communication point,
  computed by {TOOL} {__version__} stepping this FMU ({computed_on} binary) with the options of
  `{model_name}_ref.opt` (communication step {STEP_SIZE:g} s, relative tolerance
  {RELATIVE_TOLERANCE:g}), all parameters at their start values.
"""


def write_cross_check(output_dir: str | Path, fmu_path: str | Path | None = None) -> list[Path]:
    """Write the cross-check folders for every platform the FMU has a binary for; returns them."""
    fmu = fmu_file(fmu_path)
    pendulum_variables(fmu)  # a pendulum FMU with this platform's binary, to compute the reference
    description = model_description(fmu)
    model_name = description.coSimulation.modelIdentifier
    with zipfile.ZipFile(fmu) as archive:
        platforms = sorted(
            {
                name.split("/")[1]
                for name in archive.namelist()
                if name.startswith("binaries/") and name.count("/") == 2 and not name.endswith("/")
            }
        )
    folders = [
        Path(output_dir, "fmus", description.fmiVersion, "cs", platform, TOOL, __version__, model_name)
        for platform in platforms
    ]
    check_writable(*(folder / f"{model_name}.fmu" for folder in folders))  # before the run
    rows = _input_rows()
    torque = TorqueTable(np.array([t for t, _ in rows]), np.array([u for _, u in rows]))
    run = simulate(
        torque,
        start_time=START_TIME,
        stop_time=STOP_TIME,
        step_size=STEP_SIZE,
        tolerance=RELATIVE_TOLERANCE,
        fmu_path=fmu,
    )
    reference_rows = [
        [repr(float(t)), *(repr(float(v)) for v in values)]
        for t, *values in zip(run["time"], *(run[name] for name in OUTPUTS), strict=False)
    ]
    computed_on = fmpy.platform_tuple  # this machine, as FMI 3.0 names platforms
    for folder in folders:
        # Each write below makes the folder, or says in one line why it cannot.
        with replacing_path(folder / f"{model_name}.fmu") as copy:
            shutil.copyfile(fmu, copy)
        _write_csv(folder / f"{model_name}_in.csv", ("time", "torque"), ((repr(t), repr(u)) for t, u in rows))
        _write_csv(folder / f"{model_name}_ref.csv", ("time", *OUTPUTS), reference_rows)
        with replacing(folder / f"{model_name}_ref.opt") as options:
            options.write(
                f"StartTime, {START_TIME!r}\nStopTime, {STOP_TIME!r}\n"
                f"StepSize, {STEP_SIZE!r}\nRelTol, {RELATIVE_TOLERANCE!r}\n"
            )
        with replacing(folder / "ReadMe.md") as readme:
            readme.write(_readme(computed_on, model_name))
    return folders
