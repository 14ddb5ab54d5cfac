"""M, C and G checked against the tutorial's method: a SymPy Euler-Lagrange derivation from T and U."""

import numpy as np
import sympy as sp

from armgame.physics import TUTORIAL_ARM, TwoJointArm


def derive_two_joint():
    t = sp.symbols("t")
    l1, r1, r2, m1, m2, i1, i2, g = sp.symbols("l1 r1 r2 m1 m2 i1 i2 g", positive=True)
    q1, q2 = sp.Function("q1")(t), sp.Function("q2")(t)
    x1, y1 = r1 * sp.cos(q1), r1 * sp.sin(q1)
    x2 = l1 * sp.cos(q1) + r2 * sp.cos(q1 + q2)
    y2 = l1 * sp.sin(q1) + r2 * sp.sin(q1 + q2)
    T = (m1 * (x1.diff(t) ** 2 + y1.diff(t) ** 2) / 2 + i1 * q1.diff(t) ** 2 / 2
         + m2 * (x2.diff(t) ** 2 + y2.diff(t) ** 2) / 2 + i2 * (q1.diff(t) + q2.diff(t)) ** 2 / 2)
    U = g * (m1 * y1 + m2 * y2)
    L = T - U
    Q = [sp.expand(L.diff(q.diff(t)).diff(t) - L.diff(q)) for q in (q1, q2)]
    a1, a2, w1, w2, p1, p2 = sp.symbols("a1 a2 w1 w2 p1 p2")
    plain = {q1.diff(t, 2): a1, q2.diff(t, 2): a2}
    Q = [e.subs(plain).subs({q1.diff(t): w1, q2.diff(t): w2}).subs({q1: p1, q2: p2}) for e in Q]
    M = sp.Matrix([[sp.expand(e).coeff(a) for a in (a1, a2)] for e in Q])
    G = sp.Matrix([sp.expand(e).subs({a1: 0, a2: 0, w1: 0, w2: 0}) for e in Q])
    C = sp.Matrix([sp.expand(e).subs({a1: 0, a2: 0}) for e in Q]) - G
    params = (l1, r1, r2, m1, m2, i1, i2, g)
    return [sp.lambdify((p1, p2, w1, w2, *params), expr, "numpy") for expr in (M, C, G)]


def test_mass_coriolis_gravity_equal_the_euler_lagrange_derivation():
    M_fn, C_fn, G_fn = derive_two_joint()
    p = TUTORIAL_ARM
    values = (p.l1, p.r1, p.r2, p.m1, p.m2, p.i1, p.i2, p.gravity)
    arm = TwoJointArm(p)
    rng = np.random.default_rng(7)
    for q1, q2, w1, w2 in rng.uniform(-4, 4, (25, 4)):
        q, qd = np.array([q1, q2]), np.array([w1, w2])
        np.testing.assert_allclose(arm.mass_matrix(q), np.array(M_fn(q1, q2, w1, w2, *values), float), atol=1e-13)
        np.testing.assert_allclose(arm.coriolis(q, qd), np.array(C_fn(q1, q2, w1, w2, *values), float).ravel(),
                                   atol=1e-12)
        np.testing.assert_allclose(arm.gravity(q), np.array(G_fn(q1, q2, w1, w2, *values), float).ravel(),
                                   atol=1e-12)
