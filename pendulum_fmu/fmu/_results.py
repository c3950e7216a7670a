"""The one result format: a numpy structured array with a row per communication point.

Row k holds the time, then what the FMU records (FmuModel.recorded: its inputs, then its outputs,
in modelDescription.xml's order; for the pendulum torque, theta, omega, alpha): theta and omega at
time[k], the torque applied from time[k] on (the step's start value), and alpha, the acceleration
just after time[k] under that torque. The last row repeats the last step's torque at its end.
Fields are SI, in the units the model description declares (s, N.m, rad, rad/s, rad/s2).

The fields are named once, by the FMU's model description: FIELDS, DTYPE and UNITS are the
default FMU's (pendulum_fmu.default_fmu()), read on first use. A column a tool cannot compute is
NaN, never zeros (with_outputs says which).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._atomic_files import replacing
from .._errors import NotComputed, WrongType

if TYPE_CHECKING:
    from ._model import FmuModel


@lru_cache(maxsize=1)
def _default_recorded() -> tuple[str, ...]:
    from ._model import fmu_model

    return fmu_model().recorded


def __getattr__(name: str):
    # The default FMU's fields, read from its model description on first use, not at import.
    if name == "FIELDS":
        return ("time", *_default_recorded())
    if name == "DTYPE":
        return dtype(_default_recorded())
    if name == "UNITS":
        from ._model import fmu_model

        return units(("time", *_default_recorded()), fmu_model())
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def dtype(recorded: Sequence[str]) -> np.dtype:
    """The structured dtype of a result recording these variables: time, then each, as float64.

    Parameters
    ----------
    recorded : sequence of str
        What the run records (FmuModel.recorded, or a subset or superset of it).

    Returns
    -------
    numpy.dtype

    Examples
    --------
    >>> dtype(("torque", "theta")).names
    ('time', 'torque', 'theta')
    """
    return np.dtype([(name, "f8") for name in ("time", *recorded)])


def units(fields: Sequence[str], model: FmuModel) -> dict[str, str]:
    """{field: unit} of a result's fields: time in s, each variable in the unit its FMU declares.

    Parameters
    ----------
    fields : sequence of str
        The result's fields (fields(run)), time first.
    model : FmuModel
        The FMU that made the result, or whose variables it holds.

    Returns
    -------
    dict

    Examples
    --------
    >>> from pendulum_fmu.fmu._model import fmu_model
    >>> units(("time", "torque", "theta"), fmu_model())
    {'time': 's', 'torque': 'N.m', 'theta': 'rad'}
    """
    return {name: "s" if name == "time" else model.unit(name) for name in fields}


def empty(n_points: int, recorded: Sequence[str] | None = None) -> np.ndarray:
    """A result of n_points rows, every value NaN until a tool writes it.

    Parameters
    ----------
    n_points : int
        Communication points.
    recorded : sequence of str, optional
        What it records besides time (default: the default FMU's, FIELDS[1:]).

    Returns
    -------
    numpy.ndarray
        Structured, of dtype(recorded).

    Examples
    --------
    >>> empty(2, ("torque",))["torque"].tolist()
    [nan, nan]
    """
    out = np.empty(n_points, dtype=dtype(_default_recorded() if recorded is None else recorded))
    out.view(np.float64)[:] = np.nan
    return out


def fields(run: np.ndarray) -> tuple[str, ...]:
    """The fields of a result array: time, then what it records.

    Parameters
    ----------
    run : numpy.ndarray
        A result array (see the module's doc).

    Returns
    -------
    tuple of str

    Raises
    ------
    WrongType
        run is no structured array, so no result.

    Examples
    --------
    >>> fields(empty(2, ("torque", "theta")))
    ('time', 'torque', 'theta')
    """
    names = run.dtype.names
    if names is None:
        raise WrongType(f"a result is a structured array with a field per variable, not an array of {run.dtype}")
    return names


def with_outputs(run: np.ndarray, outputs: Sequence[str], tool: str) -> np.ndarray:
    """A tool's result with exactly the outputs it was asked for: time and the torque, then each
    of outputs, in that order; one it did not compute is NaN, and said so in one line
    (errors.NotComputed), never zeros.

    Parameters
    ----------
    run : numpy.ndarray
        The tool's result; a field of it that is NaN throughout counts as not computed.
    outputs : sequence of str
        The outputs asked for (the FMU's, FmuModel.outputs, or any other set).
    tool : str
        The tool's label, for the warning.

    Returns
    -------
    numpy.ndarray
        run itself when it has those fields already and computed them all.

    Warns
    -----
    NotComputed
        Naming the tool and the outputs it cannot compute.

    Examples
    --------
    >>> run = empty(1, ("torque", "theta")); run["time"], run["torque"], run["theta"] = 0, 1, 2
    >>> with_outputs(run, ("theta",), "reference") is run
    True
    """
    present = fields(run)
    missing = [name for name in outputs if name not in present or np.all(np.isnan(run[name]))]
    if missing:
        warnings.warn(
            f"{tool} cannot compute {', '.join(missing)}: "
            f"{'its column is' if len(missing) == 1 else 'their columns are'} NaN "
            f"(leave {tool} out of --tools to compare {', '.join(missing)})",
            NotComputed,
            stacklevel=2,
        )
    recorded = ("torque", *outputs)
    if present == ("time", *recorded) and not missing:
        return run
    out = empty(len(run), recorded)
    for name in fields(out):
        if name in present:
            out[name] = run[name]
    return out


def write_csv(run: np.ndarray, path: str | os.PathLike) -> Path:
    """Write a result as CSV: a header of the fields, then a row per communication point with 17
    significant digits, so the numbers read back as the same doubles.

    Parameters
    ----------
    run : numpy.ndarray
        A result array (see the module's doc).
    path : str or os.PathLike
        The file to write; it appears whole or not at all.

    Returns
    -------
    Path
        path.

    Raises
    ------
    CannotWrite
        path cannot be written.
    """
    with replacing(path) as file:
        write_rows(file, run, header=True)
    return Path(path)


def write_rows(file, run: np.ndarray, header: bool = False) -> None:
    """Append a result's rows to an open CSV as write_csv writes them, so that a run written a
    block at a time (the first with the header) reads the same, byte for byte, as written whole.

    Parameters
    ----------
    file : text file
        Open for writing.
    run : numpy.ndarray
        A result array, or a block of consecutive rows of one.
    header : bool, optional
        Write the line of field names first.
    """
    np.savetxt(
        file,
        run.view(np.float64).reshape(len(run), -1),
        delimiter=",",
        header=",".join(fields(run)) if header else "",
        comments="",
        fmt="%.17g",
    )
