"""A scenario's settings file, NAME.json: written with the kit, read back for the judge.

read_settings checks every field a person may have edited and refuses a wrong one in one line
naming the file and the field; settings_files finds the scenarios in a kit's folder.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from .._errors import InvalidInput
from .._received_files import MAX_SETTINGS_BYTES, bounded_text, shortened
from ._scenario_list import Scenario

# The tolerance the kit's FMU is run at (its own default); the judge's, in rad.
RELATIVE_TOLERANCE, JUDGE_TOLERANCE = 1e-10, 1e-9
# The kit's copy of the FMU, as every scenario's settings name it.
KIT_FMU = "Pendulum.fmu"


def scenario_settings(scenario: Scenario, parameters: dict, units: dict[str, str]) -> dict:
    """What NAME.json holds for a scenario run with these parameters (every one of the FMU's);
    units: the reference's (_results.units).
    """
    name = scenario.name
    return {
        "name": name,
        "description": scenario.description,
        "fmu": KIT_FMU,
        "input": f"{name}_in.csv",
        "reference": f"{name}_ref.csv",
        "output": f"{name}_out.csv",
        "start_time": scenario.start_time,
        "stop_time": scenario.stop_time,
        "step_size": scenario.step_size,
        "ramp": scenario.ramp,
        "resume_time": scenario.resume_time,
        "parameters": parameters,
        "theta0": scenario.theta0,
        "omega0": scenario.omega0,
        "relative_tolerance": RELATIVE_TOLERANCE,
        "tolerance": JUDGE_TOLERANCE,
        "units": {**units, "step_size": "s", "tolerance": "rad"},
    }


def read_settings(path: str | Path) -> dict:
    """A scenario's settings as judge()'s keyword arguments.

    Parameters
    ----------
    path : str or Path
        The scenario's NAME.json.

    Returns
    -------
    dict
        torque (the input's path), start_time, stop_time, step_size, ramp, parameters, theta0,
        omega0, tolerance; and output, the name of the result file a master writes.

    Raises
    ------
    InvalidInput
        One line naming the file and what is wrong with it: not JSON, not an object, a field
        missing, or a field of the wrong type or out of its range (a time that is not a finite
        number, a step size or tolerance that is not positive, stop_time not after start_time).

    Examples
    --------
    A kit's first scenario; ``judge(result, **settings)`` (without output) judges a master's
    result of it:

    >>> import tempfile
    >>> from pendulum_fmu import read_settings, write_scenarios
    >>> kit = write_scenarios(tempfile.mkdtemp())
    >>> settings = read_settings(next(path for path in kit if path.name == "constant_torque.json"))
    >>> settings["torque"].name, settings["output"], settings["stop_time"], settings["step_size"]
    ('constant_torque_in.csv', 'constant_torque_out.csv', 3.0, 0.001)
    """
    path = Path(path)
    try:
        settings = json.loads(bounded_text(path, MAX_SETTINGS_BYTES, InvalidInput, _AGAIN))
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise InvalidInput(f"{path}: not a scenario's settings: {error}") from None
    except RecursionError:  # [[[[...]]]]: the decoder recurses once per level
        raise InvalidInput(f"{path}: not a scenario's settings: nested too deep; {_AGAIN}") from None
    except OSError as error:
        raise InvalidInput(f"{path}: cannot read: {error.strerror}") from None
    if not isinstance(settings, dict):
        raise InvalidInput(
            f"{path}: not a scenario's settings: it holds a JSON {_json_kind(settings)}, not an object; {_AGAIN}"
        )
    missing = [key for key in SETTINGS_READ if key not in settings]
    if missing:
        raise InvalidInput(f"{path}: not a scenario's settings: no {', '.join(map(repr, missing))}; {_AGAIN}")
    field = _FieldChecker(path, settings)
    start_time = field.number("start_time", "s")
    stop_time = field.number("stop_time", "s")
    if not stop_time > start_time:
        raise InvalidInput(
            f"{path}: stop_time {stop_time!r} is not after start_time {start_time!r}; correct it, or {_AGAIN}"
        )
    return {
        "torque": path.parent / field.file_name("input"),
        "output": field.file_name("output"),
        "start_time": start_time,
        "stop_time": stop_time,
        "step_size": field.number("step_size", "s", positive=True),
        "ramp": field.boolean("ramp"),
        "parameters": field.parameters("parameters"),
        "theta0": field.number("theta0", "rad"),
        "omega0": field.number("omega0", "rad/s"),
        "tolerance": field.number("tolerance", "rad", positive=True),
    }


# The fields read_settings takes from NAME.json.
SETTINGS_READ = (
    "input",
    "output",
    "start_time",
    "stop_time",
    "step_size",
    "ramp",
    "parameters",
    "theta0",
    "omega0",
    "tolerance",
)

_AGAIN = "write the kit again with pendulum-fmu scenarios --output-dir FOLDER --overwrite"


def _json_kind(value) -> str:
    """What a value is called in JSON, for messages about a hand-edited file."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    kinds: dict[type, str] = {str: "string", list: "array", dict: "object"}
    return kinds.get(type(value), type(value).__name__)


@dataclass(frozen=True)
class _FieldChecker:
    """The checks of NAME.json's fields: a hand-edited value of the wrong type or out of range is
    refused naming the file and the field, before it can reach the judge's arithmetic.
    """

    path: Path
    settings: dict

    def _refuse(self, key: str, what: str):
        value = shortened(json.dumps(self.settings[key]))
        raise InvalidInput(f"{self.path}: {key} is {value}; it must be {what}: correct it, or {_AGAIN}")

    def number(self, key: str, unit: str, positive: bool = False) -> float:
        value = self.settings[key]
        # bool is an int in Python, but true is no time or angle.
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
            or (positive and value <= 0)
        ):
            self._refuse(key, f"{'a positive' if positive else 'a'} finite number ({unit})")
        return float(value)

    def boolean(self, key: str) -> bool:
        if not isinstance(self.settings[key], bool):
            self._refuse(key, "true or false")
        return self.settings[key]

    def file_name(self, key: str) -> str:
        value = self.settings[key]
        if not (isinstance(value, str) and value.strip()):
            self._refuse(key, "a file name (a JSON string)")
        # A kit's files lie beside its NAME.json: a received kit names no file elsewhere on the
        # machine for the judge to read and quote.
        if value != Path(value).name or value in (".", "..") or "\\" in value:
            self._refuse(key, "the name of a file in the kit's folder, with no folder before it")
        return value

    def parameters(self, key: str) -> dict[str, float]:
        value = self.settings[key]
        if not isinstance(value, dict):
            self._refuse(key, "an object {name: value}")
        for name, number in value.items():
            if isinstance(number, bool) or not isinstance(number, (int, float)) or not math.isfinite(number):
                raise InvalidInput(
                    f"{self.path}: parameters: {shortened(name)} is {shortened(json.dumps(number))}; it must be "
                    f"a finite number: correct it, or {_AGAIN}"
                )
        return {name: float(number) for name, number in value.items()}


def settings_files(folder: str | Path) -> dict[str, Path]:
    """The scenarios in a folder: each NAME.json with a NAME_in.csv beside it.

    Parameters
    ----------
    folder : str or Path
        A kit's folder.

    Returns
    -------
    dict
        {scenario: its NAME.json}, by name.
    """
    folder = Path(folder)
    return {path.stem: path for path in sorted(folder.glob("*.json")) if (folder / f"{path.stem}_in.csv").is_file()}
