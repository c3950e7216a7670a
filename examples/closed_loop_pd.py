"""The co-simulation the tutorial closes on: a Python master reads the angle each 1 ms step and
a PD controller with gravity feed-forward computes the torque it sets for the next step.

The master is plain fmpy (FMU2Slave): set torque, fmi2DoStep, read theta and omega.
"""

import argparse

import numpy as np

from pendulum_fmu import fmu_model, open_fmu, plot_overlay

MODEL = fmu_model()
P = MODEL.default_parameters
# Feed-forward of the gravity moment at the measured angle leaves the PD terms only the error.
GRAVITY_MOMENT = P["mass"] * P["gravity"] * P["length"]


def pd_torque(theta, omega, setpoint, kp, kd):
    """The controller's torque: the gravity moment at theta, plus kp times the angle's error, less kd times omega."""
    return GRAVITY_MOMENT * np.sin(theta) + kp * (setpoint - theta) - kd * omega


def run(setpoint=0.5, kp=270.0, kd=180.0, stop_time=3.0, step_size=1e-3):
    """Returns (time, theta, omega, torque applied over each step)."""
    theta_vr, omega_vr, torque_vr = (MODEL.value_reference(n) for n in ("theta", "omega", "torque"))
    slave = open_fmu(MODEL)
    steps = round(stop_time / step_size)
    time = step_size * np.arange(steps + 1)
    theta, omega, torque = np.zeros(steps + 1), np.zeros(steps + 1), np.zeros(steps)
    try:
        for k in range(steps):
            torque[k] = pd_torque(theta[k], omega[k], setpoint, kp, kd)
            slave.setReal([torque_vr], [torque[k]])
            slave.doStep(time[k], step_size)
            theta[k + 1], omega[k + 1] = slave.getReal([theta_vr, omega_vr])
    finally:
        slave.terminate()
        slave.freeInstance()
    return time, theta, omega, torque


def settling_time(time, theta, setpoint, band=0.02):
    """First time after which theta stays within band*setpoint of the set-point."""
    outside = np.flatnonzero(np.abs(theta - setpoint) > band * abs(setpoint))
    return time[outside[-1] + 1] if len(outside) else time[0]


def main(argv=None):
    """The command line: run the loop, print its final angle, settling time and torque, draw it."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--setpoint", type=float, default=0.5, help="rad (default: %(default)s)")
    parser.add_argument("--kp", type=float, default=270.0, help="N.m/rad (default: %(default)s)")
    parser.add_argument("--kd", type=float, default=180.0, help="N.m.s/rad (default: %(default)s)")
    parser.add_argument("--stop-time", type=float, default=3.0, help="s (default: %(default)s)")
    parser.add_argument("--output-dir", default="out/closed_loop_pd", help="where the figure goes")
    args = parser.parse_args(argv)
    time, theta, omega, torque = run(args.setpoint, args.kp, args.kd, args.stop_time)
    print(
        f"theta({time[-1]:g} s) = {theta[-1]:.6f} rad (set-point {args.setpoint} rad); "
        f"2 % settling time {settling_time(time, theta, args.setpoint):.3f} s; "
        f"final torque {torque[-1]:.3f} N.m"
    )
    result = np.zeros(len(time), dtype=[("time", "f8"), ("theta", "f8"), ("omega", "f8")])
    result["time"], result["theta"], result["omega"] = time, theta, omega
    figure = plot_overlay(
        {"PD-controlled pendulum": result},
        f"{args.output_dir}/closed_loop.png",
        "Closed loop: PD controller in a Python master",
    )
    print(f"wrote {figure}")


if __name__ == "__main__":
    main()
