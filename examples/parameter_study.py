"""The tutorial's parameter study: several torques with gravity, run as a grid on a local dask
cluster (pass --scheduler to use a running dask.distributed cluster instead).
"""

import argparse

import pyarrow.parquet as pq

from pendulum_fmu import PendulumFmuError, Study, run_sweep, sweep_grid


def run(
    torques=(5.0, 10.0, 20.0, 40.0), stop_time=3.0, output_dir="out/parameter_study", scheduler=None, overwrite=False
):
    """Returns the trajectories with each case's torque joined in, as numpy columns."""
    result = run_sweep(
        Study(sweep_grid(torques, [9.81]), stop_time=stop_time),
        output_dir=output_dir,
        scheduler=scheduler,
        overwrite=overwrite,
    )
    cases = pq.read_table(result.cases_table).sort_by("case")
    for case in cases.to_pylist():
        print(
            f"torque {case['torque']:5g} N.m: max |theta| = {case['max_abs_theta']:.6f} rad, "
            f"theta({stop_time:g} s) = {case['final_theta']:.6f} rad"
        )
    trajectories = (
        pq.read_table(result.trajectories)
        .join(cases.select(["case", "torque"]), "case")
        .sort_by([("case", "ascending"), ("time", "ascending")])
    )
    print(
        f"{result.cases} cases in {result.seconds:.1f} s; wrote {result.trajectories}, "
        f"{result.cases_table} and {result.figure}"
    )
    return {name: trajectories[name].to_numpy() for name in trajectories.column_names}


def main(argv=None):
    """The command line: run() with its options; a study it refuses is one line, exit status 2."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--torque", type=float, nargs="+", default=[5.0, 10.0, 20.0, 40.0], help="N.m")
    parser.add_argument("--stop-time", type=float, default=3.0, help="s (default: %(default)s)")
    parser.add_argument("--output-dir", default="out/parameter_study", help="where the table and figure go")
    parser.add_argument("--scheduler", default=None, help="address of a dask.distributed scheduler")
    parser.add_argument(
        "--overwrite", action="store_true", help="replace the study --output-dir holds (else such a folder is refused)"
    )
    args = parser.parse_args(argv)
    try:
        run(args.torque, args.stop_time, args.output_dir, args.scheduler, args.overwrite)
    except PendulumFmuError as error:  # a study already there, say: one line, as pendulum-fmu says it
        parser.exit(2, f"{parser.prog}: error: {error}\n")


if __name__ == "__main__":
    main()
