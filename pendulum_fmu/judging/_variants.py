"""The variants of a run with a candidate mistake made, made a window of the run at a time.

A variant is the schedule changed as the mistake changes it, integrated exactly
(reference_schedule) at the result's times; integration error's variants are the run stepped by
each of INTEGRATORS. The judge walks a run in windows of grid steps (Window); each variant carries
its own state (theta, omega) from one window to the next, so a run of any length is held a window
at a time. _diagnoses.py names the candidates and decides.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..fmu import _results as results
from ..fmu._model import FmuModel
from ..oracle._reference import model_constants, reference_schedule
from ..signals._time_grid import event_tolerance
from ..signals._torque_csv import TorqueTable
from ..signals._torque_rows import CsvReader, HeldRows, TorqueCsv
from ..signals._torque_schedule import TorqueSchedule
from ._diagnoses import (
    DIAGNOSES,
    DRIFT,
    EARLY,
    HELD,
    INTEGRATION,
    INTEGRATORS,
    INTERPOLATED,
    LATE,
    NOT_RESTORED,
    SEMI_IMPLICIT_EULER,
    SHIFTED,
    SINGLE,
)
from ._euler import euler_steps


@dataclass(frozen=True)
class Frame:
    """A window's stretch of a schedule: its steps, with the step before and the step after where
    the run has them (a late input reads the one before, an early input the one after); the
    window's first and last points are plan.time[begin] and plan.time[end].
    """

    plan: TorqueSchedule
    begin: int
    end: int


@dataclass(frozen=True)
class Window:
    """One window of the run as the judge walks it: its frame of the run's schedule (and, for a
    ramp run, of the same signal held), the result's rows in it, each row's point of the frame
    (None where a row is off the points), and whether it is the run's first and last window.
    """

    frame: Frame
    held: Frame | None
    times: np.ndarray
    index: np.ndarray | None
    first: bool
    last: bool
    # The run's own schedule integrated over the window, per state it starts from (own_run).
    own: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def on_points(self) -> bool:
        """Whether the rows are the frame's points exactly, one per point from the window's
        first after the last window's (from the run's start in the first window).
        """
        first = 0 if self.first else self.frame.begin + 1
        points = self.frame.plan.time[first : self.frame.end + 1]
        return self.index is not None and np.array_equal(self.times, points)


@dataclass(frozen=True)
class Run:
    """What every variant of one run needs: its parameters, initial state, step and FMU."""

    parameters: dict
    theta0: float
    omega0: float
    step_size: float
    model: FmuModel


def plan_index(plan: TorqueSchedule, times: np.ndarray, step_size: float) -> np.ndarray | None:
    """For each time, the index of the communication point it is; None when one is off them."""
    if not len(times):
        return np.empty(0, dtype=np.int64)
    index = np.clip(np.searchsorted(plan.time, times), 1, len(plan.time) - 1)
    index = np.where(np.abs(plan.time[index] - times) < np.abs(plan.time[index - 1] - times), index, index - 1)
    on_grid = np.abs(plan.time[index] - times) <= event_tolerance(times, step_size)
    return index if np.all(on_grid) else None


def _changed(plan: TorqueSchedule, torque: np.ndarray, rate: np.ndarray | None = None) -> TorqueSchedule:
    return TorqueSchedule(time=plan.time, torque=torque, torque_rate=plan.torque_rate if rate is None else rate)


def _integrated(
    run: Run, plan: TorqueSchedule, begin: int, end: int, at: np.ndarray, state: tuple[float, float]
) -> tuple[np.ndarray, tuple[float, float]]:
    """The schedule's steps from point begin, integrated exactly from state there, at the times
    `at`; and the state at point end, where the next window starts.
    """
    part = TorqueSchedule(time=plan.time[begin:], torque=plan.torque[begin:], torque_rate=plan.torque_rate[begin:])
    out = reference_schedule(
        part,
        parameters=run.parameters,
        theta0=state[0],
        omega0=state[1],
        at=np.r_[at, plan.time[end]],
        fmu_path=run.model,
        show_progress=False,
    )
    return out[:-1], (float(out["theta"][-1]), float(out["omega"][-1]))


def _beyond(plan: TorqueSchedule) -> TorqueSchedule:
    """The schedule one more step long: the last step's length, holding the torque it reached (as
    the FMU makes a step past the run's end).
    """
    end_torque = plan.torque[-1] + plan.torque_rate[-1] * plan.step_size[-1]
    return TorqueSchedule(
        time=np.r_[plan.time, plan.time[-1] + plan.step_size[-1]],
        torque=np.r_[plan.torque, end_torque],
        torque_rate=np.r_[plan.torque_rate, 0.0],
    )


def own_run(run: Run, window: Window, state: tuple[float, float]) -> tuple[np.ndarray, tuple[float, float]]:
    """The run's own schedule integrated from state over the window, at each point of its frame
    from the window's first on (in the run's last window one step past its end: a time column
    one step off reads it), and the state at the window's last point. Made once per window and
    state: the variants whose schedule is the run's own there (a constant torque one step late,
    early or interpolated; a time column one step off) share it.
    """
    if state not in window.own:
        frame = window.frame
        plan = _beyond(frame.plan) if window.last else frame.plan
        window.own[state] = _integrated(run, plan, frame.begin, frame.end, plan.time[frame.begin :], state)
    return window.own[state]


def _own_at_rows(run: Run, window: Window, state: tuple[float, float]) -> tuple[np.ndarray, tuple[float, float]]:
    """own_run at the window's rows, which are its points (Window.on_points)."""
    out, state = own_run(run, window, state)
    assert window.index is not None, "rows on the points have their points"
    at = out[window.index - window.frame.begin]
    at["time"] = window.times
    return at, state


def _same_steps(plan: TorqueSchedule, window: Window) -> bool:
    """Whether the schedule's steps from the window's first are the run's own."""
    own, begin = window.frame.plan, window.frame.begin
    return np.array_equal(plan.torque[begin:], own.torque[begin:]) and np.array_equal(
        plan.torque_rate[begin:], own.torque_rate[begin:]
    )


class Variant:
    """One variant of a candidate mistake, made window by window: at_window gives its result at
    the window's rows (time, torque, theta, ...), or None where the variant does not apply to the
    run (then it never does again). Its state is the one at the window's last point.
    """

    def __init__(self, run: Run):
        self.run = run
        self.state = (run.theta0, run.omega0)

    def at_window(self, window: Window, correct: np.ndarray) -> np.ndarray | None:
        frame = window.frame
        plan = self.changed(frame.plan, window)
        if plan is None:
            return None
        if window.on_points and _same_steps(plan, window):
            out, self.state = _own_at_rows(self.run, window, self.state)
        else:
            out, self.state = _integrated(self.run, plan, frame.begin, frame.end, window.times, self.state)
        return out

    def changed(self, plan: TorqueSchedule, window: Window) -> TorqueSchedule | None:
        """The frame's schedule with the mistake made."""
        raise NotImplementedError


class Late(Variant):
    """Step k holds what step k-1 should; the first step `first` (the signal's first value, or
    the FMU's start value: whatever the master set before it began).
    """

    def __init__(self, run: Run, first: float, first_rate: float):
        super().__init__(run)
        self.first, self.first_rate = first, first_rate

    def changed(self, plan, window):
        return _changed(plan, np.r_[self.first, plan.torque[:-1]], np.r_[self.first_rate, plan.torque_rate[:-1]])


class Early(Variant):
    """Step k holds what step k+1 should; the run's last step its own."""

    def changed(self, plan, window):
        return _changed(plan, np.r_[plan.torque[1:], plan.torque[-1]], np.r_[plan.torque_rate[1:], 0.0])


class Interpolated(Variant):
    """Each step ramps from its value to the next step's; the run's last step holds."""

    def changed(self, plan, window):
        return _changed(plan, plan.torque, np.r_[np.diff(plan.torque) / plan.step_size[:-1], 0.0])


class Held(Variant):
    """A ramp run's signal held over each step: the one variant of input held."""

    def at_window(self, window, correct):
        frame = window.held
        out, self.state = _integrated(self.run, frame.plan, frame.begin, frame.end, window.times, self.state)
        return out


class MissedChanges(Variant):
    """A master that applies a change of the torque only where its clock, summed step by step,
    equals the change's time (ECOS's scenarios through ecospy): a change it misses never reaches
    the FMU. It applies to a run where a change is missed (`missed`, once the run is walked).
    """

    def __init__(self, run: Run):
        super().__init__(run)
        self.clock: float | None = None  # the summed clock at the window's first point
        self.applied: float | None = None  # the torque applied there
        self.missed = False

    def changed(self, plan, window):
        frame = window.frame
        points = plan.time[frame.begin : frame.end + 1]
        torque = plan.torque[frame.begin : frame.end]
        start = points[0] if self.clock is None else self.clock
        clock = np.cumsum(np.r_[start, np.full(len(torque), self.run.step_size)])
        before = plan.torque[frame.begin - 1] if frame.begin else torque[0]
        change = torque != np.r_[before, torque[:-1]]
        applied = change & (clock[:-1] == points[:-1])
        if window.first:
            applied[0] = True
        self.missed |= bool(np.any(change & ~applied))
        last = np.maximum.accumulate(np.where(applied, np.arange(len(torque)), -1))
        values = np.where(last >= 0, torque[np.maximum(last, 0)], self.applied if self.applied is not None else 0.0)
        self.clock, self.applied = float(clock[-1]), float(values[-1])
        full = plan.torque.copy()
        full[frame.begin : frame.end] = values
        return _changed(plan, full, np.zeros(len(full)))


class Drifted(Variant):
    """The master's steps are the result's own times; each samples the signal at its start (a
    master off the communication points). Its state is at the last row so far.
    """

    def __init__(self, run: Run, signal, ramp: bool):
        super().__init__(run)
        # A CSV's rows: a reader of its own, forward through the run.
        self.signal = signal.rows() if isinstance(signal, (TorqueCsv, HeldRows)) else signal
        self.ramp = ramp
        self.last_time: float | None = None

    def at_window(self, window, correct):
        rows = np.unique(window.times)
        points = rows if self.last_time is None else np.r_[self.last_time, rows[rows > self.last_time]]
        if len(points) < 2:
            if self.last_time is None and len(rows):
                return None  # a result of one time: no step of the master's
            return _held_state(self, window.times)
        start = signal_values(self.signal, points[:-1], "after")
        rate = (
            (signal_values(self.signal, points[1:], "before") - start) / np.diff(points) if self.ramp else 0.0 * start
        )
        plan = TorqueSchedule(time=points, torque=start, torque_rate=rate)
        out, self.state = _integrated(self.run, plan, 0, len(points) - 1, window.times, self.state)
        self.last_time = float(points[-1])
        return out


def _held_state(variant: Variant, times: np.ndarray) -> np.ndarray:
    """The variant's state at rows all at the time it reached (or none)."""
    out = results.empty(len(times), variant.run.model.recorded)
    out["time"] = times
    out["theta"], out["omega"] = variant.state
    return out


def signal_values(signal, times: np.ndarray, side: str) -> np.ndarray:
    """The signal just after (side "after") or before each time, sampled as a master would,
    without the definition's snapping of events onto communication points.
    """
    if isinstance(signal, (CsvReader, HeldRows)):
        signal = signal.near(float(times[0]), float(times[-1]))
    if isinstance(signal, TorqueTable):
        return signal.value_after(times) if side == "after" else signal.value_before(times)
    if callable(signal):
        return np.array([float(signal(t)) for t in times.tolist()])
    return np.full(len(times), float(signal))


class SteppedOnClock(Variant):
    """A master whose clock is summed step by step and compared with times without a tolerance:
    it steps the FMU while its own time, the result's, is at or past the FMU's next communication
    point on that clock (FMI++'s FixedStepSizeFMU.sync), and after each row sets the torque of the
    step that starts at the row's time. Where the clocks round apart a step is skipped, the FMU a
    step behind (its rows a step old, its input a step early) until a row takes two. Only for a
    row per communication point; it applies where a step is skipped (`skipped`, once walked).
    """

    def __init__(self, run: Run):
        super().__init__(run)
        self.clock: float | None = None  # the summed clock at the window's first point
        self.done: int | None = None  # the FMU's steps done at the last row, as a point of the window's frame
        self.skipped = False

    def at_window(self, window, correct):
        frame, times, index = window.frame, window.times, window.index
        first_row = 0 if window.first else frame.begin + 1
        if index is None or not np.array_equal(index, np.arange(first_row, frame.end + 1)):
            return None
        plan = frame.plan
        points = plan.time[frame.begin :]
        clock = np.cumsum(
            np.r_[points[0] if self.clock is None else self.clock, np.full(len(points) - 1, self.run.step_size)]
        )
        # The FMU's steps done when each row is written (none before the start: a row within
        # rounding of it), as points of the frame.
        done = np.maximum(np.searchsorted(clock, times, side="right") - 1, 0) + frame.begin
        if np.any(index - done > 1):
            # This master falls one step behind at most before a row takes two: rows its clock
            # cannot reach (a torque's event between communication points) are not its.
            return None
        self.skipped |= not np.array_equal(done, index)
        before = frame.begin if self.done is None else self.done
        dones, rows = (done, index) if window.first else (np.r_[before, done], np.r_[frame.begin, index])
        # Step j runs with what the row before the first row that has it done set.
        steps = np.arange(before, done[-1])
        setter = np.searchsorted(dones, steps + 1, side="left") - 1
        stepped = TorqueSchedule(
            time=plan.time[before : done[-1] + 1], torque=plan.torque[rows[setter]], torque_rate=np.zeros(len(steps))
        )
        out, self.state = _integrated(self.run, stepped, 0, len(steps), plan.time[done], self.state)
        self.clock = float(clock[frame.end - frame.begin])
        # As a point of the next window's frame, whose first point (1) is this one's last.
        self.done = int(done[-1]) - frame.end + 1
        out["time"] = times
        return out


class Shifted(Variant):
    """Each row holds the run's state one communication point after its time (a master that
    files a step's result under the step's start), or one before; the first row the initial state.
    The last row's next point is one more step of the run's last torque, as the FMU makes it.
    """

    def __init__(self, run: Run, shift: int):
        super().__init__(run)
        self.shift = shift

    def at_window(self, window, correct):
        if window.index is None:
            return None
        out, self.state = own_run(self.run, window, self.state)
        at = out[np.maximum(window.index + self.shift, window.frame.begin) - window.frame.begin]
        at["time"] = window.times
        return at


class Restarted(Variant):
    """Up to a point the reference; from there the run restarts from its initial state, as a
    resumed run that did not restore its saved FMU state. The restart is where the first row that
    disagrees is (it shows the initial state), or the row before it (it shows the old instance's
    state, the next row the new one's): `before` rows before the first wrong row.
    """

    def __init__(self, run: Run, before: int):
        super().__init__(run)
        self.before = before

    def start(
        self, window: Window, correct: np.ndarray, first_wrong: int, rows_before: int, previous_time: float | None
    ) -> np.ndarray | None:
        """In the window holding the first wrong row (first_wrong, its index in the window;
        rows_before, the run's rows before the window; previous_time, the last of those rows'
        time): the reference before it, the restarted run from it; None where no restart fits.
        """
        restart_row = first_wrong - self.before
        if rows_before + restart_row < 1:  # a restart at the very start is no restart
            return None
        restart = window.times[restart_row] if restart_row >= 0 else previous_time
        plan = window.frame.plan
        k = int(np.argmin(np.abs(plan.time - restart)))
        off = abs(plan.time[k] - restart) > event_tolerance(restart, self.run.step_size)
        if off or k < window.frame.begin or (window.last and k >= window.frame.end):
            return None
        tail, self.state = _integrated(
            self.run, plan, k, window.frame.end, window.times[first_wrong:], (self.run.theta0, self.run.omega0)
        )
        out = correct.copy()
        out[first_wrong:] = tail
        return out

    def at_window(self, window, correct):
        if window.on_points:
            out, self.state = _own_at_rows(self.run, window, self.state)
            return out
        frame = window.frame
        out, self.state = _integrated(self.run, frame.plan, frame.begin, frame.end, window.times, self.state)
        return out


class Stepped(Variant):
    """The equation of motion stepped once per communication step of the run's plan, holding each
    step's start torque: explicit Euler, or semi-implicit (the new omega moves theta); integration
    error's variants, one per INTEGRATORS.
    """

    def __init__(self, run: Run, integrator: str):
        super().__init__(run)
        self.semi_implicit = integrator == SEMI_IMPLICIT_EULER

    def at_window(self, window, correct):
        if window.index is None:
            return None
        frame = window.frame
        plan = frame.plan
        block = slice(frame.begin, frame.end)
        thetas, omegas = euler_steps(
            self.state,
            plan.step_size[block],
            plan.torque[block],
            model_constants(self.run.parameters),
            self.semi_implicit,
        )
        self.state = (float(thetas[-1]), float(omegas[-1]))
        at = window.index - frame.begin
        out = results.empty(len(at), self.run.model.recorded)  # its FMU's fields: no other looked up
        out["time"] = window.times
        out["theta"], out["omega"] = thetas[at], omegas[at]
        out["torque"] = plan.torque[np.minimum(window.index, len(plan.torque) - 1)]
        return out


def run_variants(run: Run, first: TorqueSchedule, signal, ramp: bool, start_torque: float) -> dict[str, list[Variant]]:
    """{candidate: its variants}, in DIAGNOSES' order, of every candidate that may apply to the
    run, before it is walked (first: the first window's frame's schedule). Time grid drift's are
    both kinds: the steps on the result's times (they apply where a row is off the points) and the
    summed clocks (where every row is on them); result in single precision's are made from the
    reference (single_precision).
    """
    firsts = dict.fromkeys((float(first.torque[0]), start_torque))
    late: list[Variant] = [Late(run, u, first.torque_rate[0] if u == first.torque[0] else 0.0) for u in firsts]
    drift: list[Variant] = [] if isinstance(signal, np.ndarray) else [Drifted(run, signal, ramp)]
    if not ramp:
        drift += [SteppedOnClock(run), MissedChanges(run)]
    return {
        LATE: late,
        EARLY: [Early(run)],
        INTERPOLATED: [] if ramp else [Interpolated(run)],
        HELD: [Held(run)] if ramp else [],
        DRIFT: drift,
        SHIFTED: [Shifted(run, 1), Shifted(run, -1)],
        NOT_RESTORED: [Restarted(run, 0), Restarted(run, 1)],
        INTEGRATION: [Stepped(run, integrator) for integrator in INTEGRATORS],
    }


def single_precision(correct: np.ndarray) -> np.ndarray:
    """The reference with theta rounded to float32 (a master that hands observations out in
    single precision).
    """
    variant = correct.copy()
    variant["theta"] = correct["theta"].astype(np.float32)
    return variant


__all__ = ["DIAGNOSES", "SINGLE", "Frame", "Run", "Variant", "Window", "plan_index", "run_variants", "single_precision"]
