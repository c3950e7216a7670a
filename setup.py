"""The wheel's build steps; everything else about the package is in pyproject.toml.

- build_py also builds the FMI 2.0 and 3.0 FMUs into the wheel's pendulum_fmu/data/, from this
  source tree (a clone or the unpacked sdist), for every platform whose compiler is installed.
- The native co-simulation loop, pendulum_fmu/_cs_loop.c, is built as a shared library. It is
  plain C loaded with ctypes (pendulum_fmu/cs_loop.py), not a CPython module, so it exports its
  own function rather than a PyInit_ one. The FMI headers are fmpy's (a build requirement).
  Being no CPython module, it has the platform's plain name (_cs_loop.so, _cs_loop.pyd) and
  the wheel is tagged py3-none-<platform>: one wheel serves every Python 3 on a platform.
"""

import importlib.machinery
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.bdist_wheel import bdist_wheel
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

# This tree's pendulum_fmu (not an installed one) knows where the sources are.
sys.path.insert(0, str(Path(__file__).resolve().parent))

from pendulum_fmu.build import FMI_HEADERS  # noqa: E402


class BuildPyWithFmu(build_py):
    """build_py, then the FMI 2.0 and 3.0 FMUs into <build_lib>/pendulum_fmu/data/."""

    def run(self):
        super().run()
        # An editable install runs from the checkout, which builds dist/Pendulum.fmu on demand.
        if getattr(self, "editable_mode", False):
            return
        from pendulum_fmu import FMU_FILES, __version__
        from pendulum_fmu.build import build_fmu

        data = Path(self.build_lib, "pendulum_fmu", "data")
        for fmi_version, name in FMU_FILES.items():
            fmu = build_fmu(data / name, fmi_version=fmi_version)
            print(f"pendulum_fmu {__version__}: built {fmu}")


class BuildCLibrary(build_ext):
    def get_export_symbols(self, extension):
        return extension.export_symbols

    def get_ext_filename(self, fullname):
        # The last suffix is the one every CPython of the platform loads: .so, .pyd.
        return str(Path(*fullname.split("."))) + importlib.machinery.EXTENSION_SUFFIXES[-1]


class PlatformWheel(bdist_wheel):
    def get_tag(self):
        return "py3", "none", super().get_tag()[2]


setup(
    ext_modules=[Extension("pendulum_fmu._cs_loop", sources=["pendulum_fmu/_cs_loop.c"],
                           include_dirs=[str(FMI_HEADERS)],
                           export_symbols=["cs_loop_run", "cs_loop_interface"])],
    cmdclass={"build_py": BuildPyWithFmu, "build_ext": BuildCLibrary, "bdist_wheel": PlatformWheel},
)
