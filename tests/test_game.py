"""The game without a window: muscles, rules, the fixed-step session and scripts."""

import math
import subprocess
import sys

import pytest
from test_simulate_cli import in_process

from armgame.errors import UserError
from armgame.game.muscles import DEFAULT_MUSCLES, MuscleSet, remap_keys
from armgame.game.rules import GameConfig, Target
from armgame.game.script import ScriptError, parse_script
from armgame.game.session import GameSession, InputEvent, RealTimeDriver

HIT_SCRIPT = "0.0 k down\n0.0 d down\n0.25 k up\n0.3 d up\n"


def play(script: str, target_at: float | None = None, target_script: str = HIT_SCRIPT, **config) -> GameSession:
    """Play ``script`` headless; with ``target_at``, the first target sits where
    ``target_script`` takes the hand at that time (found by playing it first, so the tests
    hold whatever the muscle tuning)."""
    session = GameSession(GameConfig(**config))
    if target_at is not None:
        probe = play(target_script, time_limit=target_at)
        session.rules.target = Target(*probe.hand(), session.config.target_radius)
    session.play(parse_script(script, session.keys, session.config.dt))
    return session


def test_a_scripted_reach_hits_the_target():
    session = play(HIT_SCRIPT, time_limit=3.0, target_at=0.6)
    board = session.rules.board
    assert board.hits >= 1 and board.score == board.hits
    assert 0.0 < board.hit_times[0] <= 0.6


def test_no_input_no_hit():
    session = play("", time_limit=3.0, target_at=0.6)
    assert session.rules.board.hits == 0
    assert session.state == (math.radians(45), math.radians(90), 0.0, 0.0)


def test_reset_costs_a_point_and_restores_the_start_posture():
    session = play(HIT_SCRIPT + "1.5 space down\n1.6 space up\n", time_limit=1.6, target_at=0.6)
    board = session.rules.board
    assert board.hits == 1 and board.resets == 1 and board.score == 0
    assert session.state[:2] == (math.radians(45), math.radians(90))
    assert session.muscles.activation == [0.0] * 4


def test_score_never_drops_below_zero():
    session = play("0.1 space down\n0.2 space up\n0.3 space down\n0.4 space up\n", time_limit=1.0)
    assert session.rules.board.resets == 2
    assert session.rules.board.score == 0


def test_time_limit_ends_the_game_and_later_events_are_ignored():
    session = play("0.5 d down\n2.5 d up\n2.6 space down\n", time_limit=2.0)
    assert session.over and session.time == pytest.approx(2.0) and session.time_left == 0.0
    assert session.rules.board.resets == 0
    assert session.advance(100) == 0
    assert [e.key for e in session.timeline] == ["d"]


def test_tab_hides_the_arm_without_changing_the_motion():
    moving = "0.0 d down\n0.3 d up\n0.4 j down\n0.9 j up\n"
    plain = play(moving, time_limit=2.0)
    hidden = play(moving + "1.0 tab down\n1.1 tab up\n", time_limit=2.0)
    assert plain.rules.arm_visible and not hidden.rules.arm_visible
    assert hidden.state == plain.state


def test_same_seed_and_script_give_identical_games():
    script = "0.0 d down\n0.4 d up\n0.5 j down\n0.8 j up\n1.0 f down\n1.3 f up\n"
    a, b = play(script, time_limit=5.0, seed=3), play(script, time_limit=5.0, seed=3)
    assert a.state == b.state and a.result() == b.result()
    assert a.rules.target == b.rules.target
    assert play(script, time_limit=5.0, seed=4).rules.target != a.rules.target


def drive_in_real_time(fps: float, events_at_frames: dict[int, list[tuple[str, str]]], seconds: float):
    """Feed a session as a window would: frames of 1/fps s, key events between frames."""
    session = GameSession(GameConfig(time_limit=seconds, seed=5))
    driver = RealTimeDriver(session)
    frame = 0
    while not session.over:
        for key, action in events_at_frames.get(frame, []):
            session.key_event(key, action)
        driver.advance(1.0 / fps)
        frame += 1
    return session


def test_result_is_independent_of_the_frame_rate():
    # Key events at whole thirtieths of a second, delivered between frames at each rate.
    at_thirtieths = {0: [("d", "down")], 12: [("d", "up"), ("j", "down")], 27: [("j", "up")], 40: [("tab", "down")]}
    runs = {}
    for fps in (30, 60, 120, 240):
        per = fps // 30
        runs[fps] = drive_in_real_time(fps, {k * per: v for k, v in at_thirtieths.items()}, 2.0)
    reference = runs[30]
    steps_per_second = round(1 / reference.config.dt)
    expected = [round(t * steps_per_second) for t in (0.0, 0.4, 0.4, 0.9)] + [math.floor(4 / 3 * steps_per_second)]
    assert [e.step for e in reference.timeline] == expected
    for session in runs.values():
        assert session.timeline == reference.timeline
        assert session.state == reference.state
    # Headless play of the recorded timeline reproduces the windowed game exactly.
    replay = GameSession(GameConfig(time_limit=2.0, seed=5))
    replay.play(reference.timeline)
    assert replay.state == reference.state and replay.result() == reference.result()


def test_a_stall_is_clamped_not_caught_up():
    session = GameSession(GameConfig(time_limit=10.0))
    driver = RealTimeDriver(session, max_frame_time=0.25)
    driver.advance(5.0)
    assert session.steps == round(0.25 / session.config.dt)


@pytest.mark.parametrize("dt", [0.002, 0.001, 0.00025])
def test_activation_follows_physical_time_whatever_the_step(dt):
    muscles = MuscleSet(DEFAULT_MUSCLES, dt)
    muscles.command(0, True)
    for _ in range(round(0.1 / dt)):
        muscles.step()
    rise = DEFAULT_MUSCLES[0].rise_time
    assert muscles.activation[0] == pytest.approx(1.0 - math.exp(-0.1 / rise), rel=1e-12)
    muscles.command(0, False)
    for _ in range(round(0.05 / dt)):
        muscles.step()
    expected = (1.0 - math.exp(-0.1 / rise)) * math.exp(-0.05 / DEFAULT_MUSCLES[0].decay_time)
    assert muscles.activation[0] == pytest.approx(expected, rel=1e-12)


def test_session_activation_matches_the_muscle_model():
    session = GameSession(GameConfig(time_limit=1.0))
    session.key_event("j", "down")
    session.advance(50)
    reference = MuscleSet(DEFAULT_MUSCLES, session.config.dt)
    reference.command(2, True)
    for _ in range(50):
        reference.step()
    assert session.muscles.activation == reference.activation
    assert session.muscles.torque() == reference.torque()


def test_targets_are_reachable_on_screen_and_not_under_the_hand():
    session = GameSession(GameConfig(seed=11))
    rules, arm = session.rules, session.config.arm
    xmin, xmax, ymin, ymax = session.config.view
    for _ in range(200):
        t = rules.target
        assert xmin + t.radius <= t.x <= xmax - t.radius and ymin + t.radius <= t.y <= ymax - t.radius
        assert abs(arm.l1 - arm.l2) <= math.hypot(t.x, t.y) <= arm.l1 + arm.l2
        hand = (t.x, t.y)
        rules.hand_moved(*hand, 0.0)
        assert math.dist(hand, (rules.target.x, rules.target.y)) > 3 * t.radius


def test_key_map_is_configurable():
    muscles = remap_keys(DEFAULT_MUSCLES, "asdf")
    session = GameSession(GameConfig(muscles=muscles, time_limit=1.0))
    assert session.keys[:4] == ("a", "s", "d", "f")
    assert session.key_event("a", "down") and not session.key_event("j", "down")
    for bad in ("abc", "aabb", "a,b,c,space"):
        with pytest.raises(UserError):
            remap_keys(DEFAULT_MUSCLES, bad)


@pytest.mark.parametrize(
    ("text", "message"),
    [("0.5 d\n", "line 1: expected"), ("0 d down\nx d down\n", "line 2: time 'x'"),
     ("-1 d down\n", "line 1: time must be"), ("# c\n\n0.5 q down\n", "line 3: unknown key 'q'"),
     ("0.5 d press\n", "line 1: action"), ("1 d down\n0.5 d up\n", "line 2: time 0.5 comes before"),
     ("inf d down\n", "line 1: time must be")],
)
def test_malformed_script_lines_are_reported_with_their_number(text, message):
    with pytest.raises(ScriptError, match=message):
        parse_script(text, ("d", "f", "j", "k", "space", "tab"), 0.001)


def test_script_times_map_to_the_nearest_physics_step():
    events = parse_script("0.0004 d down  # early\n0.0016 D UP\n0.0101 d down", ("d", "space"), 0.001)
    assert events == [InputEvent(0, "d", "down"), InputEvent(2, "d", "up"), InputEvent(10, "d", "down")]
    assert parse_script("0.0101 d down", ("d",), 0.004) == [InputEvent(3, "d", "down")]


def run_cli(*args):
    """The real program in a subprocess: for what only a fresh process shows (the same output run to run)."""
    return subprocess.run([sys.executable, "-m", "armgame", *args], capture_output=True, text=True)


def test_headless_cli_json_is_reproducible(tmp_path):
    script = tmp_path / "s.txt"
    script.write_text("0.0 d down\n0.5 d up\n0.6 j down\n1.0 j up\n2 space down\n")
    args = ("play", "--headless", "--script", str(script), "--seed", "4", "--duration", "5", "--json")
    first, second = run_cli(*args), run_cli(*args)
    assert first.returncode == 0, first.stderr
    assert first.stdout == second.stdout
    import json

    result = json.loads(first.stdout)
    assert {"score", "hits", "resets", "seed", "duration"} <= set(result)
    assert result["seed"] == 4 and result["duration"] == 5.0 and result["resets"] == 1


def test_headless_run_does_not_import_pygame(tmp_path):
    code = ("import sys; from armgame.cli import main; main(['play', '--headless', '--duration', '1']);"
            "print('pygame' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.stdout.strip().splitlines()[-1] == "False"


@pytest.mark.parametrize(
    ("args", "message"),
    [(("--duration", "-1"), "--duration"), (("--seed", "x"), "--seed"), (("--keys", "ab"), "--keys"),
     (("--script", "missing.txt"), "no such script")],
)
def test_headless_cli_bad_input_is_one_line(tmp_path, args, message, capsys):
    code, _, err = in_process(capsys, ["play", "--headless", *args])
    assert code not in (0, None)
    assert len(err.strip().splitlines()) == 1 and message in err


def test_unreadable_script_files_are_one_line(tmp_path, capsys):
    binary = tmp_path / "binary.txt"
    binary.write_bytes(b"\xff\xfe\x00 d down\n")
    (tmp_path / "empty").mkdir()
    for path, message in ((binary, "not a text file"), (tmp_path / "empty", "no *.txt scripts")):
        code, _, err = in_process(capsys, ["play", "--headless", "--script", str(path)])
        assert code == 2
        assert len(err.strip().splitlines()) == 1 and message in err
