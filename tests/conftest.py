import pytest

from pendulum_fmu.build import build_fmu


@pytest.fixture(scope="session")
def fmu(tmp_path_factory):
    """The FMU built from this checkout's sources, once per test session."""
    return build_fmu(tmp_path_factory.mktemp("fmu") / "Pendulum.fmu")


@pytest.fixture(scope="session")
def fmu3(tmp_path_factory):
    """The FMI 3.0 FMU built from the same sources, once per test session."""
    return build_fmu(tmp_path_factory.mktemp("fmu3") / "Pendulum-fmi3.fmu", fmi_version=3)


@pytest.fixture
def other_package_installed(tmp_path):
    """The environment of a process in which another pendulum_fmu (the main job's non-editable
    install, say) comes first on the path: a script that imports it instead of the clone's fails."""
    import os

    decoy = tmp_path / "site-packages" / "pendulum_fmu"
    decoy.mkdir(parents=True)
    (decoy / "__init__.py").write_text('raise ImportError("the installed pendulum_fmu, not the clone\'s")\n')
    return {**os.environ, "PYTHONPATH": str(decoy.parent)}
