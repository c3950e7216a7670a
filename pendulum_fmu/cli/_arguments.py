"""The argument types and option groups that several commands share."""

from __future__ import annotations

import argparse
from pathlib import Path

from .._errors import InvalidInput
from ..signals._time_grid import DEFAULT_MAX_STEPS


def assignment(text: str) -> tuple[str, str]:
    """A --set NAME=VALUE as (name, value)."""
    name, equals, value = text.partition("=")
    if not equals or not name or not value:
        raise argparse.ArgumentTypeError(f"expected name=value, got {text!r}")
    return name.strip(), value.strip()


def output_path(text: str) -> Path:
    """An output's path, refused when empty."""
    # An empty path would be the current folder: most likely an unset shell variable ("$OUT").
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; give a file or folder name (is a shell variable unset?)")
    return Path(text)


def output_location(text: str) -> str:
    """A folder's path or an fsspec URL, not empty."""
    output_path(text)
    return text


def float_number(text: str) -> float:
    """An option's number."""
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def positive_int(text: str) -> int:
    """An option's whole number, at least 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text} must be at least 1")
    return value


def parameters_of(assignments) -> dict[str, float]:
    """The --set assignments as {name: value}; InvalidInput for a value that is no number."""
    parameters = {}
    for name, value in assignments or ():
        try:
            parameters[name] = float(value)
        except ValueError:
            raise InvalidInput(f"--set {name}={value}: {value!r} is not a number") from None
    return parameters


def torque_signal(args):
    """The signal the options name: the --torque-file, or the --torque."""
    return args.torque_file if args.torque_file is not None else args.torque


def add_signal_arguments(parser, required: bool = True) -> None:
    """Add the options of a signal's run: the torque, the times, the parameters, the start values, the FMU."""
    group = parser.add_mutually_exclusive_group(required=required)
    group.add_argument("--torque", type=float_number, help="constant torque in N.m")
    group.add_argument(
        "--torque-file",
        type=Path,
        help="CSV with columns time,torque in fmpy's convention: linear between "
        "rows, a jump where a time repeats, held outside; each step holds the "
        "value just after its start unless --ramp (docs/signals.md)",
    )
    parser.add_argument(
        "--stop-time",
        type=float_number,
        default=None,
        help="end of the simulation in s (default: 3, or the CSV's last time)",
    )
    parser.add_argument(
        "--step-size", type=float_number, default=1e-3, help="communication step in s (default: %(default)s)"
    )
    parser.add_argument(
        "--set",
        dest="assignments",
        type=assignment,
        action="append",
        metavar="NAME=VALUE",
        help="parameter: mass, length, inertia, gravity, damping (repeatable)",
    )
    parser.add_argument("--theta0", type=float_number, default=0.0, help="initial angle in rad")
    parser.add_argument("--omega0", type=float_number, default=0.0, help="initial rate in rad/s")
    parser.add_argument(
        "--max-steps",
        type=positive_int,
        default=None,
        help=f"refuse runs longer than this many steps (default: {DEFAULT_MAX_STEPS:,})",
    )
    add_fmu_argument(parser)


def add_fmu_argument(parser) -> None:
    """Add --fmu, the FMU to run."""
    parser.add_argument(
        "--fmu",
        type=Path,
        default=None,
        help="the FMU to run, whose own parameters and defaults apply (default: "
        "the packaged FMU, or dist/Pendulum.fmu in a source checkout)",
    )


def check_outputs(outputs: dict, inputs: dict) -> None:
    """Refuse before the run an output that cannot be written, or that names a file twice.

    An output (option -> path) is refused when it cannot be written, when another output names
    it too, or when it is a file the command reads (option -> path): writing it would destroy the
    input.
    """
    from .._atomic_files import check_writable

    given = {option: Path(path) for option, path in outputs.items() if path}
    check_writable(*given.values())
    if given.get("--plot"):
        from ..figures._plot import check_figure_path  # here: matplotlib only for a command that draws

        check_figure_path(given["--plot"])
    read = {option: Path(path) for option, path in inputs.items() if path}
    for number, (option, path) in enumerate(given.items()):
        for other, other_path in [*list(given.items())[:number], *read.items()]:
            if same_file(path, other_path):
                raise InvalidInput(
                    f"{option} {path} names the same file as {other}: writing it would "
                    f"{'destroy what the command reads' if other in read else 'lose one of the two'}; "
                    "choose another path"
                )


def same_file(one: Path, other: Path) -> bool:
    """Whether two paths name the same file, also when it is not there yet."""
    try:
        return one.samefile(other)
    except OSError:  # one of them does not exist yet: the same file only by its name
        return one.resolve() == other.resolve()


def signal_options(args: argparse.Namespace) -> dict:
    """The keyword arguments of simulate, reference, compare and judge that the options give.

    Those that add_signal_arguments declares, with the torque aside (torque_signal), and --ramp,
    which every command that runs a signal declares with its own help.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of a command that declared them.

    Returns
    -------
    dict
        stop_time, step_size, ramp, parameters, theta0, omega0, max_steps and fmu_path.

    Raises
    ------
    InvalidInput
        A --set whose value is not a number.
    """
    return {
        "stop_time": args.stop_time,
        "step_size": args.step_size,
        "ramp": args.ramp,
        "parameters": parameters_of(args.assignments),
        "theta0": args.theta0,
        "omega0": args.omega0,
        "max_steps": args.max_steps,
        "fmu_path": args.fmu,
    }
