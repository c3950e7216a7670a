"""Drake as a compare tool.

The pendulum is a MultibodyPlant with one rigid body, the head, whose spatial inertia is the mass
at its centre and the head's own inertia about it, joined to the world by a RevoluteJoint about y
whose frame on the head sits `length` above the centre; the joint's damping is the FMU's
damping, gravity is along -z, so theta is measured from the downward vertical. A JointActuator
takes the torque. What the adapter sets, and the traps it avoids:

- the actuation input port is fixed to the step's torque before each step: an input port must be
  fixed or connected, and Drake 1.51 takes an unconnected actuation port as zero torque, silently;
- theta and omega are read from the plant's state, and a discrete plant's sampled output ports
  are switched off: a sampled port (the generalized acceleration among them) reports the value of
  the previous step, so alpha would lag a step;
- accurate: a continuous plant (time_step 0) under the error-controlled fifth-order Runge-Kutta
  integrator at target accuracy 1e-12, advanced to each communication point;
- default: the discrete plant Drake's MultibodyPlantConfig gives (SAP, semi-implicit), with its
  time step set to the communication step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import FixedOffsetFrame, RevoluteJoint, SpatialInertia, UnitInertia
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder

from .._errors import InvalidInput
from ..signals._torque_schedule import TorqueSchedule
from . import held_results, runner


@dataclass(frozen=True)
class Setup:
    """How the adapter drives Drake; tests turn each trap back on through the last two fields."""

    discrete: bool
    integrator: str = "runge_kutta5"
    accuracy: float = 1e-12
    # Read alpha from a discrete plant's sampled acceleration port (the lag trap).
    sampled_outputs: bool = False
    # Leave the actuation input port unfixed (the input-port trap).
    fix_input: bool = True


SETUPS = {"accurate": Setup(discrete=False), "default": Setup(discrete=True)}


class UnequalSteps(InvalidInput):
    """Drake's discrete plant has one period; default mode needs equal communication steps."""


def build(parameters: dict, time_step: float, sampled_outputs: bool):
    """(diagram, plant) of the pendulum; time_step 0 makes the plant continuous."""
    p = parameters
    builder = DiagramBuilder()
    plant = MultibodyPlant(time_step)
    builder.AddSystem(plant)
    if time_step > 0:
        plant.SetUseSampledOutputPorts(sampled_outputs)
    mass, inertia = p["mass"], p["inertia"]
    # pydrake's stubs write its 3-vectors in pybind11's notation, numpy.ndarray[numpy.float64[3, 1]],
    # which mypy reads as an array whose shape is a float: no vector matches it, hence the four
    # ignores of that error alone below.
    at_centre = np.zeros(3)
    head = plant.AddRigidBody(
        "head",
        SpatialInertia(mass, at_centre, UnitInertia(*(inertia / mass,) * 3)),  # type: ignore[arg-type]
    )
    pin_on_head = plant.AddFrame(
        FixedOffsetFrame(
            "pin_on_head",
            head.body_frame(),
            RigidTransform([0.0, 0.0, p["length"]]),  # type: ignore[call-overload]
        )
    )
    y_axis = [0.0, 1.0, 0.0]
    joint = plant.AddJoint(
        RevoluteJoint("pin", plant.world_frame(), pin_on_head, y_axis, p["damping"])  # type: ignore[call-overload]
    )
    plant.AddJointActuator("torque", joint)
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -p["gravity"]])  # type: ignore[arg-type]
    plant.Finalize()
    return builder.Build(), plant


def simulate(plan: TorqueSchedule, parameters: dict, theta0: float, omega0: float, setup: Setup) -> np.ndarray:
    """The schedule through Drake as setup says; the result array of _results.py."""
    time_step = 0.0
    if setup.discrete:
        time_step = float(plan.step_size[0])
        if not np.allclose(plan.step_size, time_step, rtol=1e-9, atol=0):
            raise UnequalSteps(
                "drake:default steps a discrete plant at one period, but the "
                "communication steps differ (a torque jump off the step grid, or a "
                "short last step): use drake (accurate) or a grid-aligned signal"
            )
    diagram, plant = build(parameters, time_step, setup.sampled_outputs)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    context.SetTime(float(plan.time[0]))
    plant_context = plant.GetMyMutableContextFromRoot(context)
    plant.SetPositions(plant_context, [theta0])
    plant.SetVelocities(plant_context, [omega0])
    if not setup.discrete:
        integrator = ResetIntegratorFromFlags(simulator, setup.integrator, float(plan.step_size.max()))
        integrator.set_target_accuracy(setup.accuracy)
    actuation = plant.get_actuation_input_port()
    acceleration = plant.get_generalized_acceleration_output_port()

    out = held_results(plan)

    def record(k):
        if setup.fix_input:
            actuation.FixValue(plant_context, [float(out["torque"][k])])
        out["theta"][k] = plant.GetPositions(plant_context)[0]
        out["omega"][k] = plant.GetVelocities(plant_context)[0]
        out["alpha"][k] = acceleration.Eval(plant_context)[0]

    record(0)
    simulator.Initialize()
    for k, t in enumerate(plan.time[1:].tolist()):
        simulator.AdvanceTo(t)
        record(k + 1)
    return out


run = runner("drake", simulate, SETUPS)
