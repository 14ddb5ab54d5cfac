"""The harder tasks' physics in a batch: motor noise, a field at the hand and the speed guard.

Owns what ``armgame.game.variant.GameVariant`` adds to a batch's games beyond the dwell (which
``BatchGameSession`` keeps with its rules): each game's muscle moments under motor noise
(``BatchMuscleNoise``), the compiled kernel's ``loads`` (the field and the guard), and which games the
guard stopped, with why, and the state each is put back to. The compiled kernel's lanes step it
(``_clanes.c``'s loaded step); the numpy kernel does not, so a batch with noise or a field needs the
compiled kernel (``needs_compiled``).

Invariant: game ``i`` equals the single ``GameVariant.session`` fed the same inputs with its
``MuscleNoise`` applied before each decision (``apply_noise``, one call per ``advance`` of the batch,
as the env calls ``MuscleNoise.apply`` once per step):

* the noise: game ``i``'s stream is ``MuscleNoise``'s own generator, seeded from the game's seed, and
  its normals are the same draws in the same order (``Generator.standard_normal`` of ``4 k`` values is
  ``k`` calls of 4), drawn ``BLOCK`` decisions ahead; the state's update, the factors' clip and the
  moments' products are ``MuscleNoise.apply``'s operations on arrays, each one IEEE operation;
* the field: the kernel adds ``J(q)^T F(v)`` at every RK4 stage as ``physics.loads`` does, operation for
  operation (the exact kernel with the C library's cos and sin, which Python's ``math`` calls; the fast
  kernel with the arm's own, within an ulp: round-off, as the fast kernel's elbow);
* the guard: a game whose joint speed passes ``speed_limit`` after a physics step stops; it is put back
  to its state, activations and step at the start of the ``advance`` (``keep``), where
  ``GameSession.advance`` leaves a game whose step raised ``RunawayError``; its hits before that step stay,
  and ``reasons[i]`` is the single game's message.
"""

from __future__ import annotations

import math

import numpy as np

from ..variant import (
    FIELD_CODES,
    NOISE_CORRELATION_TIME,
    NOISE_FACTOR_MAX,
    GameVariant,
    noise_generator,
    runaway_message,
)

#: The kernel's flag of a game the guard stopped (``_ckernel.h``'s FLAG_RUNAWAY).
FLAG_RUNAWAY = 2


class BatchMuscleNoise:
    """``MuscleNoise`` for every game of a batch: ``start`` a game's stream, then ``factors()`` before each decision.

    The normals come from each game's own generator ``BLOCK`` decisions at a time (a Python call per game
    and block, not per decision), into rows that every game reads at the same position: a game started
    mid-block fills the rest of the block from its first draws."""

    #: Decisions drawn at once for each game: 8,192 games refill in about 25 ms, once in 64 steps.
    BLOCK = 64
    #: The memory a game's noise takes at most (its block of normals, state, moments and generator): ReachNoisy-v1's
    #: vector env took 3.1 KB a game more than Reach-v1's at 20,000 and 60,000 games (peak RSS), rounded up.
    BYTES_PER_GAME = 4 * 1024

    def __init__(self, level: float, decision_time: float, n: int) -> None:
        self.level = level
        self._keep = math.exp(-decision_time / NOISE_CORRELATION_TIME)
        self._fresh = level * math.sqrt(1.0 - self._keep * self._keep)
        self._generators: list[np.random.Generator | None] = [None] * n
        #: Every game's noise state, (n, 4) (a game's row is ``MuscleNoise.state``).
        self.state = np.zeros((n, 4))
        # A game's block is one contiguous row, which its generator fills in place (a strided copy of each
        # game's draws was half the refill's time).
        self._normals = np.zeros((n, self.BLOCK, 4))
        self._row = 0  # the block's row the next decision reads

    def start(self, i: int, seed: int) -> None:
        """Game ``i`` begins with the seed ``seed``: its generator, its stationary first state, its block's rest."""
        generator = self._generators[i] = noise_generator(seed)
        left = self.BLOCK - self._row
        drawn = generator.standard_normal(4 + 4 * left)
        self.state[i] = drawn[:4] * self.level
        self._normals[i, self._row:] = drawn[4:].reshape(left, 4)

    def factors(self) -> np.ndarray:
        """Every game's next decision's factors on its muscles' moments, (n, 4): ``MuscleNoise.apply``'s."""
        if self._row == self.BLOCK:
            normals = self._normals.reshape(len(self._generators), -1)
            for i, generator in enumerate(self._generators):
                if generator is not None:
                    generator.standard_normal(out=normals[i])
            self._row = 0
        normals = self._normals[:, self._row]
        self._row += 1
        state = self.state
        state *= self._keep
        state += self._fresh * normals
        return np.clip(1.0 + state, 0.0, NOISE_FACTOR_MAX)


class BatchVariant:
    """A batch's noise, field and guard (see the module's docstring); ``None`` parts where the variant has none."""

    def __init__(self, variant: GameVariant, dt: float, n: int, shoulder: tuple[float, ...],
                 elbow: tuple[float, ...]) -> None:
        self.variant = variant
        self._shoulder = np.array(shoulder)[:, None]
        self._elbow = np.array(elbow)[:, None]
        #: Each game's muscle moments (8, n), rows shoulder then elbow, for the kernel; None without noise.
        self.moments: np.ndarray | None = None
        self.noise: BatchMuscleNoise | None = None
        if variant.motor_noise:
            self.moments = np.empty((8, n))
            self.moments[:4] = self._shoulder
            self.moments[4:] = self._elbow
            self.noise = BatchMuscleNoise(variant.motor_noise, variant.decision_steps * dt, n)
        #: The kernel's loads (kind, four parameters, the guard), or None: no field and no guard.
        self.loads: np.ndarray | None = None
        if variant.field is not None or math.isfinite(variant.speed_limit):
            self.loads = np.array((FIELD_CODES[variant.field], *variant.field_parameters, variant.speed_limit),
                                  dtype=float)
        #: Games the guard stopped (over until restarted), and the single game's message for each.
        self.stopped = np.zeros(n, dtype=bool)
        self.reasons: dict[int, str] = {}
        self._kept: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def guarded(self) -> bool:
        return self.loads is not None and math.isfinite(float(self.loads[5]))

    @staticmethod
    def needs_compiled(variant: GameVariant | None) -> bool:
        """Whether a batch of ``variant`` needs the compiled kernel (its noise or field)."""
        return variant is not None and (bool(variant.motor_noise) or variant.field is not None
                                        or math.isfinite(variant.speed_limit))

    def start(self, i: int, seed: int) -> None:
        """Game ``i`` begins (seed ``seed``): not stopped, its noise's stream from its seed."""
        self.stopped[i] = False
        self.reasons.pop(i, None)
        if self.noise is not None:
            self.noise.start(i, seed)

    def apply_noise(self) -> None:
        """The decision's noise on every game's moments (``MuscleNoise.apply`` for each)."""
        if self.noise is None or self.moments is None:
            return
        factors = self.noise.factors().T
        np.multiply(factors, self._shoulder, out=self.moments[:4])
        np.multiply(factors, self._elbow, out=self.moments[4:])

    def keep(self, x: np.ndarray, act: np.ndarray, steps: np.ndarray) -> None:
        """The games' state, activations and steps at an ``advance``'s start: where a runaway puts its game back."""
        if self.guarded:
            self._kept = x[:4].copy(), act.copy(), steps.copy()

    def runaway(self, i: int, x: np.ndarray, act: np.ndarray, steps: np.ndarray) -> None:
        """The kernel stopped game ``i`` at the guard with the state of the step that passed it (in ``x``): its
        message from that state, then the game put back and stopped."""
        limit = float(self.variant.speed_limit)
        self.reasons[i] = runaway_message(limit, float(x[2, i]), float(x[3, i]))
        if self._kept is not None:
            kept_x, kept_act, kept_steps = self._kept
            x[:4, i], act[:, i], steps[i] = kept_x[:, i], kept_act[:, i], kept_steps[i]
        self.stopped[i] = True
