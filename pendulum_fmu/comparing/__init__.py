"""One torque signal through several tools, each judged by the reference (pendulum-fmu compare).

_compare runs the tools and tabulates their differences; _compare_tools names the tools --tools
takes (the FMU, the reference, engines/, any FMU through a --map: _mapped_fmu); _demo is the
OpenSim tutorial end to end (a comparison, then a parameter study).

May import: engines/, oracle/, figures/, fmu/, signals/, sweep/ (the demo's study) and the basics.
"""
