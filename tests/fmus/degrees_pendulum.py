"""A pendulum as another tool would export it, for tests/test_compare_tools.py: FMI 3.0, Model Exchange
and Co-Simulation (pythonfmu3), angles in degrees, its own names (tau, phi, w, a; m, L, J, g, c),
the start angle and rate as parameters of their own. A Co-Simulation step integrates with
scipy's DOP853 at 1e-12, in degrees.
"""

import math

from pythonfmu3 import CoSimulation, Float64, Fmi3Causality, Fmi3Initial, Fmi3SlaveBase, Fmi3Variability, ModelExchange
from scipy.integrate import solve_ivp

DEGREE = math.pi / 180


class DegreesPendulum(Fmi3SlaveBase, ModelExchange, CoSimulation):
    author = "pendulum-fmu tests"
    description = "Torque-driven pendulum with angles in degrees"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.time = 0.0
        self.tau, self.phi, self.w, self.der_phi, self.der_w = 0.0, 0.0, 0.0, 0.0, 0.0
        self.m, self.L, self.J, self.g, self.c = 1.0, 1.0, 1.0, 9.81, 0.0
        self.phi_start, self.w_start = 0.0, 0.0
        self.register_variable(
            Float64("time", causality=Fmi3Causality.independent, variability=Fmi3Variability.continuous)
        )
        for name in ("phi", "w"):  # value references 1 and 2: the states
            self.register_variable(
                Float64(
                    name,
                    causality=Fmi3Causality.output,
                    variability=Fmi3Variability.continuous,
                    initial=Fmi3Initial.calculated,
                )
            )
        self.register_variable(
            Float64("der_phi", causality=Fmi3Causality.local, derivative=1, variability=Fmi3Variability.continuous)
        )
        self.register_variable(
            Float64("der_w", causality=Fmi3Causality.local, derivative=2, variability=Fmi3Variability.continuous)
        )
        self.register_variable(Float64("tau", causality=Fmi3Causality.input, start=0.0))
        self.register_variable(Float64("a", causality=Fmi3Causality.output))
        for name in ("m", "L", "J", "g", "c", "phi_start", "w_start"):
            self.register_variable(
                Float64(name, causality=Fmi3Causality.parameter, variability=Fmi3Variability.tunable)
            )

    def _acceleration(self, phi, w):
        """deg/s2 from phi in deg and w in deg/s."""
        torque = self.tau - self.m * self.g * self.L * math.sin(phi * DEGREE) - self.c * w * DEGREE
        return torque / (self.J + self.m * self.L**2) / DEGREE

    @property
    def a(self):
        """A direct feedthrough: the acceleration under the torque set now."""
        return self._acceleration(self.phi, self.w)

    def exit_initialization_mode(self):
        self.phi, self.w = self.phi_start, self.w_start

    def get_continuous_state_derivatives(self) -> list[float]:
        self.der_phi, self.der_w = self.w, self.a
        return [self.der_phi, self.der_w]

    def do_step(self, current_time, step_size):
        solution = solve_ivp(
            lambda t, y: (y[1], self._acceleration(y[0], y[1])),
            (current_time, current_time + step_size),
            (self.phi, self.w),
            method="DOP853",
            rtol=1e-12,
            atol=1e-10,
        )
        self.phi, self.w = solution.y[:, -1]
        return True
