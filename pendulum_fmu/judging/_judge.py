"""Judge a result file from any tool against the independent reference, and name the mistake.

    pendulum-fmu judge RESULT.csv --torque-file torque.csv [--step-size 0.001] [--map ...]
    pendulum-fmu judge KIT          (every NAME_out.csv beside a scenario kit's inputs)

A result is a CSV with a time column and theta, optionally omega and alpha (any names and units,
through --map as compare's: theta=phi*0.0174532925). The verdict compares it with the
independent reference (reference.reference: the signal read by its own reader, integrated by
its Taylor series) at the result's own times: pass when max |dtheta| <= the tolerance.

A result that fails gets a diagnosis. Each candidate mistake is a variant of the run with that
mistake made: the schedule a master should feed (torque_schedule.schedule) changed as the mistake changes
it, integrated exactly (reference.reference_schedule) and compared with the result at the
result's times. A candidate's residual is max |theta_result - theta_variant|: the mistake that
explains the result leaves only rounding and solver noise (about 1e-11 rad). The candidates:

- input one step late: step k holds what step k-1 should (the first step holds the signal's first
  value, or the FMU's start value);
- input one step early: step k holds what step k+1 should;
- input interpolated linearly: each step ramps to the next step's value where the signal holds;
- input held: each step holds where the run asked for a ramp (ramp runs only);
- time grid drift: the master stepped on the result's own times, off the communication points,
  sampling the signal there (when the result's times are off the grid); or its clock is summed
  step by step and compared without a tolerance: it stepped wherever its time reached the FMU's
  next point on that clock (FMI++'s FixedStepSizeFMU.sync; a row per communication point, where
  that skips a step), or applied a change of the torque only where that clock equals the change's
  time (ECOS's scenarios through ecospy; where that misses a change);
- time column one step off: each row holds the run's state at the next communication point (a
  master that files a step's result under the step's start), or at the one before;
- state not restored: from the last row that agrees, the run restarts from the initial state
  (a resumed run that did not restore its saved FMU state);
- result in single precision: the reference with theta rounded to float32 (only when every theta
  of the result is a float32 value);
- integration error: the FMU's equation stepped by explicit or semi-implicit Euler at the
  communication step (a master that integrates the Model Exchange interface itself, or
  Pendulum-v1's semi-implicit Euler); when one of them leaves only noise, the judgement names it
  (Judgement.integrator).

The reading is _result_file.py's, the variants' integration _variants.py's, the verdict and
what is printed of it _judgement.py's.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .._errors import InvalidInput
from ..fmu._model import FmuModel, fmu_model
from ..fmu._simulate import resolve_parameters
from ..oracle._reference import reference
from ..scenarios._scenario_settings import JUDGE_TOLERANCE as DEFAULT_TOLERANCE, read_settings, settings_files
from ..signals._torque_schedule import schedule
from ._diagnoses import AGREES, INTEGRATION, INTEGRATORS, diagnose
from ._judgement import Judgement, score_variants
from ._regression_tools import regression_verdicts
from ._result_file import ResultFileError, check_span, read_result
from ._variants import KEEP_ROWS, Run, Variant, candidate_variants, shared_variants


class JudgedRun:
    """One run's definition, and what every result of it is judged against.

    The schedule is made once. The reference and the variants of the candidate mistakes that do
    not depend on the result (all but state not restored) are made once per set of result times
    and kept for the next result on the same times: the results of one scenario share them. A
    result of more than KEEP_ROWS rows keeps none: its variants are made one at a time.

    Parameters
    ----------
    torque, start_time, stop_time, step_size, ramp, parameters, theta0, omega0, tolerance, fmu_path, max_steps
        As judge() takes them.

    Raises
    ------
    InvalidInput
        A tolerance that is not positive and finite, or a run definition simulate() would refuse.
    """

    # Sets of result times whose reference and variants are kept (results of one scenario share
    # one; a master whose times drift has its own per result).
    KEPT_TIMES = 4

    def __init__(
        self,
        torque,
        *,
        start_time: float = 0.0,
        stop_time: float | None = None,
        step_size: float = 1e-3,
        ramp: bool = False,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        tolerance: float | None = None,
        fmu_path: str | Path | FmuModel | None = None,
        max_steps: int | None = None,
    ):
        tolerance = DEFAULT_TOLERANCE if tolerance is None else tolerance
        if not (math.isfinite(tolerance) and tolerance > 0):
            raise InvalidInput(f"the tolerance {tolerance} must be a positive finite number (rad)")
        self.torque, self.tolerance = torque, tolerance
        self.start_time, self.stop_time, self.step_size, self.ramp = start_time, stop_time, step_size, ramp
        self.theta0, self.omega0, self.max_steps = theta0, omega0, max_steps
        self.model = fmu_model(fmu_path)
        self.parameters = resolve_parameters(parameters, self.model)
        self.plan = schedule(
            torque, start_time=start_time, stop_time=stop_time, step_size=step_size, ramp=ramp, max_steps=max_steps
        )
        self.held = schedule(torque, start_time=start_time, stop_time=stop_time, step_size=step_size) if ramp else None
        self.start_torque = float(self.model.variables["torque"].start or 0.0)
        self._kept: dict[bytes, tuple[np.ndarray, Run, dict[str, list[Variant]]]] = {}

    def _shared(self, times: np.ndarray) -> tuple[np.ndarray, Run, dict[str, list[Variant]]]:
        """The reference at these times, the frame of the run's variants, and the variants every
        result on these times shares (made here the first time, kept for the next: for a result
        of up to KEEP_ROWS rows).
        """
        key = times.tobytes() if len(times) <= KEEP_ROWS else None
        if key is None or key not in self._kept:
            correct = reference(
                self.torque,
                start_time=self.start_time,
                stop_time=self.stop_time,
                step_size=self.step_size,
                ramp=self.ramp,
                parameters=self.parameters,
                theta0=self.theta0,
                omega0=self.omega0,
                at=times,
                fmu_path=self.model,
                max_steps=self.max_steps,
            )
            run = Run(self.plan, times, self.step_size, self.parameters, self.theta0, self.omega0, self.model)
            run.keep = key is not None
            if key is None:
                return correct, run, shared_variants(run, self.torque, self.held, self.start_torque)
            if len(self._kept) >= self.KEPT_TIMES:
                del self._kept[next(iter(self._kept))]
            self._kept[key] = (correct, run, shared_variants(run, self.torque, self.held, self.start_torque))
        return self._kept[key]

    def judge(self, result, mapping: str | dict | None = None) -> Judgement:
        """Judge one result of this run (judge() says how).

        Parameters
        ----------
        result : str, Path or numpy.ndarray
            A result CSV (read_result) or an array with fields time and theta (omega, alpha: optional).
        mapping : str or dict, optional
            The result's column names and unit factors (--map), for a CSV.

        Returns
        -------
        Judgement
            As judge() returns it.

        Raises
        ------
        ResultFileError
            A result file that cannot be read, whose times fall outside the run, or whose first
            and last rows are not the run's start and stop (a result of part of the run).
        InvalidInput
            A map given with an array result, or values with which the reference fails.
        """
        source = str(result) if isinstance(result, (str, Path)) else "result"
        if isinstance(result, (str, Path)):
            # The fields of this run's FMU: a judge of a named FMU looks no other up.
            result = read_result(result, mapping, self.model.recorded)
        elif mapping:
            raise InvalidInput(
                "a map renames and scales a result file's columns: an array result is "
                "judged as it is, in the fields time and theta (rad); leave out mapping"
            )
        check_span(result, self.plan, self.step_size, source)
        times = np.asarray(result["time"], dtype=float)
        correct, run, shared = self._shared(times)
        difference = np.abs(result["theta"] - correct["theta"])
        raw = float(np.max(difference))
        variants = candidate_variants(shared, run, correct, result, self.tolerance)
        scores, best, smallest_input_effect = score_variants(variants, result, correct, self.tolerance)
        if raw <= self.tolerance:
            diagnosis, residual, explained = AGREES, raw, False
        else:
            diagnosis, residual, explained = diagnose(raw, self.tolerance, scores, smallest_input_effect)
        return Judgement(
            verdict="pass" if raw <= self.tolerance else "fail",
            diagnosis=diagnosis,
            residual=residual,
            max_abs_dtheta=raw,
            worst_time=float(times[int(np.argmax(difference))]),
            tolerance=self.tolerance,
            candidates=scores,
            smallest_input_effect=smallest_input_effect,
            result=result,
            reference=correct,
            explanation=variants[diagnosis][best[diagnosis]]() if diagnosis in best else None,
            source=source,
            integrator=INTEGRATORS[best[INTEGRATION]] if explained and diagnosis == INTEGRATION else None,
            regression_tools=regression_verdicts(times, correct["theta"], result["theta"]),
        )


def judge(
    result,
    torque,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    tolerance: float | None = None,
    mapping: str | dict | None = None,
    fmu_path: str | Path | FmuModel | None = None,
    max_steps: int | None = None,
) -> Judgement:
    """Judge a result from any tool against the independent reference, and diagnose a failure.

    Parameters
    ----------
    result : str, Path or numpy.ndarray
        A result CSV (read_result) or an array with fields time and theta (omega, alpha: optional).
    torque : float, callable, str or Path
        The run's signal, as simulate() takes it: a constant (N.m), a callable of time or a
        time,torque CSV (docs/signals.md).
    start_time, stop_time, step_size, ramp, parameters, theta0, omega0, max_steps, fmu_path
        The run's definition, as simulate() takes it; fmu_path may also be the FMU's model
        (fmu_model), looked up once here and passed to everything the judgement runs.
    tolerance : float, optional
        The largest ``|dtheta|`` (rad) that passes (default: DEFAULT_TOLERANCE, 1e-9 rad).
    mapping : str or dict, optional
        The result's column names and unit factors (--map), for a CSV.

    Returns
    -------
    Judgement
        The verdict, the diagnosis and its residual, ``max |dtheta|`` and where, every candidate's
        residual and effect.

    Raises
    ------
    ResultFileError
        A result file that cannot be read, whose times fall outside the run, or whose first
        and last rows are not the run's start and stop (a result of part of the run).
    InvalidInput
        A tolerance that is not positive and finite, or a run definition simulate() would refuse.

    Examples
    --------
    The FMU's own run, written as a result file and judged:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import judge, simulate
    >>> from pendulum_fmu.fmu._results import write_csv
    >>> result = write_csv(simulate(20.0, stop_time=1.0), Path(tempfile.mkdtemp()) / "fmu.csv")
    >>> judgement = judge(result, 20.0, stop_time=1.0)
    >>> judgement.passed, judgement.diagnosis
    (True, 'agrees')
    """
    return JudgedRun(
        torque,
        start_time=start_time,
        stop_time=stop_time,
        step_size=step_size,
        ramp=ramp,
        parameters=parameters,
        theta0=theta0,
        omega0=omega0,
        tolerance=tolerance,
        fmu_path=fmu_path,
        max_steps=max_steps,
    ).judge(result, mapping)


def judge_results(
    results,
    torque,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    tolerance: float | None = None,
    mapping: str | dict | None = None,
    fmu_path: str | Path | FmuModel | None = None,
    max_steps: int | None = None,
) -> list[Judgement]:
    """Judge many results of one run, each as judge() would, making the reference once.

    The results of one scenario (a regression suite's runs of it, one per master or version)
    share their times: the reference and the candidate mistakes' variants are made for the first
    and reused for the others (JudgedRun).

    Parameters
    ----------
    results : iterable of str, Path or numpy.ndarray
        The result CSVs or arrays, as judge() takes one.
    torque, start_time, stop_time, step_size, ramp, parameters, theta0, omega0, tolerance, mapping, fmu_path, max_steps
        As judge() takes them, the same for every result.

    Returns
    -------
    list of Judgement
        One per result, in their order.

    Raises
    ------
    ResultFileError
        The first result file that cannot be judged (judge() says which); none after it is judged.
    InvalidInput
        A tolerance that is not positive and finite, or a run definition simulate() would refuse.

    Examples
    --------
    The FMU's run and one whose torque steps a millisecond late, judged against one reference:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import judge_results, simulate
    >>> from pendulum_fmu.fmu._results import write_csv
    >>> folder = Path(tempfile.mkdtemp())
    >>> right = write_csv(simulate(lambda t: 0.0 if t < 0.25 else 20.0, stop_time=0.5), folder / "right.csv")
    >>> late = write_csv(simulate(lambda t: 0.0 if t < 0.251 else 20.0, stop_time=0.5), folder / "late.csv")
    >>> judgements = judge_results([right, late], lambda t: 0.0 if t < 0.25 else 20.0, stop_time=0.5)
    >>> [(j.verdict, j.diagnosis) for j in judgements]
    [('pass', 'agrees'), ('fail', 'input one step late')]
    """
    run = JudgedRun(
        torque,
        start_time=start_time,
        stop_time=stop_time,
        step_size=step_size,
        ramp=ramp,
        parameters=parameters,
        theta0=theta0,
        omega0=omega0,
        tolerance=tolerance,
        fmu_path=fmu_path,
        max_steps=max_steps,
    )
    return [run.judge(result, mapping) for result in results]


def judge_kit(
    folder: str | Path,
    *,
    tolerance: float | None = None,
    mapping: str | None = None,
    fmu_path: str | Path | FmuModel | None = None,
) -> dict[str, Judgement | None]:
    """Judge every NAME_out.csv beside the settings NAME.json of a scenario kit (_scenarios.py).

    Parameters
    ----------
    folder : str or Path
        The kit's folder, as `pendulum-fmu scenarios` wrote it.
    tolerance : float, optional
        Overrides each scenario's own tolerance (rad).
    mapping, fmu_path
        As judge() takes them.

    Returns
    -------
    dict
        {scenario: Judgement, or None where the folder has no NAME_out.csv}, in the kit's order.

    Raises
    ------
    ResultFileError
        A folder that holds no scenario, or none with a result.

    Examples
    --------
    A kit in which one scenario has a result (its reference, copied: it passes) and the others none:

    >>> import shutil, tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import judge_kit, write_scenarios
    >>> kit = Path(tempfile.mkdtemp())
    >>> _ = write_scenarios(kit)
    >>> _ = shutil.copy(kit / "constant_torque_ref.csv", kit / "constant_torque_out.csv")
    >>> verdicts = judge_kit(kit)
    >>> verdicts["constant_torque"].passed, [name for name, judgement in verdicts.items() if judgement is None]
    (True, ['decimal_steps', 'ramp', 'random_steps', 'resume', 'steps_on_grid'])
    """
    folder = Path(folder)
    found = settings_files(folder)
    if not found:
        raise ResultFileError(
            f"{folder}: no scenario settings (NAME.json) in this folder; write a kit "
            "with pendulum-fmu scenarios --output-dir FOLDER"
        )
    model = None  # the FMU's model, looked up once, for the first result there is
    verdicts: dict[str, Judgement | None] = {}
    for name, settings_path in found.items():
        settings = read_settings(settings_path)
        output = folder / settings.pop("output")
        if not output.is_file():
            verdicts[name] = None
            continue
        if tolerance is not None:
            settings["tolerance"] = tolerance
        model = model or fmu_model(fmu_path)
        verdicts[name] = judge(output, mapping=mapping, fmu_path=model, **settings)
    if all(v is None for v in verdicts.values()):
        raise ResultFileError(
            f"{folder}: no result to judge: run each scenario and write NAME_out.csv "
            f"(time,theta[,omega,alpha]) beside its NAME_in.csv, e.g. "
            f"{next(iter(found))}_out.csv"
        )
    return verdicts


__all__ = ["JudgedRun", "judge", "judge_kit", "judge_results"]
