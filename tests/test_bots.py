"""The autopilots: deterministic, keyboard-only, replayable, and knowing the interaction torques pays."""

import json

import pytest
from test_simulate_cli import in_process

from armgame.errors import UserError
from armgame.game.bots import Autopilot, make_bot, play_bot
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, RealTimeDriver


@pytest.mark.parametrize("name", ["model", "naive"])
def test_a_bot_plays_the_same_game_from_the_same_seed(name):
    a = play_bot(GameConfig(seed=4, time_limit=6.0), name)
    b = play_bot(GameConfig(seed=4, time_limit=6.0), name)
    assert a.timeline == b.timeline and a.result() == b.result() and a.state == b.state
    assert a.rules.board.hits >= 1


@pytest.mark.parametrize("name", ["model", "naive"])
def test_bots_press_only_the_muscle_keys(name):
    session = play_bot(GameConfig(seed=2, time_limit=6.0), name)
    assert session.timeline
    assert {e.key for e in session.timeline} <= set(session.muscles.keys)
    assert session.rules.board.resets == 0


def test_model_beats_naive():
    for seed in (0, 7):
        config = GameConfig(seed=seed, time_limit=20.0)
        model, naive = (play_bot(config, n).rules.board.hits for n in ("model", "naive"))
        assert naive >= 1 and model >= 1.5 * naive, (seed, model, naive)


def test_a_bot_game_replays_from_its_timeline():
    played = play_bot(GameConfig(seed=3, time_limit=5.0), "model")
    replay = GameSession(GameConfig(seed=3, time_limit=5.0))
    assert replay.play(played.timeline) == played.result()
    assert replay.state == played.state


def test_the_window_driver_gives_the_headless_game_at_any_frame_rate():
    headless = play_bot(GameConfig(seed=1, time_limit=3.0), "naive")
    for fps in (24.0, 60.0, 144.0):
        session = GameSession(GameConfig(seed=1, time_limit=3.0))
        driver = RealTimeDriver(Autopilot(session, make_bot("naive")))  # type: ignore[arg-type]
        while not session.over:
            driver.advance(1.0 / fps)
        assert session.timeline == headless.timeline and session.result() == headless.result()


def test_unknown_bot_is_refused():
    with pytest.raises(UserError, match="unknown bot"):
        make_bot("oracle")


def test_play_headless_bot_json(capsys):
    code, out, err = in_process(capsys, ["play", "--headless", "--bot", "model", "--json", "--duration", "5",
                                         "--seed", "3"])
    assert code in (0, None), err
    result = json.loads(out)
    expected = play_bot(GameConfig(seed=3, time_limit=5.0), "model").result()
    assert result["seed"] == 3 and result["hits"] == expected.hits
    code, _, err = in_process(capsys, ["play", "--headless", "--bot", "model", "--script", "x"])
    assert code not in (0, None) and "--bot" in err


@pytest.mark.parametrize("interaction", [True, False])
@pytest.mark.parametrize("with_load", [True, False])
def test_the_forward_model_written_out_equals_accel_step_by_step(interaction, with_load):
    """``InternalModel.predict`` is ``accel`` and ``bias`` inlined for speed: it must give the same floats."""
    import math
    import random

    from armgame.game.bots import InternalModel

    model = InternalModel.of(GameConfig(), interaction)
    rng = random.Random(5)
    rows = [(None, None, rng.uniform(-1.5, 1.5), rng.uniform(-1.1, 1.1)) for _ in range(80)]

    def load(q1, q2, w1, w2):
        return 0.3 * math.sin(q1) * w2, -0.2 * math.cos(q1 + q2) * w1

    start = (0.7, 1.4, 2.0, -3.0)
    q1, q2, w1, w2 = start
    for *_, t1, t2 in rows:
        if with_load:
            e1, e2 = load(q1, q2, w1, w2)
            t1, t2 = t1 + e1, t2 + e2
        a1, a2 = model.accel(q2, w1, w2, t1, t2)
        w1 += a1 * 0.004
        w2 += a2 * 0.004
        q1 += w1 * 0.004
        q2 += w2 * 0.004
    assert model.predict_in_python(start, rows, 0.004, load if with_load else None) == (q1, q2, w1, w2)
    if not with_load:  # the compiled loop, where built, takes no Python load
        assert model.predict(start, rows, 0.004) == (q1, q2, w1, w2)


def test_the_curl_load_equals_the_lab_bots_unit_field_and_torque():
    """``CurlLoad`` forms the Jacobian once; it must equal the lab's two documented functions."""
    import random

    from armgame.game.bots import CurlLoad
    from armgame.lab.bots import curl_unit_force, curl_unit_torque, make_lab_bot
    from armgame.lab.presets import preset
    from armgame.lab.session import LabSession, lab_config

    session = LabSession(lab_config(preset("curl"), 10), preset("curl"))
    bot = make_lab_bot("adaptive")
    bot.curl_learner.fast, bot.curl_learner.slow = 0.7, 1.1  # an estimate of b = 1.8 N s/m
    bot.act(session)  # a new trial (the run's first): the bot installs what it expects of the arm's load
    assert type(bot.load_estimate) is CurlLoad  # the type the compiled loop takes
    l1, l2 = session.config.arm.l1, session.config.arm.l2
    b = bot.curl_estimate
    rng = random.Random(2)
    for _ in range(200):
        q1, q2, w1, w2 = (rng.uniform(-3, 3) for _ in range(4))
        fx, fy = curl_unit_force(l1, l2, q1, q2, w1, w2)
        assert bot.load_estimate(q1, q2, w1, w2) == curl_unit_torque(l1, l2, q1, q2, b * fx, b * fy)


def _compiled_predict_or_skip():
    import os

    from armgame.game import bots

    if bots._c_predict is None:
        if os.environ.get("ARMGAME_REQUIRE_COMPILED"):
            pytest.fail("the compiled forward model (_cbots) was not built")
        pytest.skip("the compiled forward model was not built (no C compiler at install)")
    return bots


@pytest.mark.parametrize("interaction", [True, False])
@pytest.mark.parametrize("curl", [None, 2.3, -1.1])
def test_the_compiled_forward_model_gives_the_python_loops_floats(interaction, curl):
    import random

    bots = _compiled_predict_or_skip()
    model = bots.InternalModel.of(GameConfig(), interaction)
    load = None if curl is None else bots.CurlLoad(0.3, 0.33, curl)
    rng = random.Random(11)
    for _ in range(40):
        rows = [(None, None, rng.uniform(-1.5, 1.5), rng.uniform(-1.1, 1.1)) for _ in range(rng.randrange(0, 90))]
        state = tuple(rng.uniform(-4, 4) for _ in range(4))
        assert model.predict(state, rows, 0.004, load) == model.predict_in_python(state, rows, 0.004, load)


def test_the_compiled_forward_model_refuses_bad_arguments_without_crashing():
    bots = _compiled_predict_or_skip()
    predict = bots._c_predict
    with pytest.raises(ValueError):
        predict((0.0, 1.0, 0.0), [], 0.004, 1.0, 1.0, 1.0, 0.1, 0.1, True, None, 0.3, 0.3)
    with pytest.raises(ValueError):
        predict((0.0, 1.0, 0.0, 0.0), [(1.0,)], 0.004, 1.0, 1.0, 1.0, 0.1, 0.1, True, None, 0.3, 0.3)
    with pytest.raises(TypeError):
        predict((0.0, 1.0, 0.0, "x"), [], 0.004, 1.0, 1.0, 1.0, 0.1, 0.1, True, None, 0.3, 0.3)
    with pytest.raises(TypeError):
        predict((0.0, 1.0, 0.0, 0.0), 5, 0.004, 1.0, 1.0, 1.0, 0.1, 0.1, True, None, 0.3, 0.3)
