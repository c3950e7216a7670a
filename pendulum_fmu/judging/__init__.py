"""A master's result file and calls, judged against the reference, the mistake named (pendulum-fmu judge).

_judge judges a result file (read by _result_file, from any tool, through a --map) and a scenario
kit; _variants integrates the candidate mistakes (a late input, a wrong integrator, ...) and
_diagnoses names the one that explains a result; _judgement is the verdict, printed or as JSON;
_regression_tools applies the FMI cross-check's regression criteria. _call_record reads a
master's calls from the FMU's call record or its own call log; _call_judge names where they
differ from the intended run (judge --calls).

May import: scenarios/, comparing/ (a result file read through a --map), oracle/, fmu/, signals/
and the basics.
"""
