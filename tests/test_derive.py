"""armgame derive: the SymPy derivation printed as M, C, G and checked against the numeric core."""

import pytest

from armgame.cli import main
from armgame.derive import MATCH_TOLERANCE, compare_with_core, derive_one_joint, format_text


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
    d = derive_one_joint()
    assert compare_with_core(d, states=10, seed=3) <= MATCH_TOLERANCE
    assert "qd1" in format_text(d)


def test_bad_states_is_a_one_line_error(capsys):
    assert main(["derive", "two", "--states", "0"]) == 2
    assert "--states" in capsys.readouterr().err
