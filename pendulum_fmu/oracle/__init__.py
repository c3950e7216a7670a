"""The independent reference: the pendulum's equation integrated on its own, not through the FMU.

_reference reads a signal itself (_exact_signal: exact times, its own CSV reader, the pieces of
linear torque) and integrates it by the equation's Taylor series (_taylor.py,
held to scipy's solve_ivp and to closed forms by tests/test_taylor.py; _taylor_native.c the same
stepping in C, where compiled, to the same bits); every tool, the judge and the
scenario kit are held to it. Its only use of the FMU is to read the FMU's defaults and to ask it
whether it accepts a parameter set, so that both refuse the same sets in the same words.

May import: fmu/, signals/ and the basics. Nothing that is held to it.
"""
