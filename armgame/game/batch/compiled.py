"""The compiled batch kernel: the batched game's hot loop in C, optional, and exact.

``_ckernel`` (``_ckernel.c``, built by ``pip install`` where a C compiler exists) runs each
game of a batch from its step to a halt step in registers: the muscles, RK4 and the hand's
slack, with the muscle keys' commands applied at their steps. It stops a game early only
when its hand may be on its target, and the batch judges that with the single session's own
test and rules (``BatchGameSession._hit_test``). Its arithmetic is the single session's,
operation for operation, with the C library's cos and sin, which Python's ``math`` calls too:
a batched game is the single game bit for bit (tests/test_batch.py checks states with ``==``).
With ``fast`` (``BatchGameSession(exact=False)``, games up to 60 s) RK4's elbow cos and sin
come by angle addition instead, as numpy's fast kernel takes them: round-off, within
``batch.STATE_TOLERANCE`` (tests/test_batch_fast.py runs both kernels).

Where it was not built (no compiler) or is stale, ``AVAILABLE`` is False and the batch runs
its numpy kernel: the same results, slower. It runs RK4, the game's integrator; batches of the
Euler schemes go through numpy.

Speed (``python benchmarks/class_speed.py``): see the README's "Performance" section.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...physics.batch import SERIES_LIMIT
from ...physics.integrators import _SIXTH

try:
    from .. import _ckernel
except ImportError:  # built without a C compiler: numpy does the work
    _ckernel = None

if TYPE_CHECKING:
    from .session import BatchGameSession

#: The calling convention this module speaks; a build of another (a stale ``.so``) is not used.
KERNEL_VERSION = 2
_PARAMS = 26



def speaks_our_convention(module: object) -> bool:
    """Whether a built ``_ckernel`` is the one this module calls (not a stale build of another)."""
    return getattr(module, "VERSION", None) == KERNEL_VERSION and getattr(module, "PARAMS", None) == _PARAMS


if _ckernel is not None and not speaks_our_convention(_ckernel):
    _ckernel = None

#: Whether the compiled kernel is here to use.
AVAILABLE = _ckernel is not None

#: A hand this close to a target's edge (relative to radius^2) goes to the exact scalar test.
NEAR = 1.0 + 1e-6


def hand_move_bounds(l1: float, l2: float) -> tuple[float, float]:
    """(c1, c2) with |the hand's move| <= c1 |dq1| + c2 |dq2|: chords are shorter than arcs; a hair over."""
    return (l1 + l2) * (1.0 + 1e-9), l2 * (1.0 + 1e-9)


@dataclass
class MuscleEvents:
    """Muscle commands by game: game i's are ``cursor[i]:end[i]`` of the flat arrays, by step.

    ``cursor`` advances as the kernel applies them (an event at step s applies before the
    step from s, as ``BatchGameSession.play`` applies it).
    """

    cursor: np.ndarray  # int64 (n,)
    end: np.ndarray  # int64 (n,)
    step: np.ndarray  # int64 (events,)
    muscle: np.ndarray  # int64 (events,), 0-3
    goal: np.ndarray  # float64 (events,)
    rate: np.ndarray  # float64 (events,)

    @classmethod
    def none(cls, n: int) -> MuscleEvents:
        zeros = np.zeros(n, dtype=np.int64)
        return cls(zeros, zeros.copy(), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                   np.zeros(0), np.zeros(0))

    @classmethod
    def by_game(cls, n: int, steps: np.ndarray, flat: np.ndarray, goal: np.ndarray,
                rate: np.ndarray) -> MuscleEvents:
        """From ``BatchGameSession._schedule``'s commands: by game, within a game by step, flat
        indices ``muscle * n + game``."""
        muscle, game = np.divmod(flat, n)
        end = np.cumsum(np.bincount(game, minlength=n), dtype=np.int64)
        cursor = np.concatenate([[0], end[:-1]]).astype(np.int64)
        return cls(cursor, end, steps.astype(np.int64), muscle.astype(np.int64), goal.astype(float),
                   rate.astype(float))


class CompiledKernel:
    """Runs a ``BatchGameSession``'s games to given steps with ``_ckernel``, on the batch's own arrays."""

    def __init__(self, batch: BatchGameSession, fast: bool = False) -> None:
        if _ckernel is None:
            raise RuntimeError("the compiled kernel is not built (reinstall with a C compiler: pip install -e .)")
        self.batch = batch
        #: RK4's elbow trig by angle addition (round-off, not bit for bit; see ``_ckernel.c``).
        self.fast = bool(fast)
        model, config = batch.model, batch.config
        p = model.params
        dt, radius = config.dt, config.target_radius
        self.mode = 2 if p.has_gravity else 1 if p.has_damping else 0
        # The order of _ckernel.c's P_* enum.
        self.params = np.array([
            dt, 0.5 * dt, dt * _SIXTH, model.b, model.d, model.a * model.d - model.d * model.d, model.a - model.d,
            model.g1, model.g2, p.damping1, p.damping2,
            p.l1, p.l2, radius, NEAR * radius * radius, *hand_move_bounds(p.l1, p.l2), SERIES_LIMIT * SERIES_LIMIT,
            *batch._shoulder, *batch._elbow,
        ], dtype=float)
        assert len(self.params) == _PARAMS
        self.flags = np.zeros(batch.n, dtype=np.uint8)
        self.no_events = MuscleEvents.none(batch.n)

    def run(self, halt: np.ndarray, events: MuscleEvents | None = None) -> None:
        """Every game ``i`` to step ``halt[i]`` (none past its end), its hits scored on the way."""
        b = self.batch
        ev = self.no_events if events is None else events
        halt = np.ascontiguousarray(halt, dtype=np.int64)
        while _ckernel.run(self.params, self.mode, self.fast, b.n, b._xs, b._act, b._goal, b._rate, b._slack,
                           b.target_x, b.target_y, b.steps, halt, ev.cursor, ev.end, ev.step, ev.muscle, ev.goal,
                           ev.rate, self.flags):
            for i in np.flatnonzero(self.flags).tolist():
                b._hit_test(i, b._x[:, i], int(b.steps[i]))
