"""pendulum-fmu simulate: the FMU under a torque signal, through fmpy."""

from __future__ import annotations

import argparse

import numpy as np

from ..fmu import WASM_PLATFORM
from ._arguments import (
    add_signal_arguments,
    check_outputs,
    float_number,
    output_path,
    parameters_of,
    signal_options,
    torque_signal,
)


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `simulate` and its options, each with its help, among the parser's commands."""
    simulate = commands.add_parser(
        "simulate",
        help="simulate the FMU under a torque signal",
        description="Simulate the FMU through fmpy; the torque is held over each communication step unless --ramp.",
    )
    add_signal_arguments(simulate)
    simulate.add_argument(
        "--ramp", action="store_true", help="ramp the torque linearly over each step (input derivatives)"
    )
    simulate.add_argument(
        "--tolerance",
        type=float_number,
        default=None,
        help="relative tolerance of the FMU's integrator (default: 1e-10)",
    )
    simulate.add_argument(
        "--platform",
        choices=[WASM_PLATFORM],
        default=None,
        help="run the FMU's WebAssembly binary (FMI 3.0, FMI-LS-WASM) through wasmtime instead of "
        "this machine's native one",
    )
    simulate.add_argument("--output", type=output_path, help="write time,torque,theta,omega,alpha CSV")
    simulate.add_argument("--plot", type=output_path, help="write a PNG of theta and omega")
    simulate.set_defaults(run=run)
    return simulate


def run(args) -> int:
    """Run `pendulum-fmu simulate` with the parsed arguments; returns the exit status."""
    from ..fmu import _results as results
    from ..fmu._model import fmu_model

    check_outputs(
        {"--output": args.output, "--plot": args.plot}, {"--torque-file": args.torque_file, "--fmu": args.fmu}
    )
    options = dict(tolerance=args.tolerance, platform=args.platform, **signal_options(args))
    if args.output:
        # Written as it runs: the memory it takes is a window's, however long the run.
        from ..fmu._streamed import simulate_to_csv

        drawn = ("theta", "omega") if args.plot else ()
        streamed = simulate_to_csv(args.output, torque_signal(args), drawn=drawn, **options)
        fields, steps, last, largest = streamed.fields, streamed.steps, streamed.last[0], streamed.largest["theta"]
        drawn_run = streamed.drawn.rows if streamed.drawn else None
    else:
        from ..fmu._simulate import simulate

        run = simulate(torque_signal(args), **options)
        fields, steps, last, largest = results.fields(run), len(run) - 1, run[-1], np.max(np.abs(run["theta"]))
        drawn_run = run
    # The fields and units of the FMU that ran, --fmu's or the default one: its outputs, as many
    # as it has, after time and torque.
    units = results.units(fields, fmu_model(args.fmu))
    outputs = ", ".join(f"{name} = {last[name]:.12g} {units[name]}" for name in list(units)[2:])
    print(f"{steps} steps to t = {last['time']:g} s: {outputs}; max |theta| = {largest:.6g} rad")
    if args.output:
        print(f"wrote {args.output} ({','.join(units)}; units {', '.join(units.values())})")
    if args.plot:
        from ..figures._plot import case_title, plot_overlay

        title = case_title(torque_signal(args), parameters_of(args.assignments), args.theta0, args.omega0, args.fmu)
        print(f"wrote {plot_overlay({'FMU': drawn_run}, args.plot, title)}")
    return 0
