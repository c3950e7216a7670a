"""Run the FMU through fmpy, one communication step at a time.

simulate() runs each schedule through a Simulator: an FMU instance made once per thread and FMU
file, and restarted (fmi2Reset, initialized again) for every run, which gives the numbers of a
fresh instance bit for bit without paying for loading and instantiating again.
"""

from __future__ import annotations

import array
import ctypes
import os
import threading
from collections import OrderedDict
from collections.abc import Iterable, Iterator
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from .. import default_fmu
from .._errors import InvalidInput
from ..signals._torque_schedule import TorqueSchedule, TorqueSignal, schedule
from . import WASM_PLATFORM, _native_loop as cs_loop, _results as results
from ._instance import FmuError, FmuInstance, initialize, instantiated, open_fmu
from ._model import FmuModel, file_version, fmu_file, fmu_model
from ._parameters import merged_with, start_value


def __getattr__(name: str):
    # RECORDED, what a result of the default FMU records at every communication point (the torque
    # it received, then its outputs), is its model's (FmuModel.recorded), read on first use.
    if name == "RECORDED":
        return fmu_model().recorded
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def run_schedule(slave: FmuInstance, plan: TorqueSchedule) -> np.ndarray:
    """Feed a schedule to an initialized slave (from open_fmu); returns the result array (see
    _results.py).

    One call into the native loop (_native_loop.py) when it was compiled and the FMU is FMI 2.0, else
    the Python loop, the readable reference; the two give the same numbers bit for bit.
    """
    if not cs_loop.drives(slave):
        return run_schedule_python(slave, plan)
    return _stepped(_stepper(slave), plan, slave.model.recorded)


def _stepper(slave, start_names: tuple[str, ...] = ()) -> cs_loop.Stepper:
    """The native loop bound to an instance: the torque in, its model's recorded variables out,
    a restart setting start_names.
    """
    value_references = slave.model.value_references

    def references(names):
        return np.array([value_references[name] for name in names], np.uint32)

    return cs_loop.Stepper(slave, references(["torque"]), references(slave.model.recorded), references(start_names))


def _stepped(
    stepper: cs_loop.Stepper, plan: TorqueSchedule, recorded_names: tuple[str, ...], ramped: bool = False, **restart
) -> np.ndarray:
    """The result array of a schedule through the native loop, which records recorded_names;
    ramped: set the rates even if all are zero; restart: Stepper.run's start_values and tolerance.
    """
    recorded = np.empty((len(plan.time), len(recorded_names)))
    ramped = ramped or bool(np.count_nonzero(plan.torque_rate))
    rates = np.ascontiguousarray(plan.torque_rate)[:, None] if ramped else None
    stepper.run(plan.time, np.ascontiguousarray(plan.torque)[:, None], rates, recorded, **restart)
    return _result(plan, recorded_names, recorded)


def _result(plan: TorqueSchedule, recorded_names: tuple[str, ...], recorded: np.ndarray) -> np.ndarray:
    """The result array of a schedule from the columns recorded_names at every point."""
    out = results.empty(len(plan.time), recorded_names)
    out["time"] = plan.time
    for name, column in zip(recorded_names, recorded.T, strict=False):
        out[name] = column
    return out


def run_schedule_python(slave: FmuInstance, plan: TorqueSchedule, ramped: bool = False) -> np.ndarray:
    """run_schedule in Python: the reference the native loop is checked against, and the loop for
    FMI 3.0; ramped: set the rates even if all are zero.

    The FMI functions are bound once from the library fmpy loaded, without fmpy's argtypes (with
    them ctypes converts every argument on every call), and every argument is a ctypes object
    allocated before the loop, so a step costs little more than the FMU's own work.
    """
    dll, messages, fmi3 = slave.dll, slave.messages, slave.fmi_version == 3
    ramped = ramped or bool(np.any(plan.torque_rate))
    if fmi3:
        check_held(plan)
    names = (
        ("fmi3SetFloat64", "fmi3GetFloat64", None, "fmi3DoStep")
        if fmi3
        else ("fmi2SetReal", "fmi2GetReal", "fmi2SetRealInputDerivatives", "fmi2DoStep")
    )
    # ctypes functions of the library (FMI 3.0 has no input derivatives: no set_rate, never called).
    set_real, get_real, do_step = dll[names[0]], dll[names[1]], dll[names[3]]
    set_rate: Any = dll[names[2]] if names[2] else None
    component = ctypes.c_void_p(slave.component)
    recorded_names = slave.model.recorded
    count = len(recorded_names)
    value_references = slave.model.value_references
    torque_vr = (ctypes.c_uint * 1)(value_references["torque"])
    recorded_vr = (ctypes.c_uint * count)(*(value_references[n] for n in recorded_names))
    one, recorded_count = ctypes.c_size_t(1), ctypes.c_size_t(count)
    first_order = (ctypes.c_int * 1)(1)
    no_rollback = ctypes.c_int(1)
    torque, rate, recorded = (ctypes.c_double * 1)(), (ctypes.c_double * 1)(), (ctypes.c_double * count)()
    recorded_bytes = memoryview(recorded).cast("B")
    time, step = ctypes.c_double(), ctypes.c_double()
    # FMI 3.0 getters and setters also take the number of values, and fmi3DoStep reports back.
    torque_arguments = (component, torque_vr, one, torque) + ((one,) if fmi3 else ())
    get_recorded = (component, recorded_vr, recorded_count, recorded) + ((recorded_count,) if fmi3 else ())
    step_report = (
        (
            ctypes.byref(ctypes.c_bool()),
            ctypes.byref(ctypes.c_bool()),
            ctypes.byref(ctypes.c_bool()),
            ctypes.byref(ctypes.c_double()),
        )
        if fmi3
        else ()
    )
    step_arguments = (component, time, step, ctypes.c_bool(True) if fmi3 else no_rollback, *step_report)

    rows = array.array("d")  # 32 bytes a step, not a Python list of floats
    for t, h, u, r in zip(
        plan.time.tolist(), plan.step_size.tolist(), plan.torque.tolist(), plan.torque_rate.tolist(), strict=False
    ):
        torque[0] = u
        status = set_real(*torque_arguments)
        if status > 1:
            raise messages.error(status, f"{names[0]} at t = {t:.17g}")
        if ramped:
            rate[0] = r
            status = set_rate(component, torque_vr, one, first_order, rate)
            if status > 1:
                raise messages.error(status, f"fmi2SetRealInputDerivatives at t = {t:.17g}")
        status = get_real(*get_recorded)
        if status > 1:
            raise messages.error(status, f"{names[1]} at t = {t:.17g}")
        rows.frombytes(recorded_bytes)
        time.value, step.value = t, h
        status = do_step(*step_arguments)
        if status > 1:
            raise messages.error(status, f"{names[3]} at t = {t:.17g}")
    # After a ramp the FMU's torque is where the ramp ended.
    status = get_real(*get_recorded)
    if status > 1:
        raise messages.error(status, f"{names[1]} at the end")
    rows.frombytes(recorded_bytes)

    return _result(plan, recorded_names, np.frombuffer(rows).reshape(-1, count))


def check_held(plan: TorqueSchedule) -> None:
    """InvalidInput when the schedule ramps the torque, which an FMI 3.0 FMU cannot (it has no
    input derivatives).
    """
    if np.any(plan.torque_rate):
        raise InvalidInput(
            "FMI 3.0 has no input derivatives, so an FMI 3.0 FMU cannot ramp the "
            "torque: hold it over each step (no --ramp), or use the FMI 2.0 FMU"
        )


def simulate(
    torque: TorqueSignal = 20.0,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    tolerance: float | None = None,
    fmu_path: str | Path | None = None,
    max_steps: int | None = None,
    platform: str | None = None,
) -> np.ndarray:
    """Simulate the pendulum FMU under a torque signal, one communication step at a time.

    The whole schedule runs in one call into the native loop (_native_loop.py) when it was compiled
    and the FMU is FMI 2.0, else in the Python loop; the two give the same numbers bit for bit.
    It runs through this thread's instance of the FMU (simulator()), restarted for the run: after
    the first call in a thread, a call costs tens of microseconds besides its steps.

    Parameters
    ----------
    torque : float, callable, sequence of float, str or Path
        A constant (N.m), a callable of time (sampled at each step's start), a per-step array
        (one held value per step) or a CSV path in fmpy's convention (docs/signals.md). Each
        step holds the signal's value just after its start unless ramp.
    start_time, stop_time : float, optional
        In s; stop_time defaults to the CSV's last time, the array's last step, or 3 s.
    step_size : float, optional
        Communication step in s.
    ramp : bool, optional
        Ramp the torque over each step through fmi2SetRealInputDerivatives, along the CSV's own
        piecewise-linear signal (FMI 2.0 only).
    parameters : dict, optional
        Overrides of the FMU's parameters (mass, length, inertia, gravity, damping).
    theta0, omega0 : float, optional
        Start angle in rad and rate in rad/s.
    tolerance : float, optional
        Relative tolerance of the FMU's integrator (None: the FMU's 1e-10).
    fmu_path : str or Path, optional
        The FMU to run (default: pendulum_fmu.default_fmu(); for platform "wasm32-wasip2" the
        package's FMI 3.0 FMU stands for it); its own parameters apply.
    max_steps : int, optional
        The longest run accepted (default _time_grid.DEFAULT_MAX_STEPS); a longer one, or
        one that would not fit in memory, is refused before anything is allocated.
    platform : {None, "wasm32-wasip2"}, optional
        The FMU's binary to run: None, this machine's native one; "wasm32-wasip2", the
        WebAssembly one an FMI 3.0 FMU carries (FMI-LS-WASM), through wasmtime (the wasm extra).

    Returns
    -------
    numpy.ndarray
        A structured array with fields time, torque, theta, omega, alpha, one row per
        communication point (see _results.py); torque is what the FMU received.

    Raises
    ------
    InvalidInput
        A signal, time, step, parameter or run length the package refuses.
    TorqueFileError
        A torque CSV that is not a signal (names the file, line and problem).
    FmuError
        The FMU refused the parameters or a step; the message carries what it logged.
    MissingFile
        No FMU at fmu_path.
    MissingDependency
        platform "wasm32-wasip2" without the wasmtime package.

    Examples
    --------
    A constant 20 N.m for 1 s in 1 ms steps:

    >>> from pendulum_fmu import simulate
    >>> run = simulate(20.0, stop_time=1.0)
    >>> len(run), run.dtype.names
    (1001, ('time', 'torque', 'theta', 'omega', 'alpha'))
    >>> round(float(run["theta"][-1]), 6)
    0.187205
    """
    plan = schedule(
        torque, start_time=start_time, stop_time=stop_time, step_size=step_size, ramp=ramp, max_steps=max_steps
    )
    return simulate_plan(
        plan,
        parameters=parameters,
        theta0=theta0,
        omega0=omega0,
        tolerance=tolerance,
        fmu_path=fmu_path,
        platform=platform,
    )


def simulate_plan(
    plan: TorqueSchedule,
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    tolerance: float | None = None,
    fmu_path: str | Path | FmuModel | None = None,
    platform: str | None = None,
) -> np.ndarray:
    """A schedule through this thread's Simulator of the FMU's binary for platform (see simulate)."""
    options = dict(parameters=parameters, theta0=theta0, omega0=omega0, tolerance=tolerance)
    return next(simulate_windows((plan,), fmu_path=fmu_path, platform=platform, **options))


def simulate_windows(
    windows: Iterable[TorqueSchedule],
    *,
    fmu_path: str | Path | FmuModel | None = None,
    platform: str | None = None,
    **options,
) -> Iterator[np.ndarray]:
    """Consecutive windows of one schedule through one run of this thread's Simulator (see
    Simulator.run_windows): results that concatenate to simulate_plan's of the whole schedule;
    options: simulate_plan's parameters, theta0, omega0 and tolerance.
    """
    runner = simulator(fmu_path, platform)
    try:
        yield from runner.run_windows(windows, **options)
    except FmuError:
        resolve_parameters(options.get("parameters"), fmu_path)  # refused with the same words as every other tool
        raise


def resolve_parameters(
    overrides: dict[str, float] | None = None, fmu_path: str | Path | FmuModel | None = None
) -> dict[str, float]:
    """The FMU's parameters with overrides applied (parameters.merged_with), and a set it accepts.

    fmu_path is the FMU: a path, its model (fmu_model), or None for the default FMU.

    The physical checks (mass > 0, an inertia about the pivot > 0, ...) live in one place, the
    FMU's model.c, and every tool goes through them here: the FMU, the reference, OpenSim,
    the engines. Each refuses a bad set with the FMU's own message, word for word.
    """
    model = fmu_model(fmu_path)
    parameters = merged_with(model.default_parameters, overrides)
    refusal = _refusal(model, tuple(parameters.items()))
    if refusal:
        raise InvalidInput(refusal)
    return parameters


@lru_cache(maxsize=256)
def _refusal(model: FmuModel, items: tuple) -> str | None:
    """What the FMU says when it refuses these parameters at initialization, or None; asked once
    per model (a file rebuilt or replaced is another model) and set of parameters.
    """
    try:
        if model.binary(refuse=False) is None and model.binary(WASM_PLATFORM, refuse=False):
            slave = _wasm().instantiated(model, "pendulum")  # an FMU that carries only that one
            initialize(slave, parameters=dict(items))
        else:
            slave = open_fmu(model, parameters=dict(items))
    except FmuError as error:
        # "initialization failed: [ERROR] fmi2ExitInitializationMode: mass must be > 0"
        return f"the FMU refuses the parameters: {str(error).rsplit(': ', 1)[-1]}"
    slave.terminate()
    slave.freeInstance()
    return None


class Simulator:
    """An FMU instance that runs schedule after schedule, restarting before each: fmi2Reset, then
    initialization with the run's parameters, start values and tolerance, which leaves it as a
    fresh instance would be, so the numbers are a fresh instance's bit for bit.

    One thread at a time: simulator() keeps one per thread, FMU file and platform. The native loop
    restarts and steps it in one call (FMI 2.0); else (FMI 3.0, or no native loop) fmpy's calls
    do; the WebAssembly binary (platform "wasm32-wasip2") is stepped through wasmtime (_wasm.py).
    """

    # Also names the restart's start values, in this order.
    START_STATES = ("theta", "omega")

    def __init__(self, fmu_path: Path, version: tuple, platform: str | None = None):
        self.fmu_path, self.version = fmu_path, version
        model = fmu_model(fmu_path)
        wasm = platform == WASM_PLATFORM
        self.slave = _wasm().instantiated(model, "pendulum") if wasm else instantiated(model, "pendulum")
        self.loop = _wasm().run_schedule if wasm else None
        self.defaults = dict(self.slave.model.default_parameters)
        self.stepper = (
            _stepper(self.slave, (*self.defaults, *self.START_STATES)) if cs_loop.drives(self.slave) else None
        )

    def run(
        self,
        plan: TorqueSchedule,
        *,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        tolerance: float | None = None,
    ) -> np.ndarray:
        """The result array of a schedule (see simulate); FmuError when the FMU refuses."""
        return next(self.run_windows((plan,), parameters=parameters, theta0=theta0, omega0=omega0, tolerance=tolerance))

    def run_windows(
        self,
        windows: Iterable[TorqueSchedule],
        *,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        tolerance: float | None = None,
    ) -> Iterator[np.ndarray]:
        """The results of a schedule given as consecutive windows sharing their boundary points,
        a window at a time: restarted before the first, the instance carries its state on, and the
        results concatenate to run()'s of the whole schedule, bit for bit. A boundary's row is the
        later window's (read after that step's torque was set, as the whole run reads it).
        """
        start = [
            *(merged_with(self.defaults, parameters) if parameters else self.defaults).values(),
            start_value("theta0", theta0, "rad"),
            start_value("omega0", omega0, "rad/s"),
        ]
        self.slave.messages.lines.clear()
        recorded = self.slave.model.recorded
        windows = iter(windows)
        # The first window, not named past this (a name held it for the whole run).
        window: TorqueSchedule | None = next(windows)
        assert window is not None, "next() of windows gives a window"
        start_time = float(window.time[0])
        if self.stepper is None:
            self.slave.reset()
            options: dict[str, Any] = dict(parameters=parameters, theta0=theta0, omega0=omega0, tolerance=tolerance)
            initialize(self.slave, **options, start_time=start_time)
        restart: dict = {"start_values": start, "tolerance": tolerance}
        ramped = False
        while window is not None:
            # The FMU keeps an input's rate until it is set again: once a window ramped, every
            # later one sets its rates, zero or not, as the whole run sets them.
            if self.stepper is not None:
                result = _stepped(self.stepper, window, recorded, ramped, **restart)
                restart = {}  # the instance goes on where the window before left it
            elif self.loop is None:
                result = run_schedule_python(self.slave, window, ramped)
            else:
                check_held(window)
                result = _result(window, recorded, self.loop(self.slave, window))
            ramped = ramped or bool(np.count_nonzero(window.torque_rate))
            window = next(windows, None)
            yield result if window is None else result[:-1]

    def close(self) -> None:
        self.slave.freeInstance()


# What simulate's platform takes: this machine's native binary, or the WebAssembly one.
PLATFORMS = (None, WASM_PLATFORM)


def _wasm():
    """The _wasm module, imported when the WebAssembly binary is asked for (it needs wasmtime)."""
    from . import _wasm

    return _wasm


# Simulators a thread keeps, the least recently used dropped first (each holds an instance).
SIMULATORS_PER_THREAD = 8
_simulators = threading.local()


@lru_cache(maxsize=2)
def _default_fmu(fmi_version: int = 2) -> Path:
    """default_fmu(fmi_version), looked up once per process (in a checkout: rebuilt then if stale)."""
    return default_fmu(fmi_version)


def simulator(fmu_path: str | Path | FmuModel | None = None, platform: str | None = None) -> Simulator:
    """The Simulator of an FMU file's binary kept by the calling thread, made on first use and
    again whenever the file is rebuilt or replaced (its file_version changes).

    Parameters
    ----------
    fmu_path
        The FMU file or its model; None: pendulum_fmu.default_fmu(), looked up once per process
        (for the WebAssembly binary, which is FMI 3.0 only, the package's FMI 3.0 FMU stands for
        it, given or not).
    platform : {None, "wasm32-wasip2"}
        Which binary: this machine's native one, or the WebAssembly one (see simulate).

    Returns
    -------
    Simulator
        The same object for every call of this thread while the file stays as it is.

    Raises
    ------
    MissingFile
        When there is no such file.
    InvalidInput
        A platform other than those.
    """
    if platform not in PLATFORMS:
        raise InvalidInput(
            f"platform {platform!r} is none the package runs: None (this machine's binary) or {WASM_PLATFORM!r}"
        )
    path = _default_fmu() if fmu_path is None else fmu_file(fmu_path)
    if platform and path.resolve() == _default_fmu().resolve():
        # The package's FMU, whose WebAssembly binary its FMI 3.0 file carries (same sources,
        # same numbers: docs/fmi3.md); compare hands every tool the FMI 2.0 file it resolved.
        path = _default_fmu(3)
    version = file_version(path)
    kept = getattr(_simulators, "kept", None)
    if kept is None:
        kept = _simulators.kept = OrderedDict()
    key = (os.fspath(path), platform)
    current = kept.pop(key, None)
    if current is not None and current.version != version:
        current.close()
        current = None
    if current is None:
        current = Simulator(Path(path), version, platform)
        while len(kept) >= SIMULATORS_PER_THREAD:
            kept.popitem(last=False)[1].close()
    kept[key] = current
    return current
