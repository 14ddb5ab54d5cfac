"""Arm dynamics: pure numpy and math, nothing that draws."""

from .hand import hand_from_trig, hand_xy, hand_xy_arm_sine, hand_xy_arrays
from .integrators import INTEGRATOR_NAMES, SCHEMES, Integrator, UnknownIntegratorError
from .onejoint import OneJointArm
from .params import (
    GAME_ARM,
    PENDULUM,
    TUTORIAL_ARM,
    OneJointParams,
    ParameterError,
    TwoJointParams,
)
from .twojoint import TwoJointArm, UnreachableError

__all__ = [
    "GAME_ARM",
    "INTEGRATOR_NAMES",
    "PENDULUM",
    "SCHEMES",
    "TUTORIAL_ARM",
    "Integrator",
    "OneJointArm",
    "OneJointParams",
    "ParameterError",
    "TwoJointArm",
    "TwoJointParams",
    "UnknownIntegratorError",
    "UnreachableError",
    "hand_from_trig",
    "hand_xy",
    "hand_xy_arm_sine",
    "hand_xy_arrays",
]
