"""The candidate mistakes a failed result is tried against, and the diagnosis they give.

Each candidate is a variant of the run with that mistake made (_variants.py makes them; see
_judge.py's docstring). diagnose() names the candidate whose variant leaves only noise, an integration
error, or none; an integration error whose variant leaves only noise is named by its integrator
(INTEGRATORS).
"""

from __future__ import annotations

AGREES = "agrees"


LATE, EARLY = "input one step late", "input one step early"


INTERPOLATED, HELD = "input interpolated linearly", "input held"


DRIFT, NOT_RESTORED = "time grid drift", "state not restored"


# A time column one step off its values (a master that files a step's result under the step's
# start, or the reverse), and a result whose theta went through single precision (float32).
SHIFTED, SINGLE = "time column one step off", "result in single precision"


INTEGRATION, UNEXPLAINED = "integration error", "unexplained"


# The integrators of integration error's variants, in their order: what a master that integrates
# the Model Exchange interface itself steps by, and Pendulum-v1 (Gymnasium's, EnvPool's) does.
EXPLICIT_EULER = "explicit Euler at the communication step"
SEMI_IMPLICIT_EULER = "semi-implicit (symplectic) Euler at the communication step"
INTEGRATORS = (EXPLICIT_EULER, SEMI_IMPLICIT_EULER)


DIAGNOSES = (
    AGREES, LATE, EARLY, INTERPOLATED, HELD, DRIFT, SHIFTED, NOT_RESTORED, SINGLE, INTEGRATION, UNEXPLAINED
)  # fmt: skip


# The mistakes in the timing of the input or of the result's rows: a solver's error must be
# small beside them.
INPUT_TIMING = (LATE, EARLY, INTERPOLATED, HELD, DRIFT, SHIFTED)


# A candidate explains a result when its variant removes nearly all of the difference: its
# residual is at most EXPLAINS of the raw difference, or below the noise floor of the comparison
# (NOISE of the tolerance; a correct run leaves 1e-11 rad against the reference). A variant that
# removes only part of it merely resembles the mistake made: explicit Euler lags like an input half
# a step late, and with gravity off semi-implicit Euler is close to an input ramped over each step.
# Measured on the deliberately wrong masters of tests/test_judge.py: the mistake made leaves at most
# 1.2e-8 of the raw difference; the closest other candidate 3.3e-4 of it (semi-implicit Euler
# against a ramped input, gravity off), the others 0.37 or more. 1e-5 sits between 1.2e-8 and
# 3.3e-4, and the smallest residual decides among candidates under it.
EXPLAINS = 1e-5


NOISE = 0.1


# A difference no candidate explains is an integration error when it grows as a solver's does:
# no larger than explicit Euler's at the communication step (the crudest solver a master would
# use), and at most INTEGRATION_SMALL of the smallest difference any input-timing mistake makes in
# this run, so that no such mistake hides in it. Measured: Heun's method at the communication step
# (second order) is 3.2e-3 and 6.4e-3 of the input-timing effects; an input late at one jump only
# (no candidate of its own) 0.38. 0.05 sits between, about a decade from either.
INTEGRATION_SMALL = 0.05


def diagnose(
    raw: float, tolerance: float, scores: dict[str, dict | None], smallest_input_effect: float | None
) -> tuple[str, float, bool]:
    """The candidate that explains the difference, or integration error, or unexplained; its
    residual; and whether its variant explains it (leaves only noise).
    """
    applicable = {name: score for name, score in scores.items() if score is not None}
    best = min(applicable, key=lambda name: applicable[name]["residual"], default=None)
    if best is not None and applicable[best]["residual"] <= max(EXPLAINS * raw, NOISE * tolerance):
        # Variants the same to the noise are the same run: from rest at an equilibrium, a first step
        # without torque and a restart from the initial state after it cannot be told apart. The
        # earlier in DIAGNOSES, the commoner mistake, names it.
        tied = [
            name
            for name in DIAGNOSES
            if name in applicable and applicable[name]["residual"] <= applicable[best]["residual"] + NOISE * tolerance
        ]
        return tied[0], applicable[tied[0]]["residual"], True
    euler = applicable.get(INTEGRATION)
    if (
        euler is not None
        and raw <= euler["effect"]
        and (smallest_input_effect is None or raw <= INTEGRATION_SMALL * smallest_input_effect)
    ):
        return INTEGRATION, raw, False
    return UNEXPLAINED, applicable[best]["residual"] if best is not None else raw, False
