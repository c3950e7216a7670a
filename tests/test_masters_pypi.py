"""Masters from the package index that nobody here wrote: each driven the way it works, its result
judged against the reference, and each one's pitfall reproduced and named by the judge
(docs/masters.md, "Masters from the package index").

Only ecospy fits the package's environment, and the test set-up brings it. The others are skipped
where missing (docs/masters.md says how to get each): fmugym and gemseo-fmu pin gymnasium below
0.30 and fmpy below 0.3.28, and run here on the package's newer ones; fmipp builds from source;
cofmupy fails on a newer fmpy, so it runs in its own environment, whose python COFMUPY_PYTHON
names.
"""

import importlib
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pendulum_fmu import judge
from pendulum_fmu.judging._diagnoses import DRIFT, EARLY, SHIFTED, SINGLE

pytestmark = pytest.mark.masters

STEP, STEPS = 1e-3, 2000  # 2 s of 1 ms communication steps
SWITCH = 1000  # the step from which the torque is -20 N.m, 20 N.m before it


def torque(t: float) -> float:
    """The run's signal: 20 N.m, from 1 s on -20 N.m."""
    return 20.0 if t < SWITCH * STEP else -20.0


def master(name: str, why: str):
    """The master's module, or a skip that says how to get it (ecospy's library also needs libtbb)."""
    try:
        return importlib.import_module(name)
    except ImportError:
        pytest.skip(f"{name} not installed: {why}")
    except OSError as error:  # ecospy loads its C++ library on import
        pytest.skip(f"{name} cannot load its library ({error}): apt-get install libtbb12")


def judged(times, theta, fmu, signal=torque):
    """The judgement of a master's times and theta as a run of the signal on this FMU."""
    result = np.rec.fromarrays([np.asarray(times, float), np.asarray(theta, float)], names="time,theta")
    return judge(result, signal, stop_time=STEPS * STEP, step_size=STEP, fmu_path=fmu)


@pytest.fixture(params=["fmi2", "fmi3"])
def either_fmu(request, fmu, fmu3):
    return {"fmi2": fmu, "fmi3": fmu3}[request.param]


# --- ECOS (ecospy) ------------------------------------------------------------------------------


def ecos_run(fmu, scenario=None):
    """ECOS steps the FMU; with no scenario the torque is set before each step. Returns times, theta."""
    ecospy = master("ecospy", "pip install -e '.[test]'")
    with ecospy.EcosSimulationStructure() as structure:
        structure.add_model("pendulum", str(fmu))
        with ecospy.EcosSimulation(structure=structure, step_size=STEP) as simulation:
            if scenario:
                scenario(simulation)
            simulation.init()
            times, theta = [0.0], [simulation.get_real("pendulum::theta")]
            for k in range(STEPS):
                if not scenario:
                    simulation.set_real("pendulum::torque", torque(k * STEP))
                times.append(simulation.step())
                theta.append(simulation.get_real("pendulum::theta"))
    return times, theta


def test_ecos_setting_the_torque_each_step_agrees(either_fmu):
    judgement = judged(*ecos_run(either_fmu), either_fmu)
    # ECOS sums its clock (1.9999999999998905 s at the end): the reference at those times.
    assert judgement.passed and judgement.max_abs_dtheta < 1e-12


def ecos_actions(simulation):
    simulation.add_scenario(real_actions=[(0.0, "pendulum::torque", 20.0), (1.0, "pendulum::torque", -20.0)])


def ecos_actions_with_tolerance(simulation):
    """The actions through ECOS's C function with its fifth argument, the time tolerance, which
    ecospy's add_scenario leaves out: so called, the actions fire.
    """
    from ctypes import c_bool, c_char_p, c_double, c_void_p

    from ecospy.lib import dll

    dll.ecos_scenario_create.restype = c_void_p
    scenario = dll.ecos_scenario_create()
    add = dll.ecos_scenario_add_real_action
    add.argtypes, add.restype = [c_void_p, c_double, c_char_p, c_double, c_double], c_bool
    for time, value in ((0.0, 20.0), (1.0, -20.0)):
        assert add(scenario, time, b"pendulum::torque", value, 1e-9)
    simulation._add_listener(simulation.sim, b"scenario", scenario)


def test_ecos_scenario_never_switches_the_torque(fmu):
    # ECOS's summed clock reads 1.0000000000000007 s where the action is at 1 s: no time equals it.
    times, theta = ecos_run(fmu, ecos_actions)
    judgement = judged(times, theta, fmu)
    assert judgement.diagnosis == DRIFT and judgement.residual < 1e-12 < 0.3 < judgement.max_abs_dtheta
    # The torque stayed at its first action's 20 N.m: the run of that constant agrees.
    assert judged(times, theta, fmu, signal=20.0).max_abs_dtheta < 1e-12
    assert judged(*ecos_run(fmu, ecos_actions_with_tolerance), fmu).passed


# --- fmugym ---------------------------------------------------------------------------------------


def fmugym_run(fmu):
    """An fmugym environment steps the FMU; returns times, theta read from the FMU in float64 and
    the observations fmugym hands out.
    """
    fmugym = master("fmugym", "pip install --no-deps fmugym==0.2.0 (docs/masters.md)")

    class Pendulum(fmugym.FMUGym):
        def __init__(self, config):
            self.init_states = {}  # fmugym's _noisy_init fills this dict, which its base class never makes
            super().__init__(config)

        def compute_reward(self, *args, **kwargs):
            return 0.0

    inputs, outputs = fmugym.VarSpace("inputs"), fmugym.VarSpace("outputs")
    inputs.add_var_box("torque", -50.0, 50.0)
    outputs.add_var_box("theta", -10.0, 10.0)
    config = fmugym.FMUGymConfig(
        fmu_path=str(fmu),
        stop_time=STEPS * STEP,
        sim_step_size=STEP,
        action_step_size=STEP,
        inputs=inputs,
        outputs=outputs,
        random_vars=fmugym.VarSpace("random_vars"),
    )
    env = Pendulum(config)
    observation, _ = env.reset()
    read = env.fmu.getFloat64 if env.is_fmi3 else env.fmu.getReal
    vr = env.output_dict["theta"]
    times, theta, observed = [0.0], [read([vr])[0]], [float(observation[0])]
    for k in range(STEPS):
        observation, *_ = env.step(np.array([torque(k * STEP)]))
        times.append(env.time)
        theta.append(read([vr])[0])
        observed.append(float(observation[0]))
    env.close()
    return times, theta, observed


def test_fmugym_theta_read_in_float64_agrees_observations_are_single_precision(either_fmu):
    times, theta, observed = fmugym_run(either_fmu)
    assert judged(times, theta, either_fmu).max_abs_dtheta < 1e-12
    judgement = judged(times, observed, either_fmu)
    assert judgement.diagnosis == SINGLE and judgement.residual == 0.0
    assert 5e-9 < judgement.max_abs_dtheta < 3e-8  # half a float32 ulp at |theta| up to 0.4 rad


# --- FMI++ (fmipp) ---------------------------------------------------------------------------------


def fmipp_run(fmu, tmp_path, master_times):
    """FMI++'s FixedStepSizeFMU synced at the master's times (accumulated t + h, or k * h); sync
    steps to its t1, then sets the inputs for the next step. Returns times and theta.
    """
    fmipp = master("fmipp", "fmipp==2.1.0 builds from source (docs/masters.md)")
    instance = fmipp.FixedStepSizeFMU(fmipp.extractFMU(str(fmu), str(tmp_path)), "Pendulum")
    names = {}
    for direction, name in (("in", "torque"), ("out", "theta")):
        names[direction] = fmipp.new_string_array(1)
        fmipp.string_array_setitem(names[direction], 0, name)
    instance.defineRealInputs(names["in"], 1)
    instance.defineRealOutputs(names["out"], 1)
    assert instance.init("pendulum", fmipp.new_string_array(0), fmipp.new_double_array(0), 0, 0.0, STEP) == 1
    inputs = fmipp.new_double_array(1)
    fmipp.double_array_setitem(inputs, 0, torque(0.0))
    instance.sync(0.0, 0.0, inputs, None, None, None)
    times, theta = [0.0], [0.0]
    for k in range(STEPS):
        t = master_times(times[-1], k + 1)
        fmipp.double_array_setitem(inputs, 0, torque(t))
        instance.sync(times[-1], t, inputs, None, None, None)
        times.append(t)
        theta.append(fmipp.double_array_getitem(instance.getRealOutputs(), 0))
    return times, theta


def test_fmipp_synced_at_accumulated_times_agrees(either_fmu, tmp_path):
    times, theta = fmipp_run(either_fmu, tmp_path, lambda before, k: before + STEP)
    assert judged(times, theta, either_fmu).max_abs_dtheta < 1e-12


def test_fmipp_synced_at_grid_times_skips_a_step_and_takes_two_later(fmu, tmp_path):
    # sync compares t1 with its own summed clock plus a step without a tolerance: 0.01 falls
    # short of 0.009000000000000001 + 0.001, so the FMU lags a step until 1.005 takes two.
    judgement = judged(*fmipp_run(fmu, tmp_path, lambda before, k: k * STEP), fmu)
    assert judgement.diagnosis == DRIFT and judgement.residual < 1e-12 < 5e-4 < judgement.max_abs_dtheta


# --- cofmupy ----------------------------------------------------------------------------------------


def cofmupy_run(fmu, how, tmp_path):
    """The result file tests/cofmupy_master.py writes, run by the python COFMUPY_PYTHON names."""
    python = os.environ.get("COFMUPY_PYTHON")
    if not python:
        pytest.skip("cofmupy pins fmpy 0.3.20: set COFMUPY_PYTHON to a venv's python with cofmupy==1.0.0")
    out = tmp_path / f"cofmupy_{how}.csv"
    subprocess.run([python, str(Path(__file__).with_name("cofmupy_master.py")), str(fmu), how, str(out)], check=True)
    return out


def test_cofmupy_setting_the_torque_each_step_agrees(either_fmu, tmp_path):
    judgement = judge(cofmupy_run(either_fmu, "setter", tmp_path), torque, stop_time=STEPS * STEP, fmu_path=either_fmu)
    assert judgement.max_abs_dtheta < 1e-12


def test_cofmupy_results_table_files_each_step_under_its_start(fmu, tmp_path):
    table = cofmupy_run(fmu, "table", tmp_path)
    # Its clock is a sum, 1.9999999999998905 s after 2,000 steps, under the end time: one more step.
    assert len(table.read_text().splitlines()) == 1 + STEPS + 1
    judgement = judge(table, 20.0, stop_time=STEPS * STEP, mapping="theta=pendulum.theta", fmu_path=fmu)
    assert judgement.diagnosis == SHIFTED and judgement.residual < 1e-12
    assert judgement.max_abs_dtheta > 2e-4


# --- gemseo-fmu -------------------------------------------------------------------------------------


def gemseo_discipline(fmu, whole_run=False):
    """A discipline of the torque in and theta out: named, since by default gemseo-fmu takes every
    input and parameter, calls float() on the String parameter callRecordFile's start value (FMI
    2.0), and sets the fixed parameters before every step, which the FMU refuses.
    """
    master("gemseo_fmu", "a venv of gemseo-fmu==3.1.1 beside the package's (docs/masters.md)")
    from gemseo_fmu.disciplines.do_step_fmu_discipline import DoStepFMUDiscipline
    from gemseo_fmu.disciplines.fmu_discipline import FMUDiscipline

    kind = FMUDiscipline if whole_run else DoStepFMUDiscipline
    return kind(str(fmu), input_names=["torque"], output_names=["theta"], time_step=STEP, final_time=STEPS * STEP)


def gemseo_steps(discipline, per_step):
    """One execute a step, each given per_step(k); returns times and theta (the first: the start)."""
    times, theta = [0.0], [0.0]
    for k in range(STEPS):
        out = discipline.execute({"torque": per_step(k)})
        times.append(float(out["Pendulum_time"][0]))
        theta.append(float(out["theta"][0]))
    return times, theta


def test_gemseo_one_execute_a_step_or_the_signal_over_the_run_agrees(either_fmu):
    times, theta = gemseo_steps(gemseo_discipline(either_fmu), lambda k: np.array([torque(k * STEP)]))
    assert judged(times, theta, either_fmu).max_abs_dtheta < 1e-12
    out = gemseo_discipline(either_fmu, whole_run=True).execute({"torque": torque})
    assert judged(out["Pendulum_time"], out["theta"], either_fmu).max_abs_dtheta < 1e-12


def test_gemseo_signal_given_each_step_is_sampled_at_its_end(fmu):
    judgement = judged(*gemseo_steps(gemseo_discipline(fmu), lambda k: torque), fmu)
    assert judgement.diagnosis == EARLY and judgement.residual < 1e-12 < 5e-4 < judgement.max_abs_dtheta


def test_gemseo_by_default_fails_on_the_string_parameter(fmu):
    master("gemseo_fmu", "a venv of gemseo-fmu==3.1.1 beside the package's (docs/masters.md)")
    from gemseo_fmu.disciplines.do_step_fmu_discipline import DoStepFMUDiscipline

    with pytest.raises(ValueError, match="could not convert string to float: ''"):
        DoStepFMUDiscipline(str(fmu), time_step=STEP, final_time=STEPS * STEP)
