"""A master's result file and calls, judged against the reference, the mistake named (pendulum-fmu judge).

_judge judges a result file (read by _result_file a block at a time, from any tool, through a
--map) and a scenario kit, walking the run a window at a time (_window_walk); _variants integrates
the candidate mistakes (a late input, a wrong integrator, ...) window by window and _diagnoses
names the one that explains a result; _judgement is the verdict, printed or as JSON;
_regression_tools applies csv-compare's and the FMI cross-check's criteria to the rows
_theta_series spills. _call_record reads a
master's calls from the FMU's call record or its own call log; _call_judge names where they
differ from the intended run (judge --calls).

May import: scenarios/, comparing/ (a result file read through a --map), oracle/, fmu/, signals/
and the basics.
"""
