"""Every bad input of tests/bad_inputs.py gets its exit code and one clear line, no traceback;
docs/bad_inputs.md is what the cases give."""

from pathlib import Path

import pytest

from bad_inputs import CASES, markdown, run_case, write_files

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    write_files(folder)
    return folder


@pytest.mark.parametrize("case", CASES, ids=[" ".join(c.argv) for c in CASES])
def test_bad_input(files, case):
    code, printed = run_case(case, files)
    assert code == case.exit_code, printed
    assert "Traceback" not in printed
    lines = printed.strip().splitlines()
    assert case.message in lines[-1]
    # One line of our own; argparse's refusals put its usage lines before it.
    assert len(lines) == 1 or lines[0].startswith("usage:")
    assert not (files / "out").exists() or not any((files / "out").iterdir())


def test_the_documented_table_is_what_the_cases_give(files):
    rows = [(case, *run_case(case, files)) for case in CASES]
    documented = (ROOT / "docs" / "bad_inputs.md").read_text()
    assert documented == markdown(rows), "regenerate: python tests/bad_inputs.py docs/bad_inputs.md"
