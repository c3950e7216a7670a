"""PyBullet as a compare tool.

The pendulum is a URDF: a fixed base link and the head, joined by a continuous joint about y at
the base's origin, the head's centre of mass `length` below it, gravity along -z, so theta is
measured from the downward vertical. PyBullet integrates with semi-implicit Euler, so the
accurate mode can only shrink the step. What the adapter sets, and the traps it avoids:

- setGravity: a new PyBullet world has no gravity;
- URDF_USE_INERTIA_FROM_FILE: without it loadURDF replaces the file's inertia by one computed
  from the collision shapes (here, with none, 2.7e-5 kg.m2 instead of 20), whatever the file says;
- changeDynamics(linearDamping=0, angularDamping=0): every link has a hidden velocity damping by
  default (here it slows the pendulum as a joint damping of 2.2 N.m.s/rad would); the FMU's
  damping goes in as jointDamping;
- setJointMotorControl2(VELOCITY_CONTROL, force=0): every joint starts with a velocity motor that
  holds it still;
- the torque is applied again before every stepSimulation: a TORQUE_CONTROL force lasts one step;
- maxJointVelocity raised from its default of 100 rad/s, where PyBullet clamps silently.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..signals._torque_schedule import TorqueSchedule
from . import held_results, runner, substeps


def _import_quietly():
    """Import pybullet, which prints its build time on stderr from C, where a user error is
    one line.
    """
    sys.stderr.flush()
    saved, devnull = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    try:
        import pybullet
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    return pybullet


pybullet = _import_quietly()


@dataclass(frozen=True)
class Setup:
    """How the adapter drives PyBullet; tests turn each trap back on through the flags."""

    # The longest internal step; each communication step is cut into equal substeps.
    largest_step: float
    set_gravity: bool = True
    inertia_from_file: bool = True
    remove_hidden_damping: bool = True
    disable_velocity_motor: bool = True
    # Apply the torque before every stepSimulation, not only when it changes (a TORQUE_CONTROL
    # force lasts one stepSimulation).
    reapply_torque: bool = True
    raise_velocity_limit: bool = True


# 10 us substeps (100 per 1 ms step): semi-implicit Euler's error is first order in the step;
# this keeps a 4 s signal near a second (1 us: ten times closer, ten times slower).
ACCURATE = Setup(largest_step=1e-5)
DEFAULT = Setup(largest_step=math.inf)
SETUPS = {"accurate": ACCURATE, "default": DEFAULT}

_NO_VELOCITY_LIMIT = 1e12


def urdf(parameters: dict) -> str:
    """The URDF of the pendulum with these parameters."""
    p = parameters
    inertia = repr(p["inertia"])
    return f"""<robot name="pendulum">
  <link name="base"><inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="head">
    <inertial><origin xyz="0 0 {-p["length"]!r}"/><mass value="{p["mass"]!r}"/>
      <inertia ixx="{inertia}" iyy="{inertia}" izz="{inertia}" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="pin" type="continuous"><parent link="base"/><child link="head"/><axis xyz="0 1 0"/></joint>
</robot>"""


def simulate(plan: TorqueSchedule, parameters: dict, theta0: float, omega0: float, setup: Setup) -> np.ndarray:
    """The schedule through PyBullet as setup says; the result array of _results.py."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        with tempfile.TemporaryDirectory(prefix="pendulum_pybullet_") as folder:
            path = Path(folder) / "pendulum.urdf"
            path.write_text(urdf(parameters))
            flags = pybullet.URDF_USE_INERTIA_FROM_FILE if setup.inertia_from_file else 0
            body = pybullet.loadURDF(str(path), useFixedBase=True, flags=flags, physicsClientId=client)
        return _step_through(plan, parameters, theta0, omega0, setup, client, body)
    finally:
        pybullet.disconnect(client)


def _step_through(plan, parameters, theta0, omega0, setup, client, body):
    joint = 0
    if setup.set_gravity:
        pybullet.setGravity(0, 0, -parameters["gravity"], physicsClientId=client)
    # Two calls: PyBullet drops a jointDamping given in the same call as maxJointVelocity.
    if setup.raise_velocity_limit:
        pybullet.changeDynamics(body, joint, maxJointVelocity=_NO_VELOCITY_LIMIT, physicsClientId=client)
    dynamics = {"jointDamping": parameters["damping"]}
    if setup.remove_hidden_damping:
        dynamics.update(linearDamping=0.0, angularDamping=0.0)
    pybullet.changeDynamics(body, joint, physicsClientId=client, **dynamics)
    if setup.disable_velocity_motor:
        pybullet.setJointMotorControl2(body, joint, pybullet.VELOCITY_CONTROL, force=0, physicsClientId=client)
    pybullet.resetJointState(body, joint, theta0, omega0, physicsClientId=client)

    def apply(u):
        pybullet.setJointMotorControl2(body, joint, pybullet.TORQUE_CONTROL, force=u, physicsClientId=client)

    def state():
        theta, omega, _, _ = pybullet.getJointState(body, joint, physicsClientId=client)
        return theta, omega

    out = held_results(plan)
    counts = substeps(plan.step_size, setup.largest_step)
    out["theta"][0], out["omega"][0] = theta0, omega0
    applied = None
    for k, (h, n, u) in enumerate(zip(plan.step_size.tolist(), counts.tolist(), plan.torque.tolist(), strict=False)):
        # One stepSimulation per substep: PyBullet's numSubSteps would be faster, but Bullet then
        # counts substeps from accumulated time and drops or adds one when that rounds.
        pybullet.setTimeStep(h / n, physicsClientId=client)
        for substep in range(n):
            if setup.reapply_torque or u != applied:
                apply(u)
                applied = u
            pybullet.stepSimulation(physicsClientId=client)
            if substep == 0:
                # Semi-implicit Euler moves omega by the acceleration at the step's start: alpha
                # is what the engine used, read from the first substep.
                out["alpha"][k] = (state()[1] - out["omega"][k]) * n / h
        out["theta"][k + 1], out["omega"][k + 1] = state()
    # alpha at the end: one more substep under the last torque.
    apply(out["torque"][-1])
    pybullet.stepSimulation(physicsClientId=client)
    out["alpha"][-1] = (state()[1] - out["omega"][-1]) * n / h
    return out


run = runner("pybullet", simulate, SETUPS)
