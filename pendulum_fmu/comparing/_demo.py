"""The OpenSim pendulum tutorial end to end, as `pendulum-fmu demo` runs it.

Gravity off and on, the FMU against the independent reference (and OpenSim when installed), with the
error table of each; the two runs overlaid; and the tutorial's parameter study on a local dask
cluster. It prints what it finds and writes the figures and tables into one folder.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._errors import PendulumFmuError
from ..figures._plot import plot_overlay
from ..fmu._parameters import default_parameters, total_inertia
from ..sweep import Study, run_sweep, sweep_grid
from ._compare import compare, format_comparison
from ._compare_tools import installed_defaults

# The tutorial's constant torque, N.m.
TORQUE = 20.0
# The parameter study's torques, N.m, with gravity.
STUDY_TORQUES = (5.0, 10.0, 20.0, 40.0)
# What the demo writes into its folder.
ENTRIES = ("no_gravity", "gravity", "gravity_effect.png", "parameter_study")


class DemoExists(PendulumFmuError, FileExistsError):
    """The output folder holds a previous demo's outputs that the run would replace without being
    asked to; the message names them and --overwrite.
    """


def run_demo(output_dir: str | Path, workers: int | None = None, overwrite: bool = False) -> bool:
    """Run the tutorial into output_dir, printing each step's findings.

    Parameters
    ----------
    output_dir : str or Path
        Folder for the figures and tables: no_gravity/ and gravity/ (each a comparison's
        trajectories.csv, differences.csv and comparison.png), gravity_effect.png and
        parameter_study/ (a sweep).
    workers : int, optional
        Processes of a local dask cluster for the parameter study; without, the study (4 short
        cases) runs in this process, as run_sweep runs a study this small.
    overwrite : bool, optional
        Replace the outputs of a previous demo the folder holds (ENTRIES); without it such a
        folder is refused before anything runs. Other files in it are kept either way.

    Returns
    -------
    bool
        Whether every tool agreed with the reference, gravity off and on.

    Raises
    ------
    DemoExists
        A folder that holds a previous demo's outputs, without overwrite.
    PendulumFmuError
        An output that cannot be written, or a tool or FMU that fails (see compare, run_sweep).
    """
    out = Path(output_dir)
    held = [name for name in ENTRIES if (out / name).exists()]
    if held and not overwrite:
        raise DemoExists(
            f"{out} already holds a demo's outputs ({', '.join(held)}): choose another "
            "output directory, or add --overwrite to run the demo again in their place"
        )
    tools = installed_defaults()  # warns which it skipped, and how to install them
    print(f"Tutorial case: constant torque {TORQUE:g} N.m, 3 s in 1 ms steps; tools: {', '.join(tools)}")
    runs, agree = {}, True
    for label, gravity, folder in (("No Gravity", 0.0, "no_gravity"), ("With Gravity", 9.81, "gravity")):
        comparison = compare(
            TORQUE,
            tools,
            output_dir=out / folder,
            parameters={"gravity": gravity},
            title=rf"Constant Torque $\tau = {TORQUE:g}$ N.m — {label}",
        )
        print(f"\n{label} (gravity = {gravity:g} m/s2)")
        print(format_comparison(comparison))
        fmu = comparison.runs["fmu"]
        if gravity == 0.0:
            parabola = 0.5 * TORQUE / total_inertia(default_parameters()) * fmu["time"] ** 2
            print(f"fmu vs analytic theta = tau t^2 / (2 I): {np.max(np.abs(fmu['theta'] - parabola)):.3e} rad")
        print(f"theta(3 s) = {fmu['theta'][-1]:.10f} rad, omega(3 s) = {fmu['omega'][-1]:.10f} rad/s")
        print(f"wrote {comparison.figure}")
        runs[label] = fmu
        agree &= comparison.agree
    overlay = plot_overlay(
        {
            rf"No gravity ($\tau = {TORQUE:g}$ N.m)": runs["No Gravity"],
            rf"With gravity ($\tau = {TORQUE:g}$ N.m)": runs["With Gravity"],
        },
        out / "gravity_effect.png",
        "Effect of Gravity on Torque-Driven Pendulum",
    )
    print(f"\nwrote {overlay}")
    print(f"\nParameter study: torque {', '.join(f'{t:g}' for t in STUDY_TORQUES)} N.m with gravity")
    # Asked to overwrite, the study too is replaced (once the new one is whole).
    result = run_sweep(
        Study(sweep_grid(STUDY_TORQUES, [9.81])),
        output_dir=out / "parameter_study",
        overwrite=overwrite,
        workers=workers,
    )
    where = (
        "on a local dask cluster"
        if result.ran_in == "cluster"
        else "in this process (a study this small takes less time here than a local dask cluster's "
        "start; --workers N runs it on one)"
    )
    print(f"{result.cases} cases in {result.seconds:.1f} s, {where}\nwrote {result.cases_table}\nwrote {result.figure}")
    return agree
