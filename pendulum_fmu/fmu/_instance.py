"""One FMI instance of a model: opened through fmpy, its messages kept, initialized for a run.

open_fmu() gives an initialized FmuInstance: fmpy's FMU2Slave or FMU3Slave of an FmuModel
(_model.py), with the log of what the FMU says (MessageLog), so that an FMI call that fails can
say why (FmuError). _simulate.py runs schedules through such instances.
"""

from __future__ import annotations

import copy
import ctypes
import itertools
import weakref
from pathlib import Path

import fmpy
from fmpy.fmi1 import printLogMessage
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Slave

from .._errors import PendulumFmuError
from ._model import FmuModel, fmu_model
from ._parameters import merged_with, start_value

_STATUS = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"]


class FmuError(PendulumFmuError, RuntimeError):
    """An FMI call failed, or the FMU refused a value; the message carries what the FMU logged.

    Examples
    --------
    A relative tolerance the FMU refuses when it is set up:

    >>> from pendulum_fmu import FmuError, simulate
    >>> try:
    ...     simulate(20.0, tolerance=2.0)
    ... except FmuError as error:
    ...     print(error)
    initialization failed: [ERROR] fmi2SetupExperiment: tolerance 2 must be in (0, 1)
    """


def _log_to_instance(environment, instance_name, status, category, message):
    log = _logs.get(environment)
    if log is not None:
        log.log_fmi3(environment, status, category, message)
    elif environment is None:
        # An instance fmpy made with its default callbacks (the user's own FMU2Slave): fmpy's
        # proxy now calls this logger for it too, so print its messages as fmpy's would.
        printLogMessage(environment, instance_name, status, category, message)


# One FMI 2.0 logger for every instance, never freed, which hands each message to its instance's
# log by the componentEnvironment the instance was given: fmpy's formatting proxy keeps the last
# logger it was given in one global, so a logger per instance would be called for another
# instance's messages, or after it was freed (a crash when instances live in several threads).
_LOGGER = fmi2CallbackLoggerTYPE(_log_to_instance)


_logs: weakref.WeakValueDictionary[int, MessageLog] = weakref.WeakValueDictionary()


_log_keys = itertools.count(1)


class MessageLog:
    """FMI callbacks whose logger keeps what the FMU says, so a failure can say why.

    FMI 2.0: `callbacks` for fmi2Instantiate. FMI 3.0: `log_fmi3` is the logMessage callback (it
    has no instance name), and fmpy's FMI 2.0 proxy is left alone.
    """

    def __init__(self, fmi_version: int = 2):
        self.lines: list[str] = []
        if fmi_version == 3:
            return
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = _LOGGER
        key = next(_log_keys)
        self.callbacks.componentEnvironment = key
        _logs[key] = self
        try:
            # fmpy's C proxy formats printf-style arguments before they reach Python.
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(ctypes.byref(self.callbacks))
        except Exception:
            pass

    def log_fmi3(self, environment, status, category, message):
        self.lines.append(f"[{_STATUS[status] if 0 <= status < 6 else status}] {message.decode('utf-8', 'replace')}")

    def error(self, status: int, call: str) -> FmuError:
        detail = "; ".join(self.lines[-3:]) or "no message"
        return FmuError(f"{call} returned {_STATUS[status]}: {detail}")

    def initialization_error(self, reason: str) -> FmuError:
        return FmuError(f"initialization failed: {'; '.join(self.lines) or reason}")

    def instantiation_error(self, fmu_path) -> FmuError:
        """An FMU that returned no instance (fmpy raises a bare Exception), with what it logged."""
        return FmuError(f"{fmu_path}: the FMU refused to instantiate: {'; '.join(self.lines) or 'no message'}")


def instantiate(slave: FMU2Slave | FMU3Slave, messages: MessageLog, fmu_path) -> None:
    """slave.instantiate with messages as its logger; FmuError naming fmu_path and what the FMU
    logged when it returns no instance.
    """
    try:
        if isinstance(slave, FMU3Slave):
            slave.instantiate(logMessage=messages.log_fmi3)
        else:
            slave.instantiate(callbacks=messages.callbacks)
    except Exception:  # fmpy's own, for a NULL instance
        raise messages.instantiation_error(fmu_path) from None


def _unzipped(fmu_path):
    """(folder, model description) of an FMU file, extracted once per model (model.FmuModel)."""
    model = fmu_model(fmu_path)  # refuses what is no FMU before it is unzipped
    return model.folder, model.description


def fmi2_library(folder: str, model_identifier: str) -> str | None:
    """The FMI 2.0 binary for fmpy to load (FMU2Slave's libraryPath), or None to let fmpy choose.

    fmpy 0.3 looks in binaries/linux64 on ARM64 Linux too, where an FMU (this one, the Reference
    FMUs) keeps its binary in binaries/aarch64-linux: that one, when the FMU has it.

    Parameters
    ----------
    folder : str
        The extracted FMU.
    model_identifier : str
        The Co-Simulation model identifier, the binary's file name.

    Returns
    -------
    str or None
        The binary's path on ARM64 Linux when the FMU has binaries/aarch64-linux, else None.
    """
    if fmpy.system == "linux" and fmpy.architecture == "aarch64":
        library = Path(folder, "binaries", "aarch64-linux", f"{model_identifier}.so")
        if library.is_file():
            return str(library)
    return None


def open_fmu(
    fmu_path: str | Path | FmuModel | None = None,
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    tolerance: float | None = None,
    start_time: float = 0.0,
    instance_name: str = "pendulum",
):
    """An FMU instance, initialized and in step mode, to drive call by call with fmpy's calls.

    The FMI version is read from the FMU's model description (instance.fmi_version says which);
    fmpy's calls (doStep, getReal, setReal, setFloat64, ...) pass through to its FMU2Slave or
    FMU3Slave. The caller frees it with ``instance.terminate(); instance.freeInstance()``.

    Parameters
    ----------
    fmu_path : str, Path, FmuModel or None, optional
        The FMU; None: pendulum_fmu.default_fmu(). Its parameters and value references apply.
    parameters : dict, optional
        The FMU's parameters over its defaults (mass, length, inertia, gravity, damping).
    theta0, omega0 : float, optional
        Start angle (rad) and rate (rad/s).
    tolerance : float, optional
        The relative tolerance handed to the FMU (None: the FMU's own).
    start_time : float, optional
        The time of the first communication point, in s.
    instance_name : str, optional
        The FMI instance name, which the FMU's log messages carry.

    Returns
    -------
    FmuInstance
        With its message log as instance.messages and its model as instance.model.

    Raises
    ------
    MissingFile, FmuFileError
        No file at fmu_path, or none that is a pendulum FMU this machine can run (checked before
        anything is unzipped or loaded).
    InvalidInput
        A parameter or start value that is no finite number, or a parameter the FMU has not.
    FmuError
        The FMU refused the parameters, start values, tolerance or start time; the message
        carries what it logged.

    Examples
    --------
    One 0.1 s step with 20 N.m from theta = 0.1 rad:

    >>> from pendulum_fmu import open_fmu
    >>> instance = open_fmu(theta0=0.1)
    >>> theta, omega, torque = (instance.model.value_reference(name) for name in ("theta", "omega", "torque"))
    >>> instance.fmi_version, instance.getReal([theta, omega])
    (2, [0.1, 0.0])
    >>> instance.setReal([torque], [20.0])
    >>> instance.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.1)
    >>> [round(value, 6) for value in instance.getReal([theta, omega])]
    [0.100068, 0.001361]
    >>> instance.terminate()  # fmpy returns the FMI status: 0, OK
    0
    >>> instance.freeInstance()
    """
    slave = instantiated(fmu_model(fmu_path), instance_name)
    try:
        initialize(
            slave, parameters=parameters, theta0=theta0, omega0=omega0, tolerance=tolerance, start_time=start_time
        )
    except BaseException:
        slave.freeInstance()
        raise
    return slave


def instantiated(model: FmuModel, instance_name: str) -> FmuInstance:
    """An instantiated FmuInstance of a model, not yet initialized (see open_fmu)."""
    _ = model.pendulum_variables  # FmuFileError when it is no pendulum FMU
    model.binary()  # FmuFileError when it has no binary this machine loads
    folder, description, fmi_version = model.folder, model.description, model.fmi_version
    messages = MessageLog(fmi_version)
    arguments = dict(
        guid=description.guid,
        unzipDirectory=folder,
        instanceName=instance_name,
        modelIdentifier=description.coSimulation.modelIdentifier,
    )
    if fmi_version == 3:
        slave = FMU3Slave(**arguments)
    else:
        slave = FMU2Slave(**arguments, libraryPath=fmi2_library(folder, arguments["modelIdentifier"]))
    instantiate(slave, messages, model.path)
    return FmuInstance(slave, messages, model)


def sibling(instance: FmuInstance, instance_name: str) -> FmuInstance:
    """Another FMI 2.0 instance of instance's FMU, instantiated (not initialized) through the
    library instance already loaded, with a message log of its own.

    fmpy binds every FMI function of its library anew for each slave it makes (about 1 ms and
    50 kB an instance); a sibling shares the first one's (16 us and 3 kB), so that a batch of
    thousands starts at once. Free it with ``sibling.fmi2FreeInstance(sibling.component)``, not
    freeInstance(), which would unload the library the others still use.
    """
    slave = copy.copy(instance.slave)
    slave.instanceName = instance_name
    messages = MessageLog(instance.fmi_version)
    instantiate(slave, messages, instance.model.path)
    return FmuInstance(slave, messages, instance.model)


def initialize(
    slave: FmuInstance,
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    tolerance: float | None = None,
    start_time: float = 0.0,
) -> None:
    """Set the parameters and start values of an instantiated (or reset) slave from open_fmu and
    leave it in step mode; FmuError says why the FMU refused.
    """
    # The FMU checks the parameters itself, here as everywhere (resolve_parameters).
    start = {
        **merged_with(slave.model.default_parameters, parameters),
        "theta": start_value("theta0", theta0, "rad"),
        "omega": start_value("omega0", omega0, "rad/s"),
    }
    value_references = slave.model.value_references
    references = [value_references[n] for n in start]
    try:
        if slave.fmi_version == 3:
            slave.enterInitializationMode(tolerance=tolerance, startTime=start_time)
            slave.setFloat64(references, list(start.values()))
        else:
            slave.setupExperiment(tolerance=tolerance, startTime=start_time)
            slave.enterInitializationMode()
            slave.setReal(references, list(start.values()))
        slave.exitInitializationMode()
    except Exception as error:
        raise slave.messages.initialization_error(str(error)) from None


class FmuInstance:
    """One FMI instance of a model: fmpy's FMU2Slave or FMU3Slave, the log of what the FMU says,
    and the model whose value references and parameters apply.

    fmpy's calls (doStep, getReal, setFloat64, terminate, freeInstance, dll, component, ...) pass
    through to the slave, so an instance is used as the slave would be.

    Made by open_fmu(), which instantiates and initializes it.

    Parameters
    ----------
    slave : fmpy.fmi2.FMU2Slave or fmpy.fmi3.FMU3Slave
        Instantiated with messages as its logger.
    messages : MessageLog
        Keeps what the FMU logs (and its logger callback alive as long as the instance).
    model : FmuModel
        The FMU the slave was made from.

    Attributes
    ----------
    slave : fmpy.fmi2.FMU2Slave or fmpy.fmi3.FMU3Slave
        fmpy's instance, which the calls pass through to.
    messages : MessageLog
        What the FMU logged.
    model : FmuModel
        The FMU's model object: value references, parameters, outputs.
    fmi_version : {2, 3}
        The FMI standard of the FMU.
    dll, component
        fmpy's loaded library and the FMI component, as the native loop binds them.

    Examples
    --------
    >>> from pendulum_fmu import open_fmu
    >>> instance = open_fmu()
    >>> type(instance).__name__, instance.fmi_version, instance.model.outputs
    ('FmuInstance', 2, ('theta', 'omega', 'alpha'))
    >>> instance.getReal([instance.model.value_reference("theta")])
    [0.0]
    >>> status = instance.terminate(); instance.freeInstance()
    """

    def __init__(self, slave, messages, model: FmuModel):
        self.slave, self.messages, self.model = slave, messages, model
        self.fmi_version = model.fmi_version  # 2 or 3
        # Read on every run (the loops bind the FMI functions): plain attributes, not a pass-through.
        self.dll, self.component = slave.dll, slave.component

    def __getattr__(self, name: str):
        # Only what the instance itself lacks: fmpy's calls and attributes (never the slave itself,
        # which an instance not yet initialized, as when copied, lacks).
        if name == "slave":
            raise AttributeError(name)
        return getattr(self.slave, name)
