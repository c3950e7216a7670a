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
