"""pendulum-fmu compare: one torque signal through several tools, judged by the reference."""

from __future__ import annotations

import argparse

from ._arguments import add_signal_arguments, float_number, output_path, signal_options, torque_signal


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `compare` and its options, each with its help, among the parser's commands."""
    compare = commands.add_parser(
        "compare",
        help="run one torque signal through several tools",
        description="Run one torque signal through the FMU and OpenSim "
        "and judge each against the independent "
        "reference, which reads the signal itself: write "
        "trajectories, a table of max and RMS differences "
        "(and of the torque each tool received against the "
        "signal) and a figure. Exits 1 when a tool differs "
        "by more than --tol or received another torque.",
    )
    add_signal_arguments(compare)
    compare.add_argument(
        "--ramp",
        action="store_true",
        help="ramp the torque along the CSV's piecewise-linear signal in every "
        "tool that can (the FMU, the reference); OpenSim cannot and says so",
    )
    compare.add_argument(
        "--tools",
        default=None,
        help="comma-separated, each once: fmu, reference, opensim, mujoco, drake, "
        "pybullet (NAME:default for the engine's own defaults), wasm (the FMI 3.0 FMU's "
        "WebAssembly binary, through wasmtime), gymnasium, envpool (their Pendulum-v1, "
        "docs/comparing.md), or "
        "LABEL=path/to/Their.fmu for any FMI 2.0/3.0 FMU; the reference always "
        "runs as the judge (default: fmu,reference,opensim, those installed; the line "
        "that says which were skipped says how to install them)",
    )
    compare.add_argument(
        "--map",
        dest="mapping",
        default=None,
        metavar="OURS=THEIRS[*FACTOR],...",
        help="for LABEL=FMU tools: their variable names for torque, theta, omega, "
        "alpha and the parameters, with a factor where they use other units, "
        "e.g. torque=u,theta=phi*0.0174532925 (docs/engines.md)",
    )
    compare.add_argument(
        "--output-dir",
        type=output_path,
        required=True,
        help="folder for trajectories.csv, differences.csv and comparison.png",
    )
    compare.add_argument(
        "--tol",
        type=float_number,
        default=1e-9,
        help="largest allowed |dtheta| (rad) or |domega| (rad/s), positive and finite (default: %(default)s)",
    )
    compare.set_defaults(run=run)
    return compare


def run(args) -> int:
    """Run `pendulum-fmu compare` with the parsed arguments; returns the exit status."""
    from ..comparing._compare import compare, format_comparison
    from ..signals._time_grid import WINDOW_STEPS

    comparison = compare(
        torque_signal(args),
        args.tools,
        output_dir=args.output_dir,
        tolerance=args.tol,
        mapping=args.mapping,
        **signal_options(args),
    )
    print(format_comparison(comparison))
    steps = len(next(iter(comparison.runs.values()))) - 1  # every row, where a tool ran whole
    if comparison.whole and steps > WINDOW_STEPS:
        # Past a window, what such a tool holds is what the run's memory grows with.
        print(
            f"{', '.join(comparison.whole)} ran the whole run at once, held in memory "
            "(fmu, wasm and Co-Simulation FMUs run a window at a time)"
        )
    for path in (comparison.trajectories, comparison.table, comparison.figure):
        print(f"wrote {path}")
    return 0 if comparison.agree else 1
