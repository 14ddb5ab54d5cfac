"""Many games in lockstep: a class's scripts, a batch of replays, a vector of environments.

``BatchGameSession`` runs N games at once with one numpy array per quantity (joint state,
activations, targets, clocks), so a physics step of a thousand games costs about as many
numpy operations as a step of one. Each game of a batch equals the single ``GameSession``
fed the same inputs: hits, score, resets and steps exactly, and its joint state to
round-off. How that holds:

* The physics is the single session's own step function, ``Integrator(name, model,
  "numpy")``: the very same closures with numpy's sin and cos, so every array element goes
  through the same IEEE operations in the same order as the Python floats of one game. Where
  numpy's float64 sin and cos are the C library's (checked on x86-64 with AVX2, numpy 2.4:
  identical on 6 million arguments), a batched game is bit for bit the single one. Where numpy
  uses its own vectorised sin and cos (AVX-512 builds), they may differ by an ulp, and the
  states differ by round-off: ``STATE_TOLERANCE`` bounds that over a 60 s game.
* The hit test never depends on numpy's round-off: numpy only flags games whose hand is
  within a relative 1e-6 of a target's edge, and for those (rare: the hand is on or at a
  target) the single session's own test is evaluated on Python floats from the game's state,
  and the hit is scored by the game's own ``GameRules`` (which draws the next target from
  the game's own random sequence). Given equal states the decision is identical, knife edge
  or not.
* Events (keys, resets, tab) are applied between physics steps exactly where the single
  session applies them; ``play`` advances every game to the next step at which any game has
  an event, vectorised in between.

The implicit integrators (midpoint, gauss4) iterate until the largest change over the
whole batch converges, so a game's iteration count would depend on the others: a batch
refuses them and ``replay_many`` plays such games one at a time.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import fields, replace

import numpy as np

from .. import __version__
from ..errors import UserError
from ..physics.integrators import Integrator
from ..physics.twojoint import TwoJointArm
from .muscles import MuscleLevelError, MuscleSet
from .rules import GameConfig, GameRules
from .session import DOWN, RESET_KEY, TOGGLE_ARM_KEY, GameResult, GameSession, InputEvent

#: Integrators whose batched step is the single step to round-off (no batch-wide iteration).
BATCH_INTEGRATORS = ("rk4", "euler", "symplectic-euler")

#: Fields a batch's games may differ in; every other field of ``GameConfig`` must be equal.
PER_GAME_FIELDS = ("seed", "time_limit", "scene")

#: Largest joint-state difference (rad, rad/s) from the single session over a 60 s game where
#: numpy's sin and cos are not the C library's; zero where they are (measured: tests/test_batch.py).
STATE_TOLERANCE = 1e-9

# A hand this close to a target's edge (relative to radius^2) is checked by the exact scalar test.
_NEAR = 1.0 + 1e-6


def batch_problem(configs: Sequence[GameConfig]) -> str | None:
    """Why these games cannot share one batch, or None if they can."""
    if not configs:
        return "a batch needs at least one game"
    first = configs[0]
    if first.integrator not in BATCH_INTEGRATORS:
        return (f"integrator {first.integrator!r} cannot be batched (batched: {', '.join(BATCH_INTEGRATORS)}); "
                "play such games one at a time")
    for name in (f.name for f in fields(GameConfig) if f.name not in PER_GAME_FIELDS):
        value = getattr(first, name)
        for i, c in enumerate(configs):
            if getattr(c, name) != value:
                return f"the games of a batch must share {name}: game {i} differs from game 0"
    return None


class BatchGameSession:
    """``n`` games in lockstep; game ``i`` equals ``GameSession(configs[i])`` fed the same inputs.

    Seeds, time limits and scene names may differ; everything the physics and the targets
    depend on must be equal (``UserError`` naming the field otherwise). Per-game quantities
    are arrays indexed by game: ``steps``, ``total_steps``, ``over``, ``q1 q2 w1 w2`` (rad,
    rad/s), ``activation`` and ``held`` (n, 4), ``score hits resets``, ``target_x target_y`` (m).
    Where an argument is a boolean mask ``games`` of shape (n,), only those games are touched.
    """

    def __init__(self, configs: Sequence[GameConfig]) -> None:
        configs = list(configs)
        problem = batch_problem(configs)
        if problem:
            raise UserError(problem)
        self.configs = configs
        self.config = c = configs[0]
        self.n = n = len(configs)
        self.model = TwoJointArm(c.arm)
        self._physics_step = Integrator(c.integrator, self.model, "numpy").step_components
        muscles = MuscleSet(c.muscles, c.dt)
        self.muscle_keys = muscles.keys
        self.keys = (*muscles.keys, RESET_KEY, TOGGLE_ARM_KEY)
        self._rise = np.array(muscles._rise)
        self._decay = np.array(muscles._decay)
        self._shoulder = tuple(m[0] for m in muscles.moments)
        self._elbow = tuple(m[1] for m in muscles.moments)
        self.target_radius = c.target_radius
        self.total_steps = np.array([g.total_steps for g in configs], dtype=np.int64)
        # Rows of the state: q1, q2, w1, w2; rows of the muscle arrays: the four muscles. Rows
        # are contiguous, so each is one fast array for the step.
        self._x = np.empty((4, n))
        self._act = np.zeros((MuscleSet.COUNT, n))
        self._goal = np.zeros((MuscleSet.COUNT, n))
        self._rate = np.empty((MuscleSet.COUNT, n))
        self.held = np.zeros((n, MuscleSet.COUNT), dtype=bool)
        self.steps = np.zeros(n, dtype=np.int64)
        self.score = np.zeros(n, dtype=np.int64)
        self.hits = np.zeros(n, dtype=np.int64)
        self.resets = np.zeros(n, dtype=np.int64)
        self.arm_visible = np.ones(n, dtype=bool)
        self.target_x = np.empty(n)
        self.target_y = np.empty(n)
        self.rules: list[GameRules] = [None] * n  # type: ignore[list-item]
        for i in range(n):
            self._start(i, configs[i])

    def _start(self, i: int, config: GameConfig) -> None:
        self.configs[i] = config
        self.rules[i] = rules = GameRules(config)
        self._x[:, i] = (*config.start_posture, 0.0, 0.0)
        self._act[:, i] = 0.0
        self._goal[:, i] = 0.0
        self._rate[:, i] = self._decay
        self.held[i] = False
        self.steps[i] = self.score[i] = self.hits[i] = self.resets[i] = 0
        self.arm_visible[i] = True
        self.target_x[i], self.target_y[i] = rules.target.x, rules.target.y

    # ------------------------------------------------------------------ queries
    q1 = property(lambda self: self._x[0], doc="shoulder angles (rad), one per game")
    q2 = property(lambda self: self._x[1], doc="elbow angles (rad)")
    w1 = property(lambda self: self._x[2], doc="shoulder angular velocities (rad/s)")
    w2 = property(lambda self: self._x[3], doc="elbow angular velocities (rad/s)")

    @property
    def activation(self) -> np.ndarray:
        """Muscle activations, shape (n, 4), from 0 to 1 (a view: do not write)."""
        return self._act.T

    @property
    def over(self) -> np.ndarray:
        return self.steps >= self.total_steps

    @property
    def time_left(self) -> np.ndarray:
        return np.maximum(0, self.total_steps - self.steps) * self.config.dt

    def hand(self) -> tuple[np.ndarray, np.ndarray]:
        """Hand positions (m), x and y, one per game."""
        p = self.config.arm
        q1, q2 = self._x[0], self._x[1]
        return p.l1 * np.cos(q1) + p.l2 * np.cos(q1 + q2), p.l1 * np.sin(q1) + p.l2 * np.sin(q1 + q2)

    def state(self, i: int) -> tuple[float, float, float, float]:
        """Game ``i``'s joint state as Python floats, as ``GameSession.state``."""
        return tuple(float(v) for v in self._x[:, i])  # type: ignore[return-value]

    def result(self, i: int) -> GameResult:
        c = self.configs[i]
        return GameResult(int(self.score[i]), int(self.hits[i]), int(self.resets[i]), c.seed, c.time_limit,
                          int(self.steps[i]), c.scene, c.integrator, c.dt, __version__)

    # ------------------------------------------------------------------- input
    def _mask(self, games: np.ndarray | None) -> np.ndarray:
        """Games to touch: the mask given (or all), less the games that are over."""
        if games is None:
            return ~self.over
        games = np.asarray(games)
        if games.shape != (self.n,) or games.dtype != bool:
            raise ValueError(f"games must be a boolean mask of shape ({self.n},), got {games.dtype} {games.shape}")
        return games & ~self.over

    def _rows(self, values: np.ndarray, games: np.ndarray | None, dtype: type) -> np.ndarray:
        """(n, 4) values; with a mask, (n, 4) or one row per selected game."""
        values = np.asarray(values, dtype=dtype)
        count = self.n if games is None else int(np.count_nonzero(games))
        if values.shape == (count, MuscleSet.COUNT) and games is not None:
            full = np.zeros((self.n, MuscleSet.COUNT), dtype=dtype)
            full[games] = values
            return full
        if values.shape != (self.n, MuscleSet.COUNT):
            raise ValueError(f"expected shape ({self.n}, {MuscleSet.COUNT}), got {values.shape}")
        return values

    def set_held(self, held: np.ndarray, games: np.ndarray | None = None) -> None:
        """Hold or release the muscle keys: as key events on the muscle keys of each game."""
        mask = self._mask(games)
        held = self._rows(held, games, bool)
        change = (held != self.held) & mask[:, None]
        if not change.any():
            return
        self.held[change] = held[change]
        change, held = change.T, held.T
        self._goal[change] = held[change]
        self._rate[change] = np.where(held, self._rise[:, None], self._decay[:, None])[change]

    def set_levels(self, levels: np.ndarray, games: np.ndarray | None = None) -> None:
        """Command activation levels in [0, 1], as ``GameSession.set_muscle_levels`` per game."""
        mask = self._mask(games)
        levels = self._rows(levels, games, float)
        if not np.all((levels[mask] >= 0.0) & (levels[mask] <= 1.0)):
            raise MuscleLevelError("muscle levels must be from 0 to 1")
        levels, mask = levels.T, mask
        self._goal[:, mask] = levels[:, mask]
        rise = levels[:, mask] > self._act[:, mask]
        self._rate[:, mask] = np.where(rise, self._rise[:, None], self._decay[:, None])

    def reset_arms(self, games: np.ndarray) -> None:
        """The reset key (space) in the masked games: start posture, muscles relaxed, the reset cost."""
        for i in np.flatnonzero(self._mask(games)):
            self._reset_arm(int(i))

    def _reset_arm(self, i: int) -> None:
        self._x[:, i] = (*self.config.start_posture, 0.0, 0.0)
        self._act[:, i] = 0.0
        board = self.rules[i].board
        self.rules[i].reset_penalty()
        self.score[i], self.resets[i] = board.score, board.resets

    def key_event(self, i: int, key: str, action: str) -> bool:
        """``GameSession.key_event`` for game ``i``."""
        if self.steps[i] >= self.total_steps[i]:
            return False
        if key in self.muscle_keys:
            m = self.muscle_keys.index(key)
            down = action == DOWN
            if self.held[i, m] == down:
                return False
            self.held[i, m] = down
            self._goal[m, i] = 1.0 if down else 0.0
            self._rate[m, i] = self._rise[m] if down else self._decay[m]
        elif key == RESET_KEY and action == DOWN:
            self._reset_arm(i)
        elif key == TOGGLE_ARM_KEY and action == DOWN:
            self.arm_visible[i] = not self.arm_visible[i]
            self.rules[i].toggle_arm()
        else:
            return False
        return True

    def restart(self, games: np.ndarray, seeds: Sequence[int]) -> None:
        """Start the masked games afresh (same time limits) with new seeds, in order."""
        chosen = np.flatnonzero(np.asarray(games, dtype=bool))
        if len(seeds) != len(chosen):
            raise ValueError(f"{len(chosen)} games to restart but {len(seeds)} seeds")
        for i, seed in zip(chosen, seeds, strict=True):
            self._start(int(i), replace(self.configs[i], seed=int(seed)))

    # ----------------------------------------------------------------- physics
    def advance(self, steps: int) -> None:
        """Every game not over runs ``steps`` physics steps (or up to its end)."""
        left = int(steps)
        while left > 0:
            alive = np.flatnonzero(self.steps < self.total_steps)
            if len(alive) == 0:
                return
            chunk = min(left, int(np.min(self.total_steps[alive] - self.steps[alive])))
            self._run(None if len(alive) == self.n else alive, chunk)
            left -= chunk

    def _run(self, games: np.ndarray | None, count: int) -> None:
        """``count`` physics steps of the games at indices ``games`` (None: all), none of which may end."""
        if count <= 0:
            return
        if games is None:
            x, act, goal, rate = self._x, self._act, self._goal, self._rate
            tx, ty = self.target_x, self.target_y
        else:  # work on compact copies, written back below
            x, act, goal, rate = self._x[:, games], self._act[:, games], self._goal[:, games], self._rate[:, games]
            tx, ty = self.target_x[games], self.target_y[games]
        base = self.steps if games is None else self.steps[games]
        step, dt = self._physics_step, self.config.dt
        l1, l2 = self.config.arm.l1, self.config.arm.l2
        s0, s1, s2, s3 = self._shoulder
        e0, e1, e2, e3 = self._elbow
        a0, a1, a2, a3 = act
        near = _NEAR * self.target_radius * self.target_radius
        change = np.empty_like(act)
        cos, sin = np.cos, np.sin
        for k in range(count):
            # The session's hot loop, term for term: torque from the activations, then the muscles step.
            t1 = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3
            t2 = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3
            np.subtract(goal, act, out=change)
            change *= rate
            act += change
            x[0], x[1], x[2], x[3] = step(x[0], x[1], x[2], x[3], t1, t2, dt)
            q1, q2 = x[0], x[1]
            s12 = q1 + q2
            dx = l1 * cos(q1) + l2 * cos(s12) - tx
            dy = l1 * sin(q1) + l2 * sin(s12) - ty
            dx *= dx
            dy *= dy
            dx += dy
            if (dx <= near).any():
                for j in np.flatnonzero(dx <= near):
                    self._hit_test(int(j) if games is None else int(games[j]), x[:, j], int(base[j]) + k + 1, tx, ty,
                                   int(j))
        if games is not None:
            self._x[:, games], self._act[:, games] = x, act
            self.target_x[games], self.target_y[games] = tx, ty
            self.steps[games] += count
        else:
            self.steps += count

    def _hit_test(self, i: int, state: np.ndarray, step: int, tx: np.ndarray, ty: np.ndarray, j: int) -> None:
        """The single session's hit test and scoring, on Python floats, for game ``i`` (row ``j`` of the work)."""
        p = self.config.arm
        q1, q2 = float(state[0]), float(state[1])
        s12 = q1 + q2
        hx = p.l1 * math.cos(q1) + p.l2 * math.cos(s12)
        hy = p.l1 * math.sin(q1) + p.l2 * math.sin(s12)
        rules = self.rules[i]
        target = rules.target
        if (hx - target.x) ** 2 + (hy - target.y) ** 2 <= target.radius * target.radius:
            rules.hand_moved(hx, hy, step * self.config.dt)
            board = rules.board
            self.score[i], self.hits[i] = board.score, board.hits
            tx[j], ty[j] = rules.target.x, rules.target.y
            self.target_x[i], self.target_y[i] = tx[j], ty[j]

    # ------------------------------------------------------------------- play
    def play(self, timelines: Sequence[Sequence[InputEvent]],
             stop_steps: Sequence[int | None] | None = None) -> list[GameResult]:
        """Play every game from its timeline, as ``GameSession.play`` does for one.

        All games must be at the same step (fresh, typically). Game ``i`` stops at
        ``stop_steps[i]`` (None: its time limit); events up to that step are applied.
        """
        if len(timelines) != self.n:
            raise ValueError(f"{self.n} games but {len(timelines)} timelines")
        stops = [None] * self.n if stop_steps is None else list(stop_steps)
        if len(stops) != self.n:
            raise ValueError(f"{self.n} games but {len(stops)} stop steps")
        if np.any(self.steps != self.steps[0]):
            raise ValueError("play needs every game of the batch at the same step")
        now = int(self.steps[0])
        limit = np.array([t if s is None else min(int(s), t) for s, t in zip(stops, self.total_steps.tolist(),
                                                                            strict=True)], dtype=np.int64)
        # Every event TimelineInput would apply, at the step it takes effect: in list order, up to
        # the first beyond the game's stop, never before the game's clock.
        at, who, what = [], [], []
        for i, events in enumerate(timelines):
            clock, stop = now, int(limit[i])
            for e in events:
                if e.step > stop:
                    break
                clock = max(clock, e.step)
                at.append(clock)
                who.append(i)
                what.append(e)
        order = np.argsort(np.array(at, dtype=np.int64), kind="stable")
        at_sorted = np.array(at, dtype=np.int64)[order].tolist()
        alive = np.flatnonzero(limit > now)
        pos, total = 0, len(order)
        while True:
            next_event = at_sorted[pos] if pos < total else None
            next_end = int(np.min(limit[alive])) if len(alive) else None
            if next_event is None and next_end is None:
                break
            target = min(v for v in (next_event, next_end) if v is not None)
            if target > now:
                self._run(None if len(alive) == self.n else alive, target - now)
                now = target
            while pos < total and at_sorted[pos] == now:
                k = order[pos]
                e = what[k]
                self.key_event(who[k], e.key, e.action)
                pos += 1
            if len(alive) and next_end == now:
                alive = alive[limit[alive] > now]
        return [self.result(i) for i in range(self.n)]


def replay_many(configs: Sequence[GameConfig], timelines: Sequence[Sequence[InputEvent]],
                stop_steps: Sequence[int | None] | None = None, batch_size: int = 4096) -> list[GameResult]:
    """Play many recorded games, in batches where their configurations allow; results in input order.

    Games whose configurations can share a batch (``batch_problem``) run together, at most
    ``batch_size`` at a time; the others (an implicit integrator) run one at a time in a
    ``GameSession``. Each result equals ``GameSession(config).play(timeline, stop_step)``.
    """
    n = len(configs)
    if len(timelines) != n:
        raise ValueError(f"{n} configurations but {len(timelines)} timelines")
    stops = [None] * n if stop_steps is None else list(stop_steps)
    results: list[GameResult | None] = [None] * n
    groups: dict[tuple, list[int]] = {}
    for i, c in enumerate(configs):
        if c.integrator in BATCH_INTEGRATORS:
            key = tuple(getattr(c, f.name) for f in fields(GameConfig) if f.name not in PER_GAME_FIELDS)
            groups.setdefault(key, []).append(i)
        else:
            results[i] = GameSession(c).play(timelines[i], stops[i])
    for members in groups.values():
        for lo in range(0, len(members), batch_size):
            part = members[lo:lo + batch_size]
            if len(part) == 1:  # a batch of one costs more than the single session
                i = part[0]
                results[i] = GameSession(configs[i]).play(timelines[i], stops[i])
                continue
            batch = BatchGameSession([configs[i] for i in part])
            for i, r in zip(part, batch.play([timelines[i] for i in part], [stops[i] for i in part]), strict=True):
                results[i] = r
    return results  # type: ignore[return-value]


__all__ = ["BATCH_INTEGRATORS", "STATE_TOLERANCE", "BatchGameSession", "batch_problem", "replay_many"]
