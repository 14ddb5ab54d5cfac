"""The equations of motion derived symbolically, as the tutorial's onejoint_lagrange.py and
twojointarm_lagrange.py do: kinematics -> kinetic energy T and potential energy U -> L = T - U ->
Euler-Lagrange -> tau = M(q) qdd + C(q, qd) + G(q). Needs SymPy (the optional ``derive`` extra).

In armgame's convention (see the README): q1 from +x counter-clockwise, q2 relative to the upper arm,
gravity along -y, potential energy zero with the arm hanging straight down. The result is compared with
the numeric core (``armgame.physics``) at random states: the derivation checks the hand-written model.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
import sympy as sp

from .physics.onejoint import OneJointArm
from .physics.params import PENDULUM, TUTORIAL_ARM
from .physics.twojoint import TwoJointArm

#: A difference from the core larger than this (in N m, kg m^2) means the two disagree.
MATCH_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Derivation:
    joints: int
    T: Any  # kinetic energy (sympy expression in q, qd)
    U: Any  # potential energy
    M: Any  # sympy Matrix (n x n)
    C: Any  # sympy Matrix (n x 1): Coriolis-centrifugal torques
    G: Any  # sympy Matrix (n x 1): gravity torques
    q: tuple[Any, ...]  # angle symbols
    qd: tuple[Any, ...]  # velocity symbols
    params: tuple[Any, ...]  # parameter symbols, in the order ``parameter_values`` gives them


def _euler_lagrange(t: Any, coords: list[Any], T: Any, U: Any, params: tuple[Any, ...]) -> Derivation:
    n = len(coords)
    names = ("1", "2")[:n]
    q = tuple(sp.Symbol(f"q{k}") for k in names)
    qd = tuple(sp.Symbol(f"qd{k}") for k in names)
    qdd = tuple(sp.Symbol(f"qdd{k}") for k in names)
    L = T - U
    # Q_j = d/dt (dL/dqd_j) - dL/dq_j, the tutorial's Euler-Lagrange equation.
    Q = [L.diff(c.diff(t)).diff(t) - L.diff(c) for c in coords]

    def plain(e: Any) -> Any:
        # Highest derivatives first: replacing q(t) first would also rewrite inside its derivatives.
        e = e.subs({c.diff(t, 2): a for c, a in zip(coords, qdd, strict=True)})
        e = e.subs({c.diff(t): w for c, w in zip(coords, qd, strict=True)})
        return sp.expand(e.subs(dict(zip(coords, q, strict=True))))

    Q = [plain(e) for e in Q]
    zero_acc = {a: 0 for a in qdd}
    zero_vel = {w: 0 for w in qd}
    squares = {sp.sin(a) ** 2: 1 - sp.cos(a) ** 2 for a in q}

    def trig_reduced(e: Any) -> Any:
        # What trigsimp found here, a few times faster: angle sums expanded, then sin^2 = 1 - cos^2
        # leaves a polynomial in which each sin is of degree one, a canonical form, so every
        # sin^2 + cos^2 cancels (M and C of this arm then hold only cos q2 and sin q2).
        return sp.expand(sp.expand(sp.expand_trig(e)).subs(squares))

    M = sp.Matrix([[trig_reduced(sp.factor_terms(e.coeff(a))) for a in qdd] for e in Q])
    G = sp.Matrix([sp.factor_terms(e.subs(zero_acc).subs(zero_vel)) for e in Q])
    C = sp.Matrix([sp.factor(trig_reduced(e.subs(zero_acc) - e.subs(zero_acc).subs(zero_vel))) for e in Q])
    T = sp.collect(trig_reduced(plain(T)), [w1 * w2 for w1 in qd for w2 in qd])
    return Derivation(n, T, sp.factor_terms(plain(U)), M, C, G, q, qd, params)


@cache  # a derivation takes seconds and never changes
def derive_one_joint() -> Derivation:
    """The pendulum: a link of mass m, centre of mass r from the joint, inertia i about it."""
    t = sp.Symbol("t")
    r, m, i, g = sp.symbols("r m i g", positive=True)
    q = sp.Function("q1")(t)
    x, y = r * sp.cos(q), r * sp.sin(q)
    T = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2 + i * q.diff(t) ** 2 / 2
    U = m * g * (y + r)  # + r: zero hanging straight down, as the tutorial sets it
    return _euler_lagrange(t, [q], T, U, (r, m, i, g))


@cache
def derive_two_joint() -> Derivation:
    """The two-joint arm: links 1 (upper arm) and 2 (forearm), centres of mass r1, r2 from their joints."""
    t = sp.Symbol("t")
    l1, r1, r2, m1, m2, i1, i2, g = sp.symbols("l1 r1 r2 m1 m2 i1 i2 g", positive=True)
    q1, q2 = sp.Function("q1")(t), sp.Function("q2")(t)
    x1, y1 = r1 * sp.cos(q1), r1 * sp.sin(q1)
    x2 = l1 * sp.cos(q1) + r2 * sp.cos(q1 + q2)
    y2 = l1 * sp.sin(q1) + r2 * sp.sin(q1 + q2)
    T = (m1 * (x1.diff(t) ** 2 + y1.diff(t) ** 2) / 2 + i1 * q1.diff(t) ** 2 / 2
         + m2 * (x2.diff(t) ** 2 + y2.diff(t) ** 2) / 2 + i2 * (q1.diff(t) + q2.diff(t)) ** 2 / 2)
    U = g * (m1 * (y1 + r1) + m2 * (y2 + l1 + r2))  # zero with the arm hanging straight down
    return _euler_lagrange(t, [q1, q2], T, U, (l1, r1, r2, m1, m2, i1, i2, g))


def derive(joints: int) -> Derivation:
    if joints == 1:
        return derive_one_joint()
    if joints == 2:
        return derive_two_joint()
    raise ValueError(f"joints must be 1 or 2, got {joints!r}")


def parameter_values(joints: int) -> tuple[float, ...]:
    """The tutorial's arm (two joints) or pendulum (one), in the order of ``Derivation.params``."""
    if joints == 1:
        p1 = PENDULUM
        return (p1.r, p1.m, p1.i, p1.gravity)
    p = TUTORIAL_ARM
    return (p.l1, p.r1, p.r2, p.m1, p.m2, p.i1, p.i2, p.gravity)


def compare_with_core(d: Derivation, states: int = 5, seed: int = 0) -> float:
    """The largest |derived - core| over M, C and G at ``states`` random states of the tutorial's arm."""
    values = parameter_values(d.joints)
    args = (*d.q, *d.qd, *d.params)
    M_fn, C_fn, G_fn = (sp.lambdify(args, e, "numpy") for e in (d.M, d.C, d.G))
    rng = np.random.default_rng(seed)
    worst = 0.0
    if d.joints == 1:
        core = OneJointArm(PENDULUM)
        for q, w in rng.uniform(-4.0, 4.0, (states, 2)):
            derived = [np.asarray(f(q, w, *values), float).ravel() for f in (M_fn, C_fn, G_fn)]
            expected = [np.array([core.inertia]), np.array([0.0]), np.atleast_1d(core.gravity(q))]
            worst = max(worst, *(float(np.max(np.abs(a - b))) for a, b in zip(derived, expected, strict=True)))
        return worst
    core = TwoJointArm(TUTORIAL_ARM)
    for q1, q2, w1, w2 in rng.uniform(-4.0, 4.0, (states, 4)):
        q, qd = np.array([q1, q2]), np.array([w1, w2])
        derived = [np.asarray(f(q1, q2, w1, w2, *values), float).reshape(-1) for f in (M_fn, C_fn, G_fn)]
        expected = [core.mass_matrix(q).ravel(), core.coriolis(q, qd), core.gravity(q)]
        worst = max(worst, *(float(np.max(np.abs(a - b))) for a, b in zip(derived, expected, strict=True)))
    return worst


def _entries(d: Derivation) -> list[tuple[str, Any]]:
    n = d.joints
    out: list[tuple[str, Any]] = []
    for r in range(n):
        for c in range(n):
            out.append((f"M{r + 1}{c + 1}" if n > 1 else "M", d.M[r, c]))
    for name, vec in (("C", d.C), ("G", d.G)):
        for r in range(n):
            out.append((f"{name}{r + 1}" if n > 1 else name, vec[r]))
    return out


def format_text(d: Derivation) -> str:
    n = d.joints
    lines = [
        f"{'One' if n == 1 else 'Two'}-joint arm, by Euler-Lagrange (q1 from +x counter-clockwise"
        + (", q2 relative to the upper arm" if n == 2 else "") + "; gravity along -y)",
        f"T = {sp.sstr(d.T)}",
        f"U = {sp.sstr(d.U)}",
        "tau = M(q) qdd + C(q, qd) + G(q)" if n == 2 else "tau = M qdd1 + C + G",
    ]
    lines += [f"  {name} = {sp.sstr(expr)}" for name, expr in _entries(d)]
    return "\n".join(lines)


def format_latex(d: Derivation) -> str:
    names: dict[Any, str] = {}
    for k, (q, w) in enumerate(zip(d.q, d.qd, strict=True), start=1):
        names[q] = f"q_{k}"
        names[w] = rf"\dot{{q}}_{k}"
    for s in d.params:
        text = str(s)
        names[s] = f"{text[0]}_{text[1:]}" if len(text) > 1 else text
    tex = lambda e: sp.latex(e, symbol_names=names)  # noqa: E731
    lines = [f"T = {tex(d.T)}", f"U = {tex(d.U)}"]
    lines.append(r"\tau = M(q)\,\ddot{q} + C(q, \dot{q}) + G(q)")
    lines += [f"{name[0]}_{{{name[1:]}}} = {tex(expr)}" if len(name) > 1 else f"{name} = {tex(expr)}"
              for name, expr in _entries(d)]
    return "\n".join(lines)
