"""Classroom demonstrations of the tutorial's ideas.

The modules here hold the pure logic (runs, the minimum-jerk reach, the torque split, figures through
matplotlib when asked); only ``window`` imports pygame. This file stays import-light so that the command
line can list the demos without loading numpy.
"""

DEMO_NAMES = ("pendulum", "passive", "chaos", "interaction", "planning")
