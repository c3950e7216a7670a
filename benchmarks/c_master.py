"""Running step_master.c, the bare C master, natively or under a tool."""

from __future__ import annotations

import subprocess
import tempfile
from pathlib import Path

import numpy as np

from .builds import BuiltFmu


class MasterError(RuntimeError):
    """The master (or the tool running it) failed; the message carries its output."""


def master_command(
    master: Path, fmu: BuiltFmu, steps: int, step_size: float, tolerance: float | None, trajectory: Path | None = None
) -> list[str]:
    """The command line; tolerance None leaves it undefined so the FMU uses its default."""
    return [
        str(master),
        str(fmu.library),
        fmu.guid,
        str(steps),
        repr(step_size),
        repr(tolerance or 0.0),
        *([str(trajectory)] if trajectory else []),
    ]


def run(command: list[str]) -> None:
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise MasterError(f"{' '.join(command)} failed:\n{result.stderr[-2000:]}")


def theta_trajectory(master: Path, fmu: BuiltFmu, steps: int, step_size: float, tolerance: float | None) -> np.ndarray:
    """Theta at t = 0, h, ..., steps*h, as the master saw it."""
    with tempfile.TemporaryDirectory() as scratch:
        path = Path(scratch) / "theta.txt"
        run(master_command(master, fmu, steps, step_size, tolerance, path))
        return np.loadtxt(path)
