"""Every bad call of tests/bad_calls.py gets its status and message, and the instance survives."""

import zipfile

import pytest
from fmpy import read_model_description

from bad_calls import CASES, STATUS_NAMES, Harness, markdown, run_case
from pendulum_fmu.build import ROOT


@pytest.fixture(scope="module")
def harness(fmu, tmp_path_factory):
    folder = tmp_path_factory.mktemp("unzipped")
    zipfile.ZipFile(fmu).extractall(folder)
    harness = Harness(folder / "binaries/linux64/Pendulum.so", read_model_description(str(fmu)).guid)
    yield harness
    harness.close()


@pytest.mark.parametrize("case", CASES, ids=[f"{c.group}: {c.bad_input}" for c in CASES])
def test_bad_call(harness, case):
    status, message = run_case(harness, case)
    if case.call == "fmi2Instantiate":
        assert status == 0, "fmi2Instantiate must return NULL"
    else:
        assert STATUS_NAMES[status] == STATUS_NAMES[case.expected_status]
    assert case.expected_message in message


def test_the_documented_table_is_what_the_cases_give(harness):
    rows = [(case, *run_case(harness, case)) for case in CASES]
    documented = (ROOT / "docs" / "robustness.md").read_text()
    assert documented == markdown(rows), "regenerate: python tests/bad_calls.py docs/robustness.md"
