"""One validation: every tool refuses a parameter set the FMU refuses, with the FMU's own words.

The physical checks live once, in the FMU's model.c; simulate.resolve_parameters asks the FMU,
and the scipy reference, OpenSim and the engines all go through it."""

import importlib.util

import numpy as np
import pytest

from pendulum_fmu.compare_tools import KINDS, parse_tools
from pendulum_fmu.reference import reference
from pendulum_fmu.simulate import simulate
from pendulum_fmu.torque_schedule import schedule

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
    for run in (lambda: simulate(20.0, stop_time=0.01, parameters=parameters, fmu_path=fmu),
                lambda: reference(20.0, stop_time=0.01, parameters=parameters, fmu_path=fmu),
                *(lambda tool=tool: tool.run(PLAN, parameters=parameters)
                  for tool in parse_tools(TOOLS, fmu_path=fmu))):
        with pytest.raises(ValueError) as refused:
            run()
        messages.add(str(refused.value))
    assert messages == {expected}


def test_an_accepted_set_runs_everywhere(fmu):
    parameters = {"mass": 2.0, "length": 0.0, "inertia": 0.1, "gravity": 0.0}
    run = simulate(20.0, stop_time=0.01, parameters=parameters, fmu_path=fmu)
    assert np.allclose(run["alpha"], 20.0 / 0.1, rtol=1e-14)
    assert np.allclose(reference(20.0, stop_time=0.01, parameters=parameters)["alpha"], 200.0, rtol=1e-14)
