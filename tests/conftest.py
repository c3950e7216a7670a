"""What every test module shares: the FMUs built once per session, and the markers of the full run.

The README's `pytest` runs the suite on every core (pyproject's addopts: pytest-xdist, `-n auto`),
each worker a process of its own. A build that many tests use (the FMUs, the wheels, the docs
site) runs once per session, not once per worker: `build_once` makes it in a folder every worker
of the session shares, under a file lock, and the other workers take what it made.

The fast loop, `pytest -m "not slow"`, leaves out every test that needs a system tool or takes
long; each such test carries the marker that says why (pyproject's markers), and each of those
markers implies `slow`.
"""

import contextlib
import os
import pickle
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from filelock import FileLock

from fmu_build import build_fmu, build_pid_controller

# The markers of tests the fast loop leaves out; each implies `slow` (pyproject says what each means).
SLOW_MARKERS = ("packaging", "wine", "qemu", "sanitizers", "fuzz", "docs", "build", "notebook", "readme", "cluster")
# ... and the wasm hosts: Node (jco) and Chromium.
SLOW_MARKERS += ("node", "browser")
# ... and the masters from the package index, each in the environment its pins allow.
SLOW_MARKERS += ("masters",)


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items):
    """Mark `slow` every test that carries one of SLOW_MARKERS, before `-m` selects; and put the
    slow tests first, so that the workers (one module each, pyproject's --dist loadfile) start
    with the modules that hold them and share out the short ones at the end, rather than wait for
    a long one that came last (each kind keeps its order).
    """
    for item in items:
        if any(item.get_closest_marker(name) for name in SLOW_MARKERS):
            item.add_marker(pytest.mark.slow)
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


@pytest.fixture(scope="session")
def session_folder(tmp_path_factory) -> Path:
    """The temporary folder every worker of this test session shares."""
    folder = tmp_path_factory.getbasetemp()
    # Each worker's basetemp is a folder of the session's.
    return folder.parent if os.environ.get("PYTEST_XDIST_WORKER") else folder


@pytest.fixture(scope="session")
def checkout_build_lock(session_folder) -> FileLock:
    """Held by a build that writes into the checkout (setuptools' build/ and *.egg-info there), so
    that no two such builds of one session run at once.
    """
    return FileLock(session_folder / "checkout-build.lock")


@pytest.fixture(scope="session", autouse=True)
def _checkout_fmus_built_once(session_folder):
    """The checkout's dist/ FMUs (default_fmu(), controller_fmu()), rebuilt when stale by the
    first worker, before any test asks for them: else each worker would rebuild them at once.
    A build that fails here fails again in the tests that need it, which say so.
    """
    from pendulum_fmu import FMU_FILES, default_fmu
    from pendulum_fmu._errors import BuildError
    from pendulum_fmu.ssp._closed_loop import controller_fmu

    with FileLock(session_folder / "checkout-fmus.lock"), contextlib.suppress(BuildError):
        for fmi_version in FMU_FILES:
            default_fmu(fmi_version)
        controller_fmu()


@pytest.fixture(scope="session")
def build_once(session_folder) -> Callable[[str, Callable[[Path], Any]], Any]:
    """build(name, make): what make(folder) returned, made once per session for every worker.

    The first worker to ask runs make in a fresh folder NAME of the session's shared temporary
    folder, holding NAME's lock; the others wait for it and take its result. A make that failed
    (or skipped) leaves nothing: the next worker to ask tries again, and fails or skips the same way.
    """
    shared = session_folder

    def build(name: str, make: Callable[[Path], Any]) -> Any:
        folder, made = shared / name, shared / f"{name}.pickle"
        with FileLock(shared / f"{name}.lock"):
            if made.is_file():
                return pickle.loads(made.read_bytes())
            shutil.rmtree(folder, ignore_errors=True)  # what a failed make left
            folder.mkdir()
            result = make(folder)
            made.write_bytes(pickle.dumps(result))
            return result

    return build


@pytest.fixture(scope="session")
def fmu(build_once):
    """The FMU built from this checkout's sources, once per test session."""
    return build_once("fmu", lambda folder: build_fmu(folder / "Pendulum.fmu"))


@pytest.fixture(scope="session")
def fmu3(build_once):
    """The FMI 3.0 FMU built from the same sources, once per test session."""
    return build_once("fmu3", lambda folder: build_fmu(folder / "Pendulum-fmi3.fmu", fmi_version=3))


@pytest.fixture(scope="session")
def pid_controller(build_once):
    """The closed loop's PID controller FMU built from this checkout's sources, once per session."""
    return build_once("pid_controller", lambda folder: build_pid_controller(folder / "PIDController.fmu"))


@pytest.fixture
def generated_by_script(tmp_path):
    """What a generator script of tests/ writes when run as the README has it, `python
    tests/NAME.py OUT`, where another pendulum_fmu (the main job's non-editable install, say)
    comes first on the path: a script that imported it instead of the clone's would fail.
    """
    decoy = tmp_path / "site-packages" / "pendulum_fmu"
    decoy.mkdir(parents=True)
    (decoy / "__init__.py").write_text('raise ImportError("the installed pendulum_fmu, not the clone\'s")\n')

    def generate(script: str) -> str:
        out = tmp_path / "generated.md"
        done = subprocess.run(
            [sys.executable, str(Path(__file__).parent / script), str(out)],
            cwd=tmp_path,
            env={**os.environ, "PYTHONPATH": str(decoy.parent)},
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert done.returncode == 0, done.stderr
        return out.read_text()

    return generate
