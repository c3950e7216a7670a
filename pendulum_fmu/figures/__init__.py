"""Every figure the package draws: runs overlaid, their differences, a sweep's cases, a judgement.

_plot draws them; a long run comes to it thinned (pendulum_fmu._drawn_points: every extreme kept).

matplotlib is imported here and only here, and only by a command that draws.

May import: fmu/ (the units and parameters in the labels) and the basics. It draws what it is
given (runs, a judgement, a sweep's cases) and imports none of the jobs that give them.
"""
