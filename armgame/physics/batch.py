"""Classic RK4 for a large batch of arms, in place.

``Integrator(name, model, "numpy")`` already steps a batch with the same code as one arm,
but every operation there allocates a new array: at 10,000 arms that costs about as much
as the arithmetic. ``BatchRK4`` holds the four state components and the torques as
contiguous arrays and writes every intermediate into preallocated scratch through numpy's
``out=``, so a step allocates nothing. It computes the same RK4 step as ``Integrator("rk4")``
to round-off.

Half of a step's time would go to sin and cos of whole arrays (about 15 ns an element each,
against well under 1 ns for a multiply). Stages 2 to 4 evaluate the elbow angle a small
increment past the start of the step, so their cos and sin come from the start's by angle
addition, with the increment's own cos and sin from short Taylor series: exact to
round-off while every increment is below ``SERIES_LIMIT``; a larger one (a huge step or a
wild spin) falls back to full sin and cos for that stage.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .trig import cos_array, sin_cos_array
from .twojoint import TwoJointArm

FloatArray = NDArray[np.float64]

#: Largest |increment| (rad) for the series: the first dropped terms, x^10/10! and x^11/11!,
#: are then below 3e-17.
SERIES_LIMIT = 0.1


class BatchRK4:
    """``n`` two-joint arms with the same parameters, each with its own state and torque.

    ``q1, q2, w1, w2`` (angles and velocities) and ``t1, t2`` (torques, held over each
    step) are 1-D arrays that callers may read and write in place between steps.
    """

    def __init__(self, model: TwoJointArm, states: ArrayLike, torques: ArrayLike = (0.0, 0.0)) -> None:
        x = np.asarray(states, dtype=float)
        if x.ndim != 2 or x.shape[1] != 4:
            raise ValueError(f"states must have shape (n, 4), got {x.shape}")
        u = np.broadcast_to(np.asarray(torques, dtype=float), (x.shape[0], 2))
        self._bind(model, *(np.ascontiguousarray(x[:, i]) for i in range(4)),
                   *(np.ascontiguousarray(u[:, i]) for i in range(2)))

    def _bind(self, model: TwoJointArm, *components: FloatArray) -> None:
        self.model = model
        self.q1, self.q2, self.w1, self.w2, self.t1, self.t2 = components
        self.n = len(self.q1)
        self._gravity = model.params.has_gravity
        self._damping = model.params.has_damping
        # Scratch: stage state (sq, sw), first and current accel (a, k), midpoint sums (m), accel temporaries.
        names = ("sq1", "sq2", "sw1", "sw2", "a1", "a2", "k1", "k2", "mq1", "mq2", "mw1", "mw2",
                 "bc", "bs", "m12", "f1", "f2", "r", "tmp", "c0", "s0", "d", "d2", "cd", "sd")
        self._s = {name: np.empty(self.n) for name in names}
        self._parts: list[BatchRK4] = []

    def _part(self, lo: int, hi: int) -> BatchRK4:
        """A stepper over arms lo..hi that shares this batch's arrays (slices are views)."""
        part = object.__new__(BatchRK4)
        part._bind(self.model, *(c[lo:hi] for c in (self.q1, self.q2, self.w1, self.w2, self.t1, self.t2)))
        return part

    @property
    def states(self) -> FloatArray:
        """A copy of the states, shape (n, 4)."""
        return np.stack([self.q1, self.q2, self.w1, self.w2], axis=-1)

    def _accel(self, q1: Any, q2: Any, w1: Any, w2: Any, out1: Any, out2: Any) -> None:
        """qdd into (out1, out2); the arithmetic of ``TwoJointArm.component_dynamics`` in place.

        Expects b cos(q2) and b sin(q2) already in the scratch arrays ``bc`` and ``bs``.
        """
        s, m = self._s, self.model
        bc, bs, m12, f1, f2, r, tmp = s["bc"], s["bs"], s["m12"], s["f1"], s["f2"], s["r"], s["tmp"]
        # f1 = t1 + b sin(q2) (2 w1 + w2) w2, f2 = t2 - b sin(q2) w1^2
        np.add(w1, w1, out=f1)
        f1 += w2
        f1 *= w2
        f1 *= bs
        f1 += self.t1
        np.multiply(w1, w1, out=f2)
        f2 *= bs
        np.subtract(self.t2, f2, out=f2)
        if self._gravity:
            np.add(q1, q2, out=tmp)
            cos_array(tmp, tmp)
            tmp *= m.g2
            f1 -= tmp
            f2 -= tmp
            cos_array(q1, tmp)
            tmp *= m.g1
            f1 -= tmp
        if self._damping:
            np.multiply(w1, m.params.damping1, out=tmp)
            f1 -= tmp
            np.multiply(w2, m.params.damping2, out=tmp)
            f2 -= tmp
        # det(M) = a d - d^2 - (b cos q2)^2; m11 = m12 + (a - d) + b cos q2.
        np.multiply(bc, bc, out=r)
        np.subtract(m.a * m.d - m.d * m.d, r, out=r)
        np.divide(1.0, r, out=r)
        np.add(bc, m.d, out=m12)
        np.multiply(f1, m.d, out=out1)
        np.multiply(m12, f2, out=tmp)
        out1 -= tmp
        out1 *= r
        np.add(m12, bc, out=tmp)
        tmp += m.a - m.d
        tmp *= f2
        np.multiply(m12, f1, out=out2)
        np.subtract(tmp, out2, out=out2)
        out2 *= r

    def _elbow_trig(self, delta: Any) -> None:
        """b cos and b sin of (q2 + delta) into ``bc`` and ``bs``, from cos and sin of q2 in ``c0``, ``s0``."""
        s, b = self._s, self.model.b
        bc, bs, c0, s0 = s["bc"], s["bs"], s["c0"], s["s0"]
        if float(np.max(np.abs(delta))) > SERIES_LIMIT:
            np.add(self.q2, delta, out=bc)
            sin_cos_array(bc, bs, bc)
        else:
            d2, cd, sd = s["d2"], s["cd"], s["sd"]
            np.multiply(delta, delta, out=d2)
            # Horner in x^2: cos x = 1 - x^2/2! + x^4/4! - x^6/6! + x^8/8!; sin x = x (1 - x^2/3! + ... + x^8/9!).
            np.multiply(d2, 1.0 / 40320.0, out=cd)
            np.multiply(d2, 1.0 / 362880.0, out=sd)
            for cos_coefficient, sin_coefficient in ((-1.0 / 720.0, -1.0 / 5040.0), (1.0 / 24.0, 1.0 / 120.0),
                                                     (-0.5, -1.0 / 6.0)):
                cd += cos_coefficient
                cd *= d2
                sd += sin_coefficient
                sd *= d2
            cd += 1.0
            sd += 1.0
            sd *= delta
            # cos(q + d) = cos q cos d - sin q sin d; sin(q + d) = sin q cos d + cos q sin d.
            np.multiply(c0, cd, out=bc)
            np.multiply(s0, sd, out=d2)
            bc -= d2
            np.multiply(s0, cd, out=bs)
            np.multiply(c0, sd, out=d2)
            bs += d2
        bc *= b
        bs *= b

    def step(self, dt: float) -> None:
        """One RK4 step of ``dt`` seconds for every arm, torques held."""
        s = self._s
        q1, q2, w1, w2 = self.q1, self.q2, self.w1, self.w2
        sq1, sq2, sw1, sw2 = s["sq1"], s["sq2"], s["sw1"], s["sw2"]
        a1, a2, k1, k2 = s["a1"], s["a2"], s["k1"], s["k2"]
        mq1, mq2, mw1, mw2 = s["mq1"], s["mq2"], s["mw1"], s["mw2"]
        c0, s0, delta = s["c0"], s["s0"], s["d"]
        b = self.model.b
        h = 0.5 * dt
        # Stage 1: slopes (w, a) at the start.
        sin_cos_array(q2, s0, c0)
        np.multiply(c0, b, out=s["bc"])
        np.multiply(s0, b, out=s["bs"])
        self._accel(q1, q2, w1, w2, a1, a2)
        # Stages 2 and 3 at the midpoint, stage 4 at the end. Each stage's state is the start
        # plus c times the previous stage's slopes: its position slope is the previous stage's
        # velocity (w itself before stage 2), its velocity slope the previous accel.
        pw1, pw2, pa1, pa2 = w1, w2, a1, a2
        for c in (h, h, dt):
            np.multiply(pw2, c, out=delta)
            np.add(q2, delta, out=sq2)
            self._elbow_trig(delta)
            if self._gravity:
                np.multiply(pw1, c, out=sq1)
                sq1 += q1
            np.multiply(pa1, c, out=sw1)
            sw1 += w1
            np.multiply(pa2, c, out=sw2)
            sw2 += w2
            self._accel(sq1, sq2, sw1, sw2, k1, k2)
            if c is h and pa1 is a1:  # stage 2 opens the midpoint sums
                np.copyto(mq1, sw1)
                np.copyto(mq2, sw2)
                np.copyto(mw1, k1)
                np.copyto(mw2, k2)
            elif c is h:
                mq1 += sw1
                mq2 += sw2
                mw1 += k1
                mw2 += k2
            pw1, pw2, pa1, pa2 = sw1, sw2, k1, k2
        # x' = x + dt/6 (slope1 + 2 (slope2 + slope3) + slope4); positions first, they use the old w.
        for x, start, mid, last in ((q1, w1, mq1, sw1), (q2, w2, mq2, sw2), (w1, a1, mw1, k1), (w2, a2, mw2, k2)):
            mid *= 2.0
            mid += start
            mid += last
            mid *= dt / 6.0
            x += mid

    def run(self, dt: float, steps: int, threads: int = 1) -> None:
        """``steps`` steps with the torques held; ``threads`` > 1 splits the arms among threads.

        Arms are independent, so each thread steps its own contiguous share of them for all
        ``steps`` with no synchronisation, and the result is the same as with one thread.
        numpy lets go of the GIL inside each operation, and half of a step's time goes to
        sin and cos of whole arrays, so two threads on two cores come close to twice the rate.
        """
        if threads <= 1 or self.n < 2 * threads:
            for _ in range(steps):
                self.step(dt)
            return
        from concurrent.futures import ThreadPoolExecutor

        if len(self._parts) != threads:
            bounds = np.linspace(0, self.n, threads + 1).astype(int)
            self._parts = [self._part(lo, hi) for lo, hi in itertools.pairwise(bounds)]
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(lambda part: part.run(dt, steps), self._parts))
