"""Part 10: the FMU's WebAssembly binary (wasm32-wasip2, FMI-LS-WASM, run by wasmtime) beside its
native FMI 3.0 binary: the cost of a step, side by side, on one FMU file and one schedule (the
tutorial's 3000 steps), and how far apart their theta are.

Three ways through a step (set-float64 torque, get-float64 of the recorded variables, do-step):
- native: the package's Python loop over the native binary (run_schedule_python, the loop
  simulate() runs for FMI 3.0), ctypes calls with arguments made once;
- wasm, Python host: the package's loop over the wasm binary (_wasm.run_schedule), each call
  through wasmtime-py's component Func, which lowers and lifts its Python arguments anew;
- wasm, raw calls: the same three calls through wasmtime's C API with their arguments lowered
  once and only the numbers rewritten in place, which is what the wasm binary and wasmtime's
  canonical ABI cost without the Python conversions (wasmtime-py's private _ffi: a measure,
  not a host).
"""

from __future__ import annotations

import ctypes
from pathlib import Path
from typing import Any

import numpy as np

from pendulum_fmu.fmu import WASM_PLATFORM
from pendulum_fmu.fmu._instance import initialize, instantiated
from pendulum_fmu.fmu._model import fmu_model
from pendulum_fmu.fmu._simulate import run_schedule_python
from pendulum_fmu.signals._torque_schedule import TorqueSchedule, schedule

from . import tutorial
from .report import Row, microseconds, ratio, skipped
from .timing import interleaved, median, timed

PART = "10 wasm"


class RawCall:
    """One component function with its arguments lowered once into wasmtime's C values; set_float()
    rewrites a float in place, call() calls it. Each call's result replaces (and frees) the last
    one in place, as wasmtime's C API assigns it; close() frees the last and the arguments.
    """

    def __init__(self, slave, function, *arguments: Any):
        from wasmtime import _ffi as ffi

        self.ffi, self.store, self.function = ffi, slave.store, function
        types = [value_type for _, value_type in function.type(self.store).params]
        self.arguments = (ffi.wasmtime_component_val_t * len(arguments))()
        for index, (value_type, value) in enumerate(zip(types, arguments, strict=True)):
            value_type.convert_to_c(self.store, value, ctypes.pointer(self.arguments[index]))
        self.result = ffi.wasmtime_component_val_t()  # zeroed: a bool, which owns nothing

    def set_float(self, argument: int, value: float, element: int | None = None) -> None:
        """Rewrite argument (an f64, or element of a list<f64>) to value."""
        slot = self.arguments[argument]
        (slot.of.list.data[element] if element is not None else slot).of.f64 = value

    def call(self) -> None:
        function, context, count = ctypes.byref(self.function._func), self.store._context(), len(self.arguments)
        error = self.ffi.wasmtime_component_func_call(
            function, context, self.arguments, count, ctypes.byref(self.result), 1
        )
        if error:
            raise RuntimeError("a raw call failed")

    def floats(self, count: int) -> list[float]:
        """The list<f64> of the result<list<f64>, status> just returned."""
        ok = self.result.of.result.val.contents.of.list
        return [ok.data[index].of.f64 for index in range(count)]

    def close(self) -> None:
        self.ffi.wasmtime_component_val_delete(ctypes.byref(self.result))
        for index in range(len(self.arguments)):
            self.ffi.wasmtime_component_val_delete(ctypes.byref(self.arguments[index]))


def raw_schedule(slave, plan: TorqueSchedule) -> np.ndarray:
    """_wasm.run_schedule's calls, made raw (see RawCall); (N + 1, recorded) values."""
    references = slave.model.value_references
    recorded_vr = [references[name] for name in slave.model.recorded]
    method = "[method]co-simulation-instance."
    set_torque = RawCall(slave, slave.function(method + "set-float64"), slave.resource, [references["torque"]], [0.0])
    get_recorded = RawCall(slave, slave.function(method + "get-float64"), slave.resource, recorded_vr)
    do_step = RawCall(slave, slave.function(method + "do-step"), slave.resource, 0.0, 0.0, True)
    count, rows = len(recorded_vr), []
    try:
        for t, h, u in zip(plan.time.tolist(), plan.step_size.tolist(), plan.torque.tolist(), strict=False):
            set_torque.set_float(2, u, element=0)
            set_torque.call()
            get_recorded.call()
            rows.append(get_recorded.floats(count))
            do_step.set_float(1, t)
            do_step.set_float(2, h)
            do_step.call()
        get_recorded.call()
        rows.append(get_recorded.floats(count))
    finally:
        for call in (set_torque, get_recorded, do_step):
            call.close()
    return np.array(rows)


def _fresh(model, platform: str | None):
    """An initialized Co-Simulation instance of the model's native or wasm binary."""
    if platform is None:
        slave = instantiated(model, "pendulum")
    else:
        from pendulum_fmu.fmu import _wasm

        slave = _wasm.instantiated(model, "pendulum")
    initialize(slave)
    return slave


def wasm_cost_rows(fmu3: Path, repetitions: int) -> list[Row]:
    """Per-step cost of the native and the wasm binary of one FMI 3.0 FMU, and theta's gap."""
    model = fmu_model(fmu3)
    if model.binary(WASM_PLATFORM, refuse=False) is None:
        return [skipped(PART, "wasm binary beside native", f"{fmu3.name} carries no {WASM_PLATFORM} binary")]
    try:
        from pendulum_fmu.fmu import _wasm
    except ImportError:
        return [skipped(PART, "wasm binary beside native", "wasmtime is not installed")]
    plan = schedule(tutorial.TORQUE, stop_time=tutorial.STOP_TIME, step_size=tutorial.STEP)
    column = model.recorded.index("theta")
    loops = {
        "native": (None, lambda slave: run_schedule_python(slave, plan)["theta"]),
        "wasm": (WASM_PLATFORM, lambda slave: _wasm.run_schedule(slave, plan)[:, column]),
        "raw": (WASM_PLATFORM, lambda slave: raw_schedule(slave, plan)[:, column]),
    }
    theta: dict[str, np.ndarray] = {}

    def contender(name: str):
        platform, loop = loops[name]

        def run() -> float:
            slave = _fresh(model, platform)
            try:
                seconds, theta[name] = timed(lambda: loop(slave))
            finally:
                slave.terminate()
                slave.freeInstance()
            return seconds

        return run

    seconds = interleaved({name: contender(name) for name in loops}, repetitions)
    step = {name: median(values) / tutorial.STEPS for name, values in seconds.items()}
    gap = float(np.max(np.abs(theta["wasm"] - theta["native"])))
    identical = int(np.count_nonzero(theta["wasm"] == theta["native"]))
    assert np.array_equal(theta["wasm"], theta["raw"]), "the raw calls and the Python host differ in theta"
    steps = f"{tutorial.STEPS} x 1 ms, median of {repetitions}"
    return [
        Row(PART, f"native FMI 3.0 binary, Python loop (ctypes), {steps}", f"{microseconds(step['native'])}/step"),
        Row(PART, "wasm binary, Python host (wasmtime-py component Func)", f"{microseconds(step['wasm'])}/step"),
        Row(PART, "wasm binary, raw calls (arguments lowered once)", f"{microseconds(step['raw'])}/step"),
        Row(PART, "wasm Python host / native", ratio(step["wasm"] / step["native"])),
        Row(PART, "wasm raw calls / native", ratio(step["raw"] / step["native"])),
        Row(PART, "max |theta wasm - theta native| (rad)", f"{gap:.3g}", "<= 1e-12", gap <= 1e-12),
        Row(PART, "theta points bit-identical", f"{identical} of {len(theta['wasm'])}"),
    ]
