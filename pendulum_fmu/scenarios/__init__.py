"""The scenario kit a master's vendor runs, and the judge reads back (pendulum-fmu scenarios).

_scenario_list is the scenarios; _scenario_settings reads and writes each one's NAME.json;
_scenarios writes the kit: the FMU, the settings, the torque inputs and the reference results.

May import: oracle/, fmu/, signals/, the basics and the top's own names (__version__). The judge
reads the kit; the kit knows nothing of the judge.
"""
