"""Build the PythonFMU peer (pendulum_slave.py) into an FMU with pythonfmu's builder."""

from pathlib import Path

SLAVE = Path(__file__).resolve().parent / "pendulum_slave.py"


def build_pythonfmu_pendulum(out_dir) -> Path:
    """Build PythonPendulum.fmu into out_dir; ImportError when pythonfmu is not installed."""
    from pythonfmu.builder import FmuBuilder

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    return Path(FmuBuilder.build_FMU(SLAVE, dest=out_dir))
