"""The native co-simulation loop, pendulum_fmu/_cs_loop.c, built as a shared library.

It is plain C loaded with ctypes (pendulum_fmu/cs_loop.py), not a CPython module, so it exports
its own function rather than a PyInit_ one. The FMI 2.0 headers are fmpy's (a build requirement).
"""

from pathlib import Path

import fmpy
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class BuildCLibrary(build_ext):
    def get_export_symbols(self, extension):
        return extension.export_symbols


setup(
    ext_modules=[Extension("pendulum_fmu._cs_loop", sources=["pendulum_fmu/_cs_loop.c"],
                           include_dirs=[str(Path(fmpy.__file__).parent / "c-code")],
                           export_symbols=["cs_loop_run"])],
    cmdclass={"build_ext": BuildCLibrary},
)
