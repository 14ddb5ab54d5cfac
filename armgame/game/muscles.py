"""Four key-driven "muscles" mapped onto shoulder and elbow torques.

Each muscle's activation follows first-order dynamics toward 1 while its key is held and
toward 0 once released, with separate rise and decay time constants. The update is the
exact solution over one physics step, so the activation curve depends on physical time
alone: neither the frame rate nor the physics rate changes it.

No force-length or force-velocity relation: the game's muscles are torque sources, as in
the tutorial ("there is no real muscle model right now").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import UserError


@dataclass(frozen=True)
class MuscleSpec:
    name: str
    key: str
    #: Torque on (shoulder, elbow) at full activation, in N m: a row of the muscle-to-joint matrix.
    moment: tuple[float, float]
    rise_time: float = 0.08
    decay_time: float = 0.10

    def __post_init__(self) -> None:
        for label in ("rise_time", "decay_time"):
            value = getattr(self, label)
            if not (math.isfinite(value) and value > 0.0):
                raise UserError(f"muscle {self.name}: {label} must be a positive number of seconds, got {value!r}")
        if not all(math.isfinite(m) for m in self.moment):
            raise UserError(f"muscle {self.name}: moments must be finite, got {self.moment!r}")


SHOULDER_MAX_TORQUE = 1.5
ELBOW_MAX_TORQUE = 1.125

DEFAULT_MUSCLES: tuple[MuscleSpec, ...] = (
    MuscleSpec("pectoralis", "d", (SHOULDER_MAX_TORQUE, 0.0)),
    MuscleSpec("posterior deltoid", "f", (-SHOULDER_MAX_TORQUE, 0.0)),
    MuscleSpec("biceps", "j", (0.0, ELBOW_MAX_TORQUE)),
    MuscleSpec("triceps", "k", (0.0, -ELBOW_MAX_TORQUE)),
)


def remap_keys(muscles: tuple[MuscleSpec, ...], keys: str) -> tuple[MuscleSpec, ...]:
    """The same muscles on other keys, e.g. ``"asdf"`` or ``"a,s,d,f"``, in the default order."""
    names = [k.strip().lower() for k in (keys.split(",") if "," in keys else list(keys))]
    if len(names) != len(muscles) or any(not n for n in names):
        raise UserError(f"--keys needs {len(muscles)} keys (one per muscle), got {keys!r}")
    if len(set(names)) != len(names):
        raise UserError(f"--keys must name {len(muscles)} different keys, got {keys!r}")
    reserved = {"space", "tab", "escape", "p"}
    if reserved & set(names):
        raise UserError(f"--keys cannot use {', '.join(sorted(reserved & set(names)))}: the game needs them")
    return tuple(
        MuscleSpec(m.name, key, m.moment, m.rise_time, m.decay_time) for m, key in zip(muscles, names, strict=True)
    )


class MuscleLevelError(UserError, ValueError):
    """A muscle level outside 0..1 (or not a number)."""


class MuscleSet:
    """Activations of the game's four muscles, stepped at a fixed physics step ``dt``.

    Each activation moves toward its goal (1 while the key is held, 0 once released) by
    ``(goal - a) * rate`` per step, with ``rate = 1 - exp(-dt / T)``: the exact solution
    of the first-order dynamics over one step.
    """

    COUNT = 4

    def __init__(self, muscles: tuple[MuscleSpec, ...], dt: float) -> None:
        if len(muscles) != self.COUNT:
            raise UserError(f"the game has {self.COUNT} muscles, got {len(muscles)}")
        self.muscles = muscles
        self.keys = tuple(m.key for m in muscles)
        self._rise = tuple(-math.expm1(-dt / m.rise_time) for m in muscles)
        self._decay = tuple(-math.expm1(-dt / m.decay_time) for m in muscles)
        self.moments = tuple(m.moment for m in muscles)
        self.activation = [0.0] * self.COUNT
        self.goal = [0.0] * self.COUNT
        self.rate = list(self._decay)

    def command(self, index: int, on: bool) -> None:
        self.goal[index] = 1.0 if on else 0.0
        self.rate[index] = self._rise[index] if on else self._decay[index]

    def set_level(self, index: int, level: float) -> None:
        """Drive muscle ``index`` toward ``level`` (0 to 1) instead of fully on or off.

        The rate is the rise rate if the level is above the present activation, else the decay
        rate: the activation moves monotonically toward its goal and never crosses it while the
        command holds, so choosing the rate once, now, keeps the per-step update the exact
        solution. Levels 0 and 1 do exactly what ``command`` does (a key), so key play is
        unchanged.
        """
        level = float(level)
        if not 0.0 <= level <= 1.0:  # also refuses NaN
            raise MuscleLevelError(f"muscle {self.muscles[index].name}: level must be from 0 to 1, got {level!r}")
        self.goal[index] = level
        self.rate[index] = self._rise[index] if level > self.activation[index] else self._decay[index]

    def reset(self) -> None:
        self.activation = [0.0] * self.COUNT

    def torque(self) -> tuple[float, float]:
        shoulder = elbow = 0.0
        for a, (ms, me) in zip(self.activation, self.moments, strict=True):
            shoulder += a * ms
            elbow += a * me
        return shoulder, elbow

    def step(self) -> None:
        act, goal, rate = self.activation, self.goal, self.rate
        for i in range(self.COUNT):
            act[i] += (goal[i] - act[i]) * rate[i]
