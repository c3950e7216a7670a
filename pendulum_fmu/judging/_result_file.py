"""A result file from any tool, read as a result array: the time column and theta (omega and
alpha where it has them), under any names and units a --map gives.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._errors import InvalidInput
from .._received_files import bounded_lines, shortened
from ..comparing._mapped_fmu import as_map
from ..fmu import _results as results

RESULT_QUANTITIES = ("time", "theta", "omega", "alpha")


OPTIONAL = ("omega", "alpha")


class ResultFileError(InvalidInput):
    r"""A result file, or a kit's folder, that cannot be judged; the message names the file, the
    line and the problem.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import ResultFileError, judge
    >>> result = Path(tempfile.mkdtemp(), "result.csv")
    >>> _ = result.write_text("time,theta\n0,0\n0.5,x\n")
    >>> try:
    ...     judge(result, 20.0, stop_time=1.0)
    ... except ResultFileError as error:
    ...     print(str(error).replace(str(result), "result.csv"))
    result.csv:3: theta 'x' is not a number
    """


_GIVE_CSV = "give the result CSV the tool wrote"


def read_result(
    path: str | Path, mapping: str | dict | None = None, recorded: Sequence[str] | None = None
) -> np.ndarray:
    """A result CSV as a result array (_results.py); omega and alpha are NaN where it has none.

    Parameters
    ----------
    path : str or Path
        A CSV with a header: a time column and theta, optionally omega and alpha.
    mapping : str or dict, optional
        Their names and unit factors, as --map gives them: "time=t,theta=phi*0.0174532925".
    recorded : sequence of str, optional
        The array's fields after time: the judged run's FMU's (FmuModel.recorded; default: the
        default FMU's, looked up for it).

    Returns
    -------
    numpy.ndarray
        Fields time (s), torque (NaN: not judged), theta (rad), omega (rad/s), alpha (rad/s2).

    Raises
    ------
    ResultFileError
        One line naming the file, the line and the problem: no time column, a mapped column
        missing, a cell that is not a finite number, times that go backwards, no rows.
    """
    path = Path(path)
    mapped = as_map(mapping, RESULT_QUANTITIES)
    try:
        with open(path, newline="", encoding="utf-8-sig") as file:
            rows = list(csv.reader(bounded_lines(file, str(path), ResultFileError, _GIVE_CSV)))
    except OSError as error:
        raise ResultFileError(f"{path}: cannot read: {error.strerror}") from None
    except csv.Error as error:  # a quoted cell across lines, over csv.field_size_limit()
        raise ResultFileError(f"{path}: not a CSV the judge reads ({error}); {_GIVE_CSV}") from None
    except UnicodeDecodeError:
        raise ResultFileError(f"{path}: not UTF-8 text; save the result as a UTF-8 CSV") from None
    numbered = [(number, row) for number, row in enumerate(rows, start=1) if any(c.strip() for c in row)]
    if not numbered:
        raise ResultFileError(f"{path}: the file is empty; expected a header such as time,theta")
    header = [cell.strip() for cell in numbered[0][1]]
    listed = shortened(",".join(header))
    columns = {}
    for quantity in RESULT_QUANTITIES:
        given = mapped.get(quantity)
        name = given.variable if given else quantity
        if name in header:
            columns[quantity] = (header.index(name), given.factor if given else 1.0)
        elif given:
            raise ResultFileError(
                f"{path}:1: no column {name!r}, which --map names for {quantity} (header is {listed})"
            )
        elif quantity not in OPTIONAL:
            raise ResultFileError(
                f"{path}:1: no column {quantity!r} (header is {listed}); "
                f"name the result's {quantity} column with --map {quantity}=NAME"
            )
    data = numbered[1:]
    if not data:
        raise ResultFileError(f"{path}: no data rows after the header")
    out = results.empty(len(data), recorded)
    out["torque"] = np.nan
    for quantity in OPTIONAL:
        out[quantity] = np.nan
    if _read_columns(out, data, columns):
        return out
    _refuse_rows(path, out, data, columns)
    return out


def _read_columns(out: np.ndarray, data: list, columns: dict) -> bool:
    """Fill out's columns from the rows a column at a time; False, with nothing to trust in out,
    when a cell is missing, not a number or not finite, or a time goes backwards (_refuse_rows
    then finds the first such row and says what is wrong with it).
    """
    for quantity, (column, factor) in columns.items():
        try:
            values = np.array([float(row[column]) for _, row in data])
        except (ValueError, IndexError):
            return False
        if not np.isfinite(values).all():
            return False
        out[quantity] = values * factor
    return not np.any(np.diff(out["time"]) < 0)


def _refuse_rows(path: Path, out: np.ndarray, data: list, columns: dict) -> None:
    """Read the rows one by one, raising ResultFileError at the first that cannot be judged."""
    for i, (number, row) in enumerate(data):
        for quantity, (column, factor) in columns.items():
            cell = row[column].strip() if column < len(row) else ""
            try:
                value = float(cell)
            except ValueError:
                raise ResultFileError(f"{path}:{number}: {quantity} {shortened(repr(cell))} is not a number") from None
            if not math.isfinite(value):
                raise ResultFileError(f"{path}:{number}: {quantity} is {shortened(cell)}; values must be finite")
            out[quantity][i] = value * factor
        if i and out["time"][i] < out["time"][i - 1]:
            raise ResultFileError(
                f"{path}:{number}: time {out['time'][i]:.17g} goes backwards (previous "
                f"row: {out['time'][i - 1]:.17g}); a result's times must not decrease"
            )
