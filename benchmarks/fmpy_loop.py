"""The master everyone starts with: fmpy's FMU2Slave, one wrapper call per FMI call."""

from __future__ import annotations

import numpy as np
from fmpy.fmi2 import FMU2Slave

from . import tutorial
from .builds import BuiltFmu
from .timing import timed


def open_slave(fmu: BuiltFmu) -> FMU2Slave:
    """An instance in step mode with the FMU's own defaults: no parameter set, no tolerance."""
    slave = FMU2Slave(
        guid=fmu.guid, unzipDirectory=str(fmu.unzip_dir), modelIdentifier=fmu.model_identifier, instanceName="benchmark"
    )
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    return slave


def tutorial_loop(slave: FMU2Slave, fmu: BuiltFmu) -> list[float]:
    """Each step: setReal torque, doStep, getReal theta. Returns theta after each step."""
    torque_vr, theta_vr = [fmu.value_references["torque"]], [fmu.value_references["theta"]]
    torque_value = [tutorial.TORQUE]
    theta = []
    for k in range(tutorial.STEPS):
        slave.setReal(torque_vr, torque_value)
        slave.doStep(k * tutorial.STEP, tutorial.STEP)
        theta.append(slave.getReal(theta_vr)[0])
    return theta


def timed_tutorial_loop(fmu: BuiltFmu) -> tuple[float, np.ndarray]:
    """(seconds of the stepping loop alone, theta at every communication point) of the tutorial
    case on a fresh instance.
    """
    slave = open_slave(fmu)
    try:
        initial = slave.getReal([fmu.value_references["theta"]])
        seconds, theta = timed(lambda: tutorial_loop(slave, fmu))
    finally:
        slave.terminate()
        slave.freeInstance()
    return seconds, np.array(initial + theta)
