"""Torque signals: what a master feeds the pendulum, as the step-wise schedule every tool is fed.

_torque_schedule turns a signal (a constant, a callable, an array, a torque CSV) into a
TorqueSchedule, whole or a window at a time, and _schedule_csv writes one as a CSV; _torque_csv
reads a torque CSV, refusing a bad one in one line; _torque_rows reads one again a block at a
time, for a run too long to hold its table; _time_grid gives the communication points and the
limits on a run's size.

May import: the basics (_errors, _atomic_files). Nothing else of the package: the FMU, the
reference and every tool read their inputs from here.
"""
