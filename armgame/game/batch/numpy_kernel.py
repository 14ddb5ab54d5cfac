"""The numpy kernel: the single session's physics step written out on arrays, one game a column.

Owns the batch's physics where the compiled kernel is not used (no C compiler, the Euler schemes,
``kernel="numpy"``), and the bound on a hand's move that both kernels use to find the hands near
their targets (``NEAR``, ``hand_move_bounds``). A physics step costs about 130 numpy calls however
many games there are.

Invariant: each column gets the bits the single session's scalar loop would, operation for
operation (or, in the fast mode, stays within ``session.STATE_TOLERANCE``):

* The physics is the single session's own arithmetic: for RK4 (the game's integrator) its hot
  loop, step and accelerations written out operation for operation on arrays (``NumpyKernel``);
  for the Euler schemes the very closures of ``Integrator(name, model, "numpy")``. Every array
  element goes through the same IEEE operations in the same order as the Python floats of one
  game, the joint angles' trig included (``physics.trig.sin_cos_array``, the arm's own sine, made of
  numpy's correctly rounded +, - and *): a batched game is bit for bit the single one.
* The kernel never decides a hit: it only flags games whose hand may be within a relative 1e-6
  of a target's edge (``NEAR``; a conservative bound on how far each hand has moved since it was
  last measured, so the batch does not pay four more sin and cos per step). The session decides
  those on Python floats (``BatchGameSession._hit_test``).
* The fast mode (``BatchGameSession(exact=False)``, from ``SERIES_MIN_GAMES`` games: below that
  numpy's call overhead outweighs sin and cos and the exact kernel is also the faster one): RK4
  stages 2-4 take the elbow's cos and sin from stage 1's by angle addition, with Taylor series for
  the small increment (as ``physics.batch.BatchRK4``; full sin and cos for any step whose
  increment exceeds ``SERIES_LIMIT``); stage 1's come from the previous step's, turned by the
  step's change of q2 (full sin and cos at the start of each run of steps and every 32 steps).
  That saves all but one in 32 of the steps' sin and cos of the whole batch, and costs round-off,
  which the arm's motion amplifies: over 1,000 games of 60 s with random keys the joint states
  stayed within 1.7e-11 of the single session's, against ``STATE_TOLERANCE``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator

import numpy as np

from ...physics.hand import hand_xy, hand_xy_arrays
from ...physics.trig import cos_array, sin_cos_array
from .kernel_inputs import KernelInputs

#: A hand this close to a target's edge (relative to radius^2) goes to the exact scalar test.
NEAR = 1.0 + 1e-6


def hand_move_bounds(l1: float, l2: float) -> tuple[float, float]:
    """(c1, c2) with |the hand's move| <= c1 |dq1| + c2 |dq2|: chords are shorter than arcs; a hair over."""
    return (l1 + l2) * (1.0 + 1e-9), l2 * (1.0 + 1e-9)


class NumpyKernel:
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

    def __init__(self, inputs: KernelInputs, m: int) -> None:
        self.inputs, self.m = inputs, m
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
        inputs, m = self.inputs, self.m
        model, config = inputs.model, inputs.config
        p = model.params
        gravity, damping = p.has_gravity, p.has_gravity or p.has_damping
        const = np.array
        B, D, G1, G2 = const(model.b), const(model.d), const(model.g1), const(model.g2)
        DET0, AMD = const(model.a * model.d - model.d * model.d), const(model.a - model.d)
        ONE, TWO, ZERO = const(1.0), const(2.0), const(0.0)
        dt = config.dt
        H, DT, SIXTH = const(0.5 * dt), const(dt), const(dt * (1.0 / 6.0))
        REACH1, REACH2 = (const(c) for c in hand_move_bounds(p.l1, p.l2))
        mul, add, sub, div = np.multiply, np.add, np.subtract, np.divide
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
        for out, moments in ((t1, inputs.shoulder), (t2, inputs.elbow)):
            terms = [(act[i], const(c)) for i, c in enumerate(moments) if c != 0.0]
            rows.append((out, terms, len(terms) < len(moments)))
        generic = None if config.integrator == "rk4" else inputs.physics_step
        exact = generic is not None or not inputs.fast or m < inputs.series_from

        def elbow(q2):
            sin_cos_array(q2, hs, bc)
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
        LIMIT2 = inputs.series_limit * inputs.series_limit
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
                cos_array(gc12, gc12)
                mul(gc12, G2, gc12)
                cos_array(q1, tmp)
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
                sin_cos_array(x[1], base[1], base[0])
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
        config = self.inputs.config
        l1, l2, radius = config.arm.l1, config.arm.l2, config.target_radius
        near = NEAR * radius * radius
        sqrt = math.sqrt
        for k in range(count):
            if step():
                where = np.flatnonzero(self.near_mask)
                if len(where) <= 16:  # the usual few: plain floats cost less than numpy on tiny arrays
                    angles = x[:2, where].tolist()
                    gaps, close_list = [], []
                    for j, a, b, x0, y0 in zip(where.tolist(), angles[0], angles[1], tx[where].tolist(),
                                               ty[where].tolist(), strict=True):
                        hx, hy = hand_xy(l1, l2, a, b)
                        dx, dy = hx - x0, hy - y0
                        d2 = dx * dx + dy * dy
                        gaps.append(sqrt(d2) - radius - 1e-9)
                        if d2 <= near:
                            close_list.append(j)
                    slack[where] = gaps
                    close = np.array(close_list, dtype=np.intp)
                else:
                    a, b = x[0, where], x[1, where]
                    hx, hy = hand_xy_arrays(l1, l2, a, b)
                    dx, dy = hx - tx[where], hy - ty[where]
                    d2 = dx * dx + dy * dy
                    slack[where] = np.sqrt(d2) - radius - 1e-9
                    close = where[d2 <= near]
                if len(close):
                    yield k, close
