"""armgame derive: the SymPy derivation printed as M, C, G and checked against the numeric core, and M, C
and G checked against the tutorial's method at many more states than the command does.

One module, so one xdist worker derives the two-joint arm once (``derive_two_joint`` is cached), and
SymPy is imported in the tests, not at collection: only that worker pays its half second.
"""

import numpy as np
import pytest

from armgame.cli import main
from armgame.physics import TUTORIAL_ARM, TwoJointArm


@pytest.mark.parametrize("arm", ["one", "two"])
def test_derive_prints_equations_and_matches_the_core(arm, capsys):
    assert main(["derive", arm]) == 0
    out = capsys.readouterr().out
    assert "T = " in out and "U = " in out
    if arm == "two":
        for name in ("M11", "M12", "M22", "C1", "C2", "G1", "G2"):
            assert f"  {name} = " in out
        assert "C2 = l1*m2*qd1**2*r2*sin(q2)" in out
    else:
        assert "  M = i + m*r**2" in out and "  G = g*m*r*cos(q1)" in out
    assert out.strip().splitlines()[-1].endswith(": matches")


def test_derive_latex(capsys):
    assert main(["derive", "two", "--latex"]) == 0
    out = capsys.readouterr().out
    assert r"M_{11} = " in out and r"\dot{q}_1" in out and r"\cos{\left(q_{2} \right)}" not in out


def test_a_wrong_core_is_reported_as_differing(monkeypatch, capsys):
    import armgame.derive as derive_module

    monkeypatch.setattr(derive_module, "compare_with_core", lambda d, states, seed: 0.5)
    assert main(["derive", "one"]) == 1
    assert capsys.readouterr().out.strip().endswith("DIFFERS")


def test_one_joint_derivation_is_exact():
    from armgame.derive import MATCH_TOLERANCE, compare_with_core, derive_one_joint, format_text

    d = derive_one_joint()
    assert compare_with_core(d, states=10, seed=3) <= MATCH_TOLERANCE
    assert "qd1" in format_text(d)


def test_bad_states_is_a_one_line_error(capsys):
    assert main(["derive", "two", "--states", "0"]) == 2
    assert "--states" in capsys.readouterr().err


def test_mass_coriolis_gravity_equal_the_euler_lagrange_derivation():
    import sympy as sp

    from armgame.derive import derive_two_joint, parameter_values

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


def test_the_seed_range_docs_physics_states(capsys):
    """docs/physics.md: "`--seed`, 0 to 2^63 - 1" (tests/test_lab_claims.py finds the phrase): both ends pass
    the check and the first seed past either is refused."""
    assert main(["derive", "one", "--states", "1", "--seed", str(2**63 - 1)]) == 0
    for seed in (-1, 2**63):
        assert main(["derive", "one", "--states", "1", "--seed", str(seed)]) != 0
        assert f"from 0 to 2^63 - 1, got {seed}" in capsys.readouterr().err
