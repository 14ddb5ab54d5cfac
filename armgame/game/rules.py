"""The game's rules: targets, hits, score, resets, the hidden-arm mode and the clock.

Everything is in world coordinates (metres, shoulder at the origin, x forward, y up);
the renderer maps the world's ``view`` rectangle onto the window.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from typing import NamedTuple

from ..errors import UserError
from ..limits import MAX_GAME_SECONDS
from ..physics.defaults import GAME_DT, GAME_INTEGRATOR
from ..physics.hand import hand_xy_arm_sine
from ..physics.params import GAME_ARM, TwoJointParams
from ..valid import INT64_MAX
from .muscles import DEFAULT_MUSCLES, MuscleSpec

#: The 2012 game's screen (800 x 800 px, shoulder at (400, 600), 500 px/m) in metres.
GAME_VIEW = (-0.8, 0.8, -0.4, 1.2)

#: The game arm with joint viscosity (the 2012 game had none): a tap of a key moves the arm
#: and the swing dies out within about a second instead of spinning on like a propeller.
#: A 0.2 s tap of d turns the shoulder about 50 deg. Heavier viscosity (0.6 and 0.45) made the
#: arm so slow that damping, not inertia, set every torque, and a player who ignores the
#: interaction torques did as well as one who knows them (the autopilot bots, armgame/game/bots.py).
GAME_PLAY_ARM = GAME_ARM.replace(damping1=0.36, damping2=0.27)


class GameRange(NamedTuple):
    """One kind of game setting's range, in ``unit``: from ``low`` to ``high`` in a replay (``records.replay``'s
    reader refuses a file beyond it); ``config``, where given, the range ``(low, high]`` a ``GameConfig`` takes
    (``GameConfig.__post_init__``)."""

    low: float
    high: float
    unit: str
    config: tuple[float, float] | None = None


#: The longest game a ``GameConfig`` takes, in seconds: a day (a replay holds at most ``limits.MAX_GAME_SECONDS``).
MAX_CONFIG_SECONDS = 24 * 3600.0


#: Every game setting's range (the arm's own are ``physics.params.PARAMETER_RANGES``). A replay's: wide enough
#: for any custom game a class would design, narrow enough that no setting makes the physics or the target draw
#: blow up or run for hours. A ``GameConfig`` takes more where ``config`` says, on purpose: a game a program
#: builds for itself need not be one a replay may hold (an env's game at a coarser step, a lab run's clock for
#: a person at the keys, up to a day); ``play`` and ``lab`` check their game against the replay's ranges before
#: it starts (``commands.play.check_recordable``).
GAME_RANGES: dict[str, GameRange] = {
    "dt": GameRange(1e-4, 0.02, "s", config=(0.0, 0.05)),
    # A replay's is above 0 (not from it), and at most MAX_GAME_STEPS steps long.
    "time_limit": GameRange(0.0, MAX_GAME_SECONDS, "s", config=(0.0, MAX_CONFIG_SECONDS)),
    "target_radius": GameRange(0.005, 0.5, "m", config=(0.0, math.inf)),
    "target_range": GameRange(-360.0, 360.0, "deg"),
    "start_posture": GameRange(-7.0, 7.0, "rad"),
    "view": GameRange(-20.0, 20.0, "m"),
    "moment": GameRange(-50.0, 50.0, "N m"),
    "muscle_time": GameRange(0.001, 10.0, "s"),  # rise and decay times, also at least one physics step
}


def _check_setting(kind: str, value: float, refusal: str) -> None:
    """Refuse ``value`` outside the range a ``GameConfig`` takes for ``kind`` (``GAME_RANGES``' ``config``):
    ``refusal`` says what it must be, with the range's ``{low}``, ``{high}`` and ``{unit}`` where it names them."""
    setting = GAME_RANGES[kind]
    low, high = setting.config  # type: ignore[misc]
    if not (math.isfinite(value) and low < value <= high):
        raise UserError(refusal.format(low=low, high=high, unit=setting.unit) + f", got {value!r}")


@dataclass(frozen=True)
class GameConfig:
    """Everything that defines a game; with the input timeline it determines the result."""

    arm: TwoJointParams = GAME_PLAY_ARM
    start_posture: tuple[float, float] = (math.radians(45.0), math.radians(90.0))
    time_limit: float = 60.0
    target_radius: float = 0.05
    #: Targets are drawn uniformly in this joint-space box (degrees), as in the 2012 game.
    target_shoulder_range: tuple[float, float] = (15.0, 90.0)
    target_elbow_range: tuple[float, float] = (45.0, 90.0)
    seed: int = 0
    muscles: tuple[MuscleSpec, ...] = DEFAULT_MUSCLES
    integrator: str = GAME_INTEGRATOR
    dt: float = GAME_DT
    reset_cost: int = 1
    view: tuple[float, float, float, float] = GAME_VIEW
    scene: str = "game"

    def __post_init__(self) -> None:
        _check_setting("time_limit", self.time_limit, "the game's duration must be between {low:g} and {high:g} {unit}")
        _check_setting("dt", self.dt, "the physics step must be between {low:g} and {high:g} {unit}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or not 0 <= self.seed <= INT64_MAX:
            raise UserError(f"--seed must be a whole number from 0 to 2^63 - 1, got {self.seed!r}")
        _check_setting("target_radius", self.target_radius, "the target radius must be a positive number of metres")

    @property
    def total_steps(self) -> int:
        return round(self.time_limit / self.dt)


@dataclass(frozen=True)
class Target:
    x: float
    y: float
    radius: float

    def contains(self, x: float, y: float) -> bool:
        dx, dy = x - self.x, y - self.y
        return dx * dx + dy * dy <= self.radius * self.radius


#: Where the rules see the hand of joint angles (q1, q2): ``physics.hand.hand_xy_arm_sine``, the arm's own
#: sine (``physics.trig``), + and * only, so the browser's engine (``classroom/static/engine.js``) and every
#: loop of this one find the same bits on any machine (the C library's ``math.cos`` differs between systems
#: and from JavaScript's).
hand_position = hand_xy_arm_sine


@dataclass
class Scoreboard:
    score: int = 0
    hits: int = 0
    resets: int = 0
    hit_times: list[float] = field(default_factory=list)


#: Postures one target drawing tries at most (``GameRules._draw_target``).
MAX_TRIES = 1000


class GameRules:
    """Targets, scoring and the clock; told where the hand is after every physics step."""

    def __init__(self, config: GameConfig) -> None:
        self.config = config
        self._rng = random.Random(config.seed)
        self.board = Scoreboard()
        self.arm_visible = True
        #: Postures tried by every target drawn so far: the cost of the targets, which a hit whose next
        #: target keeps landing on the hand makes 1,000 a hit (``records.replay.Replay.verify`` bounds it).
        self.tries = 0
        q1, q2 = config.start_posture
        self.target = self._draw_target(self._hand(q1, q2))

    def _hand(self, q1: float, q2: float) -> tuple[float, float]:
        p = self.config.arm
        return hand_position(p.l1, p.l2, q1, q2)

    def _draw_target(self, hand: tuple[float, float]) -> Target:
        """A target centred on the hand of a random posture: reachable by construction.

        Its whole disc must be on screen, and it must not appear on top of the hand.
        """
        c = self.config
        xmin, xmax, ymin, ymax = c.view
        r = c.target_radius
        # Squared distances, not math.dist: CPython's own norm (vector_norm), which JavaScript would have to copy.
        clear = 3.0 * r
        clear2 = clear * clear
        hx, hy = hand
        best, best_distance = None, -1.0
        for tries in range(1, MAX_TRIES + 1):
            q1 = math.radians(self._rng.uniform(*c.target_shoulder_range))
            q2 = math.radians(self._rng.uniform(*c.target_elbow_range))
            x, y = self._hand(q1, q2)
            if not (xmin + r <= x <= xmax - r and ymin + r <= y <= ymax - r):
                continue
            dx, dy = x - hx, y - hy
            distance = dx * dx + dy * dy
            if distance > clear2:
                self.tries += tries
                return Target(x, y, r)
            if distance > best_distance:
                best, best_distance = Target(x, y, r), distance
        self.tries += MAX_TRIES
        if best is None:
            raise UserError("no target fits on screen with these settings (target radius or ranges too large)")
        return best  # the ranges are too narrow to keep clear of the hand: the farthest one found

    def hand_moved(self, x: float, y: float, t: float) -> bool:
        """Score a hit if the hand is on the target; returns whether it was."""
        if self.target.contains(x, y):
            self.board.score += 1
            self.board.hits += 1
            self.board.hit_times.append(t)
            self.target = self._draw_target((x, y))
            return True
        return False

    def reset_penalty(self) -> None:
        self.board.resets += 1
        self.board.score = max(0, self.board.score - self.config.reset_cost)

    def toggle_arm(self) -> None:
        self.arm_visible = not self.arm_visible


class DwellRules(GameRules):
    """The game's rules with a dwell: a hit counts once the hand has stayed in the target ``hold_steps``
    physics steps in a row (``armgame/ReachHold-v1``).

    Both of the session's loops call ``hand_moved`` after every step that ends with the hand in the
    target, and only then, so a gap in the steps seen here is a step outside: the dwell starts again.
    Staying in a target of radius ``r`` for a time ``T`` holds the hand's mean speed over the dwell
    below ``2 r / T``: a hand that flies through scores nothing.
    """

    def __init__(self, config: GameConfig, hold_steps: int) -> None:
        if isinstance(hold_steps, bool) or not isinstance(hold_steps, int) or hold_steps < 1:
            raise UserError(f"the dwell must be a whole number of physics steps from 1, got {hold_steps!r}")
        super().__init__(config)
        self.hold_steps = hold_steps
        self.dwell = 0
        self._last_step = -2

    def dwell_at(self, step: int) -> int:
        """The physics steps in a row the hand has stayed in the target as of step ``step`` (0: it is not in it
        after that step)."""
        return self.dwell if self._last_step == step else 0

    def hand_moved(self, x: float, y: float, t: float) -> bool:
        if not self.target.contains(x, y):
            return False
        step = round(t / self.config.dt)
        self.dwell = self.dwell + 1 if step == self._last_step + 1 else 1
        self._last_step = step
        if self.dwell < self.hold_steps:
            return False
        self.dwell, self._last_step = 0, -2
        return super().hand_moved(x, y, t)

