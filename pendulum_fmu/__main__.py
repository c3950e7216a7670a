"""python -m pendulum_fmu: the pendulum-fmu program."""

from ._entry import run

if __name__ == "__main__":
    run()
