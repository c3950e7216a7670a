"""A result judged a window of its run at a time, in memory bounded by the window.

The result is read a block at a time (result_blocks); the run's schedule comes a window of
WINDOW_STEPS grid steps at a time (schedule_windows), and the reference integrates the same
windows on its own (reference_windows). For each window: the result's rows in it, the reference
at them, each candidate mistake's variant at them (each carrying its own state to the next
window, _variants.py), every variant's residual and effect so far, the worst difference, the
points a figure draws, and the rows the regression tools read again at the end (ThetaSeries).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._drawn_points import DrawnRows, drawn_points
from ..signals._time_grid import event_tolerance
from ..signals._torque_schedule import TorqueSchedule
from ._diagnoses import DRIFT, INPUT_TIMING, NOT_RESTORED, SINGLE
from ._result_file import OPTIONAL, ResultFileError
from ._theta_series import ThetaSeries
from ._variants import (
    Drifted,
    Frame,
    MissedChanges,
    Restarted,
    SteppedOnClock,
    Variant,
    Window,
    plan_index,
    single_precision,
)

# A run of one window with a result of up to this many rows keeps its reference and variants for
# the next result on the same times (40 bytes a row each).
KEEP_ROWS = 200_000

# Columns of time a figure's points are chosen in (drawn_points).
DRAWN_COLUMNS = 2000

# The fields of the drawn rows before the variants': the last four are those whose extremes are kept.
_BASE_FIELDS = ("time", "torque", "reference", "result", "difference")

# What Judgement.drawn holds at each drawn point.
DRAWN_FIELDS = ("time", "torque", "reference", "result", "explained_torque", "explained_theta")


@dataclass
class Score:
    """One variant's residual (max |theta_result - theta_variant|) and effect (max |theta_variant
    - theta_reference|) so far, rad; whether it still applies; the fields its torque and theta
    have among the drawn rows (Walk.drawn).
    """

    column: int
    residual: float = 0.0
    effect: float = 0.0
    applies: bool = True


class Walk:
    """The state of one result's walk: what is known of it after each window (see the module).

    Parameters
    ----------
    variants : dict
        {candidate: its variants} (_variants.run_variants).
    tolerance : float
        The judge's tolerance (rad).
    span : (float, float)
        The run's start and stop (s): the figure's columns of time.
    series : ThetaSeries
        Where the rows are spilled for the regression tools.
    """

    def __init__(self, variants: dict[str, list[Variant]], tolerance: float, span: tuple[float, float], series):
        self.variants, self.tolerance, self.span, self.series = variants, tolerance, span, series
        columns_of = range(1, 1 + sum(map(len, variants.values())))
        numbered = iter(columns_of)
        self.scores = {name: [Score(next(numbered)) for _ in made] for name, made in variants.items()}
        self.single = Score(0)
        self.raw, self.worst_time, self.exact_zeros, self.rows = 0.0, math.nan, 0, 0
        self.first_wrong: int | None = None  # the run's first row that disagrees
        self.previous_time: float | None = None
        self.off_grid = False
        self.float32 = True
        self.optional = {name: 0.0 for name in OPTIONAL}  # max |d omega|, |d alpha|; NaN: not all given
        # The drawn rows: the result's and the reference's, and each variant's torque and theta.
        # Column 0 is single precision's, the variants' the columns their scores hold.
        columns = 1 + len(columns_of)
        self.fields = [*_BASE_FIELDS, *(f"{what}{j}" for j in range(columns) for what in ("torque", "theta"))]
        self.drawn = DrawnRows(_BASE_FIELDS[1:], span, DRAWN_COLUMNS)

    def window(self, window: Window, result: np.ndarray, correct: np.ndarray, outputs: dict | None = None) -> None:
        """Take one window: its rows of the result and the reference at them. outputs: the
        variants' results at these rows that do not depend on the result, kept there when made
        (for the next result on the same times) and taken from there when kept; None: not kept.
        """
        difference = result["theta"] - correct["theta"]
        magnitude = np.abs(difference)
        if len(magnitude):
            worst = int(np.argmax(magnitude))
            if magnitude[worst] > self.raw or self.rows == 0:
                self.raw, self.worst_time = float(magnitude[worst]), float(window.times[worst])
        self.exact_zeros += int(np.count_nonzero(difference == 0))
        self.off_grid |= window.index is None
        theta = result["theta"]
        self.float32 &= bool(np.array_equal(theta.astype(np.float32).astype(float), theta))
        for name in OPTIONAL:
            given = result[name]
            if np.all(np.isfinite(given)) and len(given):
                self.optional[name] = max(self.optional[name], float(np.max(np.abs(given - correct[name]))))
            elif len(given):
                self.optional[name] = math.nan
        kept = self._kept(window.times, correct, theta, difference)
        drawn = np.full(len(kept), np.nan, dtype=[(name, float) for name in self.fields])
        for name, values in zip(
            _BASE_FIELDS, (window.times, correct["torque"], correct["theta"], theta, difference), strict=True
        ):
            drawn[name] = values[kept]
        self._score(self.single, theta, correct, single_precision(correct), kept, drawn)
        wrong = np.flatnonzero(magnitude > self.tolerance)
        starting = self.first_wrong is None and len(wrong)
        for name, made in self.variants.items():
            for i, (variant, score) in enumerate(zip(made, self.scores[name], strict=True)):
                if not score.applies:
                    continue
                if isinstance(variant, Restarted):
                    if starting:
                        out = variant.start(window, correct, int(wrong[0]), self.rows, self.previous_time)
                    elif self.first_wrong is None:
                        out = correct  # the reference until the first wrong row
                    else:
                        out = variant.at_window(window, correct)
                elif outputs is not None and (name, i) in outputs:
                    out = outputs[name, i]
                else:
                    out = variant.at_window(window, correct)
                    if outputs is not None:
                        outputs[name, i] = out
                if out is None:
                    score.applies = False
                    continue
                self._score(score, theta, correct, out, kept, drawn)
        self.drawn.add(drawn)
        if starting:
            self.first_wrong = self.rows + int(wrong[0])
        self.rows += len(window.times)
        if len(window.times):
            self.previous_time = float(window.times[-1])
        self.series.append(window.times, correct["theta"], theta)

    def _kept(self, times: np.ndarray, correct: np.ndarray, theta: np.ndarray, difference: np.ndarray) -> np.ndarray:
        """The rows a figure may draw: every extreme per column of the run's time (drawn_points)."""
        if not len(times):
            return np.empty(0, dtype=np.int64)
        return drawn_points(
            times, correct["torque"], correct["theta"], theta, difference, columns=DRAWN_COLUMNS, span=self.span
        )

    @staticmethod
    def _score(score: Score, theta: np.ndarray, correct: np.ndarray, variant: np.ndarray, kept, drawn) -> None:
        """Score a variant's window, and keep its torque and theta at the drawn rows."""
        if len(theta):
            score.residual = max(score.residual, float(np.max(np.abs(theta - variant["theta"]))))
            score.effect = max(score.effect, float(np.max(np.abs(variant["theta"] - correct["theta"]))))
        drawn[f"torque{score.column}"] = variant["torque"][kept]
        drawn[f"theta{score.column}"] = variant["theta"][kept]

    def scores_by_candidate(self) -> dict[str, list[Score]]:
        """{candidate: the scores of its variants that apply}, in DIAGNOSES' order: time grid
        drift's the steps on the result's times where a row is off the points, else the summed
        clocks; state not restored only from a first wrong row; single precision where every
        theta of the result is a float32 value.
        """
        out = {}
        for name, made in self.variants.items():
            applying = []
            for variant, score in zip(made, self.scores[name], strict=True):
                if name == DRIFT and isinstance(variant, Drifted) != self.off_grid:
                    continue
                if isinstance(variant, MissedChanges) and not variant.missed:
                    continue
                if isinstance(variant, SteppedOnClock) and not variant.skipped:
                    continue
                if name == NOT_RESTORED and self.first_wrong is None:
                    continue
                if score.applies:
                    applying.append(score)
            out[name] = applying
            if name == NOT_RESTORED:
                out[SINGLE] = [self.single] if self.float32 else []
        return out

    def drawn_array(self, explanation: Score | None) -> np.ndarray:
        """The drawn rows (DRAWN_FIELDS), the explanation's torque and theta those of the variant
        scored by `explanation` (NaN for None).
        """
        rows = self.drawn.rows
        out = np.full(len(rows), np.nan, dtype=[(name, float) for name in DRAWN_FIELDS])
        for name in DRAWN_FIELDS[:4]:
            out[name] = rows[name] if len(rows) else []
        if explanation is not None and len(rows):
            out["explained_torque"] = rows[f"torque{explanation.column}"]
            out["explained_theta"] = rows[f"theta{explanation.column}"]
        return out


def scored(
    by_candidate: dict[str, list[Score]], tolerance: float
) -> tuple[dict[str, dict | None], dict[str, Score], float | None]:
    """Per candidate, the residual and effect of its best variant (None where none applies); that
    variant's score; and the smallest effect above the tolerance of an input-timing variant.
    """
    scores: dict[str, dict | None] = {}
    best: dict[str, Score] = {}
    timing_effects: list[float] = []
    for name, made in by_candidate.items():
        if not made:
            scores[name] = None
            continue
        if name in INPUT_TIMING:
            timing_effects += [score.effect for score in made if score.effect > tolerance]
        chosen = min(made, key=lambda score: score.residual)
        best[name] = chosen
        scores[name] = {"residual": chosen.residual, "effect": chosen.effect}
    return scores, best, min(timing_effects, default=None)


def frames(plans, held_plans=None):
    """(Frame of the run's schedule, Frame of the held one or None, is last) of each window, from
    the schedule windows: each frame with the step before and after it where the run has them.
    """
    previous = previous_held = None
    current = next(plans)
    current_held = next(held_plans) if held_plans is not None else None
    while current is not None:
        following = next(plans, None)
        following_held = next(held_plans, None) if held_plans is not None else None
        frame = _frame(previous, current, following)
        held = _frame(previous_held, current_held, following_held) if current_held is not None else None
        yield frame, held, following is None
        previous, current = current, following
        previous_held, current_held = current_held, following_held


def _frame(before: TorqueSchedule | None, plan: TorqueSchedule, after: TorqueSchedule | None) -> Frame:
    time, torque, rate = [plan.time], [plan.torque], [plan.torque_rate]
    begin = 0
    if before is not None:
        time.insert(0, before.time[-2:-1])
        torque.insert(0, before.torque[-1:])
        rate.insert(0, before.torque_rate[-1:])
        begin = 1
    if after is not None:
        time.append(after.time[1:2])
        torque.append(after.torque[:1])
        rate.append(after.torque_rate[:1])
    joined = TorqueSchedule(time=np.concatenate(time), torque=np.concatenate(torque), torque_rate=np.concatenate(rate))
    return Frame(joined, begin, begin + len(plan.time) - 1)


class Rows:
    """The result's rows, taken a window at a time from its blocks."""

    def __init__(self, blocks):
        self.blocks = iter(blocks)
        self.pending: list[np.ndarray] = []
        self.first_time = self.last_time = math.nan
        self.done = False

    def until(self, end: float | None) -> np.ndarray:
        """The rows up to `end` (all that are left for None), in one array."""
        while not self.done and (end is None or not self.last_time > end):
            block = next(self.blocks, None)
            if block is None:
                self.done = True
                break
            if math.isnan(self.first_time):
                self.first_time = float(block["time"][0])
            self.pending.append(block)
            self.last_time = float(block["time"][-1])
        if end is None:
            taken, self.pending = self.pending, []
        else:
            taken, rest = [], []
            for block in self.pending:
                cut = int(np.searchsorted(block["time"], end, side="right"))
                if cut:
                    taken.append(block[:cut])
                if cut < len(block):
                    rest.append(block[cut:])
            self.pending = rest
        if not taken:
            return self.pending[0][:0] if self.pending else np.empty(0)
        return np.concatenate(taken) if len(taken) > 1 else taken[0]


def window_rows(rows: Rows, frame: Frame, last: bool, step_size: float, empty: np.ndarray) -> np.ndarray:
    """The result's rows of a window: up to its last point (within the event tolerance), or all
    that are left in the run's last window.
    """
    if last:
        taken = rows.until(None)
    else:
        end = float(frame.plan.time[frame.end])
        taken = rows.until(end + float(event_tolerance(end, step_size)))
    return taken if len(taken) else empty


def check_first(source: str, first: float, start: float, first_step: float, slack: float) -> None:
    """Refuse a result whose first row is not the run's start: before it, or nearer another
    communication point (half the first step: a master's times may drift off the grid, a
    diagnosis of its own, but a first row nearer another point is another run's).
    """
    if first < start - slack:
        raise ResultFileError(
            f"{source}: time {first:.17g} is before the run's start time {start:g} s; give the run's --start-time"
        )
    if first > start + first_step / 2:
        raise ResultFileError(
            f"{source}: the result starts at {first:.17g} s, not at the run's start "
            f"time {start:g} s: write a row per communication point from the start "
            "(judging a file alone, give the run's --start-time)"
        )


def check_last(source: str, last: float, stop: float, last_step: float, slack: float) -> None:
    """Refuse a result whose last row is not the run's stop: after it, or before it by more than
    half the last step. A result that stops short (a master that crashed, a file cut off, only
    the t = 0 row) agrees with the reference wherever it has rows, so judged it would pass a run
    that never happened.
    """
    if last > stop + slack:
        raise ResultFileError(
            f"{source}: time {last:.17g} is after the run's stop time {stop:g} s; give the run's --stop-time"
        )
    if last < stop - last_step / 2:
        raise ResultFileError(
            f"{source}: the result ends at {last:.17g} s, before the run's stop "
            f"time {stop:g} s, so it covers only part of the run: run it to the stop "
            "time (judging a file alone, give the run's --stop-time)"
        )


def make_window(
    frame: Frame, held: Frame | None, times: np.ndarray, first: bool, last: bool, step_size: float
) -> Window:
    """The Window of a frame and the result's rows in it."""
    return Window(frame, held, times, plan_index(frame.plan, times, step_size), first, last)


__all__ = [
    "DRAWN_FIELDS",
    "KEEP_ROWS",
    "Rows",
    "Score",
    "ThetaSeries",
    "Walk",
    "check_first",
    "check_last",
    "frames",
    "make_window",
    "scored",
    "window_rows",
]
