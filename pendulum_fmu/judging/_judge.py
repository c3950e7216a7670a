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

A result is judged a window of WINDOW_STEPS grid steps of its run at a time (_window_walk.py):
the file read a block at a time (_result_file.py), the schedule, the reference and each
variant made window by window, each carrying its state to the next (_variants.py), the rows
spilled for the regression tools' second pass (_theta_series.py). Memory is a window's, however
long the run; the verdict and what is printed of it are _judgement.py's.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import InvalidInput
from ..fmu import _results as results
from ..fmu._model import FmuModel, fmu_model
from ..fmu._simulate import resolve_parameters
from ..oracle._reference import reference_windows
from ..scenarios._scenario_settings import JUDGE_TOLERANCE as DEFAULT_TOLERANCE, read_settings, settings_files
from ..signals._time_grid import WINDOW_STEPS, event_tolerance
from ..signals._torque_rows import torque_rows
from ..signals._torque_schedule import schedule_windows
from ._diagnoses import AGREES, INTEGRATION, INTEGRATORS, diagnose
from ._judgement import Judgement
from ._regression_tools import series_verdicts
from ._result_file import ResultFileError, result_blocks
from ._theta_series import ThetaSeries
from ._variants import Run, run_variants
from ._window_walk import KEEP_ROWS, Rows, Walk, check_first, check_last, frames, make_window, scored, window_rows


class JudgedRun:
    """One run's definition, and what every result of it is judged against.

    A result is judged a window of WINDOW_STEPS grid steps of the run at a time (_window_walk.py),
    in memory bounded by the window however long the run. A run of one window keeps its reference
    and the variants that do not depend on the result (all but state not restored and single
    precision) for the next result on the same times: the results of one scenario share them.

    Parameters
    ----------
    torque, start_time, stop_time, step_size, ramp, parameters, theta0, omega0, tolerance, fmu_path, max_steps
        As judge() takes them.
    window_steps : int, optional
        The grid steps of a window (default WINDOW_STEPS).

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
        window_steps: int = WINDOW_STEPS,
    ):
        tolerance = DEFAULT_TOLERANCE if tolerance is None else tolerance
        if not (math.isfinite(tolerance) and tolerance > 0):
            raise InvalidInput(f"the tolerance {tolerance} must be a positive finite number (rad)")
        self.tolerance, self.ramp, self.theta0, self.omega0 = tolerance, ramp, theta0, omega0
        self.model = fmu_model(fmu_path)
        self.parameters = resolve_parameters(parameters, self.model)
        self.definition: dict[str, Any] = {
            "start_time": start_time,
            "stop_time": stop_time,
            "step_size": step_size,
            "max_steps": max_steps,
            "window_steps": window_steps,
        }
        # The signal as the variants sample it, read once; the oracle reads it on its own.
        self.torque = torque
        self.signal = torque_rows(torque) if isinstance(torque, (str, Path)) else torque
        if isinstance(self.signal, (list, tuple)):
            self.signal = np.asarray(self.signal, dtype=float)
        self._windows(ramp)  # a run simulate() would refuse is refused here, before any result is read
        self.start_torque = float(self.model.variables["torque"].start or 0.0)
        self.run = Run(self.parameters, theta0, omega0, step_size, self.model)
        self._kept: dict[bytes, tuple] = {}

    def _windows(self, ramp: bool):
        return schedule_windows(self.signal, ramp=ramp, **self.definition)

    def _oracle(self):
        return reference_windows(
            self.torque,
            ramp=self.ramp,
            parameters=self.parameters,
            theta0=self.theta0,
            omega0=self.omega0,
            fmu_path=self.model,
            **self.definition,
        )

    def judge(self, result, mapping: str | dict | None = None) -> Judgement:
        """Judge one result of this run (judge() says how).

        Parameters
        ----------
        result : str, Path or numpy.ndarray
            A result CSV (result_blocks) or an array with fields time and theta (omega, alpha: optional).
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
        blocks: Iterable[np.ndarray]
        if isinstance(result, (str, Path)):
            # The fields of this run's FMU: a judge of a named FMU looks no other up.
            blocks = result_blocks(result, mapping, self.model.recorded)
        elif mapping:
            raise InvalidInput(
                "a map renames and scales a result file's columns: an array result is "
                "judged as it is, in the fields time and theta (rad); leave out mapping"
            )
        else:
            blocks = [_as_result(result, self.model.recorded)]
        with ThetaSeries() as series, self._oracle() as oracle:
            walk = self._walk(Rows(blocks), oracle, series, source)
            regression_tools = series_verdicts(series)
        by_candidate = walk.scores_by_candidate()
        scores, best, smallest_input_effect = scored(by_candidate, self.tolerance)
        raw = walk.raw
        if raw <= self.tolerance:
            diagnosis, residual, explained = AGREES, raw, False
        else:
            diagnosis, residual, explained = diagnose(raw, self.tolerance, scores, smallest_input_effect)
        integrator = None
        if explained and diagnosis == INTEGRATION:
            integrator = next(
                i for i, s in zip(INTEGRATORS, by_candidate[INTEGRATION], strict=False) if s is best[INTEGRATION]
            )
        return Judgement(
            verdict="pass" if raw <= self.tolerance else "fail",
            diagnosis=diagnosis,
            residual=residual,
            max_abs_dtheta=raw,
            worst_time=walk.worst_time,
            tolerance=self.tolerance,
            candidates=scores,
            smallest_input_effect=smallest_input_effect,
            points=walk.rows,
            exact_zeros=walk.exact_zeros,
            optional_differences={
                f"max_abs_d{name}": value for name, value in walk.optional.items() if not math.isnan(value)
            },
            # The variant drawn is the one that explains the result: an integration error without an
            # integrator of its own draws none.
            drawn=walk.drawn_array(best.get(diagnosis) if explained else None),
            source=source,
            integrator=integrator,
            regression_tools=regression_tools,
        )

    def _walk(self, rows: Rows, oracle, series: ThetaSeries, source: str) -> Walk:
        """Walk the result's rows through the run's windows (_window_walk.py)."""
        plans = self._windows(self.ramp)
        span = (plans.start_time, plans.stop_time)
        empty = results.empty(0, self.model.recorded)
        step_size = self.definition["step_size"]
        walk = variants = None
        held = self._windows(False) if self.ramp else None
        for number, (frame, held_frame, last) in enumerate(frames(plans, held)):
            taken = window_rows(rows, frame, last, step_size, empty)
            times = np.asarray(taken["time"], dtype=float)
            points = frame.plan.time
            slack = float(event_tolerance(max(abs(span[0]), abs(span[1])), step_size))
            if number == 0:
                first = float(times[0]) if len(times) else rows.first_time
                check_first(source, first, span[0], float(points[1] - points[0]), slack)
            if last:
                # Refused before the reference integrates a row outside the run.
                final = float(times[-1]) if len(times) else rows.last_time
                check_last(source, final, span[1], float(points[frame.end] - points[frame.end - 1]), slack)
            window = make_window(frame, held_frame, times, number == 0, last, step_size)
            key = times.tobytes() if number == 0 and last and len(times) <= KEEP_ROWS else None
            kept = self._kept.get(key) if key is not None else None
            if kept is not None:
                correct, variants, outputs = kept
            else:
                correct = oracle.next(times)
                variants = variants or run_variants(self.run, frame.plan, self.signal, self.ramp, self.start_torque)
                outputs = {} if key is not None else None
            walk = walk or Walk(variants, self.tolerance, span, series)
            walk.window(window, taken, correct, outputs)
            if key is not None and kept is None:
                if len(self._kept) >= self.KEPT_TIMES:
                    del self._kept[next(iter(self._kept))]
                self._kept[key] = (correct, variants, outputs)
        assert walk is not None, "a run has a window"
        return walk


def _as_result(result: np.ndarray, recorded) -> np.ndarray:
    """An array result (fields time and theta; omega and alpha optional) as a result array."""
    names = result.dtype.names or ()
    out = results.empty(len(result), recorded)
    for name in ("time", "theta", "omega", "alpha"):
        if name in names:
            out[name] = result[name]
    return out


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
