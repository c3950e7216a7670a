"""The wheel's build step: build_py also builds the FMU into the wheel's pendulum_fmu/data/.

Everything else about the package is in pyproject.toml. The FMU is built from this source tree
(a clone or the unpacked sdist) for every platform whose compiler is installed.
"""

import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

# This tree's pendulum_fmu (not an installed one) knows where the sources are.
sys.path.insert(0, str(Path(__file__).resolve().parent))


class BuildPyWithFmu(build_py):
    """build_py, then the FMI 2.0 and 3.0 FMUs into <build_lib>/pendulum_fmu/data/."""

    def run(self):
        super().run()
        # An editable install runs from the checkout, which builds dist/Pendulum.fmu on demand.
        if getattr(self, "editable_mode", False):
            return
        from pendulum_fmu import __version__
        from pendulum_fmu.build import build_fmu

        data = Path(self.build_lib, "pendulum_fmu", "data")
        for name, fmi_version in (("Pendulum.fmu", 2), ("Pendulum-fmi3.fmu", 3)):
            fmu = build_fmu(data / name, fmi_version=fmi_version)
            print(f"pendulum_fmu {__version__}: built {fmu}")


# The native stepping loop (pendulum_fmu._cs_loop, docs/design.md) joins as ext_modules here.
setup(cmdclass={"build_py": BuildPyWithFmu})
