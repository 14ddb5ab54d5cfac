"""Named physics scenes: an arm, where it starts, and the torques applied to it.

A scene is pure physics (no game rules): ``armgame simulate``, the benchmarks and the
tests all draw from this one list.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any

from .errors import UserError
from .physics.onejoint import OneJointArm
from .physics.params import GAME_ARM, PENDULUM, TUTORIAL_ARM
from .physics.twojoint import TwoJointArm
from .words import unknown_name


@dataclass(frozen=True)
class Scene:
    name: str
    description: str
    model: Any
    initial: tuple[float, float, float, float]
    #: (start time, (shoulder torque, elbow torque)) pairs, each held until the next.
    torque_segments: tuple[tuple[float, tuple[float, float]], ...] = ((0.0, (0.0, 0.0)),)
    duration: float = 10.0
    joints: int = 2

    def torque_at(self, t: float) -> tuple[float, float]:
        current = self.torque_segments[0][1]
        for start, torque in self.torque_segments:
            if t >= start:
                current = torque
            else:
                break
        return current

    @property
    def free_after(self) -> float:
        """The time from which no torque acts, so energy must hold (inf if never)."""
        last_start, last = self.torque_segments[-1]
        return last_start if last == (0.0, 0.0) else math.inf


def _tutorial_passive() -> Scene:
    # The tutorial's a1 = 0 (hanging) is q1 = -pi/2 here; elbow at 90 deg puts the hand at (l2, -l1).
    return Scene(
        "passive",
        "the tutorial's passive two-joint arm under gravity: upper arm hanging, elbow at 90 deg",
        TwoJointArm(TUTORIAL_ARM),
        (-math.pi / 2, math.pi / 2, 0.0, 0.0),
        duration=10.0,
    )


def _pendulum() -> Scene:
    return Scene(
        "pendulum",
        "the tutorial's one-joint passive arm released from 90 deg (horizontal)",
        OneJointArm(PENDULUM),
        (0.0, 0.0, 0.0, 0.0),
        duration=10.0,
        joints=1,
    )


def _propeller() -> Scene:
    return Scene(
        "propeller",
        "game arm in the horizontal plane spun up by 2.0 / -1.5 N m for 3 s, then free",
        TwoJointArm(GAME_ARM),
        (math.pi / 4, math.pi / 2, 0.0, 0.0),
        torque_segments=((0.0, (2.0, -1.5)), (3.0, (0.0, 0.0))),
        duration=63.0,
    )


def _upright() -> Scene:
    return Scene(
        "upright",
        "the tutorial's arm straight up under gravity, 0.01 rad off the unstable equilibrium",
        TwoJointArm(TUTORIAL_ARM),
        (math.pi / 2 + 0.01, 0.0, 0.0, 0.0),
        duration=10.0,
    )


def _stiff() -> Scene:
    arm = GAME_ARM.replace(m2=0.2, i2=0.002, damping1=2.0, damping2=2.0)
    return Scene(
        "stiff",
        "heavy joint damping (2 N m s/rad) and a light forearm, pushed for 0.5 s: stiff for explicit schemes",
        TwoJointArm(arm),
        (math.pi / 4, math.pi / 2, 0.0, 0.0),
        torque_segments=((0.0, (1.0, -0.5)), (0.5, (0.0, 0.0))),
        duration=5.0,
    )


#: Seed of the game scene's key script: fixed, so every run and every machine sees the same presses.
GAME_SCRIPT_SEED = 2012
GAME_SCRIPT_DURATION = 60.0


def game_torque_script(
    seed: int = GAME_SCRIPT_SEED, duration: float = GAME_SCRIPT_DURATION
) -> tuple[tuple[float, tuple[float, float]], ...]:
    """Piecewise-constant torques that mimic a player's key presses, then zero from ``duration`` on.

    Each joint's flexor or extensor is held (or neither) at 0.5 to 1 N m for 0.2 to 0.8 s.
    Switches fall on multiples of 0.2 s, which every benchmark step (1/30 s to 1/4000 s)
    lands on exactly, so a step never straddles a switch and each scheme shows its own order.
    """
    rng = random.Random(seed)
    segments: list[tuple[float, tuple[float, float]]] = []
    tick = 0  # in units of 0.2 s, kept integral so start times are exact multiples
    while tick * 0.2 < duration - 1e-9:
        torque = tuple(rng.choice((-1.0, 0.0, 1.0)) * round(rng.uniform(0.5, 1.0), 3) for _ in range(2))
        segments.append((round(tick * 0.2, 10), (torque[0] + 0.0, torque[1] + 0.0)))
        tick += rng.randint(1, 4)
    segments.append((duration, (0.0, 0.0)))
    return tuple(segments)


def _game() -> Scene:
    return Scene(
        "game",
        "the game's arm (horizontal plane) driven for 60 s by a fixed, seeded script of key-like torque presses",
        TwoJointArm(GAME_ARM),
        (math.pi / 4, math.pi / 2, 0.0, 0.0),
        torque_segments=game_torque_script(),
        duration=GAME_SCRIPT_DURATION,
    )


SCENES = {s.name: s for s in (_tutorial_passive(), _pendulum(), _propeller(), _upright(), _stiff(), _game())}


def get_scene(name: str) -> Scene:
    try:
        return SCENES[name]
    except KeyError:
        raise UserError(unknown_name("scene", name, SCENES)) from None
