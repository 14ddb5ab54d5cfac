"""armgame demo: headless outputs, the tutorial's runs reproduced, the torque split, and the window."""

import csv
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from figure_checks import assert_reads_on_a_slide

from armgame.cli import main
from armgame.demos.reach import ReachPlan, joint_motion, reach_arm, reach_table, torque_split
from armgame.demos.runs import VISIBLY_APART, chaos_run, record
from armgame.physics import TUTORIAL_ARM, TwoJointArm

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def slides(monkeypatch):
    """The figures the demos save, captured for inspection."""
    from armgame import plotstyle

    figures, real = [], plotstyle.save

    def keep(fig, path):
        figures.append(fig)
        return real(fig, path)

    monkeypatch.setattr(plotstyle, "save", keep)
    return figures


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.parametrize(
    ("name", "columns"),
    [("pendulum", ["t", "q1", "qd1"]), ("passive", ["t", "q1", "q2"]), ("chaos", ["t", "a_q1", "b_q1"]),
     ("interaction", ["t", "q1", "tau1", "own_inertial1", "interaction_inertial2", "coriolis_centrifugal1"])],
)
def test_each_demo_runs_headless_and_writes_csv_and_figure(name, columns, tmp_path, capsys, slides):
    out = tmp_path / "figs"
    assert main(["demo", name, "--headless", "--out", str(out), "--duration", "0.5"]) == 0
    header, data = read_csv(out / f"{name}.csv")
    assert set(columns) <= set(header)
    assert data[-1, 0] == pytest.approx(0.5)
    assert (out / f"{name}.png").read_bytes()[:8] == PNG_MAGIC
    printed = capsys.readouterr().out
    assert f"wrote {out / (name + '.png')}" in printed
    (fig,) = slides
    assert_reads_on_a_slide(fig)


def test_autopilot_runs_headless_and_writes_csv_and_figure_as_the_others(tmp_path, capsys, slides):
    out = tmp_path / "figs"
    assert main(["demo", "autopilot", "--headless", "--out", str(out), "--duration", "0.3"]) == 0
    header, data = read_csv(out / "autopilot.csv")
    assert header == ["seed", "duration", "model_hits", "naive_hits"] and len(data) == 10
    assert (out / "autopilot.png").read_bytes()[:8] == PNG_MAGIC
    assert f"wrote {out / 'autopilot.png'}" in capsys.readouterr().out
    (fig,) = slides
    assert_reads_on_a_slide(fig)
    (ax,) = fig.get_axes()
    heights = [round(p.get_height()) for p in ax.patches]  # the bars show the CSV's hits, model then naive
    assert heights == [*data[:, 2].astype(int), *data[:, 3].astype(int)]


def test_pendulum_figure_puts_angle_and_velocity_on_their_own_axes(tmp_path, slides):
    assert main(["demo", "pendulum", "--headless", "--out", str(tmp_path), "--duration", "2"]) == 0
    (fig,) = slides
    labels = [ax.get_ylabel() for ax in fig.get_axes()]
    assert labels == ["angle from hanging (deg)", "angular velocity (deg/s)"]
    angle, velocity = (ax.get_lines()[0].get_ydata() for ax in fig.get_axes())
    assert angle[0] == pytest.approx(90.0) and velocity[0] == 0.0


def test_interaction_figure_shares_one_newton_metre_scale_and_prints_each_bar(tmp_path, slides):
    assert main(["demo", "interaction", "--headless", "--out", str(tmp_path)]) == 0
    (fig,) = slides
    shoulder, elbow = (ax for ax in fig.get_axes() if ax.get_ylabel().endswith("torque (N m)"))
    assert shoulder.get_ylim() == elbow.get_ylim()
    bar_axes = [ax for ax in fig.get_axes() if ax.patches]
    assert len(bar_axes) == 2 and bar_axes[0].get_xlim() == bar_axes[1].get_xlim()
    for ax in bar_axes:
        printed = [t.get_text() for t in ax.texts]
        widths = [p.get_width() for p in ax.patches]
        assert printed == [f"{w:.2f} N m" for w in widths]
    _, data = read_csv(tmp_path / "interaction.csv")
    assert float(bar_axes[0].texts[-1].get_text().split()[0]) == pytest.approx(np.max(np.abs(data[:, 11])), abs=0.006)


def test_pendulum_reproduces_the_tutorials_run(tmp_path):
    from scipy.integrate import solve_ivp  # here, not at collection: only the worker running it pays

    assert main(["demo", "pendulum", "--headless", "--out", str(tmp_path), "--no-figures"]) == 0
    _, data = read_csv(tmp_path / "pendulum.csv")
    t = np.linspace(0.0, 10.0, 1001)  # the tutorial's 10 s at 100 Hz
    np.testing.assert_allclose(data[:, 0], t, atol=1e-12)
    m, r, g, i = 1.65, 0.50, 9.81, 0.025

    def onejointarm(_t, state):  # the tutorial's code: theta from hanging straight down
        theta, theta_dot = state
        return [theta_dot, -(m * g * r * math.sin(theta)) / (i + m * r * r)]

    ref = solve_ivp(onejointarm, (0, 10), [math.pi / 2, 0.0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t)
    np.testing.assert_allclose(data[:, 1] + math.pi / 2, ref.y[0], atol=1e-8)
    np.testing.assert_allclose(data[:, 2], ref.y[1], atol=1e-7)


def test_passive_reproduces_the_tutorials_run(tmp_path):
    from scipy.integrate import solve_ivp  # here, not at collection: only the worker running it pays

    assert main(["demo", "passive", "--headless", "--out", str(tmp_path), "--no-figures"]) == 0
    _, data = read_csv(tmp_path / "passive.csv")
    t = np.linspace(0.0, 10.0, 2001)  # 10 s at 200 Hz, as twojointarm_passive.py
    np.testing.assert_allclose(data[:, 0], t, atol=1e-12)
    p = TUTORIAL_ARM

    def twojointarm(_t, state):  # the tutorial's forward dynamics, a1 from the downward vertical
        a1, a2, a1d, a2d = state
        M11 = p.i1 + p.i2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2 + 2 * p.l1 * p.r2 * math.cos(a2))
        M12 = p.i2 + p.m2 * (p.r2**2 + p.l1 * p.r2 * math.cos(a2))
        M22 = p.i2 + p.m2 * p.r2**2
        C1 = -(p.m2 * p.l1 * a2d * a2d * p.r2 * math.sin(a2)) - 2 * p.m2 * p.l1 * a1d * a2d * p.r2 * math.sin(a2)
        C2 = p.m2 * p.l1 * a1d * a1d * p.r2 * math.sin(a2)
        G1 = 9.81 * math.sin(a1) * (p.m2 * p.l1 + p.m1 * p.r1) + 9.81 * p.m2 * p.r2 * math.sin(a1 + a2)
        G2 = 9.81 * p.m2 * p.r2 * math.sin(a1 + a2)
        acc = np.linalg.solve([[M11, M12], [M12, M22]], [-C1 - G1, -C2 - G2])
        return [a1d, a2d, acc[0], acc[1]]

    ref = solve_ivp(twojointarm, (0, 10), [0.0, math.pi / 2, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=t)
    np.testing.assert_allclose(data[:, 1], ref.y[0] - math.pi / 2, atol=1e-8)  # q1 = a1 - 90 deg
    np.testing.assert_allclose(data[:, 2], ref.y[1], atol=1e-8)
    np.testing.assert_allclose(data[0, 5:7], [0.4554, -0.3384], atol=1e-12)


def test_chaos_arms_start_together_and_part():
    rec = record(chaos_run(), duration=8.0, sample_rate=50.0)
    arm = TwoJointArm(TUTORIAL_ARM)
    distance = np.hypot(*(arm.hand(rec.states[:, 0, :2]) - arm.hand(rec.states[:, 1, :2])).T)
    assert distance[0] < 1e-6
    assert np.all(distance[rec.t < 3.0] < 1e-3)
    assert distance.max() > 10 * VISIBLY_APART


@pytest.mark.parametrize("gravity", [False, True])
def test_torque_split_sums_to_inverse_dynamics(gravity):
    arm = TwoJointArm(reach_arm(gravity).params.replace(damping1=0.3, damping2=0.2))
    table = reach_table(arm, ReachPlan(), np.linspace(0.0, ReachPlan().cycle, 500))
    np.testing.assert_allclose(sum(table.parts.values()), table.total, atol=1e-12)
    rng = np.random.default_rng(1)
    q, qd, qdd = rng.uniform(-5, 5, (3, 40, 2))
    np.testing.assert_allclose(sum(torque_split(arm, q, qd, qdd).values()), arm.inverse_dynamics(q, qd, qdd),
                               atol=1e-12)
    # The tutorial's reading: C_1 holds only elbow velocity, C_2 only shoulder velocity.
    assert np.all(torque_split(arm, q, qd * [1, 0], qdd)["coriolis_centrifugal"][:, 0] == 0)
    assert np.all(torque_split(arm, q, qd * [0, 1], qdd)["coriolis_centrifugal"][:, 1] == 0)


DEMOS_PAGE = Path(__file__).resolve().parent.parent / "docs" / "demos.md"


def test_the_interaction_demo_moves_within_a_second_at_the_lessons_quarter_speed():
    """docs/teaching.md projects `armgame demo interaction --speed 0.25`: a wall second is 0.25 s of the demo's. The
    hand is on its way from the first steps and halfway by then (it once rested 0.4 s first: 1.6 s of a still arm
    on the projector), and the cycle still rests at the target and at home between the moves."""
    from armgame.demos.catalog import get_info, make_run

    run = make_run("interaction")
    start = run.arm_points(*run.states[0][:2])[-1]
    moved = []
    for _ in range(250):
        run.step()
        moved.append(math.dist(start, run.arm_points(*run.states[0][:2])[-1]))
    assert moved[99] > 0.01 and moved[-1] > 0.15  # 1 cm by 0.1 s (0.4 s of wall time), 15 cm by 0.25 s
    plan = run.plan
    speed = np.hypot(*run.table.hand_velocity.T)
    rests = speed < 1e-9
    assert rests[round((plan.move_time + plan.rest / 2) / run.dt)] and rests[-1]  # at the target, then at home
    assert plan.cycle == pytest.approx(2.6) == get_info("interaction").duration  # one cycle, as before
    # docs/demos.md's cycle: out 0.5 s, 0.4 s at the target, back, 1.2 s at home
    assert (plan.move_time, plan.rest, plan.cycle - 2 * plan.move_time - plan.rest) == pytest.approx((0.5, 0.4, 1.2))
    assert "Each 2.6 s cycle starts with the reach out (0.5 s), rests 0.4 s at the target, comes back and rests " \
           "1.2 s at home" in " ".join(DEMOS_PAGE.read_text(encoding="utf-8").split())


def test_minimum_jerk_reach_is_consistent():
    plan = ReachPlan()
    arm = reach_arm(False)
    dt = 1e-4
    t = np.arange(0.0, plan.cycle, dt)
    pos, vel, acc = plan.hand(t)
    np.testing.assert_allclose(pos[0], plan.home, atol=1e-15)
    np.testing.assert_allclose(plan.hand(plan.back_starts)[0], plan.target, atol=1e-15)
    assert np.max(np.hypot(*vel.T)) == pytest.approx(1.875 * 0.4 / plan.move_time, rel=1e-6)  # bell peak
    q, qd, qdd = joint_motion(arm, pos, vel, acc)
    np.testing.assert_allclose(arm.hand(q), pos, atol=1e-12)
    np.testing.assert_allclose(np.gradient(q, dt, axis=0)[1:-1], qd[1:-1], atol=1e-5)
    # The jerk jumps where each move starts and stops, so a central difference is off by ~jerk * dt there.
    assert np.max(np.abs(qdd)) > 10.0
    np.testing.assert_allclose(np.gradient(qd, dt, axis=0)[1:-1], qdd[1:-1], atol=2e-2)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["demo", "pendulum", "--headless"], "--out"),
        (["demo", "pendulum", "--gravity", "--headless", "--out", "x"], "--gravity"),
        (["demo", "passive", "--integrator", "dop853", "--headless", "--out", "x"], "unknown integrator"),
        (["demo", "passive", "--dt", "0", "--headless", "--out", "x"], "--dt"),
        (["demo", "chaos", "--duration", "-1", "--headless", "--out", "x"], "--duration"),
        (["demo", "chaos", "--duration", "2"], "--headless"),
    ],
)
def test_user_errors_are_one_line(args, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_missing_matplotlib_is_a_one_line_error(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert main(["demo", "pendulum", "--headless", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "armgame[plot]" in err and err.count("\n") == 1
    assert not list(tmp_path.iterdir())


def test_help_and_headless_import_no_pygame(tmp_path):
    code = (
        "import sys, argparse\n"
        "from armgame.commands import demo, derive\n"
        "p = argparse.ArgumentParser(); s = p.add_subparsers()\n"
        "demo.register(s); derive.register(s)\n"
        "assert not {'numpy', 'scipy', 'pygame', 'sympy', 'matplotlib'} & set(sys.modules), sys.modules.keys()\n"
        "from armgame.cli import main\n"
        f"assert main(['demo', 'chaos', '--headless', '--out', {str(tmp_path)!r}, '--duration', '0.1',"
        " '--no-figures']) == 0\n"
        "assert 'pygame' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)


# ------------------------------------------------------------------- the window, under SDL's dummy driver
@pytest.fixture
def dummy_sdl(monkeypatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    import pygame

    yield pygame
    pygame.display.quit()


def _dark(colour):
    return max(colour[:3]) < 100


def test_window_draws_the_arm_where_the_state_says(dummy_sdl):
    pygame = dummy_sdl
    from armgame.demos.catalog import make_run
    from armgame.ui.demo_window import DemoWindow

    now = [100.0]
    window = DemoWindow("pendulum", make_run("pendulum"), clock=lambda: now[0])
    window.open()
    window.frame()
    screen = pygame.display.get_surface()
    l = window.run.model.params.l  # noqa: E741
    assert _dark(screen.get_at(window.to_window((l / 2, 0.0))))  # released horizontal
    for _ in range(15):  # a quarter second at 60 frames per second, no sleeping
        now[0] += 1 / 60
        assert window.frame()
    assert window.run.t == pytest.approx(0.25, abs=1.5e-3)
    q = window.poses()[0][0]
    assert -math.pi / 2 < q < -0.3  # fallen a good way towards hanging
    assert _dark(screen.get_at(window.to_window((l / 2 * math.cos(q), l / 2 * math.sin(q)))))
    assert min(screen.get_at(window.to_window((l * 0.8, 0.0)))[:3]) > 245  # no longer there (white, scaled)


def test_window_keys_pause_speed_restart_and_quit(dummy_sdl):
    pygame = dummy_sdl
    from armgame.demos.catalog import make_run
    from armgame.ui.demo_window import DemoWindow

    now = [0.0]
    window = DemoWindow("interaction", make_run("interaction"), clock=lambda: now[0])
    window.open()

    def tick(seconds):
        now[0] += seconds
        assert window.frame()

    def key(k):
        return window.handle(pygame.event.Event(pygame.KEYDOWN, key=k))

    tick(0.0)
    tick(0.1)
    assert window.run.t == pytest.approx(0.1, abs=1.5e-3)
    key(pygame.K_p)
    tick(0.2)
    tick(0.2)
    assert window.run.t == pytest.approx(0.1, abs=1.5e-3)  # paused
    assert any(text.startswith("p resume") for text, _ in window.text_boxes())  # the help line says the action
    key(pygame.K_p)
    key(pygame.K_MINUS)
    assert window.speed == 0.5
    tick(0.0)
    tick(0.2)
    assert window.run.t == pytest.approx(0.2, abs=1.5e-3)  # slow motion: 0.2 s real is 0.1 s simulated
    tick(5.0)  # a stall counts as MAX_FRAME_TIME at most
    assert window.run.t == pytest.approx(0.325, abs=1.5e-3)
    key(pygame.K_r)
    tick(0.0)
    assert window.run.t == 0.0
    # The arrows skip 5 s either way, as in a replay; back lands where running on would have been.
    key(pygame.K_RIGHT)
    key(pygame.K_RIGHT)
    assert window.run.steps == 10000
    ahead = window.run.states
    key(pygame.K_LEFT)
    assert window.run.steps == 5000
    key(pygame.K_RIGHT)
    assert window.run.steps == 10000 and window.run.states == ahead
    key(pygame.K_LEFT)
    key(pygame.K_LEFT)
    key(pygame.K_LEFT)
    assert window.run.steps == 0 and window.speed == 0.5  # clamped at the start; the speed is not changed
    tick(0.0)
    help_line = window.text_boxes()[-1][0]
    assert help_line == "p pause   r restart   -/+ speed   1 real speed   left/right 5 s   F11 fullscreen   Esc quit"
    window.handle(pygame.event.Event(pygame.VIDEORESIZE, w=1000, h=600, size=(1000, 600)))
    pygame.display.set_mode((1000, 600), pygame.RESIZABLE)
    tick(0.0)
    assert window.scene_size == (1000, 600) and window.view() == (1.0, (0, 0))  # the window, at its own pixels
    assert window.room.collidepoint(window.to_scene((0.0, 0.0)))
    assert key(pygame.K_ESCAPE) is False
    assert window.handle(pygame.event.Event(pygame.QUIT)) is False


SIZES = [(640, 480), (1280, 720), (1366, 768), (1920, 1080), (720, 1280)]


def assert_fits(size, boxes, min_height, what):
    window = pygame_rect((0, 0), size)
    for name, rect in boxes:
        assert window.contains(rect), f"{what} at {size}: {name!r} {rect} is cut"
        if not name.startswith("bar") and name != "progress":
            assert rect.height >= min_height, f"{what} at {size}: {name!r} is {rect.height} px high"
    for i, (a, ra) in enumerate(boxes):
        for b, rb in boxes[i + 1:]:
            assert not ra.colliderect(rb), f"{what} at {size}: {a!r} {ra} overlaps {b!r} {rb}"


def pygame_rect(*args):
    import pygame

    return pygame.Rect(*args)


@pytest.mark.parametrize("name", ["pendulum", "passive", "chaos", "interaction"])
def test_demo_texts_fit_every_window(dummy_sdl, name):
    pygame = dummy_sdl
    from armgame.demos.catalog import make_run
    from armgame.ui.demo_window import DemoWindow

    now = [0.0]
    window = DemoWindow(name, make_run(name, gravity=name == "interaction"), clock=lambda: now[0])
    window.open()
    for size in SIZES:
        pygame.display.set_mode(size, pygame.RESIZABLE)
        window.handle(pygame.event.Event(pygame.VIDEORESIZE, w=size[0], h=size[1], size=size))
        for _ in range(3):
            now[0] += 0.3
            window.frame()
        # The scene is scaled as a whole: text shrinks with the window, never below 14 px at 720 lines.
        assert_fits(size, window.text_boxes(), int(14 * min(size) / 720), name)


@pytest.mark.parametrize("size", [(1280, 720), (1366, 768), (1920, 1080), (640, 480), (720, 1280)])
def test_autopilot_window_fits_two_games(dummy_sdl, size):
    pygame = dummy_sdl
    from armgame.ui.autopilot_window import AutopilotWindow
    from armgame.ui.display import open_window

    screen = open_window(size)
    pygame.display.set_mode(size)
    window = AutopilotWindow(10, 60.0, pygame.display.get_surface(), clock=lambda: 0.0)
    for _ in range(5):
        window.frame(0.2)
    boxes = window.all_boxes(size)
    assert_fits(size, boxes, int(14 * min(size) / 720), "autopilot")
    texts = [name for name, _ in boxes]
    assert any(t.startswith("mode: AUTOPILOT: model") for t in texts)
    assert any(t.startswith("mode: AUTOPILOT: naive") for t in texts)
    assert not any("reset" in t or "hide arm" in t for t in texts)  # keys that do nothing there
    assert sum(t.startswith("score: ") for t in texts) == 2
    assert screen is not None
    window.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_r))
    assert all(g.session.steps == 0 for g in window.games)


def test_autopilot_window_speeds_up_and_skips_both_games_as_a_replay_does(dummy_sdl):
    pygame = dummy_sdl
    from armgame.game.bots import Autopilot, make_bot
    from armgame.game.rules import GameConfig
    from armgame.game.session import GameSession
    from armgame.ui.autopilot_window import AutopilotWindow
    from armgame.ui.display import open_window

    open_window((800, 600))
    window = AutopilotWindow(3, 12.0, pygame.display.get_surface(), clock=lambda: 0.0)

    def key(k):
        window.handle(pygame.event.Event(pygame.KEYDOWN, key=k))

    key(pygame.K_EQUALS)
    window.frame(0.1)
    assert window.speed == 2.0 and all(g.session.steps == round(0.2 / g.session.config.dt) for g in window.games)
    key(pygame.K_1)
    key(pygame.K_RIGHT)
    assert all(g.session.steps == round(5.2 / g.session.config.dt) for g in window.games)
    key(pygame.K_LEFT)
    assert window.speed == 1.0
    for game in window.games:  # where the bot's own game is at 0.2 s, though the window went there and back
        alone = GameSession(GameConfig(seed=3, time_limit=12.0))
        Autopilot(alone, make_bot(game.name)).advance(game.session.steps)
        assert game.session.steps == round(0.2 / game.session.config.dt) and game.session.state == alone.state
    window.frame(0.0)
    from armgame.ui.autopilot_window import HELP

    footer = window.layout((800, 600))[2]
    assert " ".join(lab.text for lab in footer).split() == " ".join(HELP).split()
    assert HELP == ("p pause", "r restart", "-/+ speed", "1 real speed", "left/right 5 s", "F11 fullscreen", "Esc quit")


@pytest.mark.parametrize("name", ["passive", "interaction"])
def test_a_demo_frames_its_reach_and_fills_its_window(dummy_sdl, name):
    """Made for a projector: the scene takes the window's shape (no empty bands), the arm's whole reach is
    framed between the texts (the hanging arm never over the help line), and the lines are 3 px or more."""
    pygame = dummy_sdl
    from armgame.demos.catalog import make_run
    from armgame.ui.demo_window import DemoWindow

    now = [0.0]
    window = DemoWindow(name, make_run(name), clock=lambda: now[0], size=(1024, 768))
    window.open()
    for size in ((1024, 768), (1920, 1080), (768, 1024)):
        pygame.display.set_mode(size)
        window.handle(pygame.event.Event(pygame.VIDEORESIZE, w=size[0], h=size[1], size=size))
        now[0] += 0.1
        window.frame()
        scale = window.view()[0]
        shown = (window.scene_size[0] * scale) * (window.scene_size[1] * scale)
        assert shown >= 0.98 * size[0] * size[1], size  # at least 70% asked; the whole window given
        reach = window.reach_rect()
        assert pygame.Rect((0, 0), size).contains(reach), size
        assert not any(reach.colliderect(box) for _, box in window.text_boxes()), size
        assert max(reach.width / size[0], reach.height / size[1]) >= 0.45, size  # framed large, not a stamp
        smallest = min(box.height for _, box in window.text_boxes())
        assert smallest >= 0.025 * size[1] - 1, size  # a tall window's too (issue 27)
        assert window.line * scale >= 3  # the trails and paths stay 3 px or more
