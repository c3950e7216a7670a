"""The independent oracle: the same schedule through scipy's solve_ivp at tight tolerance."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from . import results
from .parameters import resolve_parameters, total_inertia
from .signal import TorqueSchedule, TorqueSignal, schedule


def reference_schedule(plan: TorqueSchedule, *, parameters: dict | None = None, theta0: float = 0.0,
                       omega0: float = 0.0, rtol: float = 1e-12, atol: float = 1e-12,
                       fmu_path: str | Path | None = None) -> np.ndarray:
    """Integrate the equation of motion over each run of steps with the same held torque.

    parameters override the defaults of the FMU at fmu_path (default: pendulum_fmu.default_fmu()).

    Steps are merged only where the torque does not change, so solve_ivp never integrates across
    a jump; each run reports at every communication point inside it.
    """
    p = resolve_parameters(parameters, fmu_path)
    inverse_inertia = 1.0 / total_inertia(p)
    gravity_moment = p["mass"] * p["gravity"] * p["length"]
    damping = p["damping"]
    time, torque, rate = plan.time, plan.torque, plan.torque_rate

    def acceleration(theta, omega, u):
        return (u - gravity_moment * np.sin(theta) - damping * omega) * inverse_inertia

    # A new run starts wherever the step's torque differs from a continuation of the previous one.
    continues = np.zeros(len(torque), dtype=bool)
    continues[1:] = (rate[1:] == 0) & (rate[:-1] == 0) & (torque[1:] == torque[:-1])
    starts = np.flatnonzero(~continues)
    ends = np.append(starts[1:], len(torque))

    out = results.empty(len(time))
    out["time"] = time
    state = np.array([theta0, omega0], dtype=float)
    out["theta"][0], out["omega"][0] = state
    for first, stop in zip(starts, ends):
        t0, u0, r = time[first], torque[first], rate[first]
        rhs = lambda t, y: (y[1], acceleration(y[0], y[1], u0 + r * (t - t0)))  # noqa: E731
        points = time[first:stop + 1]
        solution = solve_ivp(rhs, (points[0], points[-1]), state, method="DOP853", rtol=rtol,
                             atol=atol, t_eval=points)
        if not solution.success:
            raise RuntimeError(f"solve_ivp failed from t = {t0}: {solution.message}")
        out["theta"][first + 1:stop + 1] = solution.y[0, 1:]
        out["omega"][first + 1:stop + 1] = solution.y[1, 1:]
        state = solution.y[:, -1].copy()
    out["torque"][:-1] = torque
    out["torque"][-1] = torque[-1] + rate[-1] * (time[-1] - time[-2])
    out["alpha"] = acceleration(out["theta"], out["omega"], out["torque"])
    return out


def reference(torque: TorqueSignal = 20.0, *, start_time: float = 0.0, stop_time: float | None = None,
              step_size: float = 1e-3, ramp: bool = False, parameters: dict | None = None,
              theta0: float = 0.0, omega0: float = 0.0, rtol: float = 1e-12,
              atol: float = 1e-12, fmu_path: str | Path | None = None) -> np.ndarray:
    """The same signal, schedule and model arguments as simulate() (rtol and atol are scipy's in
    place of the FMU's tolerance), through scipy DOP853; same result format."""
    plan = schedule(torque, start_time=start_time, stop_time=stop_time, step_size=step_size,
                    ramp=ramp)
    return reference_schedule(plan, parameters=parameters, theta0=theta0, omega0=omega0,
                              rtol=rtol, atol=atol, fmu_path=fmu_path)
