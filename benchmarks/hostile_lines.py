"""How long reading a crafted call log takes (issue 38): read_calls on 20 MB of lines made to
make a backtracking regular expression take time in the square of a line's length.

Prints, for each shape and line length, the seconds to read the 20 MB: a reader that is linear in
a line's length takes about the same time whatever the line length (the lines are fewer as they
are longer); one that is quadratic, 4 times as long at each doubling. Before issue 38, 1280 lines
of 16 kB record markers took 114 s here, one 32 kB word in a call's arguments 24 s.

    python -m benchmarks.hostile_lines
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from pendulum_fmu._errors import InvalidInput
from pendulum_fmu._received_files import MAX_LINE_CHARS
from pendulum_fmu.judging._call_record import read_calls

TOTAL_BYTES = 20 * 2**20
MARKER_PREFIX = '[pendulum-calls] instance="" fmi2A('
# Each shape repeated to fill a line: a backtracking search tries every start in the line.
SHAPES = {
    "fmi2Ab( repeated": lambda length: "fmi2Ab(" * (length // 7),
    "record markers repeated": lambda length: MARKER_PREFIX * (length // len(MARKER_PREFIX)),
    "one word in a call's arguments": lambda length: "fmi2Ab(" + "a" * (length - 8) + ")",
}


def read_seconds(line: str, folder: Path) -> tuple[float, str]:
    """Seconds read_calls takes on TOTAL_BYTES of the line, and what it gave."""
    path = folder / "crafted.log"
    path.write_text((line + "\n") * (TOTAL_BYTES // (len(line) + 1)))
    start = time.perf_counter()
    try:
        outcome = f"{len(read_calls(path, {0: 'torque'}))} calls"
    except InvalidInput:
        outcome = "no call"
    return time.perf_counter() - start, outcome


def main() -> None:
    lengths = (MAX_LINE_CHARS // 8, MAX_LINE_CHARS // 2, MAX_LINE_CHARS - 1)
    print(f"| shape | {' | '.join(f'{n:,} characters a line' for n in lengths)} |")
    print("|---" * (len(lengths) + 1) + "|")
    with tempfile.TemporaryDirectory() as folder:
        for name, shape in SHAPES.items():
            cells = [read_seconds(shape(length), Path(folder)) for length in lengths]
            print(f"| {name} | {' | '.join(f'{seconds:.2f} s ({outcome})' for seconds, outcome in cells)} |")


if __name__ == "__main__":
    main()
