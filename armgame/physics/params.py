"""Arm parameters as validated, immutable values.

Conventions used everywhere in armgame (see README "Conventions"):
the shoulder sits at the origin, x points forward, y points up, lengths are in metres,
angles in radians. The shoulder angle q1 is measured from the +x axis, counter-clockwise;
the elbow angle q2 is measured from the upper arm's direction, counter-clockwise. Gravity,
when on, pulls along -y.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import UserError


class ParameterError(UserError, ValueError):
    """An impossible physical parameter; the message names the field and the value."""


#: Plausible range of every physical parameter (low, high, unit), checked whenever an arm is built.
#: Far wider than any human or robot arm, yet narrow enough that the dynamics stay well
#: conditioned: a mass or inertia of 1e-300 would make the mass matrix singular to round-off.
PARAMETER_RANGES: dict[str, tuple[float, float, str]] = {
    "l": (0.01, 10.0, "m"),  # link lengths
    "r": (0.001, 10.0, "m"),  # centre of mass from the proximal joint (also at most the link's length)
    "m": (0.01, 1000.0, "kg"),
    "i": (1e-5, 1000.0, "kg m^2"),  # about the centre of mass
    "gravity": (0.0, 100.0, "m/s^2"),
    "damping": (0.0, 100.0, "N m s/rad"),
}


def _check_range(name: str, value: float, kind: str) -> None:
    low, high, unit = PARAMETER_RANGES[kind]
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    if not (math.isfinite(value) and low <= value <= high):
        raise ParameterError(f"{name} must be from {low:g} to {high:g} {unit}, got {value!r}")


def _kind(name: str) -> str:
    return name if name == "gravity" else "damping" if name.startswith("damping") else name[0]


@dataclass(frozen=True)
class TwoJointParams:
    """A planar two-link arm: upper arm (1) and forearm (2).

    r1 and r2 are the distances from the proximal joint to each link's centre of mass;
    i1 and i2 are moments of inertia about the centres of mass. ``gravity`` is the
    acceleration along -y (0 for an arm moving in the horizontal plane), and
    ``damping1``/``damping2`` are viscous joint damping coefficients in N m s/rad.
    """

    l1: float
    l2: float
    r1: float
    r2: float
    m1: float
    m2: float
    i1: float
    i2: float
    gravity: float = 0.0
    damping1: float = 0.0
    damping2: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            _check_range(f.name, getattr(self, f.name), _kind(f.name))
        for com, length in (("r1", "l1"), ("r2", "l2")):
            if getattr(self, com) > getattr(self, length):
                raise ParameterError(
                    f"{com} must not exceed {length} (the centre of mass lies on the link), "
                    f"got {com}={getattr(self, com)!r} > {length}={getattr(self, length)!r}"
                )

    @property
    def has_gravity(self) -> bool:
        return self.gravity != 0.0

    @property
    def has_damping(self) -> bool:
        return self.damping1 != 0.0 or self.damping2 != 0.0

    @property
    def reach(self) -> float:
        return self.l1 + self.l2

    def replace(self, **changes: float) -> TwoJointParams:
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        unknown = set(changes) - set(values)
        if unknown:
            raise ParameterError(f"unknown arm parameter(s): {', '.join(sorted(unknown))}")
        values.update(changes)
        return TwoJointParams(**values)

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class OneJointParams:
    """A single link rotating about the origin (the tutorial's pendulum)."""

    l: float  # noqa: E741 - the tutorial's name for the link length
    r: float
    m: float
    i: float
    gravity: float = 9.81
    damping: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            _check_range(f.name, getattr(self, f.name), _kind(f.name))
        if self.r > self.l:
            raise ParameterError(
                f"r must not exceed l (the centre of mass lies on the link), got r={self.r!r} > l={self.l!r}"
            )

    def replace(self, **changes: float) -> OneJointParams:
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        unknown = set(changes) - set(values)
        if unknown:
            raise ParameterError(f"unknown arm parameter(s): {', '.join(sorted(unknown))}")
        values.update(changes)
        return OneJointParams(**values)

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


STANDARD_GRAVITY = 9.81

#: The tutorial's passive two-joint arm (twojointarm_passive.py), in a vertical plane.
TUTORIAL_ARM = TwoJointParams(
    l1=0.3384, l2=0.4554, r1=0.1692, r2=0.2277, m1=2.10, m2=1.65, i1=0.025, i2=0.075,
    gravity=STANDARD_GRAVITY,
)

#: The 2012 game's arm: horizontal plane (no gravity), centres of mass at mid-link.
GAME_ARM = TwoJointParams(
    l1=0.34, l2=0.46, r1=0.17, r2=0.23, m1=2.1, m2=1.65, i1=0.025, i2=0.075, gravity=0.0,
)

#: The tutorial's one-joint passive arm. Its text gives no link length; the animation uses 0.5 m.
PENDULUM = OneJointParams(l=0.5, r=0.5, m=1.65, i=0.025, gravity=STANDARD_GRAVITY)

TWO_JOINT_PRESETS: dict[str, TwoJointParams] = {"tutorial": TUTORIAL_ARM, "game": GAME_ARM}
