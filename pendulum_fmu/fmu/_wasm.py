"""The FMU's WebAssembly binary (FMI-LS-WASM) run through wasmtime, where fmpy runs the native one.

An FMI 3.0 FMU may carry binaries/wasm32-wasip2/<modelIdentifier>.wasm, a component of the
WebAssembly Component Model that exports the draft standard's interfaces (fmi:fmi3/co-simulation
and fmi:fmi3/model-exchange, package fmi:fmi3@3.0.0) and imports fmi:fmi3/callbacks. WasmInstance
is one instance of it, a resource in a wasmtime store of its own, with the fmpy names the
package's loops call (enterInitializationMode, setFloat64, doStep, ...), so _instance.initialize
and _simulate's Simulator drive it as they drive fmpy's FMU3Slave; run_schedule steps it through a
schedule.

The host hands the component the FMI callbacks and nothing else: its log messages go to the
instance's MessageLog, as the native binary's do; any other import (a WASI interface a C library
linked in) is defined as a trap, so the binary can neither read a file, nor the clock, nor the
network, and one that tries stops with FmuError. wasmtime is an optional dependency (the wasm
extra); without it, running the binary is refused in one line.
"""

from __future__ import annotations

import atexit
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from fmpy.fmi3 import FMU3Model

from .._errors import MissingDependency
from .._received_files import shortened
from ..signals._torque_schedule import TorqueSchedule
from . import WASM_PLATFORM
from ._instance import FmuError, MessageLog
from ._model import FmuFileError, FmuModel

CALLBACKS = "fmi:fmi3/callbacks@3.0.0"
INTERFACES = {"CoSimulation": "fmi:fmi3/co-simulation@3.0.0", "ModelExchange": "fmi:fmi3/model-exchange@3.0.0"}
RESOURCES = {"CoSimulation": "co-simulation-instance", "ModelExchange": "model-exchange-instance"}
# The draft's enum status, in the order of fmi3Status (MessageLog's index).
STATUS = ("ok", "warning", "discard", "error", "fatal")
# The longest log message kept: a line one reads, whatever length the binary sends.
MESSAGE_CHARS = 1000
# The statuses after which a run goes on.
_PASSED = ("ok", "warning")
INSTALL = 'pip install ".[wasm]" in a clone of pendulum-fmu (or "WHEEL.whl[wasm]" for its wheel)'


def wasmtime_module() -> Any:
    """The wasmtime package; MissingDependency, in one line, when it is not installed."""
    try:
        import wasmtime
        import wasmtime.component
    except ImportError:
        raise MissingDependency(
            f"running the FMU's {WASM_PLATFORM} binary needs the wasmtime package: {INSTALL}"
        ) from None
    return wasmtime


@lru_cache(maxsize=1)
def _engine() -> Any:
    """The process's wasmtime engine, which compiles every component (made on first use)."""
    return wasmtime_module().Engine()


@lru_cache(maxsize=8)
def _component(model: FmuModel) -> Any:
    """The model's WebAssembly component, compiled once per model (a file rebuilt is another model).

    Raises FmuFileError when the FMU carries no such binary or one wasmtime cannot load.
    """
    wasmtime = wasmtime_module()
    name = model.binary(WASM_PLATFORM)
    assert name is not None  # binary() raised otherwise
    try:
        return wasmtime.component.Component.from_file(_engine(), Path(model.folder, name))
    except wasmtime.WasmtimeError as error:
        first = str(error).strip().splitlines()[0] if str(error).strip() else "no reason given"
        raise FmuFileError(
            f"{model.path}: its {name} is no WebAssembly component wasmtime can load ({shortened(first, 200)}): "
            "give an FMU whose binary was made by pendulum-fmu build"
        ) from None


# wasmtime's objects free themselves through its module, which may be gone when the interpreter
# tears the modules down at exit: the compiled components go before that.
atexit.register(_component.cache_clear)


def _no_effect(store: Any, *arguments: Any) -> None:
    """clock-update, lock-preemption and unlock-preemption: the pendulum has no clocks to update
    nor partitions to preempt, so the callbacks the draft has the host provide do nothing.
    """


class WasmInstance:
    """One FMI 3.0 instance of an FMU's WebAssembly binary, in a wasmtime store of its own.

    The methods bear fmpy's FMU3Slave names, so the package's initialize and loops drive it as
    they drive fmpy's; a status other than ok or warning, a result that is an error, or a trap
    (the binary stopped: an out-of-bounds access, a WASI call it was not given) raises FmuError
    with what the binary logged.

    Parameters
    ----------
    model : FmuModel
        An FMI 3.0 pendulum FMU carrying binaries/wasm32-wasip2/<modelIdentifier>.wasm.
    instance_name : str
        The FMI instance name, which the binary's log messages carry.
    interface : {"CoSimulation", "ModelExchange"}
        Which of the component's resources to instantiate.

    Attributes
    ----------
    model : FmuModel
        The FMU.
    messages : MessageLog
        What the binary logged.
    fmi_version : int
        3: FMI-LS-WASM maps FMI 3.0.
    store, resource
        The wasmtime store and the instance's resource in it (run_schedule calls through them).

    Raises
    ------
    MissingDependency
        wasmtime is not installed.
    FmuFileError
        No wasm binary in the FMU, one wasmtime cannot load, or one that lacks the interface.
    FmuError
        The binary refused to instantiate (it returned none).

    Examples
    --------
    >>> instance = WasmInstance(fmu_model("Pendulum-fmi3.fmu"), "pendulum")  # doctest: +SKIP
    >>> instance.enterInitializationMode(); instance.exitInitializationMode()  # doctest: +SKIP
    """

    fmi_version = 3

    def __init__(self, model: FmuModel, instance_name: str, interface: str = "CoSimulation"):
        wasmtime = wasmtime_module()
        component = wasmtime.component
        self.model, self.messages, self.interface = model, MessageLog(3), interface
        self._error = wasmtime.WasmtimeError
        compiled = _component(model)
        linker = component.Linker(_engine())
        with linker.root() as root, root.add_instance(CALLBACKS) as callbacks:
            callbacks.add_func("log-message", self._log)
            for name in ("clock-update", "lock-preemption", "unlock-preemption"):
                callbacks.add_func(name, _no_effect)
        # Whatever else the binary imports (WASI's clock, files, ...) it is not given: a trap.
        linker.define_unknown_imports_as_traps(compiled)
        self.store = wasmtime.Store(_engine())
        self._instance = self.entered("instantiation", lambda: linker.instantiate(self.store, compiled))
        self._interface = self._instance.get_export_index(self.store, INTERFACES[interface])
        self._functions: dict[str, Any] = {}
        description = model.description
        self.resource = self.entered(
            "instantiation",
            lambda: self.function(f"[static]{RESOURCES[interface]}.instantiate-{_kebab(interface)}")(
                self.store,
                instance_name,
                description.guid,  # fmpy keeps FMI 3.0's instantiationToken there
                "",  # resource path: the binary reads no file, and the pendulum has no resources
                False,
                False,
                *((False, False, []) if interface == "CoSimulation" else ()),
            ),
        )
        if self.resource is None:
            raise self.messages.instantiation_error(f"{model.path} ({WASM_PLATFORM})")

    def _log(self, store: Any, instance_name: str, status: str, category: str, message: str) -> None:
        """The log-message callback: the message kept in the instance's MessageLog, bounded, and
        with Python's escapes where it holds a character that is not printable (a line break
        would start a line of its own in an error's one line).
        """
        index = STATUS.index(status) if status in STATUS else len(STATUS)
        kept = shortened(message, MESSAGE_CHARS)
        self.messages.log_fmi3(None, index, category, (kept if kept.isprintable() else repr(kept)).encode())

    def function(self, name: str) -> Any:
        """The component's function of the instance's interface, such as
        "[method]co-simulation-instance.do-step"; FmuFileError when the binary lacks it.
        """
        found = self._functions.get(name)
        if found is None:
            index = (
                None if self._interface is None else self._instance.get_export_index(self.store, name, self._interface)
            )
            found = None if index is None else self._instance.get_func(self.store, index)
            if found is None:
                raise FmuFileError(
                    f"{self.model.path}: its {WASM_PLATFORM} binary does not export {name} of "
                    f"{INTERFACES[self.interface]}: give an FMU whose binary was made by pendulum-fmu build"
                )
            self._functions[name] = found
        return found

    def entered(self, call: str, enter: Any) -> Any:
        """enter() into the binary; a trap raised as FmuError naming call and the trap's first line."""
        try:
            return enter()
        except self._error as error:
            first = str(error).strip().splitlines()[0] if str(error).strip() else "trap"
            raise FmuError(f"{call}: the {WASM_PLATFORM} binary stopped: {shortened(first, 200)}") from None

    def method(self, name: str, *arguments: Any) -> Any:
        """A method of the instance's resource, called with arguments; its result, a status
        (ok or warning) or a value, checked: FmuError for another status or a trap.
        """
        function = self.function(f"[method]{RESOURCES[self.interface]}.{name}")
        result = self.entered(name, lambda: function(self.store, self.resource, *arguments))
        if isinstance(result, str):  # a status: what every method returns, or a result's error
            if result not in _PASSED:
                raise self.messages.error(STATUS.index(result), name)
            return None
        return result

    def enterInitializationMode(
        self, tolerance: float | None = None, startTime: float = 0.0, stopTime: float | None = None
    ) -> None:
        self.method("enter-initialization-mode", tolerance, startTime, stopTime)

    def exitInitializationMode(self) -> None:
        self.method("exit-initialization-mode")

    def setFloat64(self, vr: list[int], values: list[float]) -> None:
        self.method("set-float64", list(vr), [float(value) for value in values])

    def getFloat64(self, vr: list[int]) -> list[float]:
        return self.method("get-float64", list(vr))

    def doStep(
        self,
        currentCommunicationPoint: float,
        communicationStepSize: float,
        noSetFMUStatePriorToCurrentPoint: bool = True,
    ) -> tuple[bool, bool, bool, float]:
        """As fmpy's: (eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime)."""
        point, size = currentCommunicationPoint, communicationStepSize
        step = self.method("do-step", point, size, noSetFMUStatePriorToCurrentPoint)
        return (
            getattr(step, "event-handling-needed"),
            getattr(step, "terminate-simulation"),
            getattr(step, "early-return"),
            getattr(step, "last-successful-time"),
        )

    def reset(self) -> None:
        self.method("reset")

    def terminate(self) -> int:
        self.method("terminate")
        return 0

    def freeInstance(self) -> None:
        """Drop the resource (fmi3FreeInstance); the store goes with the object."""
        if self.resource is not None:
            resource, self.resource = self.resource, None
            self.entered("freeInstance", lambda: resource.drop(self.store))


def _kebab(interface: str) -> str:
    """co-simulation for CoSimulation, model-exchange for ModelExchange (WIT's names)."""
    return RESOURCES[interface].removesuffix("-instance")


def instantiated(model: FmuModel, instance_name: str) -> WasmInstance:
    """A Co-Simulation WasmInstance of the model, not yet initialized (as _instance.instantiated)."""
    _ = model.pendulum_variables  # FmuFileError when it is no pendulum FMU
    return WasmInstance(model, instance_name)


def run_schedule(slave: WasmInstance, plan: TorqueSchedule) -> np.ndarray:
    """A held schedule through an initialized Co-Simulation instance: (N + 1, recorded) values of
    the model's recorded variables, read at every point after the step's torque was set, as
    _simulate.run_schedule_python records them.

    The three calls of a step go through wasmtime's component functions, bound once; FmuError
    names the call that failed, the time of its step and what the binary logged.
    """
    recorded_names = slave.model.recorded
    value_references = slave.model.value_references
    torque_vr = [value_references["torque"]]
    recorded_vr = [value_references[name] for name in recorded_names]
    set_float64, get_float64, do_step = (
        slave.function(f"[method]co-simulation-instance.{name}") for name in ("set-float64", "get-float64", "do-step")
    )
    store, resource, messages = slave.store, slave.resource, slave.messages
    recorded = np.empty((len(plan.time), len(recorded_names)))

    def failed(result: str, call: str, t: float) -> FmuError:
        return messages.error(STATUS.index(result), f"{call} at t = {t:.17g}")

    def step(row: int, t: float, h: float, u: float) -> None:
        status = set_float64(store, resource, torque_vr, [u])
        if status not in _PASSED:
            raise failed(status, "set-float64", t)
        values = get_float64(store, resource, recorded_vr)
        if isinstance(values, str):
            raise failed(values, "get-float64", t)
        recorded[row] = values
        report = do_step(store, resource, t, h, True)
        if isinstance(report, str):
            raise failed(report, "do-step", t)

    times = plan.time.tolist()
    for row, (t, h, u) in enumerate(zip(times, plan.step_size.tolist(), plan.torque.tolist(), strict=False)):
        slave.entered(f"the step from t = {t:.17g}", lambda: step(row, t, h, u))  # noqa: B023 (called at once)
    values = slave.entered("the read at the end", lambda: get_float64(store, resource, recorded_vr))
    if isinstance(values, str):
        raise failed(values, "get-float64", times[-1])
    recorded[-1] = values
    return recorded


class WasmModelExchange(FMU3Model):
    """fmpy's FMU3Model whose calls go to the Model Exchange resource of an FMU's WebAssembly
    binary: hand it to fmpy.simulate_fmu as fmu_instance (fmi_type "ModelExchange"), and fmpy's
    own solver (CVode or Euler), input and recorder drive the wasm binary as they drive the
    native one, so the two differ by nothing but the binary.

    FMU3Model.__init__ is not called: it loads a native library. The methods fmpy's Model
    Exchange loop calls are the wasm instance's (WasmInstance with interface "ModelExchange");
    the states and derivatives go through the ctypes arrays fmpy's solver hands over.

    Parameters
    ----------
    model : FmuModel
        An FMI 3.0 pendulum FMU carrying the wasm binary.
    instance_name : str, optional
        The FMI instance name.

    Examples
    --------
    >>> from fmpy import simulate_fmu  # doctest: +SKIP
    >>> model = fmu_model("Pendulum-fmi3.fmu")  # doctest: +SKIP
    >>> simulate_fmu(model.folder, model_description=model.description, fmi_type="ModelExchange",
    ...              fmu_instance=WasmModelExchange(model), stop_time=3.0)  # doctest: +SKIP
    """

    def __init__(self, model: FmuModel, instance_name: str = "pendulum"):
        _ = model.pendulum_variables  # FmuFileError when it is no pendulum FMU
        self.wasm = WasmInstance(model, instance_name, "ModelExchange")
        self.component = None  # fmpy's Input passes it to fmi3SetFloat64, which ignores it
        self.instanceName = instance_name

    def __getattr__(self, name: str) -> Any:
        # The setters of other types fmpy's Input looks up: the pendulum's inputs are Float64.
        if name.startswith("fmi3Set"):
            return _refused(name)
        raise AttributeError(name)

    def enterInitializationMode(self, tolerance=None, startTime=0.0, stopTime=None) -> None:
        self.wasm.enterInitializationMode(tolerance, startTime, stopTime)

    def exitInitializationMode(self) -> None:
        self.wasm.exitInitializationMode()

    def enterEventMode(self) -> None:
        self.wasm.method("enter-event-mode")

    def enterContinuousTimeMode(self) -> None:
        self.wasm.method("enter-continuous-time-mode")

    def updateDiscreteStates(self) -> tuple:
        info = self.wasm.method("update-discrete-states")
        return tuple(getattr(info, field) for field in _DISCRETE_STATES_INFO)

    def completedIntegratorStep(self, noSetFMUStatePriorToCurrentPoint=True) -> tuple[bool, bool]:
        result = self.wasm.method("completed-integrator-step", noSetFMUStatePriorToCurrentPoint)
        return getattr(result, "enter-event-mode"), getattr(result, "terminate-simulation")

    def setTime(self, time) -> None:
        self.wasm.method("set-time", float(time))

    def setContinuousStates(self, continuousStates, nContinuousStates) -> None:
        self.wasm.method("set-continuous-states", continuousStates[:nContinuousStates])

    def getContinuousStates(self, continuousStates, nContinuousStates) -> None:
        _fill(continuousStates, self.wasm.method("get-continuous-states"), nContinuousStates)

    def getContinuousStateDerivatives(self, derivatives, nContinuousStates) -> None:
        _fill(derivatives, self.wasm.method("get-continuous-state-derivatives"), nContinuousStates)

    def getEventIndicators(self, eventIndicators, nEventIndicators) -> None:
        if nEventIndicators:
            _fill(eventIndicators, self.wasm.method("get-event-indicators"), nEventIndicators)

    def getNominalsOfContinuousStates(self, nominals, nContinuousStates) -> None:
        _fill(nominals, self.wasm.method("get-nominals-of-continuous-states"), nContinuousStates)

    def getFloat64(self, vr, nValues=None) -> list[float]:
        return self.wasm.getFloat64(vr)

    def setFloat64(self, vr, values) -> None:
        self.wasm.setFloat64(vr, values)

    def fmi3SetFloat64(self, component, vr, nvr, values, nValues) -> int:
        """fmi3SetFloat64 as fmpy's Input calls it, with ctypes arrays."""
        self.wasm.setFloat64(vr[:nvr], values[:nValues])
        return 0

    def terminate(self) -> int:
        return self.wasm.terminate()

    def reset(self) -> None:
        self.wasm.reset()

    def freeInstance(self) -> None:
        self.wasm.freeInstance()


# The fields of the draft's discrete-states-info, in the order of fmpy's updateDiscreteStates.
_DISCRETE_STATES_INFO = (
    "new-discrete-states-needed",
    "terminate-simulation",
    "nominals-of-continuous-states-changed",
    "values-of-continuous-states-changed",
    "next-event-time-defined",
    "next-event-time",
)


def _fill(array: Any, values: list[float], count: int) -> None:
    """Write values into a ctypes array or pointer of count doubles (what fmpy's solver hands over)."""
    if len(values) != count:
        raise FmuError(f"the {WASM_PLATFORM} binary returned {len(values)} values where {count} were asked for")
    for index, value in enumerate(values):
        array[index] = value


def _refused(name: str) -> Any:
    def refuse(*arguments: Any) -> int:
        raise FmuError(f"{name}: the pendulum's {WASM_PLATFORM} host sets Float64 values only")

    return refuse
