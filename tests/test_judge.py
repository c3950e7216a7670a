"""The judge: deliberately wrong masters (benchmarks/masters.py) and fmpy's own solvers run the
kit's scenarios, each mistake must be diagnosed as made; results from the analytic solution under
other names and units; the command's exit codes, JSON and figure; bad result files.
"""

import json
import re

import numpy as np
import pytest

from benchmarks.masters import WRONG_MASTERS, run
from pendulum_fmu.cli import main
from pendulum_fmu.figures._plot import _log_difference
from pendulum_fmu.fmu._parameters import total_inertia
from pendulum_fmu.judging._diagnoses import (
    AGREES,
    DRIFT,
    EARLY,
    EXPLAINS,
    EXPLICIT_EULER,
    HELD,
    INTEGRATION,
    INTEGRATION_SMALL,
    INTERPOLATED,
    LATE,
    NOT_RESTORED,
    SHIFTED,
    SINGLE,
    UNEXPLAINED,
)
from pendulum_fmu.judging._judge import judge
from pendulum_fmu.judging._result_file import ResultFileError, read_result
from pendulum_fmu.scenarios._scenario_settings import KIT_FMU, read_settings
from pendulum_fmu.scenarios._scenarios import write_scenarios


@pytest.fixture(scope="module")
def kit(tmp_path_factory, fmu):
    folder = tmp_path_factory.mktemp("kit")
    write_scenarios(folder, fmu)
    return folder


def _judged(kit, name, **changes):
    settings = {**read_settings(kit / f"{name}.json"), **changes}
    return judge(kit / settings.pop("output"), **settings)


@pytest.mark.parametrize(("name", "mistake", "expected"), WRONG_MASTERS, ids=[f"{n}-{m}" for n, m, _ in WRONG_MASTERS])
def test_a_wrong_master_is_diagnosed_as_made(kit, name, mistake, expected):
    run(kit, name, mistake)
    judgement = _judged(kit, name)
    raw = judgement.max_abs_dtheta
    # float32 outputs lose half a float32 ulp of theta: 6e-8 rad at 1 rad
    assert judgement.verdict == "fail" and raw > (1e-9 if expected == SINGLE else 1e-7)
    assert judgement.diagnosis == expected, judgement.candidates
    residuals = {n: s["residual"] for n, s in judgement.candidates.items() if s is not None}
    if expected in (INTEGRATION, UNEXPLAINED) and mistake != "euler":
        # No variant comes near: every one leaves more than a tenth of the difference.
        assert min(residuals.values()) > 0.1 * raw
        if expected == INTEGRATION:  # the bound: below Euler's error, far below the input mistakes'
            assert raw <= judgement.candidates[INTEGRATION]["effect"]
            assert raw < INTEGRATION_SMALL / 5 * judgement.smallest_input_effect
        return
    # The mistake made leaves rounding only; every other candidate a decade above the threshold.
    assert judgement.residual == residuals[expected] < EXPLAINS / 100 * raw
    assert all(r > 10 * EXPLAINS * raw for n, r in residuals.items() if n != expected)


def test_the_diagnosed_variant_holds_at_fewer_points_than_steps(kit):
    """A master writing every 10th communication point only: still one step late."""
    out = run(kit, "random_steps", "late")
    lines = out.read_text().splitlines()
    out.write_text("\n".join(lines[:1] + lines[1::10]) + "\n")
    judgement = _judged(kit, "random_steps")
    assert judgement.diagnosis == LATE and judgement.points == 401
    assert judgement.residual < 1e-10


def test_the_analytic_parabola_passes_under_other_names_and_units(tmp_path):
    """Gravity off: theta = tau t^2 / (2 I); written in ms and degrees, read through --map."""
    t = np.linspace(0, 3, 301)
    theta = 20.0 / (2 * total_inertia({"mass": 40.0, "length": 0.5, "inertia": 20.0})) * t**2
    result = tmp_path / "theirs.csv"
    np.savetxt(
        result,
        np.column_stack([t * 1000, np.degrees(theta)]),
        delimiter=",",
        header="t_ms,phi_deg",
        comments="",
        fmt="%.17g",
    )
    mapping = "time=t_ms*0.001,theta=phi_deg*0.017453292519943295"
    judgement = judge(result, 20.0, step_size=0.01, parameters={"gravity": 0.0}, mapping=mapping)
    assert judgement.passed and judgement.diagnosis == AGREES and judgement.max_abs_dtheta < 1e-12
    # Late by one 10 ms step from the FMU's start value 0 N.m: theta = tau (t - h)^2 / (2 I).
    late = 20.0 / (2 * 30.0) * np.maximum(t - 0.01, 0) ** 2
    np.savetxt(result, np.column_stack([t, late]), delimiter=",", header="time,theta", comments="", fmt="%.17g")
    judgement = judge(result, 20.0, step_size=0.01, parameters={"gravity": 0.0})
    assert judgement.diagnosis == LATE and judgement.residual < 1e-12
    assert judgement.max_abs_dtheta == pytest.approx(20.0 / 60.0 * 0.01 * (2 * 3 - 0.01), rel=1e-9)


def test_the_command_exits_0_on_pass_and_1_on_fail_and_writes_json_and_plot(kit, tmp_path, capsys):
    run(kit, "decimal_steps", "late")
    arguments = [
        "judge",
        str(kit / "decimal_steps_out.csv"),
        "--torque-file",
        str(kit / "decimal_steps_in.csv"),
        "--step-size",
        "0.009",
        "--json",
        str(tmp_path / "j.json"),
        "--plot",
        str(tmp_path / "j.png"),
    ]
    assert main(arguments) == 1
    out = capsys.readouterr().out
    assert out.startswith(f"{kit / 'decimal_steps_out.csv'}: fail: {LATE} (residual ")
    summary = json.loads((tmp_path / "j.json").read_text())
    assert summary["verdict"] == "fail" and summary["diagnosis"] == LATE
    assert summary["residual"] < 1e-10 < summary["max_abs_dtheta"]
    out = np.genfromtxt(kit / "decimal_steps_out.csv", delimiter=",", names=True)
    ref = np.genfromtxt(kit / "decimal_steps_ref.csv", delimiter=",", names=True)
    worst = np.argmax(np.abs(out["theta"] - ref["theta"]))
    assert summary["worst_time"] == out["time"][worst] and summary["candidates"][HELD] is None
    assert summary["max_abs_dtheta"] == pytest.approx(abs(out["theta"] - ref["theta"])[worst], rel=1e-6)
    assert set(summary["candidates"]) == {
        LATE, EARLY, INTERPOLATED, HELD, DRIFT, SHIFTED, NOT_RESTORED, SINGLE, INTEGRATION
    }  # fmt: skip
    assert (tmp_path / "j.png").read_bytes()[:4] == b"\x89PNG"
    run(kit, "decimal_steps")
    assert main([*arguments, "--tol", "1e-9"]) == 0
    assert f"pass: {AGREES}" in capsys.readouterr().out
    assert not list(tmp_path.glob(".*"))


def test_exact_zeros_are_said_not_drawn():
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    assert _log_difference(ax, np.arange(4.0), np.array([0.0, 1e-12, 0.0, 2e-12]), "d") == 2
    assert _log_difference(ax, np.arange(4.0), np.zeros(4), "zero") == 4
    assert [line.get_label() for line in ax.get_lines()] == ["d"]
    plt.close(fig)


def test_bad_result_files_get_one_line(tmp_path):
    cases = {
        "time,theta\n0,0\n0.002,0\n0.001,0\n": "bad.csv:4: time 0.001 goes backwards (previous row: 0.002)",
        "t,theta\n0,0\n": "bad.csv:1: no column 'time' (header is t,theta)",
        "time,theta\n0,x\n": "bad.csv:2: theta 'x' is not a number",
        "time,theta\n0,nan\n": "bad.csv:2: theta is nan; values must be finite",
        "time,theta\n": "bad.csv: no data rows after the header",
        "": "bad.csv: the file is empty",
    }
    for text, message in cases.items():
        (tmp_path / "bad.csv").write_text(text)
        with pytest.raises(ResultFileError, match="^.*" + message.replace("(", r"\(").replace(")", r"\)")):
            read_result(tmp_path / "bad.csv")
    (tmp_path / "bad.csv").write_text("time,theta\n0,0\n")
    with pytest.raises(ResultFileError, match="no column 'phi', which --map names for theta"):
        read_result(tmp_path / "bad.csv", "theta=phi")
    (tmp_path / "bad.csv").write_text("time,theta\n0,0\n3.5,0\n")
    with pytest.raises(ResultFileError, match=r"time 3\.5 is after the run's stop time 3 s"):
        judge(tmp_path / "bad.csv", 1.0)


@pytest.mark.parametrize(
    ("rows", "options", "message"),
    [
        ("0,0\n", {}, "the result ends at 0 s, before the run's stop time 3 s, so it covers only part of the run"),
        (
            "0,0\n0.001,0\n",
            {"start_time": -1.0, "stop_time": 0.001},
            "the result starts at 0 s, not at the run's start time -1 s",
        ),
        ("0.001,0\n0.002,0\n", {"stop_time": 0.002}, "the result starts at 0.001 s, not at the run's start time 0 s"),
    ],
)
def test_a_result_of_part_of_the_run_is_refused(tmp_path, rows, options, message):
    """Wherever it has rows such a result agrees with the reference (theta 0 at t = 0 from rest):
    judged, it would pass a run that never happened.
    """
    (tmp_path / "part.csv").write_text("time,theta\n" + rows)
    with pytest.raises(ResultFileError, match="^" + re.escape(f"{tmp_path / 'part.csv'}: {message}")):
        judge(tmp_path / "part.csv", 0.0, **options)


def test_a_kit_result_cut_short_is_refused_naming_it(kit, tmp_path, capsys):
    out = run(kit, "decimal_steps")
    lines = out.read_text().splitlines()
    cut = tmp_path / "cut.csv"
    cut.write_text("\n".join(lines[:51]) + "\n")  # 50 rows of 100, to 0.441 s
    settings = read_settings(kit / "decimal_steps.json")
    settings.pop("output")
    with pytest.raises(ResultFileError, match=r"ends at 0\.44.* s, before the run.s stop time 0\.9 s, so it covers"):
        judge(cut, **settings)
    # Every row but the last, as a master that forgets to write after its last step.
    out.write_text("\n".join(lines[:-1]) + "\n")
    assert main(["judge", str(kit)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"pendulum-fmu judge: error: {out}: the result ends at 0.8909")
    assert "before the run's stop time 0.9 s" in err[0]
    run(kit, "decimal_steps")


def test_fmpy_applying_a_jump_in_the_first_two_rows_late_is_diagnosed(fmu, tmp_path):
    """Fmpy 0.3.32's simulate_fmu applies a jump at t = 0 one step late (docs/signals.md): the
    first step holds the value before it, 0 N.m. From rest at the equilibrium that is also a
    restart from the initial state after one step; the tie goes to the input mistake.
    """
    from fmpy import simulate_fmu

    signal = np.array([(0.0, 0.0), (0.0, 20.0), (1.0, 20.0)], dtype=[("time", "f8"), ("torque", "f8")])
    fmpy_run = simulate_fmu(str(fmu), stop_time=1.0, output_interval=1e-3, input=signal, output=["theta"])
    result = tmp_path / "fmpy.csv"
    np.savetxt(
        result,
        np.column_stack([fmpy_run["time"], fmpy_run["theta"]]),
        delimiter=",",
        header="time,theta",
        comments="",
        fmt="%.17g",
    )
    (tmp_path / "jump.csv").write_text("time,torque\n0,0\n0,20\n1,20\n")
    judgement = judge(result, tmp_path / "jump.csv", fmu_path=fmu)
    assert judgement.diagnosis == LATE and judgement.residual < 1e-10 < 1e-4 < judgement.max_abs_dtheta
    assert judgement.candidates[NOT_RESTORED]["residual"] < 1e-10


@pytest.mark.parametrize("solver", ["Euler", "CVode"])
def test_fmpy_model_exchange_solvers_are_integration_errors(kit, solver):
    """Fmpy's own Model Exchange solvers: its Euler is explicit Euler at the step (the variant to
    the last bit); CVode at its default tolerance is no variant but small and smooth.
    """
    from fmpy import simulate_fmu

    signal = np.genfromtxt(kit / "constant_torque_in.csv", delimiter=",", names=True)
    fmpy_run = simulate_fmu(
        str(kit / KIT_FMU),
        fmi_type="ModelExchange",
        solver=solver,
        step_size=1e-3,
        output_interval=1e-3,
        stop_time=3.0,
        input=signal,
        output=["theta"],
    )
    np.savetxt(
        kit / "constant_torque_out.csv",
        np.column_stack([fmpy_run["time"], fmpy_run["theta"]]),
        delimiter=",",
        header="time,theta",
        comments="",
        fmt="%.17g",
    )
    judgement = _judged(kit, "constant_torque")
    assert judgement.verdict == "fail" and judgement.diagnosis == INTEGRATION
    # Its Euler is named; CVode, which no variant explains, is not.
    assert judgement.integrator == (EXPLICIT_EULER if solver == "Euler" else None)
    if solver == "Euler":
        assert judgement.residual == 0.0 and judgement.max_abs_dtheta > 1e-4
    else:
        assert 1e-9 < judgement.max_abs_dtheta < INTEGRATION_SMALL * judgement.smallest_input_effect


def _same_judgement(together, alone):
    """Two judgements of one result agree in every number they report."""
    assert together.source == alone.source
    assert (together.verdict, together.diagnosis) == (alone.verdict, alone.diagnosis)
    assert (together.residual, together.max_abs_dtheta, together.worst_time) == (
        alone.residual,
        alone.max_abs_dtheta,
        alone.worst_time,
    )
    assert together.candidates == alone.candidates
    assert together.smallest_input_effect == alone.smallest_input_effect
    assert together.regression_tools == alone.regression_tools
    for name in together.drawn.dtype.names:
        assert np.array_equal(together.drawn[name], alone.drawn[name], equal_nan=True)


def _results_of(kit, tmp_path, name, mistakes):
    """Scenario `name` run once per mistake (None: none), each result kept under its own name."""
    paths = []
    for mistake in mistakes:
        path = tmp_path / f"{name}_{mistake or 'right'}.csv"
        path.write_bytes(run(kit, name, mistake).read_bytes())
        paths.append(path)
    return paths


@pytest.mark.parametrize(
    ("name", "mistakes"),
    [
        # A drifting master's times are its own: the reference and variants made for them too.
        ("random_steps", [None, "late", "ramped", "drift", "late_once", "euler", None]),
        ("resume", [None, "not_restored", None, "not_restored"]),
        ("ramp", ["held", None, "early"]),
    ],
)
def test_many_results_judged_together_are_judged_as_each_alone(kit, tmp_path, name, mistakes, monkeypatch):
    from pendulum_fmu import judge_results
    from pendulum_fmu.judging import _judge

    paths = _results_of(kit, tmp_path, name, mistakes)
    settings = read_settings(kit / f"{name}.json")
    settings.pop("output")
    references = []
    oracle_of = _judge.reference_windows

    def counted(*args, **kwargs):
        oracle = oracle_of(*args, **kwargs)
        integrate = oracle.next
        oracle.next = lambda at: references.append(at) or integrate(at)
        return oracle

    monkeypatch.setattr(_judge, "reference_windows", counted)
    together = judge_results(paths, **settings)
    monkeypatch.undo()
    assert len(together) == len(paths)
    # One reference per set of result times: one for all but a drifting master's.
    assert len(references) == len({read_result(path)["time"].tobytes() for path in paths}) < len(paths)
    for path, judgement in zip(paths, together, strict=True):
        _same_judgement(judgement, judge(path, **settings))
    # Each mistake named as made, the right runs passing (the ones whose diagnosis is their own).
    named = {judgement.source: judgement.diagnosis for judgement in together}
    expected = {mistake: diagnosis for scenario, mistake, diagnosis in WRONG_MASTERS if scenario == name}
    for path, mistake in zip(paths, mistakes, strict=True):
        assert named[str(path)] == (AGREES if mistake is None else expected[mistake])


def test_the_command_judges_many_results_and_exits_with_the_worst(kit, tmp_path, capsys):
    right, late = _results_of(kit, tmp_path, "decimal_steps", [None, "late"])
    signal = ["--torque-file", str(kit / "decimal_steps_in.csv"), "--step-size", "0.009"]
    assert main(["judge", str(right), str(right), *signal]) == 0
    assert capsys.readouterr().out.endswith("\n2 of 2 results pass\n")

    absent = tmp_path / "absent.csv"
    summary = tmp_path / "many.json"
    assert main(["judge", str(right), str(absent), str(late), *signal, "--json", str(summary)]) == 2
    printed = capsys.readouterr()
    # Each result's lines in the order given, the one that cannot be read said in one line.
    assert printed.out.index(f"{right}: pass: {AGREES}") < printed.out.index(f"{late}: fail: {LATE}")
    assert "2 of 3 results pass" not in printed.out and "1 of 3 results pass; 1 could not be judged" in printed.out
    assert printed.err == f"pendulum-fmu judge: error: {absent}: cannot read: No such file or directory\n"
    written = json.loads(summary.read_text())["results"]
    assert [entry["result"] for entry in written] == [str(right), str(absent), str(late)]
    assert written[1]["error"].startswith(f"{absent}: cannot read")
    assert (written[0]["verdict"], written[2]["diagnosis"]) == ("pass", LATE)
    assert main(["judge", str(right), str(late), *signal]) == 1
