"""MuJoCo as a compare tool.

The pendulum is one body hinged at the world origin about y, its centre of mass `length` below
the pin, gravity along -z, so theta is measured from the downward vertical as in the FMU. A motor
actuator with gear 1 applies the torque. What the adapter sets, and the traps it avoids:

- the model's timestep: MuJoCo's default is 2 ms, so one mj_step per 1 ms communication step
  would run the clock at twice the signal's speed; the adapter sets the timestep per step to the
  step (or an exact divisor of it);
- ctrllimited="false": a ctrlrange (common in published models) clamps the torque silently;
- the state is read from qpos/qvel after a fresh mj_forward, not from sensordata, which mj_step
  computes before it integrates and so is one step stale.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..signals._torque_schedule import TorqueSchedule
from . import held_results, runner, substeps


@dataclass(frozen=True)
class Setup:
    """How the adapter drives MuJoCo. The defaults of the fields that are not modes are the
    correct settings; tests turn each trap back on through them.
    """

    integrator: str
    # The longest internal step; None keeps MuJoCo's own timestep (2 ms) and steps once per
    # communication step whatever its length (the timestep trap).
    largest_step: float | None
    # A ctrlrange for the actuator, or None for none (the ctrlrange trap).
    ctrlrange: tuple[float, float] | None = None
    # Read theta and omega from the sensors after mj_step (the stale-sensor trap).
    read_sensors: bool = False


# RK4 at 1 ms is already within 5e-12 rad of the reference over a 4 s random step signal (the
# reference's own tolerance is 1e-12): a longer communication step is cut into 1 ms substeps.
ACCURATE = Setup(integrator="RK4", largest_step=1e-3)
# The integrator a model file gets when it names none: semi-implicit Euler, one step per
# communication step.
DEFAULT = Setup(integrator="Euler", largest_step=math.inf)
SETUPS = {"accurate": ACCURATE, "default": DEFAULT}


def model_xml(parameters: dict, setup: Setup) -> str:
    """The MJCF of the pendulum with these parameters, set up for a mode."""
    p = parameters
    limits = (
        'ctrllimited="false"'
        if setup.ctrlrange is None
        else f'ctrllimited="true" ctrlrange="{setup.ctrlrange[0]!r} {setup.ctrlrange[1]!r}"'
    )
    # MuJoCo refuses a zero inertia; the hinge only feels the y component, so a tiny one
    # elsewhere changes nothing.
    inertia = max(p["inertia"], 1e-12)
    return f"""<mujoco model="pendulum">
  <option gravity="0 0 {-p["gravity"]!r}" integrator="{setup.integrator}"/>
  <worldbody>
    <body name="head">
      <joint name="pin" type="hinge" axis="0 1 0" damping="{p["damping"]!r}"/>
      <inertial pos="0 0 {-p["length"]!r}" mass="{p["mass"]!r}" diaginertia="{inertia!r} {inertia!r} {inertia!r}"/>
    </body>
  </worldbody>
  <actuator><motor name="torque" joint="pin" gear="1" {limits}/></actuator>
  <sensor><jointpos joint="pin"/><jointvel joint="pin"/></sensor>
</mujoco>"""


def simulate(plan: TorqueSchedule, parameters: dict, theta0: float, omega0: float, setup: Setup) -> np.ndarray:
    """The schedule through MuJoCo as setup says; the result array of _results.py."""
    model = mujoco.MjModel.from_xml_string(model_xml(parameters, setup))
    data = mujoco.MjData(model)
    data.qpos[0], data.qvel[0] = theta0, omega0
    out = held_results(plan)
    counts = (
        np.ones(len(plan.step_size), dtype=int)
        if setup.largest_step is None
        else substeps(plan.step_size, setup.largest_step)
    )

    def record(k, fresh):
        if fresh:
            mujoco.mj_forward(model, data)
            theta, omega = data.qpos[0], data.qvel[0]
        else:
            theta, omega = data.sensordata[0], data.sensordata[1]
        out["theta"][k], out["omega"][k], out["alpha"][k] = theta, omega, data.qacc[0]

    data.ctrl[0] = out["torque"][0]
    record(0, True)
    for k, (h, n) in enumerate(zip(plan.step_size.tolist(), counts.tolist(), strict=False)):
        if setup.largest_step is not None:
            model.opt.timestep = h / n
        for _ in range(n):
            mujoco.mj_step(model, data)
        data.ctrl[0] = out["torque"][k + 1]
        record(k + 1, not setup.read_sensors)
    return out


run = runner("mujoco", simulate, SETUPS)
