import pytest

from pendulum_fmu.build import build_fmu


@pytest.fixture(scope="session")
def fmu(tmp_path_factory):
    """The FMU built from this checkout's sources, once per test session."""
    return build_fmu(tmp_path_factory.mktemp("fmu") / "Pendulum.fmu")
