"""The wheel's build steps; everything else about the package is in pyproject.toml.

- build_py also builds the FMI 2.0 and 3.0 FMUs and the closed loop's PID controller FMU into the
  wheel's pendulum_fmu/data/, from this source tree (a clone or the unpacked sdist), for every
  platform whose compiler is installed.
- build_ext builds the native co-simulation loop, pendulum_fmu/fmu/_cs_loop.c, and with it the
  oracle's Taylor stepping, pendulum_fmu/oracle/_taylor_native.c, and the judge's Euler stepping,
  pendulum_fmu/judging/_euler_native.c, through the project's one build description
  (CMakeLists.txt, driven by fmu_build/) with this machine's compiler. It is plain C loaded with
  ctypes (pendulum_fmu/fmu/_native_loop.py), not a CPython module: it has the platform's plain
  name (_cs_loop.so, _cs_loop.pyd) and the wheel is tagged py3-none-<platform>, one wheel for
  every Python 3 on a platform.
- bdist_wheel --linux-glibc 2.17 has both build the Linux binaries with zig for that oldest glibc
  (fmu_build's linux_glibc); build_wheels.py passes it, through
  python -m build -C--build-option=--linux-glibc=2.17.
- The wheel and the sdist are the same bytes from one commit, in any folder, at any time
  (fmu_build/release_files.py): bdist_wheel dates every entry by $SOURCE_DATE_EPOCH, which
  defaults to the commit's time (fmu_build/build_record.py), and zips files of fixed
  permissions; sdist writes its tar.gz in sorted order, every entry dated so and owned by root,
  and carries the commit and its time (source_commit.json), so that the wheel built from the
  sdist is the wheel built from the clone.
"""

import importlib.machinery
import os
import shutil
import sys
import tempfile
import warnings
from functools import partial
from pathlib import Path
from typing import ClassVar

from setuptools import Extension, setup
from setuptools.command.bdist_wheel import bdist_wheel
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

# This tree's pendulum_fmu (not an installed one) knows where the sources are.
sys.path.insert(0, str(Path(__file__).resolve().parent))


class BuildPyWithFmu(build_py):
    """build_py, then the FMI 2.0 and 3.0 FMUs and the PID controller's into <build_lib>/pendulum_fmu/data/."""

    def run(self):
        """Copy the package as build_py does, then build both FMUs into its data/."""
        super().run()
        # An editable install runs from the checkout, which builds dist/Pendulum.fmu on demand.
        if getattr(self, "editable_mode", False):
            return
        _remove_stale_modules(Path(self.build_lib, "pendulum_fmu"))
        from fmu_build import build_fmu, build_pid_controller
        from pendulum_fmu import CONTROLLER_FMU_FILE, FMU_FILES, __version__
        from pendulum_fmu._errors import PlatformSkipped
        from pendulum_fmu.fmu._export import fmu_platforms

        data = Path(self.build_lib, "pendulum_fmu", "data")
        builds = {
            **{
                name: (f"FMI {version}.0 FMU", partial(build_fmu, fmi_version=version))
                for version, name in FMU_FILES.items()
            },
            # The closed loop's controller, so that export-ssp runs from the wheel as from a clone.
            CONTROLLER_FMU_FILE: ("PID controller FMU", build_pid_controller),
        }
        for name, (what, build) in builds.items():
            with warnings.catch_warnings(record=True) as skipped:
                warnings.simplefilter("always", PlatformSkipped)
                fmu = build(data / name, linux_glibc=_linux_glibc(self))
            # A platform this machine cannot build for: one line each, what to install in it.
            for warning in skipped:
                print(f"pendulum_fmu {__version__}: {what} without {warning.message}", file=sys.stderr)
            print(f"pendulum_fmu {__version__}: built {fmu} ({', '.join(fmu_platforms(fmu))})")


def _remove_stale_modules(built: Path) -> None:
    """Remove from the build folder the modules this tree no longer has: build_py copies into a
    build/lib that an earlier build of the same checkout left, and never removes what was renamed
    or deleted since, which the wheel would then carry.
    """
    source = Path(__file__).resolve().parent / "pendulum_fmu"
    for module in built.rglob("*.py"):
        if not (source / module.relative_to(built)).exists():
            module.unlink()


class BuildNativeLoop(build_ext):
    """The native loop by CMake, for the platform of this machine."""

    def build_extension(self, extension):
        """Build the native loop with fmu_build for this machine's platform, into extension's place."""
        from fmu_build import PLATFORMS, compile_native_loop

        [platform] = [name for name, platform in PLATFORMS.items() if platform.native]
        target = Path(self.get_ext_fullpath(extension.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory() as out_dir:
            shutil.copyfile(compile_native_loop(platform, out_dir, _linux_glibc(self)), target)

    def get_ext_filename(self, fullname):
        """The native loop's plain name (_cs_loop.so, _cs_loop.pyd), not one CPython's own."""
        # The last suffix is the one every CPython of the platform loads: .so, .pyd.
        return str(Path(*fullname.split("."))) + importlib.machinery.EXTENSION_SUFFIXES[-1]


class PlatformWheel(bdist_wheel):
    """bdist_wheel tagged py3-none-<platform>, with --linux-glibc for the zig builds."""

    user_options: ClassVar[list[tuple[str, str | None, str]]] = [
        *bdist_wheel.user_options,
        (
            "linux-glibc=",
            None,
            "build the Linux binaries with zig for this oldest glibc, such as 2.17 "
            "(default: with gcc, for the build machine's glibc)",
        ),
    ]

    def initialize_options(self):
        """bdist_wheel's options, and --linux-glibc unset (gcc, the build machine's glibc)."""
        super().initialize_options()
        self.linux_glibc = None

    def get_tag(self):
        """py3, none and bdist_wheel's platform tag: one wheel for every Python 3 on a platform."""
        return "py3", "none", super().get_tag()[2]

    def run(self):
        """bdist_wheel, every entry dated by $SOURCE_DATE_EPOCH, the commit's time unless given."""
        from fmu_build.build_record import source_date_epoch

        # bdist_wheel's zip writer reads $SOURCE_DATE_EPOCH, else each file's time; so do the
        # compilers (__DATE__), which this sets it for too.
        os.environ["SOURCE_DATE_EPOCH"] = str(source_date_epoch())
        super().run()

    def write_wheelfile(self, wheelfile_base, *args, **kwargs):
        """bdist_wheel's WHEEL file, then fixed permissions for every file the wheel will hold."""
        from fmu_build.release_files import normalize_modes

        super().write_wheelfile(wheelfile_base, *args, **kwargs)
        # The last step of run() before bdist_wheel zips bdist_dir, taking each entry's
        # permissions from its file (the checkout's umask): it has no option for them. An
        # editable install calls this too, for a dist-info folder of its own, left as it is.
        if Path(wheelfile_base).resolve().parent == Path(self.bdist_dir).resolve():
            normalize_modes(self.bdist_dir)


class ReproducibleSdist(sdist):
    """sdist whose tar.gz is the same bytes from one commit, carrying that commit and its time."""

    def make_release_tree(self, base_dir, files):
        """The tree sdist makes, and in it source_commit.json: the commit and its time, for builds from it."""
        from fmu_build.build_record import write_source_record

        super().make_release_tree(base_dir, files)
        write_source_record(base_dir)

    def make_archive(self, base_name, format, root_dir=None, base_dir=None, owner=None, group=None):
        """The .tar.gz by fmu_build's write_tarball (sorted, dated by the commit, owned by root);
        other formats as sdist writes them.
        """
        if format != "gztar" or root_dir is not None:
            return super().make_archive(base_name, format, root_dir, base_dir, owner, group)
        from fmu_build.build_record import source_date_epoch
        from fmu_build.release_files import write_tarball

        write_tarball(f"{base_name}.tar.gz", base_dir, source_date_epoch())
        return f"{base_name}.tar.gz"


def _linux_glibc(command):
    """The glibc floor the wheel build was given (bdist_wheel --linux-glibc), or None."""
    return command.distribution.get_command_obj("bdist_wheel").linux_glibc


setup(
    # Declared so that setuptools builds it (in place too) and tags the wheel for a platform;
    # BuildNativeLoop builds it with CMake, not with setuptools' compiler.
    ext_modules=[
        Extension(
            "pendulum_fmu.fmu._cs_loop",
            sources=[
                "pendulum_fmu/fmu/_cs_loop.c",
                "pendulum_fmu/fmu/_cs_batch.c",
                "pendulum_fmu/oracle/_taylor_native.c",
                "pendulum_fmu/judging/_euler_native.c",
            ],
            depends=["pendulum_fmu/fmu/_cs_loop.h"],
        )
    ],
    cmdclass={
        "build_py": BuildPyWithFmu,
        "build_ext": BuildNativeLoop,
        "bdist_wheel": PlatformWheel,
        "sdist": ReproducibleSdist,
    },
)
