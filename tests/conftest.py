import pytest

from fmu_build import build_fmu


@pytest.fixture(scope="session")
def fmu(tmp_path_factory):
    """The FMU built from this checkout's sources, once per test session."""
    return build_fmu(tmp_path_factory.mktemp("fmu") / "Pendulum.fmu")


@pytest.fixture(scope="session")
def fmu3(tmp_path_factory):
    """The FMI 3.0 FMU built from the same sources, once per test session."""
    return build_fmu(tmp_path_factory.mktemp("fmu3") / "Pendulum-fmi3.fmu", fmi_version=3)


@pytest.fixture
def generated_by_script(tmp_path):
    """What a generator script of tests/ writes when run as the README has it, `python
    tests/NAME.py OUT`, where another pendulum_fmu (the main job's non-editable install, say)
    comes first on the path: a script that imported it instead of the clone's would fail.
    """
    import os
    import subprocess
    import sys
    from pathlib import Path

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
