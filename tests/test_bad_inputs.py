"""Every bad input of tests/bad_inputs.py gets its exit code and one clear line, no traceback, on
the command line, and its PendulumFmuError with a one-line message in the Python API;
docs/bad_inputs.md is what the cases give.
"""

from pathlib import Path

import pytest
from bad_inputs import CALLS, CASES, markdown, raised, run_call, run_case, write_files

from pendulum_fmu import _errors as errors

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    write_files(folder)
    return folder


def _nothing_written(files):
    assert not (files / "out").exists() or not any((files / "out").iterdir())
    assert not (files / "loop.fmu").exists()
    assert [p.name for p in (files / "not_a_study").iterdir()] == ["study.json"]
    # Refused kits and demos are left as they were, with no staging folder in them.
    assert [p.name for p in (files / "old_kit").iterdir()] == ["ReadMe.md"]
    assert (files / "old_kit" / "ReadMe.md").read_text() == "my notes\n"
    assert [p.name for p in (files / "old_demo").iterdir()] == ["gravity_effect.png"]


@pytest.mark.parametrize("case", CASES, ids=[" ".join(c.argv) for c in CASES])
def test_bad_input(files, case):
    code, printed = run_case(case, files)
    assert code == case.exit_code, printed
    assert "Traceback" not in printed
    lines = printed.strip().splitlines()
    assert case.message in lines[-1]
    # One line of our own; argparse's refusals put its usage lines before it.
    assert len(lines) == 1 or lines[0].startswith("usage:")
    _nothing_written(files)


@pytest.mark.parametrize("call", CALLS, ids=[c.code for c in CALLS])
def test_bad_call_in_python(files, call):
    error = run_call(call, files)
    # Ours, not numpy's, scipy's or fmpy's: a PendulumFmuError of the kind the table names.
    assert isinstance(error, errors.PendulumFmuError), repr(error)
    name, message = raised(error, files)
    assert name == call.error and call.message in message, repr(error)
    assert "\n" not in message
    _nothing_written(files)


def test_the_documented_table_is_what_the_cases_give(files):
    rows = [(case, *run_case(case, files)) for case in CASES]
    calls = [(call, *raised(run_call(call, files), files)) for call in CALLS]
    documented = (ROOT / "docs" / "bad_inputs.md").read_text()
    assert documented == markdown(rows, calls), "regenerate: python tests/bad_inputs.py docs/bad_inputs.md"


@pytest.mark.docs
def test_the_generator_documents_the_clone_whatever_package_is_installed(generated_by_script):
    assert generated_by_script("bad_inputs.py") == (ROOT / "docs" / "bad_inputs.md").read_text()
