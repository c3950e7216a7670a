"""The pendulum and the PID controller in a closed loop, and the SSP file a master runs it from.

_closed_loop is the loop (in fmpy's container, and its sampled reference); _ssp writes and reads
the System Structure and Parameterization file (pendulum-fmu export-ssp); _ssp_masters runs it
through the masters that read SSP; _ssp_judge judges their coupling and _ssp_calls their calls;
_ssp_kit adds the closed loop to the scenario kit.

May import: judging/, scenarios/, oracle/ (the closed loop's reference integrates as it does),
fmu/, the basics and the top's own names (default_fmu, the packaged PID controller).
"""
