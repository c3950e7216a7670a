"""The tutorial's constant torque (20 N.m), without and with gravity: the FMU against the
analytic parabola and the independent reference, in the tutorial's figures.
"""

import argparse

import numpy as np

from pendulum_fmu import fmu_model, plot_overlay, reference, simulate, total_inertia


def run(torque=20.0, stop_time=3.0, step_size=1e-3, output_dir="out/constant_torque"):
    """{gravity: (fmu result, reference result)}, after writing one figure per case."""
    runs = {}
    for gravity, title in ((0.0, "No Gravity"), (9.81, "With Gravity")):
        arguments = dict(stop_time=stop_time, step_size=step_size, parameters={"gravity": gravity})
        fmu, oracle = simulate(torque, **arguments), reference(torque, **arguments)
        print(
            f"{title}: max |theta_fmu - theta_reference| = {np.max(np.abs(fmu['theta'] - oracle['theta'])):.2e} rad, "
            f"theta({stop_time:g} s) = {fmu['theta'][-1]:.10f} rad"
        )
        if gravity == 0.0:
            parabola = 0.5 * torque / total_inertia(fmu_model().default_parameters) * fmu["time"] ** 2
            print(f"  against theta = tau t^2 / (2 I): {np.max(np.abs(fmu['theta'] - parabola)):.2e} rad")
        figure = plot_overlay(
            {"FMU": fmu, "Rigid-body ODE (reference)": oracle},
            f"{output_dir}/{title.lower().replace(' ', '_')}.png",
            rf"Constant Torque $\tau = {torque:g}$ N.m — {title}",
        )
        print(f"  wrote {figure}")
        runs[gravity] = fmu, oracle
    return runs


def main(argv=None):
    """The command line: run() with its options."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--torque", type=float, default=20.0, help="N.m (default: %(default)s)")
    parser.add_argument("--stop-time", type=float, default=3.0, help="s (default: %(default)s)")
    parser.add_argument("--step-size", type=float, default=1e-3, help="s (default: %(default)s)")
    parser.add_argument("--output-dir", default="out/constant_torque", help="where the figures go")
    args = parser.parse_args(argv)
    run(args.torque, args.stop_time, args.step_size, args.output_dir)


if __name__ == "__main__":
    main()
