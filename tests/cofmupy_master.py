"""The FMU run by cofmupy 1.0.0, its result written for the judge.

cofmupy runs in an environment of its own: it pins fmpy 0.3.20, and fails on the package's newer
fmpy (np.min of the defaultExperiment stepSizes, which fmpy 0.3.32 reads as strings).
tests/test_masters_pypi.py runs this with that environment's python and judges what it writes:

    COFMUPY_PYTHON tests/cofmupy_master.py FMU setter|table OUT.csv

setter: the torque (20 N.m, -20 N.m from 1 s) set through master.do_step each 1 ms step for 2 s,
theta after each step written under master.current_time, the time after it. table: a constant 20
N.m from the configuration, run_simulation(0.001, 2.0) and cofmupy's own save_results.
"""

import sys

from cofmupy import Coordinator

STEP, STEPS = 1e-3, 2000


def main(fmu: str, how: str, out: str) -> None:
    coordinator = Coordinator()
    initialization = {"torque": 20.0} if how == "table" else {}
    coordinator.start(
        {
            "fmus": [{"id": "pendulum", "path": fmu, "initialization": initialization}],
            "connections": [],
            "cosim_method": "jacobi",
            "iterative": False,
        }
    )
    if how == "table":
        coordinator.run_simulation(STEP, STEPS * STEP)
        coordinator.save_results(out)
        return
    rows = ["time,theta", "0.0,0.0"]  # the FMU's start: cofmupy's master returns outputs only after a step
    for k in range(STEPS):
        torque = 20.0 if k < STEPS // 2 else -20.0
        outputs = coordinator.master.do_step(STEP, input_dict={"pendulum": {"torque": [torque]}})
        rows.append(f"{coordinator.master.current_time!r},{outputs['pendulum']['theta'][0]!r}")
    with open(out, "w") as file:
        file.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main(*sys.argv[1:])
