"""Gravity on against gravity off under the same constant torque (the tutorial's section 2.11)."""

import argparse

from pendulum_fmu import plot_overlay, simulate


def run(torque=20.0, stop_time=3.0, output_dir="out/gravity_overlay"):
    """{label: result} of the runs with gravity off and on, after drawing both in one figure."""
    runs = {
        "No gravity": simulate(torque, stop_time=stop_time, parameters={"gravity": 0.0}),
        "With gravity": simulate(torque, stop_time=stop_time),
    }
    for label, run_ in runs.items():
        print(
            f"{label}: theta({stop_time:g} s) = {run_['theta'][-1]:.6f} rad, "
            f"max omega = {run_['omega'].max():.6f} rad/s"
        )
    figure = plot_overlay(
        runs,
        f"{output_dir}/gravity_overlay.png",
        rf"Effect of Gravity on Torque-Driven Pendulum ($\tau = {torque:g}$ N.m)",
    )
    print(f"wrote {figure}")
    return runs


def main(argv=None):
    """The command line: run() with its options."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--torque", type=float, default=20.0, help="N.m (default: %(default)s)")
    parser.add_argument("--stop-time", type=float, default=3.0, help="s (default: %(default)s)")
    parser.add_argument("--output-dir", default="out/gravity_overlay", help="where the figure goes")
    args = parser.parse_args(argv)
    run(args.torque, args.stop_time, args.output_dir)


if __name__ == "__main__":
    main()
