"""Count the package's files and cross-file moves of a CLI command, traced with sys.setprofile.

A cross-file move is a Python call from a function of one pendulum_fmu module into a function of
another; the files are the pendulum_fmu modules whose functions ran. Only this process is traced
(a sweep's dask workers are other processes).

    .venv/bin/python -m benchmarks.cross_file_moves simulate --torque 20
"""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "pendulum_fmu"


def _module(code) -> str | None:
    """The package module a code object belongs to, relative to the package, or None."""
    path = Path(code.co_filename)
    try:
        return str(path.resolve().relative_to(PACKAGE))
    except ValueError:
        return None


def traced(argv: list[str]) -> tuple[set[str], Counter]:
    """(files, {(from, to): moves}) of pendulum_fmu.cli.main(argv)."""
    from pendulum_fmu.cli import main

    files: set[str] = set()
    moves: Counter = Counter()

    def profile(frame, event, argument):
        if event != "call":
            return
        callee = _module(frame.f_code)
        if callee is None:
            return
        files.add(callee)
        caller = frame.f_back and _module(frame.f_back.f_code)
        if caller is not None and caller != callee:
            moves[caller, callee] += 1

    sys.setprofile(profile)
    try:
        main(argv)
    finally:
        sys.setprofile(None)
    return files, moves


if __name__ == "__main__":
    files, moves = traced(sys.argv[1:])
    print(
        f"{len(files)} files, {sum(moves.values())} cross-file moves "
        f"({len(moves)} distinct) for pendulum-fmu {' '.join(sys.argv[1:])}"
    )
    for (caller, callee), count in moves.most_common():
        print(f"  {count:4d}  {caller} -> {callee}")
