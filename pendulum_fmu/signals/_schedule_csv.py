"""A schedule written as a torque CSV in fmpy's convention, which schedule() reads back."""

from __future__ import annotations

from pathlib import Path

from ._torque_schedule import TorqueSchedule


def write_torque_csv(path: str | Path, plan: TorqueSchedule) -> Path:
    """Write a schedule as a torque CSV in fmpy's convention, which schedule() reads back.

    A row where each run of equal steps starts and ends, so a held torque reads as steps and a
    ramp as a line. Times are written with 17 significant digits, so they read back as the same
    doubles. The file is written whole or not at all.

    Parameters
    ----------
    path : str or Path
        The CSV to write (replaced if it is there).
    plan : TorqueSchedule
        The schedule, from schedule().

    Returns
    -------
    Path
        path.

    Raises
    ------
    CannotWrite
        path cannot be written.

    Examples
    --------
    5 N.m for 1 s, then 7 N.m:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import schedule, write_torque_csv
    >>> plan = schedule([5.0, 5.0, 7.0], step_size=0.5)
    >>> csv = write_torque_csv(Path(tempfile.mkdtemp(), "torque.csv"), plan)
    >>> print(csv.read_text(), end="")
    time,torque
    0.0,5.0
    1.0,5.0
    1.0,7.0
    1.5,7.0
    >>> schedule(csv, step_size=0.5).torque.tolist()
    [5.0, 5.0, 7.0]
    """
    from .._atomic_files import replacing

    end = plan.torque + plan.torque_rate * plan.step_size
    points: list[tuple[float, float]] = []
    for t0, t1, u0, u1 in zip(
        plan.time[:-1].tolist(), plan.time[1:].tolist(), plan.torque.tolist(), end.tolist(), strict=False
    ):
        if not points or points[-1] != (t0, u0):
            points.append((t0, u0))
        points.append((t1, u1))
    # A point inside a run of constant torque adds nothing.
    rows = [
        p for i, p in enumerate(points) if i in (0, len(points) - 1) or not points[i - 1][1] == p[1] == points[i + 1][1]
    ]
    with replacing(path, newline="") as file:
        file.write("time,torque\n")
        file.writelines(f"{t!r},{u!r}\n" for t, u in rows)
    return Path(path)
