"""The pendulum as a Python user would package it: a PythonFMU slave that integrates each
communication step with scipy's solve_ivp. The benchmark's peer; not part of the package.
"""

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from scipy.integrate import solve_ivp


class PythonPendulum(Fmi2Slave):
    author = "pendulum-fmu benchmarks"
    description = "Torque-driven pendulum integrated with scipy DOP853 each step"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.torque, self.theta, self.omega, self.alpha = 0.0, 0.0, 0.0, 0.0
        self.mass, self.length, self.inertia, self.gravity, self.damping = 40.0, 0.5, 20.0, 9.81, 0.0
        # rtol and atol as a Python user would pick them for a tolerance like the FMU's default.
        self.tolerance = 1e-10
        self.register_variable(Real("torque", causality=Fmi2Causality.input))
        for name in ("theta", "omega", "alpha"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))
        for name in ("mass", "length", "inertia", "gravity", "damping", "tolerance"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))

    def _acceleration(self, theta, omega):
        inertia_total = self.inertia + self.mass * self.length**2
        return (
            self.torque - self.mass * self.gravity * self.length * np.sin(theta) - self.damping * omega
        ) / inertia_total

    def do_step(self, current_time, step_size):
        solution = solve_ivp(
            lambda t, y: (y[1], self._acceleration(y[0], y[1])),
            (current_time, current_time + step_size),
            (self.theta, self.omega),
            method="DOP853",
            rtol=self.tolerance,
            atol=self.tolerance,
        )
        self.theta, self.omega = solution.y[:, -1]
        self.alpha = self._acceleration(self.theta, self.omega)
        return True
