"""ClosedLoop.ssp run in each SSP master installable from PyPI, and the table of their verdicts.

Each runner takes the SSP as a user would hand it over and returns the pendulum's theta at the
times the master reports, as the master labels them; ssp_judge then says what the master did.
Where the SSP's pendulum set names a callRecordFile (export_ssp's call_record), each runner has
the pendulum's record of its FMI calls written there, in the way that master allows, for
_ssp_calls.py to judge: libcosim applies the set itself; fmpy.ssp is handed it as its parameter_set;
fmucontainer ignores the set, so its container runs with logging on and its log is the record.
OMSimulator is not among them: its PyPI sdist downloads binaries at install time (docs/ssp.md
gives its command).
"""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .._atomic_files import replacing
from .._errors import CannotWrite, MissingDependency
from .._received_files import MAX_LINE_CHARS
from ..judging._call_record import MARKER
from ._ssp import read_ssp, rebind_ssp
from ._ssp_calls import judge_ssp_calls
from ._ssp_judge import judge_coupling

NANOSECONDS = 10**9  # libcosim counts time in ns


def run_libcosim(ssp: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """OSP libcosim (libcosimpy): CosimExecution.from_ssp_file, step from the SSP's annotation.

    Parameters
    ----------
    ssp : str or PathLike
        The closed loop's SSP.

    Returns
    -------
    tuple of numpy.ndarray
        time (s) and the pendulum's theta (rad), from 0 to the DefaultExperiment's stop time.

    Raises
    ------
    MissingDependency
        libcosimpy is not installed.

    Examples
    --------
    >>> time, theta = run_libcosim("ClosedLoop.ssp")  # doctest: +SKIP
    """
    try:
        from libcosimpy.CosimEnums import CosimVariableType
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimObserver import CosimObserver
    except ImportError:
        raise MissingDependency("libcosim runs SSPs through libcosimpy: pip install libcosimpy") from None
    stop_time = read_ssp(ssp).stop_time
    execution = CosimExecution.from_ssp_file(str(ssp))  # no step given: the osp annotation's
    slave = {info.name.decode(): info.index for info in execution.slave_infos()}["pendulum"]
    theta = {v.name.decode(): v.reference for v in execution.slave_variables(slave)}["theta"]
    steps = round(stop_time / read_ssp(ssp).step_size)
    series, last = CosimObserver.create_time_series(buffer_size=steps + 2), CosimObserver.create_last_value()
    execution.add_observer(series)
    execution.add_observer(last)
    series.start_time_series(slave, value_reference=theta, variable_type=CosimVariableType.REAL)
    execution.simulate_until(target_time=round(stop_time * NANOSECONDS))
    times, _, values = series.time_series_real_samples(slave, theta, from_step=0, sample_count=steps + 2)
    # libcosimpy 0.0.6's time series holds every communication point but the last one reached.
    times = [*times, execution.status().current_time]
    values = [*values, last.last_real_values(slave, [theta])[0]]
    return np.array(times) / NANOSECONDS, np.array(values)


def run_fmpy_ssp(ssp: str | os.PathLike, *, parameter_set: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """fmpy.ssp.simulate_ssp with the SSP's stop time and step (it reads neither itself).

    Parameters
    ----------
    ssp : str or PathLike
        The closed loop's SSP.
    parameter_set : bool, optional
        Also hand fmpy the SSP's parameter sets through its parameter_set argument: fmpy does not
        apply the .ssv files the SSP binds.

    Returns
    -------
    tuple of numpy.ndarray
        fmpy's time column and pendulum.theta.

    Examples
    --------
    >>> time, theta = run_fmpy_ssp("ClosedLoop.ssp")  # doctest: +SKIP
    """
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import Parameter, ParameterSet

    settings = read_ssp(ssp)
    given = ParameterSet()
    if settings.call_record:  # first, so that the record holds the parameters set after it
        given.parameters.append(Parameter(name="pendulum.callRecordFile", type="String", value=settings.call_record))
    if parameter_set:
        for component, values in (("controller", settings.controller), ("pendulum", settings.pendulum)):
            for name, value in values.items():
                given.parameters.append(Parameter(name=f"{component}.{name}", type="Real", value=value))
    with _fmpy_ssp_sets_strings():
        result = simulate_ssp(
            str(ssp),
            stop_time=settings.stop_time,
            step_size=settings.step_size,
            parameter_set=given if given.parameters else None,
        )
    return result["time"], result["pendulum.theta"]


@contextlib.contextmanager
def _fmpy_ssp_sets_strings():
    """fmpy.ssp with String parameters in its parameter_set, for the pendulum's callRecordFile.

    fmpy 0.3's fmpy.ssp.simulation.set_value refuses any type but Real, Integer and Boolean: while
    this lasts, a String goes to the FMU's fmi2SetString and every other type to fmpy's own.
    """
    from fmpy.ssp import simulation

    own = simulation.set_value

    def set_value(component, name, value):
        variable = component.variables[name]
        if variable.type == "String":
            component.fmu.setString([variable.valueReference], [str(value)])
        else:
            own(component, name, value)

    simulation.set_value = set_value
    try:
        yield
    finally:
        simulation.set_value = own


def run_fmucontainer(ssp: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """fmu-manipulation-toolbox's fmucontainer makes one FMU of the SSP; fmpy runs it.

    Parameters
    ----------
    ssp : str or PathLike
        The closed loop's SSP.

    Returns
    -------
    tuple of numpy.ndarray
        time and pendulum.theta at every step, to the SSP's stop time.

    Raises
    ------
    MissingDependency
        fmu-manipulation-toolbox is not installed.
    CannotWrite
        The callRecordFile the SSP names is a symbolic link, or a file that is no call record.

    Examples
    --------
    >>> time, theta = run_fmucontainer("ClosedLoop.ssp")  # doctest: +SKIP
    """
    from fmpy import simulate_fmu

    try:
        import fmu_manipulation_toolbox  # noqa: F401  (its command is run below, in a process of its own)
    except ImportError:
        raise MissingDependency("fmucontainer comes with pip install fmu-manipulation-toolbox") from None
    settings = read_ssp(ssp)
    record = settings.call_record and _record_file(Path(settings.call_record), ssp)
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_fmucontainer_") as work:
        # fmucontainer writes its FMU beside the SSP it reads: a copy, so the user's folder stays as it was.
        copy = Path(shutil.copy(ssp, Path(work) / "ClosedLoop.ssp"))
        subprocess.run(
            [
                sys.executable,
                "-c",
                "import sys; from fmu_manipulation_toolbox.cli.fmucontainer "
                "import fmucontainer; sys.exit(fmucontainer())",
                "-fmu-directory",
                work,
                "-container",
                f"{copy.name}:{settings.step_size!r}",
            ],
            cwd=work,
            check=True,
            capture_output=True,
        )
        container = str(copy.with_suffix(".fmu"))
        if not record:
            result = simulate_fmu(container, stop_time=settings.stop_time, output_interval=settings.step_size)
        else:
            # The container passes no parameter set on, but forwards its FMUs' log messages: with
            # logging on, its log (fmpy prints it) holds the pendulum's record, whose lines are kept.
            printed = io.StringIO()
            with contextlib.redirect_stdout(printed):
                result = simulate_fmu(
                    container, stop_time=settings.stop_time, output_interval=settings.step_size, debug_logging=True
                )
            with replacing(record) as log:
                log.writelines(line for line in printed.getvalue().splitlines(keepends=True) if MARKER in line)
    return result["time"], result["pendulum.theta"]


def _record_file(path: Path, ssp: str | os.PathLike) -> Path:
    """The call record file a (received) SSP names, where writing destroys nothing: a new file, or
    one whose first line is a line of a call record; never a symbolic link, which replacing()
    would follow.
    """
    if path.is_symlink():
        fault = "a symbolic link"
    elif path.exists():
        try:
            with open(path, encoding="utf-8", errors="replace") as file:
                first = file.readline(MAX_LINE_CHARS)
        except OSError as error:
            first = error.strerror or ""
        fault = "" if MARKER in first else "a file that is no call record"
    else:
        fault = ""
    if fault:
        raise CannotWrite(
            f"{ssp} names {path} as the pendulum's call record, but it is {fault}: left as it is; "
            "name a new file (pendulum-fmu export-ssp --call-record FILE)"
        )
    return path


MASTERS = {
    "libcosimpy CosimExecution.from_ssp_file": run_libcosim,
    "fmpy.ssp.simulate_ssp": run_fmpy_ssp,
    "fmpy.ssp.simulate_ssp, parameter_set= given": lambda ssp: run_fmpy_ssp(ssp, parameter_set=True),
    "fmu-manipulation-toolbox fmucontainer": run_fmucontainer,
}


def masters_table(ssp: str | os.PathLike, records: str | os.PathLike | None = None) -> str:
    """Run the SSP in every master here and tabulate what the judge says of each (Markdown).

    Parameters
    ----------
    ssp : str or PathLike
        The closed loop's SSP.
    records : str or PathLike, optional
        A folder: each master runs a copy of the SSP there whose pendulum writes its call record
        beside it (MASTER_NUMBER.log), and the row adds what the judge reads from that record.

    Returns
    -------
    str
        One row per master: theta at the stop time, the coupling, whether the parameter set was
        applied, the distance from that coupling's reference and the problems found; with records,
        the coupling, the controller parameters that did not arrive, the pendulum parameters set
        and the problems the call record shows. A master that is not installed says so in its row.

    Examples
    --------
    >>> print(masters_table("ClosedLoop.ssp"))  # doctest: +SKIP
    """
    settings = read_ssp(ssp)
    header = "| master | theta at stop time | coupling | parameter set applied | from its reference | problems |"
    if records is not None:
        header += " call record: coupling | controller parameters missing | pendulum parameters set | problems |"
    columns = header.count("|") - 1
    rows = [header, "|---" * columns + "|"]
    for number, (name, run) in enumerate(MASTERS.items()):
        record = None if records is None else Path(records, f"master_{number}.log")
        ran = ssp if record is None else rebind_ssp(ssp, record.with_suffix(".ssp"), call_record=record)
        try:
            time, theta = run(ran)
        except MissingDependency as missing:
            rows.append(f"| {name} | not run: {missing} |" + " |" * (columns - 2))
            continue
        verdict = judge_coupling(time, theta, settings)
        # fmpy.ssp labels each value with its step's start: the value at the stop time is the one
        # labelled a step earlier.
        at_stop = np.interp(settings.stop_time - verdict.labelled_at_step_start * verdict.step_size, time, theta)
        row = (
            f"| {name} | {float(at_stop)!r} | {verdict.coupling} | "
            f"{'yes' if verdict.parameter_set_applied else 'no'} | {verdict.max_error:.2g} rad | "
            f"{'; '.join(verdict.problems) or 'none'} |"
        )
        if record is not None:
            recorded = judge_ssp_calls(record, settings)
            row += (
                f" {recorded.coupling} | {', '.join(recorded.controller_missing) or 'none'} | "
                f"{', '.join(recorded.pendulum_set) or 'none'} | {'; '.join(recorded.problems) or 'none'} |"
            )
        rows.append(row)
    return "\n".join(rows)


def main(argv=None) -> int:
    """Print the masters' table for an SSP (python -m pendulum_fmu.ssp._ssp_masters [ClosedLoop.ssp]).

    Parameters
    ----------
    argv : list of str, optional
        The SSP's path; default: a fresh export in a temporary folder.

    Returns
    -------
    int
        0.

    Examples
    --------
    >>> main([])  # doctest: +SKIP
    """
    from ._ssp import export_ssp

    try:
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

        log_output_level(CosimLogLevel.WARNING)  # libcosim's debug lines would bury the table
    except ImportError:
        pass  # its row says it is not installed
    argv = sys.argv[1:] if argv is None else argv
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_ssp_") as tmp:
        ssp = argv[0] if argv else export_ssp(Path(tmp) / "ClosedLoop.ssp")
        print(masters_table(ssp, records=tmp))
    return 0


if __name__ == "__main__":
    sys.exit(main())
