"""The tutorial's parameter study: several torques with gravity, run as a grid on a local dask
cluster (pass --scheduler to use a running dask.distributed cluster instead)."""

import argparse

import numpy as np

from pendulum_fmu.sweep import run_sweep, sweep_grid


def run(torques=(5.0, 10.0, 20.0, 40.0), stop_time=3.0, output_dir="out/parameter_study", scheduler=None):
    summary = run_sweep(sweep_grid(torques, [9.81]), output_dir=output_dir, stop_time=stop_time,
                        scheduler=scheduler)
    table = np.genfromtxt(summary["results"], delimiter=",", names=True)
    for torque in torques:
        rows = table[table["torque"] == torque]
        print(f"torque {torque:5g} N.m: max theta = {rows['theta'].max():.6f} rad, "
              f"theta({stop_time:g} s) = {rows['theta'][-1]:.6f} rad")
    print(f"{summary['cases']} cases in {summary['seconds']:.1f} s; wrote {summary['results']} and {summary['figure']}")
    return table


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--torque", type=float, nargs="+", default=[5.0, 10.0, 20.0, 40.0], help="N.m")
    parser.add_argument("--stop-time", type=float, default=3.0, help="s (default: %(default)s)")
    parser.add_argument("--output-dir", default="out/parameter_study", help="where the table and figure go")
    parser.add_argument("--scheduler", default=None, help="address of a dask.distributed scheduler")
    args = parser.parse_args(argv)
    run(args.torque, args.stop_time, args.output_dir, args.scheduler)


if __name__ == "__main__":
    main()
