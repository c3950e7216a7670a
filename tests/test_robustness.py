"""Every bad call of tests/bad_calls.py gets its status and message, and the instance survives:
the FMI 2.0 cases on the FMI 2.0 binary, the FMI 3.0 cases on the FMI 3.0 binary.
"""

import zipfile

import pytest
from bad_calls import CASES, CASES_FMI3, Harness, Harness3, markdown, run_case, status_name
from fmpy import read_model_description

from fmu_build import ROOT


def _harness(fmu, folder, kind, platform):
    zipfile.ZipFile(fmu).extractall(folder)
    return kind(folder / f"binaries/{platform}/Pendulum.so", read_model_description(str(fmu)).guid)


@pytest.fixture(scope="module")
def harness(fmu, tmp_path_factory):
    harness = _harness(fmu, tmp_path_factory.mktemp("unzipped"), Harness, "linux64")
    yield harness
    harness.close()


@pytest.fixture(scope="module")
def harness3(fmu3, tmp_path_factory):
    harness = _harness(fmu3, tmp_path_factory.mktemp("unzipped3"), Harness3, "x86_64-linux")
    yield harness
    harness.close()


def _check(harness, case):
    status, message = run_case(harness, case)
    if "Instantiate" in case.call:
        assert status == 0, f"{case.call} must return NULL"
    else:
        assert status_name(case.call, status) == status_name(case.call, case.expected_status)
    assert case.expected_message in message


@pytest.mark.parametrize("case", CASES, ids=[f"{c.group}: {c.bad_input}" for c in CASES])
def test_bad_call(harness, case):
    _check(harness, case)


@pytest.mark.parametrize("case", CASES_FMI3, ids=[f"{c.group}: {c.bad_input}" for c in CASES_FMI3])
def test_bad_call_fmi3(harness3, case):
    _check(harness3, case)


def test_the_documented_table_is_what_the_cases_give(harness, harness3):
    rows = [(case, *run_case(harness, case)) for case in CASES]
    rows_fmi3 = [(case, *run_case(harness3, case)) for case in CASES_FMI3]
    documented = (ROOT / "docs" / "robustness.md").read_text()
    assert documented == markdown(rows, rows_fmi3), "regenerate: python tests/bad_calls.py docs/robustness.md"


@pytest.mark.docs
def test_the_generator_documents_the_clone_whatever_package_is_installed(generated_by_script):
    # The README says either set-up serves to run it; the main job's installs the package.
    assert generated_by_script("bad_calls.py") == (ROOT / "docs" / "robustness.md").read_text()
