"""The closed loop in the scenario kit: the SSP, its settings and a reference per coupling.

    pendulum-fmu scenarios --output-dir kit --closed-loop

adds to kit/:
- ClosedLoop.ssp: the pendulum under the PID controller (ssp.export_ssp);
- ClosedLoop.json: what it asks (stop time, step, both parameter sets), the couplings a master may
  use, what to write and the command that judges it;
- ClosedLoop_ref.csv: time and theta of every coupling with the SSP's parameter sets
  (closed_loop.sampled_loop_reference), one column per coupling.

A master runs ClosedLoop.ssp and writes ClosedLoop_out.csv (time,theta); `pendulum-fmu judge
ClosedLoop_out.csv --ssp ClosedLoop.ssp` names its coupling (_ssp_judge.py). The controller FMU is
the one the package carries (built from the sources in a checkout).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from .._atomic_files import make_folder, replacing
from ..scenarios._scenarios import KitExists
from ._closed_loop import COUPLINGS, sampled_loop_reference
from ._ssp import export_ssp, read_ssp

CLOSED_LOOP_FILES = ("ClosedLoop.ssp", "ClosedLoop.json", "ClosedLoop_ref.csv")
JUDGE_COMMAND = "pendulum-fmu judge ClosedLoop_out.csv --ssp ClosedLoop.ssp"


def write_closed_loop_kit(output_dir: str | os.PathLike, *, overwrite: bool = False) -> list[Path]:
    """Write the closed loop's SSP, settings and references into a scenario kit's folder.

    Parameters
    ----------
    output_dir : str or PathLike
        The kit's folder (made when missing).
    overwrite : bool, optional
        Replace the closed loop's files the folder holds already.

    Returns
    -------
    list of Path
        The files written: CLOSED_LOOP_FILES in the folder.

    Raises
    ------
    KitExists
        The folder holds one of CLOSED_LOOP_FILES and overwrite is False.
    CannotWrite
        The folder cannot be written.
    MissingFile
        An installed package without its packaged FMUs.
    BuildError
        A checkout whose FMUs are stale and cannot be rebuilt here.

    Examples
    --------
    >>> import tempfile
    >>> [path.name for path in write_closed_loop_kit(tempfile.mkdtemp())]  # doctest: +SKIP
    ['ClosedLoop.ssp', 'ClosedLoop.json', 'ClosedLoop_ref.csv']
    """
    folder = Path(output_dir)
    held = [name for name in CLOSED_LOOP_FILES if (folder / name).exists()]
    if held and not overwrite:
        raise KitExists(
            f"{folder} already holds the closed loop ({', '.join(held)}): choose another output directory, "
            "or add --overwrite"
        )
    make_folder(folder, folder, "output directory")
    paths = [folder / name for name in CLOSED_LOOP_FILES]
    settings = read_ssp(export_ssp(paths[0], overwrite=True))
    described = {
        "ssp": paths[0].name,
        "start_time": 0.0,
        "stop_time": settings.stop_time,
        "step_size": settings.step_size,
        "controller": settings.controller,
        "pendulum": settings.pendulum,
        "couplings": COUPLINGS,
        "reference": paths[2].name,
        "output": "ClosedLoop_out.csv: header time,theta, a row per communication point, 17 significant digits",
        "judge": JUDGE_COMMAND,
    }
    with replacing(paths[1]) as file:
        file.write(json.dumps(described, indent=2) + "\n")
    references = {
        coupling: sampled_loop_reference(
            settings.stop_time,
            settings.step_size,
            controller=settings.controller,
            parameters=settings.pendulum,
            coupling=coupling,
        )
        for coupling in COUPLINGS
    }
    time = next(iter(references.values()))["time"]
    with replacing(paths[2], newline="") as file:
        file.write(",".join(("time", *COUPLINGS)) + "\n")
        for row, moment in enumerate(time):
            file.write(",".join(f"{value:.17g}" for value in (moment, *(r["theta"][row] for r in references.values()))))
            file.write("\n")
    return paths
