"""Many games in lockstep: a class's scripts, a batch of replays, a vector of environments.

``BatchGameSession`` runs N games at once with one array per quantity (joint state,
activations, targets, clocks). Each game of a batch equals the single ``GameSession`` fed the
same inputs: hits, score, resets and steps exactly, and its joint state to round-off (bit for
bit where stated below). Two kernels step them:

* **compiled** (``compiled.py``, ``_ckernel.c``; the default where ``pip install`` could build
  it, for RK4): each game runs its own steps in C, the single session's expressions operation
  for operation with the C library's cos and sin, so bit for bit; ``play`` hands it each game's
  muscle commands and it runs each game to its next reset, tab or stop, back in Python only to
  judge a hand at a target. With ``exact=False`` (games of at most ``FAST_MAX_SECONDS``) it
  takes the elbow's cos and sin by angle addition, as numpy's fast kernel below does.
* **numpy** (``_Kernel``; the fallback, and the Euler schemes): a physics step costs about 130
  numpy operations however many games there are. How it equals the single session:

* The physics is the single session's own arithmetic: for RK4 (the game's integrator) its
  hot loop, step and accelerations written out operation for operation on arrays
  (``_Kernel``); for the Euler schemes the very closures of ``Integrator(name, model,
  "numpy")``. Every array element goes through the same IEEE operations in the same order
  as the Python floats of one game, with numpy's sin and cos for ``math``'s. Where
  numpy's float64 sin and cos are the C library's (checked on x86-64 with AVX2, numpy 2.4:
  identical on 6 million arguments), a batched game is bit for bit the single one. Where numpy
  uses its own vectorised sin and cos (AVX-512 builds), they may differ by an ulp, and the
  states differ by round-off: ``STATE_TOLERANCE`` bounds that over a 60 s game. A hit could
  then differ only if the hand crossed a target's edge within about 1e-13 m of it, where it
  moves about 1e-3 m a step: a chance of the order of 1e-10 per crossing.
* The hit test never depends on numpy's round-off: numpy only flags games whose hand may
  be within a relative 1e-6 of a target's edge (a conservative bound on how far each hand
  has moved since it was last measured, so the batch does not pay four more sin and cos
  per step), and for those (rare: the hand is on or at a target) the single session's own
  test is evaluated on Python floats from the game's state, and the hit is scored by the
  game's own ``GameRules`` (which draws the next target from the game's own random
  sequence). Given equal states the decision is identical, knife edge or not.
* ``exact=False`` (the vector env, ``replay_many``: class scoring and verification) runs the
  fast kernel (numpy's from ``SERIES_MIN_GAMES`` games, the compiled one's at any size): RK4
  stages 2-4 take the elbow's cos and sin from stage 1's by angle addition, with Taylor series
  for the small increment (as ``physics.batch.BatchRK4``; full sin and cos for any step whose increment exceeds
  ``SERIES_LIMIT``); stage 1's come from the previous step's, turned by the step's change of
  q2 (full sin and cos at the start of each run of steps and every 32 steps). That saves all
  but one in 32 of the steps' sin and cos of the whole batch, and costs round-off, which the
  arm's motion amplifies: over 1,000 games of 60 s with random keys the joint states stayed
  within 1.7e-11 of the single session's (compiled: 9.6e-12), against ``STATE_TOLERANCE``
  (games longer than ``FAST_MAX_SECONDS`` run the exact kernel). Hits are still decided by the exact test on
  Python floats, on the fast state; the hand is then within about 1.4e-11 m of the single
  session's, so a decision could differ only if the hand were that close to the edge, where it
  moves about 1e-3 m a step: about 3e-8 per crossing. A decision within ``KNIFE_EDGE`` (1e-8 m)
  marks the game ``knife_edge`` (about 2e-5 per crossing), and ``replay_many`` plays marked games
  again alone, so its results are the single session's; the vector env, with no timeline to
  replay, keeps the 3e-8 odds. Below ``SERIES_MIN_GAMES`` games numpy's call overhead outweighs
  sin and cos, and the exact kernel is also the faster one, whatever ``exact`` says.
* Events (keys, resets, tab) are applied between physics steps exactly where the single
  session applies them; ``play`` advances every game to the next step at which any game has
  an event, vectorised in between (the compiled kernel needs no such common step).

The implicit integrators (midpoint, gauss4) iterate until the largest change over the
whole batch converges, so a game's iteration count would depend on the others: a batch
refuses them and ``replay_many`` plays such games one at a time.
"""

from __future__ import annotations

import math
import os
import stat
from collections.abc import Callable, Iterator, Sequence
from dataclasses import fields, replace
from pathlib import Path

import numpy as np

from ... import __version__
from ...errors import UserError
from ...physics.batch import SERIES_LIMIT
from ...physics.integrators import Integrator
from ...physics.twojoint import TwoJointArm
from . import compiled
from .compiled import NEAR, CompiledKernel, MuscleEvents, hand_move_bounds
from ..muscles import MuscleLevelError, MuscleSet
from ..rules import GameConfig, GameRules
from ..session import DOWN, RESET_KEY, TOGGLE_ARM_KEY, GameResult, GameSession, InputEvent, NonFiniteStateError

#: ``BatchGameSession(kernel=...)``: None, the compiled kernel where built (and RK4), else numpy.
KERNELS = (None, "compiled", "numpy")

#: Integrators whose batched step is the single step to round-off (no batch-wide iteration).
BATCH_INTEGRATORS = ("rk4", "euler", "symplectic-euler")

#: Fields a batch's games may differ in; every other field of ``GameConfig`` must be equal.
PER_GAME_FIELDS = ("seed", "time_limit", "scene")

#: Largest joint-state difference (rad, rad/s) from the single session that a batch allows itself.
#: Where numpy's sin and cos are the C library's the difference is zero (every test checks). Where
#: they are not, they may be an ulp off: with sin and cos an ulp off in half their calls, 20 student
#: games of 60 s stayed within 1.1e-13 of the exact ones, with the same results (the viscous arm
#: forgets round-off rather than amplifying it; tests/test_batch.py repeats this on two games).
STATE_TOLERANCE = 1e-10

#: The fast kernel's series pay from about this many games; smaller batches (where a numpy call's
#: overhead outweighs sin and cos of its elements) run the exact kernel whatever ``exact`` says.
#: Kernel steps per CPU second under load, exact against series: 1,000 games 0.85-0.9x, 2,048 about
#: even, 4,096 1.15-1.4x, 8,192 1.4-1.75x.
SERIES_MIN_GAMES = 2048

#: The longest game (s) the fast kernel plays; longer ones run the exact kernel. The arm's motion
#: amplifies round-off: over 1,000 games with random keys the largest state difference from the
#: single session was 1.7e-11 at 60 s, 4.2e-11 at 120 s and 1.4e-9 at 180 s.
FAST_MAX_SECONDS = 60.0

#: In the fast kernel (``exact=False``), a hand whose distance from a target's edge is within this
#: (m) when its hit is decided marks its game ``knife_edge``. Within ``FAST_MAX_SECONDS`` the fast
#: states stayed within 1.7e-11 rad of the single session's, so its hand within about 1.4e-11 m: a
#: decision farther from the edge than this (700 times that) is the single session's decision.
KNIFE_EDGE = 1e-8


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

    def __init__(self, configs: Sequence[GameConfig], exact: bool = True, kernel: str | None = None) -> None:
        configs = list(configs)
        problem = batch_problem(configs)
        if problem:
            raise UserError(problem)
        if kernel not in KERNELS:
            raise ValueError(f"kernel {kernel!r}: expected one of {', '.join(map(repr, KERNELS))}")
        if kernel == "compiled" and not compiled.AVAILABLE:
            raise ValueError("kernel 'compiled': the compiled kernel is not built here (no C compiler at install?)")
        self.configs = configs
        #: True: the single session's arithmetic, bit for bit; False: the numpy kernel may use its fast RK4
        #: stages (see ``_Kernel``). The compiled kernel is exact and the fastest, so it ignores this.
        self.exact = bool(exact)
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
        # are contiguous, so each is one fast array for the step. Rows 4-5 of ``_xs`` are scratch
        # for the first RK4 stage's accelerations (see _Kernel._build).
        self._xs = np.zeros((6, n))
        self._x = self._xs[:4]
        self._act = np.zeros((MuscleSet.COUNT, n))
        self._goal = np.zeros((MuscleSet.COUNT, n))
        self._rate = np.empty((MuscleSet.COUNT, n))
        # Stored muscle by muscle as the activations are, so set_held's masked copies run contiguous.
        self._held = np.zeros((MuscleSet.COUNT, n), dtype=bool)
        self.steps = np.zeros(n, dtype=np.int64)
        self.score = np.zeros(n, dtype=np.int64)
        self.hits = np.zeros(n, dtype=np.int64)
        self.resets = np.zeros(n, dtype=np.int64)
        self.arm_visible = np.ones(n, dtype=bool)
        self.target_x = np.empty(n)
        self.target_y = np.empty(n)
        # A lower bound on each hand's distance from its target's disc (m); negative: measure it.
        self._slack = np.full(n, -1.0)
        #: Games whose hand came within ``KNIFE_EDGE`` of a target's edge in the fast kernel: their hits
        #: could differ from the single session's (``replay_many`` plays them again alone).
        self.knife_edge = np.zeros(n, dtype=bool)
        use_compiled = kernel != "numpy" and compiled.AVAILABLE and c.integrator == "rk4"
        # Whether the kernel may round differently from the single session: the fast stages, which
        # compiled pay at any batch size, in numpy only from ``_series_from`` games (call overhead).
        self._series_from = SERIES_MIN_GAMES
        self._rounds = (not self.exact and c.integrator == "rk4"
                        and int(self.total_steps.max()) * c.dt <= FAST_MAX_SECONDS
                        and (use_compiled or n >= self._series_from))
        self.rules: list[GameRules] = [None] * n  # type: ignore[list-item]
        self._kernels: dict[int, _Kernel] = {}
        for i in range(n):
            self._start(i, configs[i])
        #: The compiled kernel where built (and asked for) and the integrator is RK4; else None: numpy.
        self.compiled = CompiledKernel(self, fast=self._rounds) if use_compiled else None

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
        self._slack[i] = -1.0
        self.knife_edge[i] = False

    # ------------------------------------------------------------------ queries
    q1 = property(lambda self: self._x[0], doc="shoulder angles (rad), one per game")
    q2 = property(lambda self: self._x[1], doc="elbow angles (rad)")
    w1 = property(lambda self: self._x[2], doc="shoulder angular velocities (rad/s)")
    w2 = property(lambda self: self._x[3], doc="elbow angular velocities (rad/s)")

    @property
    def held(self) -> np.ndarray:
        """Muscle keys held, shape (n, 4) (a view: change it through ``set_held`` or ``key_event``)."""
        return self._held.T

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
        # A vector env with random keys changes half of them every step. At 8,192 games this call
        # took 1.9 ms by boolean indexing of the (n, 4) arrays, 0.8 ms by masked copies (np.copyto
        # with where=), 0.25 ms so: one transposed copy, then the changed places as flat indices.
        held = np.ascontiguousarray(held.T)
        change = held != self._held
        change &= mask
        where = np.flatnonzero(change)
        if not len(where):
            return
        self._held ^= change
        down = held.reshape(-1)[where]
        muscle = where // self.n
        self._goal.reshape(-1)[where] = down
        self._rate.reshape(-1)[where] = np.where(down, self._rise[muscle], self._decay[muscle])

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
        self._slack[i] = -1.0
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
    def _stop_if_non_finite(self) -> None:
        """``GameSession.advance``'s ``NonFiniteStateError``, naming the first game whose state blew up.

        A single game stops at once; here the others ran on to the end of the call, which changes
        nothing they report, since the error ends the batch.
        """
        if math.isfinite(float(np.sum(self._x))):  # one pass; a sum that overflows is checked below
            return
        bad = np.flatnonzero(~np.isfinite(self._x).all(axis=0))
        if len(bad):
            i, dt = int(bad[0]), self.config.dt
            raise NonFiniteStateError(f"game {i}: the arm's state became non-finite by t = {self.steps[i] * dt:g} s: "
                                      f"this game's physics blows up ({self.config.integrator}, dt {dt:g} s)")

    def advance(self, steps: int) -> None:
        """Every game not over runs ``steps`` physics steps (or up to its end).

        A game whose physics blows up raises ``NonFiniteStateError``, as ``GameSession.advance`` does.
        """
        try:
            self._advance(steps)
        except (ValueError, OverflowError, ZeroDivisionError):  # math.cos(inf) on the way to a hand
            self._stop_if_non_finite()
            raise
        self._stop_if_non_finite()

    def _advance(self, steps: int) -> None:
        left = int(steps)
        if left <= 0:
            return
        if self.compiled is not None:
            self.compiled.run(np.minimum(self.steps + min(left, int(self.total_steps.max())), self.total_steps))
            return
        while left > 0:
            running = self.steps < self.total_steps
            alive = np.flatnonzero(running)
            if len(alive) == 0:
                return
            chunk = min(left, int(np.min(self.total_steps[alive] - self.steps[alive])))
            if len(alive) == self.n:
                self._run(None, chunk)
            elif 2 * len(alive) >= self.n:
                # Games over (waiting for a restart, say) ride along, stepped for nothing and put
                # back: cheaper than gathering the others.
                idle = np.flatnonzero(~running)
                kept = self._x[:, idle].copy(), self._act[:, idle].copy(), self._slack[idle].copy()
                self._slack[idle] = np.inf
                self._run(None, chunk, running)
                self._x[:, idle], self._act[:, idle], self._slack[idle] = kept
            else:
                self._run(alive, chunk)
            left -= chunk

    def _run(self, games: np.ndarray | None, count: int, clocks: np.ndarray | None = None) -> None:
        """``count`` physics steps of the games at indices ``games`` (None: all), none of which may end.

        With ``games`` None, ``clocks`` (a mask) says whose step counts advance: the others are
        stepped for nothing (``play`` keeps games that have stopped in the batch rather than
        gather the rest every step, and puts their states back at the end).
        """
        if count <= 0:
            return
        if games is None:
            x, act, goal, rate = self._xs, self._act, self._goal, self._rate
            tx, ty, slack = self.target_x, self.target_y, self._slack
            base = self.steps
        else:  # work on compact copies, written back below
            x, act, goal, rate = self._xs[:, games], self._act[:, games], self._goal[:, games], self._rate[:, games]
            tx, ty, slack = self.target_x[games], self.target_y[games], self._slack[games]
            base = self.steps[games]
        m = x.shape[1]
        kernel = self._kernels.get(m)
        if kernel is None:
            if len(self._kernels) > 2:  # keep the full batch's and a few others, not one per size ever seen
                self._kernels = {k: v for k, v in self._kernels.items() if k == self.n}
            kernel = self._kernels[m] = _Kernel(self, m)
        for k, near in kernel.run(x, act, goal, rate, tx, ty, slack, count):
            for j in near.tolist():
                i = j if games is None else int(games[j])
                if self._hit_test(i, x[:, j], int(base[j]) + k + 1):
                    tx[j], ty[j], slack[j] = self.target_x[i], self.target_y[i], -1.0
        if games is not None:
            self._x[:, games], self._act[:, games] = x[:4], act
            self.target_x[games], self.target_y[games], self._slack[games] = tx, ty, slack
            self.steps[games] += count
        elif clocks is None:
            self.steps += count
        else:
            self.steps[clocks] += count

    def _hit_test(self, i: int, state: np.ndarray, step: int) -> bool:
        """The single session's hit test and scoring, on Python floats, for game ``i`` after step ``step``."""
        p = self.config.arm
        q1, q2 = float(state[0]), float(state[1])
        s12 = q1 + q2
        hx = p.l1 * math.cos(q1) + p.l2 * math.cos(s12)
        hy = p.l1 * math.sin(q1) + p.l2 * math.sin(s12)
        rules = self.rules[i]
        target = rules.target
        d2 = (hx - target.x) ** 2 + (hy - target.y) ** 2
        if self._rounds and abs(math.sqrt(d2) - target.radius) <= KNIFE_EDGE:
            self.knife_edge[i] = True
        if d2 <= target.radius * target.radius:
            rules.hand_moved(hx, hy, step * self.config.dt)
            board = rules.board
            self.score[i], self.hits[i] = board.score, board.hits
            self.target_x[i], self.target_y[i] = rules.target.x, rules.target.y
            self._slack[i] = -1.0
            return True
        return False

    # ------------------------------------------------------------------- play
    def play(self, timelines: Sequence[Sequence[InputEvent]],
             stop_steps: Sequence[int | None] | None = None) -> list[GameResult]:
        """Play every game from its timeline, as ``GameSession.play`` does for one.

        All games must be at the same step (fresh, typically). Game ``i`` stops at
        ``stop_steps[i]`` (None: its time limit); events up to that step are applied. A game
        whose physics blows up raises ``NonFiniteStateError``, as the single session does.
        """
        try:
            results = self._play(timelines, stop_steps)
        except (ValueError, OverflowError, ZeroDivisionError):
            self._stop_if_non_finite()
            raise
        self._stop_if_non_finite()
        return results

    def _play(self, timelines: Sequence[Sequence[InputEvent]],
              stop_steps: Sequence[int | None] | None) -> list[GameResult]:
        if len(timelines) != self.n:
            raise ValueError(f"{self.n} games but {len(timelines)} timelines")
        stops = [None] * self.n if stop_steps is None else list(stop_steps)
        if len(stops) != self.n:
            raise ValueError(f"{self.n} games but {len(stops)} stop steps")
        if np.any(self.steps != self.steps[0]):
            raise ValueError("play needs every game of the batch at the same step")
        now = int(self.steps[0])
        limit = [t if s is None else min(int(s), t) for s, t in zip(stops, self.total_steps.tolist(), strict=True)]
        schedule = self._schedule(timelines, now, limit)
        muscle_steps, flat, goal, rate, specials, held = schedule
        limits = np.array(limit, dtype=np.int64)
        if self.compiled is not None:
            self._play_compiled(MuscleEvents.by_game(self.n, muscle_steps, flat, goal, rate), specials, limits)
            for i, row in held.items():
                self.held[i] = row
            return [self.result(i) for i in range(self.n)]
        # Lockstep: every game's commands by step (stable: a game's order within a step is kept).
        order = np.argsort(muscle_steps, kind="stable")
        muscle_steps, flat, goal, rate = muscle_steps[order], flat[order], goal[order], rate[order]
        specials.sort(key=lambda special: special[0])
        alive = np.flatnonzero(limits > now)
        # Games that stop while at least half the batch plays on stay in it, stepped for nothing:
        # cheaper than gathering the others every step. Their slack is infinite (no hits) and
        # their states are put back at the end.
        running = limits > now
        stopped: dict[int, tuple[np.ndarray, np.ndarray]] = {}

        def stop(games: np.ndarray) -> None:
            for i in games.tolist():
                stopped[i] = (self._x[:, i].copy(), self._act[:, i].copy())
                self._slack[i] = np.inf
            running[games] = False
        # Every step where something happens: an event of some game, or some game's stop.
        stops_at = np.unique(np.concatenate([muscle_steps, np.array([s for s, _, _ in specials], dtype=np.int64),
                                             limits[limits > now]]))
        bounds = np.searchsorted(muscle_steps, stops_at, side="right").tolist()
        goal_flat, rate_flat = self._goal.reshape(-1), self._rate.reshape(-1)
        lo, special = np.searchsorted(muscle_steps, now, side="left"), 0
        for target, hi in zip([now, *stops_at.tolist()], [lo, *bounds], strict=True):
            if target > now:
                if 2 * len(alive) >= self.n:
                    self._run(None, target - now, None if len(alive) == self.n else running)
                else:
                    self._run(alive, target - now)
                now = target
            if hi > lo:  # the muscle keys pressed and released at this step
                where = flat[lo:hi]
                goal_flat[where] = goal[lo:hi]
                rate_flat[where] = rate[lo:hi]
                lo = hi
            while special < len(specials) and specials[special][0] == now:
                _, i, key = specials[special]
                self.key_event(i, key, DOWN)
                special += 1
            if len(alive) and int(limits[alive].min()) <= now:  # after their events at their last step
                stop(alive[limits[alive] <= now])
                alive = alive[limits[alive] > now]
        for i, (x, act) in stopped.items():
            self._x[:, i], self._act[:, i], self._slack[i] = x, act, -1.0
        for i, row in held.items():
            self.held[i] = row
        return [self.result(i) for i in range(self.n)]

    def _play_compiled(self, events: MuscleEvents, specials: list[tuple[int, int, str]], limits: np.ndarray) -> None:
        """``play`` on the compiled kernel: each game runs on its own to its next reset or tab, or its stop.

        The kernel applies the muscle commands itself; at a game's reset or tab step (after that
        step's muscle commands, as ``play`` orders them) the key goes through ``key_event``.
        """
        pending: dict[int, list[tuple[int, str]]] = {}
        for step, i, key in specials:  # in timeline order: by step within each game
            pending.setdefault(i, []).append((step, key))
        halt = limits.copy()
        for i, keys in pending.items():
            keys.reverse()  # popped from the end
            halt[i] = min(keys[-1][0], int(limits[i]))
        while True:
            self.compiled.run(halt, events)
            if not pending:
                return
            for i in list(pending):
                keys = pending[i]
                at = keys[-1][0]  # where game i now is: its halt
                while keys and keys[-1][0] == at:
                    self.key_event(i, keys.pop()[1], DOWN)
                if keys:
                    halt[i] = min(keys[-1][0], int(limits[i]))
                else:
                    del pending[i]
                    halt[i] = limits[i]

    def _schedule(self, timelines: Sequence[Sequence[InputEvent]], now: int, limit: list[int]):
        """What each timeline does and when, as ``TimelineInput`` and ``key_event`` would do it.

        Key events do not depend on the motion, so their effect is worked out here once, in
        plain Python: events in list order up to the first beyond the game's stop, each at the
        later of its step and the game's clock; events at or after the game's end, repeats of a
        held key and unknown keys dropped. Muscle commands come back as flat indices into the
        (4, n) goal and rate arrays with their new values (of several for one muscle at one
        step, the last, which is what applying them all in order leaves); resets and tab as
        (step, game, key); the muscle keys held at the end by game. Both lists are in timeline
        order, so by game and within a game by step: each kernel orders them as it steps.
        """
        index = {key: m for m, key in enumerate(self.muscle_keys)}
        rise, decay = self._rise.tolist(), self._decay.tolist()
        n, totals = self.n, self.total_steps.tolist()
        steps: list[int] = []
        flat: list[int] = []
        goal: list[float] = []
        rate: list[float] = []
        specials: list[tuple[int, int, str]] = []
        held_at_end: dict[int, list[bool]] = {}
        for i, events in enumerate(timelines):
            clock, stop, end = now, limit[i], totals[i]
            held = self.held[i].tolist()
            last = [(-1, -1)] * len(held)  # per muscle: (step, position in the lists) of its last command
            for e in events:
                if e.step > stop:
                    break
                clock = max(clock, e.step)
                if clock >= end:
                    continue
                m = index.get(e.key)
                if m is not None:
                    down = e.action == DOWN
                    if held[m] == down:
                        continue
                    held[m] = down
                    values = (1.0, rise[m]) if down else (0.0, decay[m])
                    if last[m][0] == clock:
                        goal[last[m][1]], rate[last[m][1]] = values
                    else:
                        last[m] = (clock, len(steps))
                        steps.append(clock)
                        flat.append(m * n + i)
                        goal.append(values[0])
                        rate.append(values[1])
                elif e.key in (RESET_KEY, TOGGLE_ARM_KEY) and e.action == DOWN:
                    specials.append((clock, i, e.key))
            held_at_end[i] = held
        return (np.array(steps, dtype=np.int64), np.array(flat, dtype=np.intp), np.array(goal), np.array(rate),
                specials, held_at_end)

class _Kernel:
    """The session's hot loop for ``m`` games at once, every intermediate in preallocated arrays.

    Each expression is the single session's (``GameSession.advance``, ``integrators._rk4``,
    ``TwoJointArm.component_dynamics``' accel) with the same operations in the same order,
    one numpy call per operation written into scratch: IEEE arithmetic is elementwise, so
    every game gets the bits its scalar loop would. At a thousand games a call costs about
    as much as its arithmetic, so the calls are the cheapest kind (positional ``out``,
    constants as 0-d arrays, no broadcasting, names bound once in a closure), and where the
    scalar code does the same operation to a shoulder and an elbow quantity, one call does
    both rows of a (2, m) array. Integrators other than rk4 go through the generic numpy
    closures (which allocate).
    """

    def __init__(self, batch: BatchGameSession, m: int) -> None:
        self.batch, self.m = batch, m
        self._bound: tuple[tuple[int, ...], Callable[[], bool]] | None = None

    def stepper(self, x: np.ndarray, act: np.ndarray, goal: np.ndarray, rate: np.ndarray,
                slack: np.ndarray) -> Callable[[], bool]:
        """One physics step of these arrays (state rows 0-3 of ``x``, rows 4-5 scratch) as a function.

        The function returns whether some hand's ``slack`` ran out (see ``run``).
        """
        # The bound closure holds these arrays, so their ids cannot be reused while it is kept.
        key = tuple(id(a) for a in (x, act, goal, rate, slack))
        if self._bound is None or self._bound[0] != key:
            self._bound = (key, self._build(x, act, goal, rate, slack))
        return self._bound[1]

    def _build(self, x: np.ndarray, act: np.ndarray, goal: np.ndarray, rate: np.ndarray,
               slack: np.ndarray) -> Callable[[], bool]:
        batch, m = self.batch, self.m
        model, config = batch.model, batch.config
        p = model.params
        gravity, damping = p.has_gravity, p.has_gravity or p.has_damping
        const = np.array
        B, D, G1, G2 = const(model.b), const(model.d), const(model.g1), const(model.g2)
        DET0, AMD = const(model.a * model.d - model.d * model.d), const(model.a - model.d)
        ONE, TWO, ZERO = const(1.0), const(2.0), const(0.0)
        dt = config.dt
        H, DT, SIXTH = const(0.5 * dt), const(dt), const(dt * (1.0 / 6.0))
        REACH1, REACH2 = (const(c) for c in hand_move_bounds(p.l1, p.l2))
        mul, add, sub, div, cos, sin = np.multiply, np.add, np.subtract, np.divide, np.cos, np.sin
        empty = np.empty
        trig, force, inertia, pair = empty((2, m)), empty((2, m)), empty((2, m)), empty((2, m))
        bc, hs = trig
        f1, f2 = force
        inertia[0] = model.d
        i1 = inertia[1]
        p0, p1 = pair
        viscosity = empty((2, m))
        viscosity[0], viscosity[1] = p.damping1, p.damping2
        m12, r, tmp, gc12, move, move2 = (empty(m) for _ in range(6))
        torque = empty((2, m))
        t1, t2 = torque
        change, previous, total, mid = empty((4, m)), empty((2, m)), empty((4, m)), empty((4, m))
        head, state = x[:2], x[:4]
        near_mask = empty(m, dtype=bool)
        # Stages 2-4: rows 0-3 the stage's state (q1 q2 w1 w2), rows 4-5 its accelerations, so rows 2-5
        # are the stage's slopes (velocities, accelerations) without a copy; stage 1 is x itself.
        s2, s3, s4 = (empty((6, m)) for _ in range(3))
        stages = [(x, (*x, x[2:4], x[4:6]))] + [(s, (*s, s[2:4], s[4:6])) for s in (s2, s3, s4)]
        # Torque rows: (activation row, moment) pairs; a zero moment adds a +0.0 term, kept as one "+ 0.0".
        rows = []
        for out, moments in ((t1, batch._shoulder), (t2, batch._elbow)):
            terms = [(act[i], const(c)) for i, c in enumerate(moments) if c != 0.0]
            rows.append((out, terms, len(terms) < len(moments)))
        generic = None if config.integrator == "rk4" else batch._physics_step
        exact = generic is not None or not batch._rounds or m < batch._series_from

        def elbow(q2):
            cos(q2, bc)
            sin(q2, hs)
            mul(trig, B, trig)  # bc = b cos q2, h = b sin q2

        # The fast kernel's elbow trig: stage 1's b cos q2, b sin q2 (``base``) and the same turned a
        # quarter (``turn`` = b (-sin q2, cos q2)); a later stage's angle is q2 + delta, whose cos and sin
        # come by angle addition with cos and sin of delta from Taylor series in delta^2 (``series``
        # rows: cos, sin), evaluated for both rows at once. ``squares`` keeps each stage's delta^2 so one
        # check per step sees whether every delta was within the series' range.
        base, turn, series, squares = empty((2, m)), empty((2, m)), empty((2, m)), empty((4, m))
        anchor = self.anchor = [0]  # steps left before full cos and sin again; run() sets it to 0
        delta = empty(m)
        c_row, s_row = series
        K4, K3, K2, K1 = (const([[a], [b]]) for a, b in ((1.0 / 40320.0, 1.0 / 362880.0),
                                                          (-1.0 / 720.0, -1.0 / 5040.0),
                                                          (1.0 / 24.0, 1.0 / 120.0), (-0.5, -1.0 / 6.0)))
        LIMIT2 = SERIES_LIMIT * SERIES_LIMIT
        REANCHOR = 32

        def accel(q1, q2, w1, w2, o1, o2, velocity, out):
            add(bc, D, m12)
            # f1 = t1 + h (w1 + w1 + w2) w2 [- g1 cos q1 - g2 cos(q1 + q2)] [- k1 w1]
            add(w1, w1, tmp)
            add(tmp, w2, tmp)
            mul(tmp, hs, tmp)
            mul(tmp, w2, tmp)
            add(t1, tmp, f1)
            # f2 = t2 - h w1 w1 [- g2 cos(q1 + q2)] [- k2 w2]
            mul(hs, w1, tmp)
            mul(tmp, w1, tmp)
            sub(t2, tmp, f2)
            if gravity:
                add(q1, q2, gc12)
                cos(gc12, gc12)
                mul(gc12, G2, gc12)
                cos(q1, tmp)
                mul(tmp, G1, tmp)
                sub(f1, tmp, f1)
                sub(f1, gc12, f1)
                sub(f2, gc12, f2)
            if damping:
                mul(velocity, viscosity, pair)
                sub(force, pair, force)
            # r = 1 / (det0 - bc^2); qdd1 = (d f1 - m12 f2) r; qdd2 = ((m12 + a - d + bc) f2 - m12 f1) r
            mul(bc, bc, r)
            sub(DET0, r, r)
            div(ONE, r, r)
            add(m12, AMD, i1)
            add(i1, bc, i1)
            mul(force, inertia, out)
            mul(m12, f2, p0)
            mul(m12, f1, p1)
            sub(out, pair, out)
            mul(o1, r, o1)
            mul(o2, r, o2)

        def turned(angle: np.ndarray, d2: np.ndarray, out: np.ndarray) -> None:
            """b cos and b sin of q2 + angle into ``out`` (2, m), from ``base`` and ``turn``."""
            mul(angle, angle, d2)
            # Horner in delta^2: cos d = 1 - d^2/2! + ... + d^8/8!, sin d = d (1 - d^2/3! + ... + d^8/9!).
            mul(K4, d2, series)
            for k in (K3, K2, K1):
                add(series, k, series)
                mul(series, d2, series)
            add(series, ONE, series)
            mul(s_row, angle, s_row)
            # b cos(q2 + d) = bc cos d - bs sin d; b sin(q2 + d) = bs cos d + bc sin d
            mul(base, c_row, out)
            mul(turn, s_row, pair)
            add(out, pair, out)

        def fast_stages() -> None:
            # ``base`` carries over from the last step, turned by its change of q2 (see ``step``), for up
            # to ``REANCHOR`` steps of one ``run``; then, and at the start of each run, full cos and sin.
            if anchor[0] <= 0:
                cos(x[1], base[0])
                sin(x[1], base[1])
                mul(base, B, base)
                anchor[0] = REANCHOR
            anchor[0] -= 1
            np.copyto(trig, base)
            np.negative(base[1], turn[0])
            np.copyto(turn[1], base[0])
            accel(*stages[0][1])
            for (before, _), (stage, views), c, d2 in zip(stages, stages[1:], (H, H, DT), squares, strict=False):
                mul(before[2:], c, stage[:4])
                add(stage[:4], state, stage[:4])
                mul(before[3], c, delta)  # stage q2 - q2, to round-off
                turned(delta, d2, trig)
                accel(*views)
            if float(squares[:3].max()) > LIMIT2:  # a huge step or a wild spin: full trig for this step
                for (before, _), (stage, views), c in zip(stages, stages[1:], (H, H, DT), strict=False):
                    mul(before[2:], c, stage[:4])
                    add(stage[:4], state, stage[:4])
                    elbow(stage[1])
                    accel(*views)

        def step() -> bool:
            # Torque from the activations (t1 = a0 s0 + a1 s1 + a2 s2 + a3 s3, left to right), then the muscles step.
            for out, terms, has_zero in rows:
                if not terms:
                    out.fill(0.0)
                    continue
                mul(terms[0][0], terms[0][1], out)
                for a, c in terms[1:]:
                    mul(a, c, tmp)
                    add(out, tmp, out)
                if has_zero:
                    add(out, ZERO, out)  # the a * 0.0 terms: +0.0 each, and x + 0.0 + 0.0 == x + 0.0
            sub(goal, act, change)
            mul(change, rate, change)
            add(act, change, act)
            np.copyto(previous, head)
            if generic is None:
                # integrators._rk4: stage i's state is x + c (stage i-1's slopes), i.e. the scalar
                # code's q1 + h * w1 and v1 = w1 + h * a1 and so on; then
                # x + dt/6 (k1 + k4 + 2 (k2 + k3)), the scalar q1 + k * (w1 + s1 + 2.0 * (v1 + u1)).
                if exact:
                    elbow(x[1])
                    accel(*stages[0][1])
                    for (before, _), (stage, views), c in zip(stages, stages[1:], (H, H, DT), strict=False):
                        mul(before[2:], c, stage[:4])
                        add(stage[:4], state, stage[:4])
                        elbow(stage[1])
                        accel(*views)
                else:
                    fast_stages()
                add(s2[2:], s3[2:], mid)
                mul(mid, TWO, mid)
                add(x[2:], s4[2:], total)
                add(total, mid, total)
                mul(total, SIXTH, total)
                add(state, total, state)
            else:
                x[0], x[1], x[2], x[3] = generic(x[0], x[1], x[2], x[3], t1, t2, dt)
            sub(head, previous, previous)
            if not exact:  # the next step's b cos q2, b sin q2: this step's, turned by its change of q2
                turned(previous[1], squares[3], base)
                if float(squares[3].max()) > LIMIT2:
                    anchor[0] = 0
            np.abs(previous, previous)
            mul(previous[0], REACH1, move)
            mul(previous[1], REACH2, move2)
            add(move, move2, move)
            sub(slack, move, slack)
            np.less(slack, ZERO, near_mask)
            return bool(near_mask.any())

        self.near_mask = near_mask
        return step

    def run(self, x: np.ndarray, act: np.ndarray, goal: np.ndarray, rate: np.ndarray, tx: np.ndarray,
            ty: np.ndarray, slack: np.ndarray, count: int) -> Iterator[tuple[int, np.ndarray]]:
        """Step ``count`` times; after step k + 1, yields (k, indices) of the hands near their targets.

        Measuring every hand after every step would cost four more sin and cos of the whole
        batch. Instead ``slack`` holds a lower bound on each hand's distance from its target's
        disc, lowered every step by a bound on how far the hand moved; only hands whose slack
        runs out are measured (a few per step), and only those near the edge go to the exact test.
        """
        step = self.stepper(x, act, goal, rate, slack)
        self.anchor[0] = 0  # the states may have changed since the last run: the fast kernel's trig anew
        config = self.batch.config
        l1, l2, radius = config.arm.l1, config.arm.l2, config.target_radius
        near = NEAR * radius * radius
        cos, sin, sqrt = math.cos, math.sin, math.sqrt
        for k in range(count):
            if step():
                where = np.flatnonzero(self.near_mask)
                if len(where) <= 16:  # the usual few: plain floats cost less than numpy on tiny arrays
                    angles = x[:2, where].tolist()
                    gaps, close_list = [], []
                    for j, a, b, x0, y0 in zip(where.tolist(), angles[0], angles[1], tx[where].tolist(),
                                               ty[where].tolist(), strict=True):
                        dx = l1 * cos(a) + l2 * cos(a + b) - x0
                        dy = l1 * sin(a) + l2 * sin(a + b) - y0
                        d2 = dx * dx + dy * dy
                        gaps.append(sqrt(d2) - radius - 1e-9)
                        if d2 <= near:
                            close_list.append(j)
                    slack[where] = gaps
                    close = np.array(close_list, dtype=np.intp)
                else:
                    a, b = x[0, where], x[1, where]
                    dx = l1 * np.cos(a) + l2 * np.cos(a + b) - tx[where]
                    dy = l1 * np.sin(a) + l2 * np.sin(a + b) - ty[where]
                    d2 = dx * dx + dy * dy
                    slack[where] = np.sqrt(d2) - radius - 1e-9
                    close = where[d2 <= near]
                if len(close):
                    yield k, close


def replay_many(configs: Sequence[GameConfig], timelines: Sequence[Sequence[InputEvent]],
                stop_steps: Sequence[int | None] | None = None, batch_size: int = 4096,
                exact: bool = False, kernel: str | None = None) -> list[GameResult]:
    """Play many recorded games, in batches where their configurations allow; results in input order.

    Games whose configurations can share a batch (``batch_problem``) run together, at most
    ``batch_size`` at a time; the others (an implicit integrator) run one at a time in a
    ``GameSession``. Each result equals ``GameSession(config).play(timeline, stop_step)``.

    The batches run the compiled kernel where built (exact), else numpy's fast kernel unless
    ``exact``: then a game in which some hit was decided within ``KNIFE_EDGE`` of a target's
    edge (where round-off could tip it) is played again alone, so the results are the single
    session's either way. ``kernel`` is ``BatchGameSession``'s.
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
            batch = BatchGameSession([configs[i] for i in part], exact=exact, kernel=kernel)
            played = batch.play([timelines[i] for i in part], [stops[i] for i in part])
            for i, r, edge in zip(part, played, batch.knife_edge.tolist(), strict=True):
                results[i] = GameSession(configs[i]).play(timelines[i], stops[i]) if edge else r
    return results  # type: ignore[return-value]




# ------------------------------------------------------------------ many scripts at once
#: Bounds on one class run (``armgame play --headless --script A B ...``), checked before any game runs.
MAX_SCRIPTS = 5000
MAX_SCRIPT_EVENTS = 2_000_000
MAX_SCRIPTS_BYTES = 256 * 1024 * 1024


def files_in(folder: Path, suffix: str, limit: int, what: str) -> list[Path]:
    """The regular files ``*suffix`` directly in ``folder``, sorted by name.

    Symbolic links are skipped, never followed (a link could lead out of the folder), as
    are hidden files and subfolders; more than ``limit`` files is refused before any is read.
    """
    try:
        entries = sorted(os.scandir(folder), key=lambda e: e.name)
    except OSError as exc:
        raise UserError(f"{folder}: cannot list the folder: {exc.strerror or exc}") from None
    found = [Path(e.path) for e in entries
             if e.name.endswith(suffix) and not e.name.startswith(".") and e.is_file(follow_symlinks=False)]
    if len(found) > limit:
        raise UserError(f"{folder}: {len(found)} {what}, more than the {limit} one run takes")
    return found


def script_paths(names: Sequence[str | Path]) -> list[Path]:
    """Script files from the command line: files as given, folders as their ``*.txt`` files in sorted order."""
    paths: list[Path] = []
    for name in names:
        path = Path(name)
        if path.is_dir():
            inside = files_in(path, ".txt", MAX_SCRIPTS, "scripts")
            if not inside:
                raise UserError(f"{path}: no *.txt scripts in this folder")
            paths += inside
        else:
            paths.append(path)
        if len(paths) > MAX_SCRIPTS:
            raise UserError(f"more than {MAX_SCRIPTS} scripts in one run: split the class into several runs")
    total = 0
    for path in paths:
        try:
            info = path.stat()
        except OSError:
            continue  # the reader names what is wrong with it
        if stat.S_ISREG(info.st_mode):
            total += info.st_size
    if total > MAX_SCRIPTS_BYTES:
        raise UserError(f"the scripts add up to {total // (1024 * 1024)} MiB, more than the "
                        f"{MAX_SCRIPTS_BYTES // (1024 * 1024)} MiB one run takes")
    return paths


def play_scripts(config: GameConfig, paths: Sequence[Path]) -> list[GameResult]:
    """Play one game per script (``config`` with each), all in one batch; results in order.

    Every script is read and checked before any game runs, and their events together are
    bounded by ``MAX_SCRIPT_EVENTS``.
    """
    from ..script import load_script

    keys = (*(m.key for m in config.muscles), RESET_KEY, TOGGLE_ARM_KEY)
    timelines, total = [], 0
    for path in paths:
        if not path.is_file():
            raise UserError(f"{path}: not a script file" if path.exists() else f"{path}: no such script file")
        timeline = load_script(path, keys, config.dt)
        total += len(timeline)
        if total > MAX_SCRIPT_EVENTS:
            raise UserError(f"the scripts hold more than {MAX_SCRIPT_EVENTS} events together (at {path}): "
                            "split the class into several runs")
        timelines.append(timeline)
    return replay_many([config] * len(paths), timelines)
