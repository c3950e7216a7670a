"""What the readers of a received file find in it is what they found before its bounds (issue 38):
the master's-log reader, rewritten to take time linear in a line's length, finds the calls the
regular expressions it replaced found; the whole-file and line-by-line checks name the same line.
The refusals themselves are in tests/bad_inputs.py's table.
"""

import io
import random
import re

import pytest

from pendulum_fmu._received_files import bounded_lines, check_lines
from pendulum_fmu.judging._call_record import _ARGUMENT, _master_call_parts

# What _call_record.py searched a master's log with before: the reference.
BACKTRACKING_CALL = re.compile(r"(?P<function>fmi[23][A-Z]\w+)\((?P<arguments>.*)\)(?:\s*->\s*(?P<result>\S+))?\s*$")
BACKTRACKING_ARGUMENT = re.compile(r'(\w+)=(\[[^\]]*\]|\{[^}]*\}|"[^"]*"|[^,]*)')

PIECES = ["fmi2", "fmi3", "A", "Do", "b", "(", ")", "->", "-", ">", " ", "\t", "x", "_", "=", ",", '"', "[", "]", "{"]
CALL_ENDS = [")", ") -> OK", ")->x", ") ->  ", ")-> a b", "", ") -> fmi2OK ", "))->y"]


def _lines(count: int):
    """Lines of pieces of calls, half of them shaped as one (a name, a parenthesis, an end)."""
    rng = random.Random(38)

    def pieces(most):
        return "".join(rng.choice(PIECES) for _ in range(rng.randint(0, most)))

    for number in range(count):
        if number % 2:
            yield pieces(14)
        else:
            name = rng.choice(["fmi2DoStep", "fmi3SetFloat64", "xfmi2Ab", "fmi2A", "c=fmi2Set"])
            yield pieces(3) + name + "(" + pieces(6) + rng.choice(CALL_ENDS) + pieces(3) + rng.choice(CALL_ENDS)


REAL_LINES = [
    "fmi2SetReal(c=0x55d0, vr=[0], nvr=1, value=[20.0]) -> OK",
    "fmi2SetReal(vr={0}, nvr=1, value={20}) -> OK",
    'fmi2Instantiate(instanceName="pendulum", fmuType=1, fmuGUID="{5b8e}") -> 0x55d0',
    "[fmpy] fmi2DoStep(c=0x55d0, currentCommunicationPoint=0.001, communicationStepSize=0.001, noSetFMUStatePriorToCurrentPoint=1) -> OK",  # noqa: E501
    "fmi3DoStep(instance=0x1, currentCommunicationPoint=0, communicationStepSize=0.001) -> fmi3OK  ",
]


def _found(line: str):
    found = BACKTRACKING_CALL.search(line)
    return found and {"function": found["function"], "arguments": found["arguments"], "result": found["result"]}


def test_the_linear_reader_finds_what_the_regular_expressions_found():
    lines = [*REAL_LINES, *_lines(200_000)]
    differing = [line for line in lines if _master_call_parts(line) != (_found(line) or None)]
    assert differing == []
    assert [line for line in lines if _ARGUMENT.findall(line) != BACKTRACKING_ARGUMENT.findall(line)] == []
    # Else the comparison would hold for a reader that finds nothing.
    assert sum(_found(line) is not None for line in lines) > 50_000
    assert all(_master_call_parts(line) for line in REAL_LINES)


@pytest.mark.parametrize(
    ("text", "fault"),
    [
        ("a\nbbbbbbbbbb\n\0\n", "2: the line is longer than 8"),
        ("a\n\0\nbbbbbbbbbb\n", "2: a NUL byte"),
        ("a\r\nbbbbbbbb\r\nc", None),  # 8 characters and a Windows line end
        ("a\nbbbbbbbbb", "2: the line is longer than 8"),  # the last line, with no line end
    ],
)
def test_both_checks_name_the_first_faulty_line(text, fault):
    def checked_whole():
        check_lines(text.encode(), "f.csv", ValueError, "fix it", bound=8)

    def checked_by_line():
        list(bounded_lines(io.StringIO(text, newline=""), "f.csv", ValueError, "fix it", bound=8))

    for check in (checked_whole, checked_by_line):
        if fault is None:
            check()
        else:
            with pytest.raises(ValueError, match=f"^f.csv:{fault}"):
                check()
