"""FMI 2.0 input derivatives of any order, as an extrapolating master sends them: orders 1 and 2
shape the input over the step (a quadratic torque is integrated as exactly as a linear one),
higher orders are ignored with one message per instance; the PID controller FMU does the same.
"""

import ctypes

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
from scipy.integrate import solve_ivp

from pendulum_fmu.fmu._instance import MessageLog, _unzipped, open_fmu
from pendulum_fmu.fmu._parameters import default_parameters, total_inertia
from pendulum_fmu.ssp._closed_loop import controller_defaults, sampled_loop_reference

TORQUE, THETA, OMEGA = 0, 1, 2
I_TOTAL = total_inertia(default_parameters())
WARNING = 1


def _finish(*slaves):
    for slave in slaves:
        slave.terminate()
        slave.freeInstance()


@pytest.mark.parametrize("every_step", [False, True])
def test_quadratic_torque_gives_the_exact_quartic(fmu, every_step):
    """Gravity off: alpha = u(t)/I with u = u0 + u1 t + u2 t^2/2, so theta is a quartic that
    Dormand-Prince 5(4) integrates exactly. Set once, the derivatives carry the polynomial on;
    set every step (as an extrapolating master does), they give the same polynomial.
    """
    u0, u1, u2 = 5.0, 4.0, -6.0
    slave = open_fmu(fmu, parameters={"gravity": 0.0})
    h, n = 1e-3, 3000
    for k in range(n):
        t = k * h
        if k == 0 or every_step:
            slave.setReal([TORQUE], [u0 + u1 * t + u2 * t * t / 2])
            slave.setRealInputDerivatives([TORQUE, TORQUE], [1, 2], [u1 + u2 * t, u2])
        slave.doStep(t, h)
    theta, omega, torque = slave.getReal([THETA, OMEGA, TORQUE])
    _finish(slave)
    t = n * h
    assert theta == pytest.approx((u0 * t**2 / 2 + u1 * t**3 / 6 + u2 * t**4 / 24) / I_TOTAL, rel=0, abs=1e-12)
    assert omega == pytest.approx((u0 * t + u1 * t**2 / 2 + u2 * t**3 / 6) / I_TOTAL, rel=0, abs=1e-12)
    assert torque == pytest.approx(u0 + u1 * t + u2 * t**2 / 2, rel=0, abs=1e-11)


def test_orders_above_two_are_ignored_with_one_message(fmu):
    runs = []
    for orders in ([1, 2], [1, 2, 3, 4]):
        slave = open_fmu(fmu)
        for k in range(20):
            status = slave.fmi2SetRealInputDerivatives(
                slave.component, *_arrays([TORQUE] * len(orders), orders, [3.0, 1.0, 50.0, -7.0][: len(orders)])
            )
            assert status == (WARNING if k == 0 and len(orders) > 2 else 0)
            slave.doStep(k * 1e-2, 1e-2)
        runs.append(slave.getReal([THETA, OMEGA]))
        ignored = [line for line in slave.messages.lines if "ignored" in line]
        _finish(slave)
    assert runs[0] == runs[1], "orders 3 and 4 must not change the result"
    assert ignored == [
        "[WARNING] fmi2SetRealInputDerivatives: order 3 for torque ignored: inputs follow "
        "their first and second derivatives only (logged once per instance)"
    ]


def _arrays(references, orders, values):
    n = len(references)
    return (
        (ctypes.c_uint * n)(*references),
        ctypes.c_size_t(n),
        (ctypes.c_int * n)(*orders),
        (ctypes.c_double * n)(*values),
    )


def _controller(path):
    folder, description = _unzipped(path)
    slave = FMU2Slave(
        guid=description.guid,
        unzipDirectory=folder,
        instanceName="controller",
        modelIdentifier=description.coSimulation.modelIdentifier,
    )
    slave.messages = MessageLog()
    slave.instantiate(callbacks=slave.messages.callbacks)
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    return slave


def _closed_loop(fmu, controller_fmu, stop_time, h, extrapolate):
    """A master that, like the fmpy container, hands theta and omega to the controller before
    reading its torque; with extrapolate it also sends their first and second derivatives, as
    OMSimulator with --inputExtrapolation does for an FMU with maxOutputDerivativeOrder 2.
    """
    pendulum, controller = open_fmu(fmu), _controller(controller_fmu)
    names = {v.name: v.valueReference for v in read_model_description(str(controller_fmu)).modelVariables}
    inputs = [names["theta"], names["omega"]]
    theta = []
    for k in range(round(stop_time / h) + 1):
        measured = pendulum.getReal([THETA, OMEGA])
        theta.append(measured[0])
        if k * h >= stop_time - h / 2:
            break
        controller.setReal(inputs, measured)
        if extrapolate:
            derivatives = pendulum.getRealOutputDerivatives([THETA, THETA, OMEGA, OMEGA], [1, 2, 1, 2])
            controller.setRealInputDerivatives(inputs * 2, [1, 1, 2, 2], derivatives[0::2] + derivatives[1::2])
        pendulum.setReal([TORQUE], controller.getReal([names["torque"]]))
        pendulum.doStep(k * h, h)
        controller.doStep(k * h, h)
    _finish(pendulum, controller)
    return np.array(theta)


def _loop_with_exact_integral(stop_time, h):
    """The oracle of the extrapolated loop: torque sampled and held as before, but the
    controller's integral of (setpoint - theta) follows theta within the step, as the
    extrapolated inputs let it. One scipy integration of (theta, omega, integral) per step.
    """
    gains, p = controller_defaults(), default_parameters()
    gravity_moment, inverse_inertia = p["mass"] * p["gravity"] * p["length"], 1.0 / total_inertia(p)
    state = np.zeros(3)
    theta = [0.0]
    for _ in range(round(stop_time / h)):
        torque = gains["kp"] * (gains["setpoint"] - state[0]) + gains["ki"] * state[2] - gains["kd"] * state[1]

        def rhs(t, y, u=torque):
            return (y[1], (u - gravity_moment * np.sin(y[0])) * inverse_inertia, gains["setpoint"] - y[0])

        state = solve_ivp(rhs, (0.0, h), state, method="DOP853", rtol=1e-12, atol=1e-12).y[:, -1]
        theta.append(state[0])
    return np.array(theta)


def test_closed_loop_with_order_2_derivatives_every_step(fmu, pid_controller):
    stop_time, errors, differences = 2.0, [], []
    for h in (1e-2, 5e-3):
        held = _closed_loop(fmu, pid_controller, stop_time, h, extrapolate=False)
        extrapolated = _closed_loop(fmu, pid_controller, stop_time, h, extrapolate=True)
        assert np.max(np.abs(held - sampled_loop_reference(stop_time, h)["theta"])) < 1e-9
        errors.append(np.max(np.abs(extrapolated - _loop_with_exact_integral(stop_time, h))))
        differences.append(np.max(np.abs(extrapolated - held)))
    # The quadratic extrapolation misses theta's integral by (d3 theta/dt3) h^4/24 a step, so the
    # extrapolated loop meets its oracle to third order in h: that is the extrapolation's own
    # error (measured 3.5e-7 and 4.3e-8 rad).
    assert errors[0] < 1e-6 and errors[0] / errors[1] > 7
    # The held loop differs by what a held input misses of the integral, first order in h
    # (measured 2.0e-3 and 9.9e-4 rad).
    assert differences[0] < 0.25 * 1e-2 and 1.8 < differences[0] / differences[1] < 2.2
