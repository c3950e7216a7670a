"""The independent reference: the pendulum's equation integrated with scipy, not through the FMU.

_reference reads a signal itself and integrates it with solve_ivp; every tool, the judge and the
scenario kit are held to it. Its only use of the FMU is to read the FMU's defaults and to ask it
whether it accepts a parameter set, so that both refuse the same sets in the same words.

May import: fmu/, signals/ and the basics. Nothing that is held to it.
"""
