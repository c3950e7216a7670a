"""The base of every error a user's input causes, and the kinds shared across modules.

Every error the package raises for what its user gave derives from PendulumFmuError, and its
message is one line saying what, where and what to do. The command line prints exactly these as
that line (exit 2); anything else is a bug of ours, reported as an internal error. Each type also
derives from the built-in exception a Python caller would expect (ValueError for a bad value,
OSError for a file, ...). The kinds that belong to one module live there:

    torque_csv.TorqueFileError        a torque CSV that is not a signal
    instance.FmuError                 an FMI call failed or the FMU refused a value
    model.FmuFileError                a file given as an FMU that is none this package can run
    compare_tools.ToolSpecError       a --tools list that names no runnable tool
    mapped_fmu.MapError               a --map, or an FMU that does not fit it
    result_file.ResultFileError       a result file, or a kit's folder, that cannot be judged
    scenarios.KitExists               an output folder holding a scenario kit the run was not asked to replace
    ssp.SspExists                     an SSP the export was not asked to replace
    ssp.SspFileError                  a file given as the closed loop's SSP that is not one
    demo.DemoExists                   an output folder holding a demo's outputs the run was not asked to replace
    export.FmuExists                  an export's output file the run was not asked to replace
    engines.ToolCannotRamp            a ramp given to a tool that holds the torque
    engines.drake.UnequalSteps        unequal steps given to drake:default
    engines._pendulum_v1.NotRepresentable  a run Pendulum-v1 (Gymnasium's, EnvPool's) cannot represent
    sweep.store.InUse                 an output folder another run holds
    sweep.store.StudyExists           an output folder holding a study the run was not asked to replace
    sweep.client.SchedulerUnreachable a dask scheduler that does not answer
    sweep.client.SchedulerLost        a dask scheduler lost while a study ran
    BuildError                        an FMU that cannot be built (by a checkout's fmu_build/)
"""


class PendulumFmuError(Exception):
    """Base of every error the user's input causes; the message is the one line to show.

    Examples
    --------
    A stop time before the start, refused in one line:

    >>> from pendulum_fmu import PendulumFmuError, simulate
    >>> try:
    ...     simulate(20.0, stop_time=-1)
    ... except PendulumFmuError as error:
    ...     print(error)
    stop time -1 must be after start time 0.0
    """


class InvalidInput(PendulumFmuError, ValueError):
    """An argument, option, parameter or case the package refuses: a time, a step, a tolerance,
    a parameter's name or value, a sweep's values.

    Examples
    --------
    >>> from pendulum_fmu import InvalidInput, simulate
    >>> try:
    ...     simulate(20.0, step_size=0)
    ... except InvalidInput as error:
    ...     print(error)
    step size 0 must be positive
    >>> issubclass(InvalidInput, ValueError)
    True
    """


class WrongType(PendulumFmuError, TypeError):
    """An argument of a kind the function does not take (None for a folder, a list for a Study);
    the message says what it takes.

    Examples
    --------
    >>> from pendulum_fmu import WrongType, simulate
    >>> try:
    ...     simulate(20.0, parameters=[("mass", 2.0)])
    ... except WrongType as error:
    ...     print(error)
    parameters is a dict {name: value}, e.g. {'gravity': 0}; got a list
    >>> issubclass(WrongType, TypeError)
    True
    """


class MissingFile(PendulumFmuError, FileNotFoundError):
    """A file the user named, or the FMU the package needs, is not there.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import MissingFile, simulate
    >>> absent = Path(tempfile.mkdtemp(), "absent.fmu")
    >>> try:
    ...     simulate(20.0, fmu_path=absent)
    ... except MissingFile as error:
    ...     print(str(error).replace(str(absent), "absent.fmu"))
    FMU absent.fmu: No such file or directory
    >>> issubclass(MissingFile, FileNotFoundError)
    True
    """


class CannotWrite(PendulumFmuError, OSError):
    """An output cannot be written where it was asked for (a file where a folder must be, no
    permission, a full disk).

    Examples
    --------
    A file where the output's folder must be:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import CannotWrite, schedule, write_torque_csv
    >>> notes = Path(tempfile.mkdtemp(), "notes.txt")
    >>> _ = notes.write_text("a file, not a folder")
    >>> try:
    ...     write_torque_csv(notes / "torque.csv", schedule(1.0))
    ... except CannotWrite as error:
    ...     print(str(error).replace(str(notes), "notes.txt"))
    cannot write notes.txt/torque.csv: notes.txt is a file, not a folder; choose another output path
    >>> issubclass(CannotWrite, OSError)
    True
    """


class MissingDependency(PendulumFmuError, ImportError):
    """An optional package a tool needs is not installed; the message says what to install.

    Examples
    --------
    A sweep's output folder on Azure, whose fsspec package (adlfs) no extra installs:

    >>> from pendulum_fmu import MissingDependency, Study, run_sweep, sweep_grid
    >>> try:
    ...     run_sweep(Study(sweep_grid([1.0])), output_dir="abfs://container/study")
    ... except MissingDependency as error:
    ...     print(error)
    output directory abfs://container/study: Install adlfs to access Azure ...
    >>> issubclass(MissingDependency, ImportError)
    True
    """


class BuildError(PendulumFmuError, RuntimeError):
    """The FMU could not be built; the message says why. Raised by the repository's build tool
    (fmu_build/, beside the package in a checkout), and defined here so that the package's callers
    catch it without that tool.

    Examples
    --------
    In a checkout, default_fmu() rebuilds a stale FMU, and raises it when that fails:

    >>> from pendulum_fmu import BuildError, PendulumFmuError, default_fmu
    >>> try:
    ...     fmu = default_fmu()
    ... except BuildError as error:
    ...     print(error)
    >>> fmu.name, issubclass(BuildError, (PendulumFmuError, RuntimeError))
    ('Pendulum.fmu', True)
    """


class PlatformSkipped(UserWarning):
    """A platform left out of a default build because its compiler is missing (the build tool
    warns; the command line shows it in one line).

    Examples
    --------
    A warning, not an error: a caller that needs every platform makes it one.

    >>> import warnings
    >>> from pendulum_fmu import PlatformSkipped
    >>> issubclass(PlatformSkipped, UserWarning)
    True
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", PlatformSkipped)
    ...     try:
    ...         warnings.warn("win64 skipped: no cross compiler", PlatformSkipped)
    ...     except PlatformSkipped as warning:
    ...         print(warning)
    win64 skipped: no cross compiler
    """


class NotComputed(UserWarning):
    """A tool was asked for an output it cannot compute (one the FMU has and the tool does not
    model): its column is NaN, never zeros. The message is one line naming the tool and the
    outputs; the command line prints it as that line and goes on.

    Examples
    --------
    A warning, so the comparison goes on; a caller that needs every output makes it an error
    (``warnings.simplefilter("error", NotComputed)``), as PlatformSkipped shows.

    >>> from pendulum_fmu import NotComputed
    >>> issubclass(NotComputed, UserWarning)
    True
    """


class Clipped(UserWarning):
    """A tool clipped the torque or the speed of its run (Pendulum-v1's +-2 N.m and +-8 rad/s): its
    result is the clipped run's. The message is one line naming the tool, what it clipped, in how
    many steps and from when; the command line prints it as that line and goes on.

    Examples
    --------
    >>> from pendulum_fmu import Clipped
    >>> issubclass(Clipped, UserWarning)
    True
    """


class Skipped(UserWarning):
    """A part of the run left out because this machine lacks what it needs (a tool's package); the
    message is one line saying which part and how to get it. The command line prints it as that
    line and goes on.

    Examples
    --------
    compare() without tools runs the default tools installed here and warns which it left out:

    >>> import tempfile, warnings
    >>> from pendulum_fmu import Skipped, compare
    >>> issubclass(Skipped, UserWarning)
    True
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always", Skipped)
    ...     comparison = compare(20.0, output_dir=tempfile.mkdtemp(), stop_time=0.01)
    >>> skipped = [str(warning.message) for warning in caught if warning.category is Skipped]
    >>> sorted(comparison.runs) == sorted(["fmu", "reference", *([] if skipped else ["opensim"])])
    True
    """


class UnencryptedScheduler(UserWarning):
    """A sweep's dask scheduler given by a plain tcp:// address off the loopback: whoever reaches
    its port can run code on its workers. The message is one line naming TLS; the command line
    prints it as that line and goes on.

    Examples
    --------
    >>> import warnings
    >>> from pendulum_fmu.sweep.security import client_security
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = client_security("tcp://192.0.2.1:8786", None)
    >>> [warning.category.__name__ for warning in caught], "TLS" in str(caught[0].message)
    (['UnencryptedScheduler'], True)
    """
