"""Run the FMU through fmpy, one communication step at a time."""

from __future__ import annotations

import ctypes
import itertools
import tempfile
import threading
import weakref
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

from . import cs_loop, results
from .build import default_fmu
from .parameters import resolve_parameters, value_reference
from .signal import TorqueSignal, TorqueSchedule, schedule

_STATUS = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"]


class FmuError(RuntimeError):
    """An FMI call failed; the message carries what the FMU logged."""


def _log_to_instance(environment, instance_name, status, category, message):
    log = _logs.get(environment)
    if log is not None:
        log.lines.append(f"[{_STATUS[status] if 0 <= status < 6 else status}] "
                         f"{message.decode('utf-8', 'replace')}")


# One logger for every instance, never freed, which hands each message to its instance's log by
# the componentEnvironment the instance was given: fmpy's formatting proxy keeps the last logger
# it was given in one global, so a logger per instance would be called for another instance's
# messages, or after it was freed (a crash when instances live in several threads).
_LOGGER = fmi2CallbackLoggerTYPE(_log_to_instance)
_logs: weakref.WeakValueDictionary[int, MessageLog] = weakref.WeakValueDictionary()
_log_keys = itertools.count(1)


class MessageLog:
    """FMI callbacks whose logger keeps what the FMU says, so a failure can say why."""

    def __init__(self):
        self.lines: list[str] = []
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

    def error(self, status: int, call: str) -> FmuError:
        detail = "; ".join(self.lines[-3:]) or "no message"
        return FmuError(f"{call} returned {_STATUS[status]}: {detail}")


_extracted: dict[tuple[str, int], tuple[tempfile.TemporaryDirectory, object]] = {}
_extracting = threading.Lock()  # threads of one dask worker share the cache


def _unzipped(fmu_path: Path):
    """(folder, model description) of an FMU file, extracted and parsed once per process; the
    folder is removed at exit."""
    key = (str(fmu_path.resolve()), fmu_path.stat().st_mtime_ns)
    with _extracting:
        if key not in _extracted:
            folder = tempfile.TemporaryDirectory(prefix="pendulum_fmu_")
            extract(str(fmu_path), unzipdir=folder.name)
            _extracted[key] = folder, read_model_description(folder.name)
        folder, description = _extracted[key]
    return folder.name, description


def open_fmu(fmu_path: str | Path | None = None, *, parameters: dict | None = None,
             theta0: float = 0.0, omega0: float = 0.0, tolerance: float | None = None,
             start_time: float = 0.0, instance_name: str = "pendulum"):
    """An initialized FMU2Slave (in step mode) and its message log.

    fmu_path defaults to the FMU built from this checkout. The caller frees it with
    slave.terminate(); slave.freeInstance().
    """
    fmu_path = Path(fmu_path) if fmu_path else default_fmu()
    folder, description = _unzipped(fmu_path)
    slave = FMU2Slave(guid=description.guid, unzipDirectory=folder,
                      modelIdentifier=description.coSimulation.modelIdentifier,
                      instanceName=instance_name)
    messages = MessageLog()
    slave.instantiate(callbacks=messages.callbacks)
    slave.messages = messages  # keeps the logger callback alive as long as the slave
    try:
        initialize(slave, parameters=parameters, theta0=theta0, omega0=omega0,
                   tolerance=tolerance, start_time=start_time)
    except BaseException:
        slave.freeInstance()
        raise
    return slave


def initialize(slave: FMU2Slave, *, parameters: dict | None = None, theta0: float = 0.0,
               omega0: float = 0.0, tolerance: float | None = None, start_time: float = 0.0) -> None:
    """Set the parameters and start values of an instantiated (or reset) slave with a
    MessageLog as slave.messages, and leave it in step mode; FmuError says why the FMU refused."""
    start = {**resolve_parameters(parameters), "theta": float(theta0), "omega": float(omega0)}
    try:
        slave.setupExperiment(tolerance=tolerance, startTime=start_time)
        slave.enterInitializationMode()
        slave.setReal([value_reference(n) for n in start], list(start.values()))
        slave.exitInitializationMode()
    except Exception as error:
        raise FmuError(f"initialization failed: {'; '.join(slave.messages.lines) or error}") from None


def run_schedule(slave: FMU2Slave, plan: TorqueSchedule) -> np.ndarray:
    """Feed a schedule to an initialized slave; returns the result array (see results.py).

    One call into the native loop (cs_loop.py) when it was compiled, else the Python loop below,
    the readable reference; the two give the same numbers bit for bit.
    """
    if not cs_loop.available():
        return run_schedule_python(slave, plan)
    torque_vr = np.array([value_reference("torque")], np.uint32)
    output_vr = np.array([value_reference(n) for n in ("theta", "omega", "alpha")], np.uint32)
    outputs, final_torque = np.empty((len(plan.time), 3)), np.empty(1)
    ramped = bool(np.any(plan.torque_rate))
    cs_loop.Stepper(slave, torque_vr, output_vr, plan.time).run(
        np.ascontiguousarray(plan.torque)[:, None],
        np.ascontiguousarray(plan.torque_rate)[:, None] if ramped else None, outputs, final_torque)
    return _result(plan, outputs, final_torque[0])


def _result(plan: TorqueSchedule, outputs: np.ndarray, final_torque: float) -> np.ndarray:
    """The result array of a schedule from theta, omega, alpha at every point (columns)."""
    out = results.empty(len(plan.time))
    out["time"] = plan.time
    out["torque"][:-1] = plan.torque
    out["torque"][-1] = final_torque
    for name, column in zip(("theta", "omega", "alpha"), outputs.T):
        out[name] = column
    return out


def run_schedule_python(slave: FMU2Slave, plan: TorqueSchedule) -> np.ndarray:
    """run_schedule in Python: the reference the native loop is checked against.

    The FMI functions are bound once from the library fmpy loaded, without fmpy's argtypes (with
    them ctypes converts every argument on every call), and every argument is a ctypes object
    allocated before the loop, so a step costs little more than the FMU's own work.
    """
    dll, messages = slave.dll, slave.messages
    set_real, get_real, set_rate, do_step = (
        dll[name] for name in ("fmi2SetReal", "fmi2GetReal", "fmi2SetRealInputDerivatives", "fmi2DoStep"))
    component = ctypes.c_void_p(slave.component)
    torque_vr = (ctypes.c_uint * 1)(value_reference("torque"))
    output_vr = (ctypes.c_uint * 3)(*(value_reference(n) for n in ("theta", "omega", "alpha")))
    one, three = ctypes.c_size_t(1), ctypes.c_size_t(3)
    first_order = (ctypes.c_int * 1)(1)
    no_rollback = ctypes.c_int(1)
    torque, rate, outputs = (ctypes.c_double * 1)(), (ctypes.c_double * 1)(), (ctypes.c_double * 3)()
    time, step = ctypes.c_double(), ctypes.c_double()
    ramped = bool(np.any(plan.torque_rate))

    recorded = []
    for t, h, u, r in zip(plan.time.tolist(), plan.step_size.tolist(), plan.torque.tolist(),
                          plan.torque_rate.tolist()):
        torque[0] = u
        status = set_real(component, torque_vr, one, torque)
        if status > 1:
            raise messages.error(status, f"fmi2SetReal at t = {t:.17g}")
        if ramped:
            rate[0] = r
            status = set_rate(component, torque_vr, one, first_order, rate)
            if status > 1:
                raise messages.error(status, f"fmi2SetRealInputDerivatives at t = {t:.17g}")
        status = get_real(component, output_vr, three, outputs)
        if status > 1:
            raise messages.error(status, f"fmi2GetReal at t = {t:.17g}")
        recorded.append(outputs[:])
        time.value, step.value = t, h
        status = do_step(component, time, step, no_rollback)
        if status > 1:
            raise messages.error(status, f"fmi2DoStep at t = {t:.17g}")
    # After a ramp the FMU's torque is where the ramp ended.
    status = max(get_real(component, torque_vr, one, torque),
                 get_real(component, output_vr, three, outputs))
    if status > 1:
        raise messages.error(status, "fmi2GetReal at the end")
    recorded.append(outputs[:])
    return _result(plan, np.array(recorded), torque[0])


def simulate(torque: TorqueSignal = 20.0, *, start_time: float = 0.0, stop_time: float | None = None,
             step_size: float = 1e-3, ramp: bool = False, parameters: dict | None = None,
             theta0: float = 0.0, omega0: float = 0.0, tolerance: float | None = None,
             fmu_path: str | Path | None = None) -> np.ndarray:
    """Simulate the pendulum FMU under a torque signal.

    torque: a constant (N.m), a callable of time, or a CSV path (fmpy's convention). Each
    communication step holds the signal's value at its start, or ramps (ramp=True) through
    fmi2SetRealInputDerivatives. parameters: overrides of mass, length, inertia, gravity, damping.
    tolerance: relative tolerance for fmi2SetupExperiment (None: the FMU's 1e-10).
    Returns a structured array with fields time, torque, theta, omega, alpha (see results.py).
    """
    plan = schedule(torque, start_time=start_time, stop_time=stop_time, step_size=step_size,
                    ramp=ramp)
    slave = open_fmu(fmu_path, parameters=parameters, theta0=theta0, omega0=omega0,
                     tolerance=tolerance, start_time=float(plan.time[0]))
    try:
        return run_schedule(slave, plan)
    finally:
        slave.terminate()
        slave.freeInstance()
