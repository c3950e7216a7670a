"""The base of every error a user's input causes, and the kinds shared across modules.

Every error the package raises for what its user gave derives from PendulumFmuError, and its
message is one line saying what, where and what to do. The command line prints exactly these as
that line (exit 2); anything else is a bug of ours, reported as an internal error. Each type also
derives from the built-in exception a Python caller would expect (ValueError for a bad value,
OSError for a file, ...). The kinds that belong to one module live there:

    torque_schedule.TorqueFileError   a torque CSV that is not a signal
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
    """


class WrongType(PendulumFmuError, TypeError):
    """An argument of a kind the function does not take (None for a folder, a list for a Study);
    the message says what it takes.
    """


class MissingFile(PendulumFmuError, FileNotFoundError):
    """A file the user named, or the FMU the package needs, is not there."""


class CannotWrite(PendulumFmuError, OSError):
    """An output cannot be written where it was asked for (a file where a folder must be, no
    permission, a full disk).
    """


class MissingDependency(PendulumFmuError, ImportError):
    """An optional package a tool needs is not installed; the message gives the pip command."""


class BuildError(PendulumFmuError, RuntimeError):
    """The FMU could not be built; the message says why. Raised by the repository's build tool
    (fmu_build/, beside the package in a checkout), and defined here so that the package's callers
    catch it without that tool.
    """


class PlatformSkipped(UserWarning):
    """A platform left out of a default build because its compiler is missing (the build tool
    warns; the command line shows it in one line).
    """


class NotComputed(UserWarning):
    """A tool was asked for an output it cannot compute (one the FMU has and the tool does not
    model): its column is NaN, never zeros. The message is one line naming the tool and the
    outputs; the command line prints it as that line and goes on.
    """


class Skipped(UserWarning):
    """A part of the run left out because this machine lacks what it needs (a tool's package); the
    message is one line saying which part and how to get it. The command line prints it as that
    line and goes on.
    """
