"""A torque-driven pendulum as an FMI 2.0 Co-Simulation FMU, and the tools to compare it."""

from .build import build_fmu, default_fmu

__all__ = ["build_fmu", "default_fmu"]
