"""M, C and G checked against the tutorial's method: a SymPy Euler-Lagrange derivation from T and U.

The derivation itself lives in ``armgame.derive`` (behind ``armgame derive``); this test evaluates it
at many more states than the command does.
"""

import numpy as np
import sympy as sp

from armgame.derive import derive_two_joint, parameter_values
from armgame.physics import TUTORIAL_ARM, TwoJointArm


def test_mass_coriolis_gravity_equal_the_euler_lagrange_derivation():
    d = derive_two_joint()
    args = (*d.q, *d.qd, *d.params)
    M_fn, C_fn, G_fn = (sp.lambdify(args, e, "numpy") for e in (d.M, d.C, d.G))
    values = parameter_values(2)
    arm = TwoJointArm(TUTORIAL_ARM)
    rng = np.random.default_rng(7)
    for q1, q2, w1, w2 in rng.uniform(-4, 4, (25, 4)):
        q, qd = np.array([q1, q2]), np.array([w1, w2])
        np.testing.assert_allclose(arm.mass_matrix(q), np.array(M_fn(q1, q2, w1, w2, *values), float), atol=1e-13)
        np.testing.assert_allclose(arm.coriolis(q, qd), np.array(C_fn(q1, q2, w1, w2, *values), float).ravel(),
                                   atol=1e-12)
        np.testing.assert_allclose(arm.gravity(q), np.array(G_fn(q1, q2, w1, w2, *values), float).ravel(),
                                   atol=1e-12)
    # T and U as the tutorial forms them: U zero hanging straight down, T = 1/2 qd' M qd.
    subs = dict(zip(d.params, values, strict=True))
    assert sp.simplify(d.U.subs({d.q[0]: -sp.pi / 2, d.q[1]: 0}).subs(subs)) == 0
    q, qd = (0.3, 1.1), (-0.7, 2.0)
    point = {**subs, **dict(zip(d.q, q, strict=True)), **dict(zip(d.qd, qd, strict=True))}
    assert float(d.T.subs(point)) == np.float64(arm.kinetic_energy(q, qd)).item() or np.isclose(
        float(d.T.subs(point)), arm.kinetic_energy(q, qd), rtol=1e-13)
