"""Run the FMU through fmpy, one communication step at a time."""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

from . import results
from .build import default_fmu
from .parameters import resolve_parameters, value_reference
from .signal import TorqueSignal, TorqueSchedule, schedule

_STATUS = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"]


class FmuError(RuntimeError):
    """An FMI call failed; the message carries what the FMU logged."""


class _Messages:
    """Collects what the FMU logs so a failure can say why."""

    def __init__(self):
        self.lines: list[str] = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        try:
            # fmpy's C proxy formats printf-style arguments before they reach Python.
            from fmpy.logging import addLoggerProxy
            addLoggerProxy(ctypes.byref(self.callbacks))
        except Exception:
            pass

    def _log(self, environment, instance_name, status, category, message):
        self.lines.append(f"[{_STATUS[status] if 0 <= status < 6 else status}] "
                          f"{message.decode('utf-8', 'replace')}")

    def check(self, status: int, call: str) -> None:
        if status > 1:
            detail = "; ".join(self.lines[-3:]) or "no message"
            raise FmuError(f"{call} returned {_STATUS[status]}: {detail}")


def open_fmu(fmu_path: str | Path | None = None, *, parameters: dict | None = None,
             theta0: float = 0.0, omega0: float = 0.0, tolerance: float | None = None,
             start_time: float = 0.0, instance_name: str = "pendulum"):
    """An initialized FMU2Slave (in step mode) and its message log.

    fmu_path defaults to the FMU built from this checkout. The caller frees it with
    slave.terminate(); slave.freeInstance().
    """
    fmu_path = Path(fmu_path) if fmu_path else default_fmu()
    description = read_model_description(str(fmu_path))
    slave = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(fmu_path)),
                      modelIdentifier=description.coSimulation.modelIdentifier,
                      instanceName=instance_name)
    messages = _Messages()
    slave.instantiate(callbacks=messages.callbacks)
    slave.messages = messages  # keeps the logger callback alive as long as the slave
    start = {**resolve_parameters(parameters), "theta": float(theta0), "omega": float(omega0)}
    try:
        slave.setupExperiment(tolerance=tolerance, startTime=start_time)
        slave.enterInitializationMode()
        slave.setReal([value_reference(n) for n in start], list(start.values()))
        slave.exitInitializationMode()
    except Exception as error:
        slave.freeInstance()
        raise FmuError(f"initialization failed: {'; '.join(messages.lines) or error}") from None
    return slave


def run_schedule(slave: FMU2Slave, plan: TorqueSchedule) -> np.ndarray:
    """Feed a schedule to an initialized slave; returns the result array (see results.py).

    Calls the FMI functions fmpy loaded, with arrays allocated once, so the per-step cost is the
    FMU's and ctypes', not fmpy's wrappers'.
    """
    dll, component, check = slave.dll, slave.component, slave.messages.check
    torque_vr = (ctypes.c_uint * 1)(value_reference("torque"))
    output_vr = (ctypes.c_uint * 3)(*(value_reference(n) for n in ("theta", "omega", "alpha")))
    order = (ctypes.c_int * 1)(1)
    torque = (ctypes.c_double * 1)()
    rate = (ctypes.c_double * 1)()
    outputs = (ctypes.c_double * 3)()
    set_real, get_real, do_step = dll.fmi2SetReal, dll.fmi2GetReal, dll.fmi2DoStep
    set_rate = dll.fmi2SetRealInputDerivatives
    ramped = bool(np.any(plan.torque_rate))

    out = results.empty(len(plan.time))
    out["time"] = plan.time
    rows = out.view(np.float64).reshape(len(out), len(results.FIELDS))
    for k, (t, h) in enumerate(zip(plan.time[:-1], plan.step_size)):
        torque[0] = plan.torque[k]
        check(set_real(component, torque_vr, 1, torque), "fmi2SetReal")
        if ramped:
            rate[0] = plan.torque_rate[k]
            check(set_rate(component, torque_vr, 1, order, rate), "fmi2SetRealInputDerivatives")
        check(get_real(component, output_vr, 3, outputs), "fmi2GetReal")
        rows[k, 1] = torque[0]
        rows[k, 2:] = outputs
        check(do_step(component, t, h, 1), f"fmi2DoStep at t = {t:.17g}")
    # After a ramp the FMU's torque is where the ramp ended.
    check(get_real(component, torque_vr, 1, torque), "fmi2GetReal")
    check(get_real(component, output_vr, 3, outputs), "fmi2GetReal")
    rows[-1, 1] = torque[0]
    rows[-1, 2:] = outputs
    return out


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
