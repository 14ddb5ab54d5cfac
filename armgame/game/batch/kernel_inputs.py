"""What a batch's kernels and its schedule read of it: two values the session builds once.

Owns the interface between ``BatchGameSession`` and the code that steps it (``numpy_kernel``,
``compiled``, ``schedule``). Before it, each of those imported the session's class for its type and
read nine of its private attributes; now they import nothing from ``session`` and are handed:

* ``KernelInputs``: the batch's fixed numbers (the arm, the shared configuration, the muscles' moment
  arms, rise and decay rates, the Euler schemes' step, whether the fast stages may run);
* ``BatchArrays``: the batch's state arrays, which the compiled kernel steps in place (the numpy
  kernel is handed its arrays call by call, compact copies of some games' columns).

Invariant: both are made in ``BatchGameSession.__init__`` and never replaced (the session changes
the arrays' contents only), so a kernel built on them sees the batch as it is.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...physics.twojoint import TwoJointArm
from ..rules import GameConfig

#: The batch's hit test and scoring of game ``i`` after step ``step`` from its state column; True on a hit.
HitTest = Callable[[int, np.ndarray, int], bool]
#: The batch's handling of game ``i``, which the speed guard stopped (``variant.BatchVariant.runaway``).
Runaway = Callable[[int], None]


@dataclass(frozen=True)
class KernelInputs:
    """The batch's fixed numbers, as its kernels and schedule read them."""

    #: The arm's model (its constants ``b``, ``d``, ``a``, ``g1``, ``g2``) and the configuration every game
    #: shares (``dt``, the integrator, the arm's lengths, the targets' radius).
    model: TwoJointArm
    config: GameConfig
    #: Each muscle's moment arm at the shoulder and at the elbow (m), in the muscle keys' order.
    shoulder: tuple[float, ...]
    elbow: tuple[float, ...]
    #: The muscle keys, and each muscle's per-step activation rate when pressed (rise) and released (decay).
    muscle_keys: tuple[str, ...]
    rise: np.ndarray
    decay: np.ndarray
    #: ``Integrator(config.integrator, model, "numpy").step_components``: the Euler schemes' step.
    physics_step: Callable
    #: Whether the kernels may run their fast RK4 stages (round-off within ``session.STATE_TOLERANCE``).
    fast: bool
    #: The numpy kernel's fast stages run from this many games, and take an elbow increment up to
    #: ``series_limit`` (rad) by series (``session.SERIES_MIN_GAMES``, ``physics.batch.SERIES_LIMIT``,
    #: read when the batch was made, so a test that lowers them holds for that batch).
    series_from: int
    series_limit: float


@dataclass(frozen=True)
class BatchArrays:
    """The batch's state, one array per quantity, columns by game (the compiled kernel's in-out arguments)."""

    #: Rows q1, q2, w1, w2, then two rows of scratch (the first RK4 stage's accelerations).
    xs: np.ndarray
    #: (4, n) activations, their goals and rates.
    act: np.ndarray
    goal: np.ndarray
    rate: np.ndarray
    #: A lower bound on each hand's distance from its target's disc (m); negative: measure it.
    slack: np.ndarray
    target_x: np.ndarray
    target_y: np.ndarray
    #: Each game's step count (int64).
    steps: np.ndarray
    #: The hand's trig and the angles it is of, (6, n) (see ``BatchGameSession.hand_trig``).
    trig: np.ndarray
    #: The harder tasks' physics (``variant.BatchVariant``), for the compiled kernel: each game's muscle moments
    #: (8, n) under motor noise, and the field and guard (6,); None where the batch's games have none.
    moments: np.ndarray | None = None
    loads: np.ndarray | None = None

    @property
    def n(self) -> int:
        return self.xs.shape[1]
