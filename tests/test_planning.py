"""armgame demo planning: minimum jerk beside minimum torque change, the science and the command."""

import csv
import math

import numpy as np
import pytest

from armgame.cli import main
from armgame.demos.planning import START, TARGET, PlanningRun, basis, plan_reach
from armgame.errors import UserError

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def planning():
    return plan_reach()


def test_basis_vanishes_with_two_derivatives_at_both_ends_exactly():
    s = np.linspace(0.0, 1.0, 201)
    values = basis(10, s)
    for v in values:
        assert np.all(v[[0, -1]] == 0.0)
    phi, phi1, phi2 = values
    assert np.min(np.max(np.abs(phi), axis=0)) > 1e-4  # no function is zero everywhere
    h = s[1] - s[0]  # the derivatives are the derivatives
    np.testing.assert_allclose(np.gradient(phi, h, axis=0)[1:-1], phi1[1:-1], atol=2e-3)
    np.testing.assert_allclose(np.gradient(phi1, h, axis=0)[1:-1], phi2[1:-1], atol=5e-2)


def test_minimum_jerk_moves_straight_with_a_bell_shaped_speed(planning):
    jerk = planning.jerk
    assert np.max(np.abs(jerk.deviation())) < 1e-12
    speed, t, duration = jerk.speed, jerk.t, planning.duration
    distance = math.dist(START, TARGET)
    assert speed.max() == pytest.approx(1.875 * distance / duration, rel=1e-9)  # Flash & Hogan's peak
    assert t[np.argmax(speed)] == pytest.approx(duration / 2, abs=1e-9)
    np.testing.assert_allclose(speed, speed[::-1], atol=1e-9)  # symmetric
    rising = speed[: len(speed) // 2 + 1]
    assert np.all(np.diff(rising) > 0)  # one peak: rises to the middle, then falls


def test_minimum_torque_change_costs_less_and_curves_the_path(planning):
    jerk, mtc = planning.jerk, planning.torque_change
    assert mtc.cost < 0.95 * jerk.cost  # 1023 against 1145 N^2 m^2/s on the game arm
    deviation = abs(mtc.max_deviation())
    distance = math.dist(START, TARGET)
    assert 0.02 < deviation < 0.15 * distance  # curved, but gently: 4.4 cm on a 57 cm reach
    # Curved to one side only, not wiggling about the line.
    d = mtc.deviation()
    assert np.all(np.sign(d[5:-5]) == np.sign(mtc.max_deviation()))


@pytest.mark.parametrize("which", ["jerk", "torque_change"])
def test_both_reaches_start_and_end_at_rest_at_the_same_postures(planning, which):
    reach = getattr(planning, which)
    np.testing.assert_allclose(reach.hand[0], START, atol=1e-12)
    np.testing.assert_allclose(reach.hand[-1], TARGET, atol=1e-12)
    np.testing.assert_allclose(reach.q[[0, -1]], planning.jerk.q[[0, -1]], atol=1e-12)
    for ends in (reach.qd[[0, -1]], reach.qdd[[0, -1]], reach.torque[[0, -1]]):
        np.testing.assert_allclose(ends, 0.0, atol=1e-12)
    # Outside the reach the arm rests where it started and where it ended.
    q, qd, qdd = planning.motion(np.array([-0.3, planning.duration + 0.3]), which)
    np.testing.assert_allclose(q, reach.q[[0, -1]], atol=1e-12)
    assert np.all(qd == 0.0) and np.all(qdd == 0.0)


def test_the_optimum_is_converged(planning):
    assert planning.optimality < 1e-6
    finer = plan_reach(basis_count=12)  # more freedom hardly changes it: the basis is rich enough
    assert finer.torque_change.cost == pytest.approx(planning.torque_change.cost, rel=2e-3)
    assert finer.torque_change.cost <= planning.torque_change.cost * (1 + 1e-9)
    np.testing.assert_allclose(finer.torque_change.hand, planning.torque_change.hand, atol=2e-4)


def test_torque_rate_is_the_derivative_of_the_torque(planning):
    from scipy.integrate import cumulative_trapezoid

    mtc = planning.torque_change
    integrated = cumulative_trapezoid(mtc.torque_rate, mtc.t, axis=0, initial=0.0)
    np.testing.assert_allclose(mtc.torque[0] + integrated, mtc.torque, atol=1e-3 * np.max(np.abs(mtc.torque)))


def test_the_reach_back_is_the_reach_out_played_backwards(planning):
    # With no damping and no gravity the criterion and the dynamics are symmetric in time.
    back = plan_reach(TARGET, START)
    np.testing.assert_allclose(back.torque_change.hand, planning.torque_change.hand[::-1], atol=1e-6)
    assert back.torque_change.cost == pytest.approx(planning.torque_change.cost, rel=1e-6)


def test_the_path_does_not_depend_on_the_movement_time(planning):
    slower = plan_reach(duration=0.9)
    # Every torque scales as 1/T^2, so the cost as 1/T^5 and the path not at all.
    assert slower.torque_change.cost * (0.9 / 0.6) ** 5 == pytest.approx(planning.torque_change.cost, rel=1e-3)
    assert slower.torque_change.max_deviation() == pytest.approx(planning.torque_change.max_deviation(), abs=1e-4)


def test_planning_is_deterministic(planning):
    again = plan_reach()
    assert np.array_equal(again.coefficients, planning.coefficients)
    assert np.array_equal(again.torque_change.torque, planning.torque_change.torque)


def test_an_unreachable_or_degenerate_reach_is_refused():
    with pytest.raises(UserError, match="out of reach"):
        plan_reach(START, (1.5, 0.0))
    with pytest.raises(UserError, match="1 cm"):
        plan_reach(START, START)
    with pytest.raises(UserError, match=r"between 0\.1 and 5 s"):
        plan_reach(duration=math.nan)


def test_the_window_run_goes_out_and_back(planning):
    run = PlanningRun(dt=0.001, planning=planning)
    start_states = run.states
    assert len(start_states) == 2 and all(s[2:] == (0.0, 0.0) for s in start_states)
    half = round(run.cycle / 2 / run.dt)  # the rest at the start and the reach out
    for _ in range(half + round(run.rest / 2 / run.dt)):
        run.step()
    at_target = [run.arm.hand(s[:2]) for s in run.states]
    np.testing.assert_allclose(at_target, [TARGET, TARGET], atol=1e-9)
    peak = max(run.hand_speeds_now())
    assert peak < 1e-6  # resting at the target before the reach back
    for _ in range(half - round(run.rest / 2 / run.dt)):
        run.step()
    np.testing.assert_allclose([s[:2] for s in run.states], [s[:2] for s in start_states], atol=1e-9)


def test_demo_planning_headless_writes_csv_and_figure(tmp_path, capsys):
    assert main(["demo", "planning", "--headless", "--out", str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    assert "lower" in printed and f"wrote {tmp_path / 'planning.png'}" in printed
    with open(tmp_path / "planning.csv", newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], np.array(rows[1:], dtype=float)
    for prefix in ("mj", "mtc"):
        assert {f"{prefix}_{c}" for c in ("q1", "hand_x", "hand_y", "speed", "tau1", "tau2", "dtau1")} <= set(header)
    assert data[0, 0] == 0.0 and data[-1, 0] == pytest.approx(0.6)
    assert (tmp_path / "planning.png").read_bytes()[:8] == PNG_MAGIC


def test_demo_planning_refuses_duration_in_one_line(tmp_path, capsys):
    assert main(["demo", "planning", "--headless", "--out", str(tmp_path), "--duration", "2"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("armgame demo: error: --duration does not apply to the planning demo")
    assert err.count("\n") == 1
    assert not list(tmp_path.iterdir())


def test_the_window_draws_both_arms_where_their_plans_put_them(monkeypatch, planning):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    import pygame

    from armgame.ui.demo_window import ARM_B, DemoWindow

    now = [0.0]
    window = DemoWindow("planning", PlanningRun(planning=planning), clock=lambda: now[0])
    window.open()
    try:
        window.frame()
        mid = window.run.rest + planning.duration / 2  # mid-reach, where the paths are furthest apart
        while window.run.t < mid:
            now[0] += 0.05
            window.frame()
        screen = pygame.display.get_surface()
        jerk_hand, mtc_hand = (window.run.arm_points(*pose)[-1] for pose in window.poses())
        assert math.dist(jerk_hand, mtc_hand) > 0.02
        colour = tuple(screen.get_at(window.to_window(mtc_hand)))[:3]
        assert max(abs(a - b) for a, b in zip(colour, ARM_B, strict=True)) <= 8  # the scene is scaled smoothly
        assert max(tuple(screen.get_at(window.to_window(jerk_hand)))[:3]) < 100  # the dark arm's hand
        assert "min torque change" in window._status()
    finally:
        pygame.display.quit()


@pytest.mark.parametrize(("scale", "step"), [(9.05, 5.0), (3.1, 2.0), (1.2, 1.0), (0.6, 0.5), (25.0, 20.0)])
def test_torque_bar_ticks_are_round_and_within_the_scale(scale, step):
    from armgame.ui.demo_window import _tick_step

    assert _tick_step(scale) == pytest.approx(step)
    assert 1 <= scale // _tick_step(scale) <= 3
