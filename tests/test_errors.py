"""Every error type the package defines for its user derives from PendulumFmuError, which the
command line prints as one line (tests/test_cli.py, tests/test_bad_inputs.py).
"""

import importlib
import importlib.util
import inspect
import pkgutil

import pendulum_fmu
from pendulum_fmu._errors import PendulumFmuError

# Engines whose Python package is missing here cannot be imported; the others are checked.
# (_cs_loop is a plain C library, not a Python module; __main__ runs the program.)
ENGINES = {
    "pendulum_fmu.engines.mujoco": "mujoco",
    "pendulum_fmu.engines.drake": "pydrake",
    "pendulum_fmu.engines.pybullet": "pybullet",
}


def test_every_exception_class_of_the_package_is_a_user_error():
    defined = {}
    for module in pkgutil.walk_packages(pendulum_fmu.__path__, "pendulum_fmu."):
        if module.name in ("pendulum_fmu.__main__", "pendulum_fmu.fmu._cs_loop") or (
            module.name in ENGINES and importlib.util.find_spec(ENGINES[module.name]) is None
        ):
            continue
        for name, value in inspect.getmembers(importlib.import_module(module.name), inspect.isclass):
            if (
                issubclass(value, Exception)
                and not issubclass(value, Warning)
                and value.__module__.startswith("pendulum_fmu")
            ):
                defined[f"{value.__module__}.{name}"] = value
    assert {
        "pendulum_fmu.signals._torque_csv.TorqueFileError",
        "pendulum_fmu.fmu._instance.FmuError",
        "pendulum_fmu.fmu._model.FmuFileError",
        "pendulum_fmu._errors.BuildError",
        "pendulum_fmu.sweep.store.InUse",
    } <= set(defined)
    assert [name for name, value in defined.items() if not issubclass(value, PendulumFmuError)] == []
