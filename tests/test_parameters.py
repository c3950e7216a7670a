"""One validation: every tool refuses a parameter set the FMU refuses, with the FMU's own words.

The physical checks live once, in the FMU's model.c; simulate.resolve_parameters asks the FMU,
and the reference, OpenSim and the engines all go through it.
"""

import importlib.util
import re
import zipfile

import numpy as np
import pytest
from bad_inputs import write_files

from pendulum_fmu.comparing._compare_tools import KINDS, parse_tools
from pendulum_fmu.fmu._cross_check import write_cross_check
from pendulum_fmu.fmu._model import FmuFileError
from pendulum_fmu.fmu._parameters import default_parameters, model_description
from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.oracle._reference import reference
from pendulum_fmu.signals._torque_schedule import schedule

BAD = [
    ({"mass": 0.0}, "mass must be > 0"),
    ({"mass": -40.0}, "mass must be > 0"),
    ({"length": -0.5}, "length must be >= 0"),
    ({"inertia": -1.0}, "inertia must be >= 0"),
    ({"damping": -2.0}, "damping must be >= 0"),
    ({"length": 0.0, "inertia": 0.0}, "inertia + mass*length^2 (the inertia about the pivot) must be > 0 and finite"),
]
PLAN = schedule(20.0, stop_time=0.01, step_size=1e-3)
TOOLS = [name for name, kind in KINDS.items() if kind.package is None or importlib.util.find_spec(kind.package)]


@pytest.mark.parametrize("parameters, reason", BAD, ids=[str(p) for p, _ in BAD])
def test_every_path_refuses_with_the_fmus_words(fmu, parameters, reason):
    expected = f"the FMU refuses the parameters: {reason}"
    messages = set()
    for run in (
        lambda: simulate(20.0, stop_time=0.01, parameters=parameters, fmu_path=fmu),
        lambda: reference(20.0, stop_time=0.01, parameters=parameters, fmu_path=fmu),
        *(lambda tool=tool: tool.run(PLAN, parameters=parameters) for tool in parse_tools(TOOLS, fmu_path=fmu)),
    ):
        with pytest.raises(ValueError) as refused:
            run()
        messages.add(str(refused.value))
    assert messages == {expected}


def test_an_accepted_set_runs_everywhere(fmu):
    parameters = {"mass": 2.0, "length": 0.0, "inertia": 0.1, "gravity": 0.0}
    run = simulate(20.0, stop_time=0.01, parameters=parameters, fmu_path=fmu)
    assert np.allclose(run["alpha"], 20.0 / 0.1, rtol=1e-14)
    assert np.allclose(reference(20.0, stop_time=0.01, parameters=parameters)["alpha"], 200.0, rtol=1e-14)


NOT_RUNNABLE = [
    ("one_row.csv", "is not an FMU (an FMU is a zip archive with a modelDescription.xml)"),
    ("empty.fmu", "the zip archive has no modelDescription.xml (it is empty)"),
    ("no_model_description.fmu", "the zip archive has no modelDescription.xml"),
    ("fmi1.fmu", "is an FMI 1.0 FMU; this package runs FMI 2.0 and 3.0 FMUs"),
    ("spring.fmu", "is not a pendulum FMU: it has no variable torque, theta, omega, alpha"),
    ("no_binary.fmu", "has no binary for this platform (binaries/linux64/Pendulum.so)"),
]


@pytest.fixture(scope="module")
def not_runnable(fmu, tmp_path_factory):
    """The files of tests/bad_inputs.py, and the pendulum's FMU without its binaries."""
    folder = tmp_path_factory.mktemp("not_fmus")
    write_files(folder)
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(folder / "no_binary.fmu", "w") as target:
        for item in source.infolist():
            if not item.filename.startswith("binaries/"):
                target.writestr(item, source.read(item))
    return folder


@pytest.mark.parametrize("name, reason", NOT_RUNNABLE, ids=[name for name, _ in NOT_RUNNABLE])
def test_a_file_that_is_no_pendulum_fmu_is_refused_by_every_entry_point(not_runnable, tmp_path, name, reason):
    path = not_runnable / name
    for run in (
        lambda: default_parameters(path),
        lambda: simulate(20.0, stop_time=0.01, fmu_path=path),
        lambda: reference(20.0, stop_time=0.01, fmu_path=path),
        lambda: write_cross_check(tmp_path / "cross_check", path),
    ):
        with pytest.raises(FmuFileError, match=f"^{re.escape(str(path))}.*{re.escape(reason)}"):
            run()
    assert not (tmp_path / "cross_check").exists()


def test_an_fmu_of_another_model_is_read_for_compare_s_own_map(not_runnable):
    """Compare --tools LABEL=path runs any FMI 2.0/3.0 model through a map: its description reads."""
    assert model_description(not_runnable / "spring.fmu").modelName == "Spring"
