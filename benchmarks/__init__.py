"""Performance benchmarks of the pendulum FMU (issue 5): run them with python -m benchmarks.

Every comparison is measured side by side in one run and reported as a ratio; the FMU's own
cost is counted in instructions by callgrind, which a noisy machine does not disturb.
"""
