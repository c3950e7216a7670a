"""pendulum-fmu cross-check: the FMI cross-check layout, passed by fmpy's validator, with
reference results that fmpy reproduces from the input file alone and that agree with the reference.
"""

import shutil

import fmpy
import numpy as np
import pytest
from fmpy.cross_check.validate_vendor_repo import read_csv, validate_repo
from fmpy.util import read_ref_opt_file

from pendulum_fmu import __version__
from pendulum_fmu.cli import main
from pendulum_fmu.oracle._reference import reference
from pendulum_fmu.signals._torque_csv import read_torque_csv


@pytest.fixture(scope="module")
def repository(fmu, tmp_path_factory):
    root = tmp_path_factory.mktemp("cross_check")
    assert main(["cross-check", "--output-dir", str(root), "--fmu", str(fmu)]) == 0
    return root


def _model_dir(root, platform="linux64"):
    return root / "fmus/2.0/cs" / platform / "pendulum_fmu" / __version__ / "Pendulum"


def test_layout_has_every_file_under_one_megabyte(repository):
    folder = _model_dir(repository)
    names = {p.name for p in folder.iterdir()}
    assert names == {"Pendulum.fmu", "Pendulum_in.csv", "Pendulum_ref.csv", "Pendulum_ref.opt", "ReadMe.md"}
    assert all(p.stat().st_size < 1_000_000 for p in folder.iterdir())
    options = read_ref_opt_file(str(folder / "Pendulum_ref.opt"))
    assert (options["StartTime"], options["StopTime"], options["StepSize"]) == (0.0, 4.0, 1e-3)
    assert options["RelTol"] > 0


def test_reference_results_agree_with_fmpy_and_the_oracle_and_pass_fmpys_validator(repository, tmp_path):
    folder = _model_dir(repository)
    options = read_ref_opt_file(str(folder / "Pendulum_ref.opt"))
    inputs, expected = read_csv(str(folder / "Pendulum_in.csv")), read_csv(str(folder / "Pendulum_ref.csv"))
    assert len(set(inputs["torque"])) >= 3  # step-wise, not constant

    # fmpy, a master that shares no code with ours, from the files alone.
    by_fmpy = fmpy.simulate_fmu(
        str(folder / "Pendulum.fmu"),
        input=inputs,
        start_time=options["StartTime"],
        stop_time=options["StopTime"],
        step_size=options["StepSize"],
        output_interval=options["StepSize"],
        relative_tolerance=options["RelTol"],
        output=["theta", "omega"],
        record_events=False,
    )
    assert np.allclose(by_fmpy["time"], expected["time"], rtol=0, atol=1e-12)
    for name in ("theta", "omega"):
        assert np.array_equal(by_fmpy[name], expected[name])  # the same binary, the same steps

    # The reference holding, over each step, the input's value at the step's start.
    table = read_torque_csv(folder / "Pendulum_in.csv")
    oracle = reference(table.value_after, stop_time=options["StopTime"], step_size=options["StepSize"])
    assert np.max(np.abs(oracle["theta"] - expected["theta"])) < 1e-8

    # fmpy's validator over the repository, with fmpy's run filed as a passed cross-check result.
    result = repository / "results/2.0/cs/linux64/fmpy" / fmpy.__version__ / "pendulum_fmu" / __version__ / "Pendulum"
    result.mkdir(parents=True)
    fmpy.util.write_csv(str(result / "Pendulum_out.csv"), by_fmpy)
    (result / "passed").touch()
    fmu_count, result_count, problems = validate_repo(str(repository))
    assert problems == [] and result_count == 1 and fmu_count >= 1
    shutil.rmtree(repository / "results")


def test_an_output_folder_nothing_can_be_written_to_is_refused_before_the_run(fmu, capsys):
    """/proc/self: a folder in which nothing can be created; one line, exit 2, no reference computed."""
    assert main(["cross-check", "--output-dir", "/proc/self/out", "--fmu", str(fmu)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    assert "cannot write /proc/self/out/fmus/2.0/cs/" in err and "the folder /proc/self/out cannot be created" in err
