"""The batched session: ``n`` games in lockstep, game ``i`` equal to ``GameSession(configs[i])``.

Owns the batch's state (one array per quantity: joint state, activations, targets, clocks), its
input (keys, levels, resets, restarts), the choice of kernel and of when the fast arithmetic may
run, the hit test and scoring, ``play`` (timelines) and ``replay_many`` (recorded games, in
batches). The physics steps run in a kernel (``numpy_kernel`` or ``compiled``); timelines become
commands in ``schedule``. Those read the batch through two values made here once (``kernel_inputs``:
its fixed numbers and its state arrays), never through this class.

Invariant: each game of a batch equals the single ``GameSession`` fed the same inputs: hits,
score, resets and steps exactly, and its joint state bit for bit (both kernels: the same operations,
the arm's sine included, ``physics.trig``) or within ``STATE_TOLERANCE`` (the fast kernels of
``exact=False``). It keeps it so:

* Events (keys, resets, tab) are applied between physics steps exactly where the single session
  applies them (``schedule``); ``play`` advances every game to the next step at which any game has
  an event, vectorised in between (the compiled kernel needs no such common step).
* The hit test never depends on a kernel's round-off: the kernels only flag hands that may be at
  a target's edge, and for those the single session's own test is evaluated here on Python floats
  from the game's state, and the hit is scored by the game's own ``GameRules`` (which draws the
  next target from the game's own random sequence). Given equal states the decision is identical,
  knife edge or not.
* ``exact=False`` (the vector env, ``replay_many``: class scoring and verification) lets the fast
  kernels run (numpy's from ``SERIES_MIN_GAMES`` games, the compiled one's at any size; games
  longer than ``FAST_MAX_SECONDS`` run the exact kernel). Hits are still decided by the exact test
  on Python floats, on the fast state; the hand is then within about 1.4e-11 m of the single
  session's, so a decision could differ only if the hand were that close to the edge, where it
  moves about 1e-3 m a step: about 3e-8 per crossing. A decision within ``KNIFE_EDGE`` (1e-8 m)
  marks the game ``knife_edge`` (about 2e-5 per crossing), and ``replay_many`` plays marked games
  again alone, so its results are the single session's; the vector env, with no timeline to
  replay, keeps the 3e-8 odds.
* The implicit integrators (midpoint, gauss4) iterate until the largest change over the whole
  batch converges, so a game's iteration count would depend on the others: a batch refuses them
  and ``replay_many`` plays such games one at a time.

The numbers tests lower (``SERIES_MIN_GAMES``, ``SERIES_LIMIT``, ``KNIFE_EDGE``) are read from this
module, the first two when a batch is made (they hold for that batch).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import fields, replace

import numpy as np

from ... import __version__
from ...errors import UserError
from ...physics.batch import SERIES_LIMIT
from ...physics.hand import hand_from_trig
from ...physics.integrators import Integrator
from ...physics.twojoint import TwoJointArm
from ..muscles import MuscleLevelError, MuscleSet
from ..rules import DwellRules, GameConfig, GameRules, hand_position
from ..session import DOWN, RESET_KEY, TOGGLE_ARM_KEY, GameResult, InputEvent, NonFiniteStateError
from ..variant import GameVariant
from .compiled import CompiledKernel
from .compiled import available as compiled_available
from .kernel_inputs import BatchArrays, KernelInputs
from .numpy_kernel import NumpyKernel
from .schedule import MuscleEvents, schedule
from .variant import BatchVariant

#: ``BatchGameSession(kernel=...)``: None, the compiled kernel where built (and RK4), else numpy.
KERNELS = (None, "compiled", "numpy")

#: Integrators whose batched step is the single step to round-off (no batch-wide iteration).
BATCH_INTEGRATORS = ("rk4", "euler", "symplectic-euler")

#: Fields a batch's games may differ in; every other field of ``GameConfig`` must be equal.
PER_GAME_FIELDS = ("seed", "time_limit", "scene")

#: Largest joint-state difference (rad, rad/s) from the single session that a fast batch
#: (``exact=False``) allows itself; an exact one differs by zero (every test checks). Round-off stays
#: far below it: with sin and cos an ulp off in half their calls, 20 student games of 60 s stayed
#: within 1.1e-13 of the exact ones, with the same results (the viscous arm forgets round-off rather
#: than amplifying it; tests/test_batch.py repeats this on two games).
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

    ``hold_steps``: every game's dwell (``rules.DwellRules``: a hit counts once the hand has stayed that many
    physics steps in the target); 0, the game's rule. The kernels flag a hand inside its target after every
    step (its slack is negative there), so the rules see each such step, as the single session's loops show
    them.

    ``variant``: the harder tasks' game (``armgame.game.variant.GameVariant``: its dwell, and its motor noise,
    field and speed guard, which ``variant.BatchVariant`` keeps and only the compiled kernel steps). With
    noise, call ``apply_noise()`` before each decision's ``advance``; a game the guard stops is ``stopped``
    (over, with ``stop_reasons[i]``) at its state at that ``advance``'s start, until restarted.
    """

    def __init__(self, configs: Sequence[GameConfig], exact: bool = True, kernel: str | None = None,
                 hold_steps: int = 0, variant: GameVariant | None = None) -> None:
        configs = list(configs)
        if variant is not None:
            if hold_steps and hold_steps != variant.hold_steps:
                raise ValueError(f"hold_steps {hold_steps} and the variant's {variant.hold_steps} differ")
            hold_steps = variant.hold_steps
        self.hold_steps = hold_steps
        problem = batch_problem(configs)
        if problem:
            raise UserError(problem)
        if kernel not in KERNELS:
            raise ValueError(f"kernel {kernel!r}: expected one of {', '.join(map(repr, KERNELS))}")
        if kernel == "compiled" and not compiled_available():
            raise ValueError("kernel 'compiled': the compiled kernel is not built here (no C compiler at install?)")
        loaded = BatchVariant.needs_compiled(variant)
        if loaded and (kernel == "numpy" or not compiled_available() or configs[0].integrator != "rk4"):
            raise UserError("a batch plays motor noise and force fields in its compiled kernel only (RK4, built "
                            "where pip install found a C compiler): play such games one at a time")
        self.configs = configs
        #: True: the single session's arithmetic, bit for bit; False: the kernels may use their fast RK4
        #: stages (see ``numpy_kernel`` and ``compiled``), within ``STATE_TOLERANCE``.
        self.exact = bool(exact)
        self.config = c = configs[0]
        self.n = n = len(configs)
        self.model = TwoJointArm(c.arm)
        muscles = MuscleSet(c.muscles, c.dt)
        self.muscle_keys = muscles.keys
        self.keys = (*muscles.keys, RESET_KEY, TOGGLE_ARM_KEY)
        self._rise = np.array(muscles._rise)
        self._decay = np.array(muscles._decay)
        self.target_radius = c.target_radius
        self.total_steps = np.array([g.total_steps for g in configs], dtype=np.int64)
        # Rows of the state: q1, q2, w1, w2; rows of the muscle arrays: the four muscles. Rows
        # are contiguous, so each is one fast array for the step. Rows 4-5 of ``_xs`` are scratch
        # for the first RK4 stage's accelerations (see NumpyKernel._build).
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
        # The hand's trig, rows cos q1, sin q1, cos(q1 + q2), sin(q1 + q2), and the q1, q2 they are of: the
        # compiled kernel writes them for the games it steps (the C library's, one sincos pair a game where
        # numpy's cos and sin cost 8 calls over the batch), ``hand_trig`` fills in the rest.
        self._trig = np.full((6, n), np.nan)
        #: Games whose hand came within ``KNIFE_EDGE`` of a target's edge in the fast kernel: their hits
        #: could differ from the single session's (``replay_many`` plays them again alone).
        self.knife_edge = np.zeros(n, dtype=bool)
        use_compiled = kernel != "numpy" and compiled_available() and c.integrator == "rk4"
        # Whether the kernel may round differently from the single session: the fast stages, which
        # compiled pay at any batch size, in numpy only from SERIES_MIN_GAMES games (call overhead).
        self._rounds = (not self.exact and c.integrator == "rk4"
                        and int(self.total_steps.max()) * c.dt <= FAST_MAX_SECONDS
                        and (use_compiled or n >= SERIES_MIN_GAMES))
        #: What the kernels and the schedule read of this batch (they are handed these, never the batch).
        self.kernel_inputs = KernelInputs(
            model=self.model, config=c, shoulder=tuple(m[0] for m in muscles.moments),
            elbow=tuple(m[1] for m in muscles.moments), muscle_keys=muscles.keys, rise=self._rise,
            decay=self._decay, physics_step=Integrator(c.integrator, self.model, "numpy").step_components,
            fast=self._rounds, series_from=SERIES_MIN_GAMES, series_limit=SERIES_LIMIT)
        #: The noise, field and guard of ``variant`` (None: the game's physics).
        self.variant = None if not loaded else BatchVariant(
            variant, c.dt, n, self.kernel_inputs.shoulder, self.kernel_inputs.elbow)  # type: ignore[arg-type]
        physics = self.variant
        self.arrays = BatchArrays(self._xs, self._act, self._goal, self._rate, self._slack, self.target_x,
                                  self.target_y, self.steps, self._trig, None if physics is None else physics.moments,
                                  None if physics is None else physics.loads)
        self.rules: list[GameRules] = [None] * n  # type: ignore[list-item]
        self._kernels: dict[int, NumpyKernel] = {}
        for i in range(n):
            self._start(i, configs[i])
        #: The compiled kernel where built (and asked for) and the integrator is RK4; else None: numpy.
        self.compiled = CompiledKernel(self.kernel_inputs, self.arrays, self._hit_test,
                                       self._runaway) if use_compiled else None

    def _start(self, i: int, config: GameConfig) -> None:
        self.configs[i] = config
        self.rules[i] = rules = DwellRules(config, self.hold_steps) if self.hold_steps else GameRules(config)
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
        if self.variant is not None:
            self.variant.start(i, config.seed)

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
        over = self.steps >= self.total_steps
        return over if self.variant is None else over | self.variant.stopped

    @property
    def stopped(self) -> np.ndarray:
        """Games the speed guard stopped (over; ``stop_reasons`` says why): none without a guard."""
        return np.zeros(self.n, dtype=bool) if self.variant is None else self.variant.stopped

    @property
    def stop_reasons(self) -> dict[int, str]:
        """Each stopped game's reason, in one line (``GameSession``'s ``RunawayError`` message)."""
        return {} if self.variant is None else self.variant.reasons

    @property
    def time_left(self) -> np.ndarray:
        return np.maximum(0, self.total_steps - self.steps) * self.config.dt

    def hand(self) -> tuple[np.ndarray, np.ndarray]:
        """Hand positions (m), x and y, one per game."""
        p = self.config.arm
        c1, s1, c12, s12 = self.hand_trig()
        return hand_from_trig(p.l1, p.l2, c1, s1, c12, s12)

    def hand_trig(self) -> np.ndarray:
        """cos q1, sin q1, cos(q1 + q2), sin(q1 + q2) of every game, rows of a (4, n) array (do not write).

        Where the compiled kernel stepped a game last, its values (the C library's); elsewhere (the
        arm reset, a game restarted, the numpy kernel) numpy's, computed now. Either is the cosine or sine
        of the game's angles to within numpy's ulp, so observations agree with the single env's to round-off.
        """
        trig, q1, q2 = self._trig, self._x[0], self._x[1]
        stale = (trig[4] != q1) | (trig[5] != q2)
        if stale.any():
            if stale.all():
                a, b, stale = q1, q2, slice(None)
            else:
                a, b = q1[stale], q2[stale]
            s12 = a + b
            trig[0, stale], trig[1, stale] = np.cos(a), np.sin(a)
            trig[2, stale], trig[3, stale] = np.cos(s12), np.sin(s12)
            trig[4, stale], trig[5, stale] = a, b
        return trig[:4]

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
        # Every game at once (a vector env's step, its games all running) takes whole rows: the boolean
        # indexing below was a seventh of a continuous vector env's step at 8,192 games.
        every = bool(mask.all())
        chosen = levels if every else levels[mask]
        if not np.all((chosen >= 0.0) & (chosen <= 1.0)):
            raise MuscleLevelError("muscle levels must be from 0 to 1")
        levels = levels.T
        if every:
            self._goal[...] = levels
            np.copyto(self._rate, np.where(levels > self._act, self._rise[:, None], self._decay[:, None]))
            return
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

    def apply_noise(self) -> None:
        """The motor noise's next decision on every game's muscles (``MuscleNoise.apply`` for each); none without."""
        if self.variant is not None:
            self.variant.apply_noise()

    def _runaway(self, i: int) -> None:
        assert self.variant is not None
        self.variant.runaway(i, self._xs, self._act, self.steps)
        self._slack[i] = -1.0

    def _advance(self, steps: int) -> None:
        left = int(steps)
        if left <= 0:
            return
        if self.compiled is not None:
            halt = np.minimum(self.steps + min(left, int(self.total_steps.max())), self.total_steps)
            if self.variant is not None:
                self.variant.keep(self._xs, self._act, self.steps)
                halt = np.where(self.variant.stopped, self.steps, halt)
            self.compiled.run(halt)
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
            kernel = self._kernels[m] = NumpyKernel(self.kernel_inputs, m)
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
        hx, hy = hand_position(p.l1, p.l2, q1, q2)
        rules = self.rules[i]
        target = rules.target
        dx, dy = hx - target.x, hy - target.y
        d2 = dx * dx + dy * dy
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
        if self.variant is not None:
            raise ValueError("play: a batch with motor noise or a field is stepped decision by decision (advance)")
        if len(timelines) != self.n:
            raise ValueError(f"{self.n} games but {len(timelines)} timelines")
        stops = [None] * self.n if stop_steps is None else list(stop_steps)
        if len(stops) != self.n:
            raise ValueError(f"{self.n} games but {len(stops)} stop steps")
        if np.any(self.steps != self.steps[0]):
            raise ValueError("play needs every game of the batch at the same step")
        now = int(self.steps[0])
        limit = [t if s is None else min(int(s), t) for s, t in zip(stops, self.total_steps.tolist(), strict=True)]
        muscle_steps, flat, goal, rate, specials, held = schedule(self.kernel_inputs, self._held, self.total_steps,
                                                                  timelines, now, limit)
        limits = np.array(limit, dtype=np.int64)
        if self.compiled is not None:
            self.compiled.play(MuscleEvents.by_game(self.n, muscle_steps, flat, goal, rate), specials, limits,
                               self.key_event)
            self._held[...] = held
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
        self._held[...] = held
        return [self.result(i) for i in range(self.n)]
