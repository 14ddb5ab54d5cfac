"""armgame/CenterOut-v0: Gymnasium's checker, determinism, the lab's bots through the env, the perturbation option."""

import dataclasses
import doctest
import math
import os
import warnings

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import armgame.env
import armgame.env.center_out
from armgame.env.center_out import CenterOutBotPolicy
from armgame.env.reach import EnvArgumentError
from armgame.game.bots import Autopilot
from armgame.lab.analysis import trial_rows
from armgame.lab.bots import make_lab_bot
from armgame.lab.perturbations import Perturbation
from armgame.lab.presets import preset
from armgame.lab.protocol import Block, Protocol
from armgame.lab.session import LabSession, lab_config

CENTER_OUT, CONTINUOUS = "armgame/CenterOut-v0", "armgame/CenterOutContinuous-v0"
#: Two baseline trials and three exposure trials, none perturbed until an option says so.
SHORT = Protocol("short", (Block("baseline", 2), Block("exposure", 3)))


def bot_run(env, seed, options=None, bot="model"):
    """Return, rewards and the reaches' rows of a whole run with a lab bot at the keys."""
    policy = CenterOutBotPolicy(bot, env)
    obs, info = env.reset(seed=seed, options=options)
    total, reaches, done = 0.0, [], False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += reward
        reaches += info.get("reaches", [])
        done = terminated or truncated
    return total, reaches, terminated, info


def same_rows(a, b):
    return len(a) == len(b) and all(
        x.keys() == y.keys() and all(x[k] == y[k] or (isinstance(x[k], float) and math.isnan(x[k])
                                                         and math.isnan(y[k])) for k in x)
        for x, y in zip(a, b, strict=True))


def test_ids_are_registered_by_the_package():
    assert {CENTER_OUT, CONTINUOUS} <= set(gym.registry)
    assert armgame.env.CENTER_OUT_IDS == (CENTER_OUT, CONTINUOUS)


@pytest.mark.parametrize("env_id", [CENTER_OUT, CONTINUOUS])
def test_gymnasiums_checker_passes_without_a_warning(env_id):
    env = gym.make(env_id, render_size=(96, 96))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)  # renders in both modes too (SDL's dummy drivers)


def test_the_same_seed_gives_the_same_rollout_bit_for_bit():
    def rollout(seed):
        """Random keys for 0.6 s (the hand leaves home), then the model bot to the end of a curl run."""
        env = gym.make(CENTER_OUT, protocol=SHORT, perturbation="curl")
        env.action_space.seed(3)
        policy = CenterOutBotPolicy("model", env)
        obs, _ = env.reset(seed=seed)
        out, n, done = [obs], 0, False
        while not done:
            action = env.action_space.sample() if n < 30 else policy(obs)
            obs, reward, terminated, truncated, info = env.step(action)
            out += [obs, np.array([reward, terminated, truncated, info["trials_done"], info["hits"]])]
            out += [np.array([v for v in r.values() if not isinstance(v, str)], dtype=float)
                    for r in info.get("reaches", [])]
            n, done = n + 1, terminated or truncated
        return np.concatenate(out), env.unwrapped.session.timeline

    (a, ta), (b, tb), (c, _) = rollout(7), rollout(7), rollout(8)
    assert a.tobytes() == b.tobytes() and ta == tb
    assert a.shape != c.shape or a.tobytes() != c.tobytes()  # the seed matters: other delays, another order


def test_the_model_bot_through_the_env_is_the_headless_lab_run():
    # The null preset's task cut to three cycles of its 8 targets (the whole 120-trial run is the same
    # loop five times longer: `armgame lab null --bot model --headless`, 120 of 120 hits).
    protocol = dataclasses.replace(preset("null"), blocks=(Block("baseline", 8), Block("exposure", 16)))
    headless = LabSession(lab_config(protocol, 10), protocol)
    Autopilot(headless, make_lab_bot("model")).play()
    assert headless.finished and len(headless.outcomes) == 24

    env = gym.make(CENTER_OUT, protocol=protocol, decision_steps=1)  # the lab bots decide every 4 ms
    total, reaches, terminated, info = bot_run(env, 10)
    session = env.unwrapped.session
    assert terminated and session.finished
    assert session.timeline == headless.timeline  # the same key presses at the same steps
    assert session.trial_records() == headless.trial_records()
    assert same_rows(reaches, trial_rows(headless))  # info's per-reach rows are the lab's table
    assert info["hits"] == headless.result().hits == 24
    assert sorted({round(r["target_deg"]) for r in reaches}) == list(range(0, 360, 45))
    assert total == pytest.approx(24 - 0.1 * session.steps * session.config.dt, abs=1e-6)


@pytest.mark.parametrize("perturbation", [Perturbation.make("curl", b=2.0), Perturbation.make("rotation", angle=30.0)])
def test_the_adaptive_bot_learns_through_the_env_as_it_does_headless(perturbation):
    protocol = Protocol("short", (Block("baseline", 4), Block("exposure", 8, perturbation), Block("washout", 4)))
    headless = LabSession(lab_config(protocol, 3), protocol)
    Autopilot(headless, make_lab_bot("adaptive")).play()
    env = gym.make(CENTER_OUT, protocol=protocol, decision_steps=1)
    _total, _reaches, terminated, _ = bot_run(env, 3, bot="adaptive")
    assert terminated
    # Its learning reads the cursor and the felt torques: every key and every trial as in the lab's own run.
    assert env.unwrapped.session.timeline == headless.timeline
    assert env.unwrapped.session.trial_records() == headless.trial_records()


def test_a_curl_field_option_deflects_the_cursor():
    env = gym.make(CENTER_OUT, protocol=SHORT, decision_steps=1)

    def exposure_errors(options):
        _total, reaches, terminated, _ = bot_run(env, 4, options)
        assert terminated and len(reaches) == 5
        assert {r["perturbation"] for r in reaches[2:]} == {options["perturbation"]["perturbation"]}
        return [r["max_perpendicular_error_m"] for r in reaches[2:]]

    plain = exposure_errors({"perturbation": {"perturbation": "none"}})
    curled = exposure_errors({"perturbation": {"perturbation": "curl", "b": 2.0}})
    assert max(map(abs, plain)) < 0.006  # the model bot reaches straight in the null field (measured: <= 0.47 cm)
    assert max(curled) < -0.01  # b = 2 N s/m pushes it clockwise (right) over a centimetre (measured: 1.4-4.3 cm)


def test_the_perturbation_option_reaches_the_protocol():
    env = gym.make(CENTER_OUT)
    env.reset(seed=1, options={"perturbation": "rotation"})
    blocks = env.unwrapped.session.protocol.blocks
    assert [b.perturbation.label() for b in blocks] == ["none", "rotation angle=30 deg", "none"]
    env.reset(seed=1, options={"protocol": "curl", "perturbation": Perturbation.make("curl", b=-3.0)})
    assert env.unwrapped.session.protocol.blocks[1].perturbation["b"] == -3.0
    env.reset(seed=1, options={"protocol": "curl", "perturbation": "none"})
    assert {b.perturbation.kind for b in env.unwrapped.session.protocol.blocks} == {"none"}


def test_a_visual_rotation_moves_the_cursor_not_the_hand():
    quarter = Protocol("rot", (Block("exposure", 1, Perturbation.make("rotation", angle=90.0)),))
    env = gym.make(CENTER_OUT, protocol=quarter, decision_steps=1)
    policy = CenterOutBotPolicy("model", env)
    obs, _ = env.reset(seed=2)
    session = env.unwrapped.session
    while obs[14] == 0.0:  # the hold
        obs, *_ = env.step(policy(obs))
    for _ in range(150):  # past the bot's reaction time (0.25 s), into the movement
        obs, *_ = env.step(policy(obs))
    hx, hy = session.home
    hand, cursor = np.subtract(session.hand(), (hx, hy)), obs[8:10] - (hx, hy)
    assert np.linalg.norm(hand) > 0.01
    assert cursor == pytest.approx([-hand[1], hand[0]], abs=1e-12)  # a quarter turn counter-clockwise


def test_levels_of_zero_and_one_play_as_keys():
    keys, levels = gym.make(CENTER_OUT, protocol=SHORT), gym.make(CONTINUOUS, protocol=SHORT)
    a, _ = keys.reset(seed=5)
    b, _ = levels.reset(seed=5)
    rng = np.random.default_rng(0)
    for _ in range(100):
        action = rng.integers(0, 2, 4)
        a, *_ = keys.step(action)
        b, *_ = levels.step(action.astype(np.float32))
    assert a.tobytes() == b.tobytes()


def test_the_observation_is_documented_and_within_its_space():
    env = gym.make(CENTER_OUT, protocol=SHORT, decision_steps=1)
    assert env.observation_space.shape == (len(armgame.env.center_out.OBSERVATION_NAMES),)
    policy = CenterOutBotPolicy("model", env)
    obs, _ = env.reset(seed=0)
    session = env.unwrapped.session
    assert tuple(obs[10:14]) == session.home * 2 and obs[14] == 0.0 and obs[16] == 0.0
    seen_go = False
    while True:
        assert env.observation_space.contains(obs)
        obs, _, terminated, truncated, _ = env.step(policy(obs))
        if obs[14] == 1.0 and not seen_go:  # the go cue: the target shows, the phase's clock restarts
            seen_go = True
            assert tuple(obs[12:14]) == session.plans[0].position and obs[15] == 0.0
        if terminated or truncated:
            break
    assert obs[16] == 5.0 and obs[17] == pytest.approx(session.time_left)


def test_what_the_bounds_cannot_bound_is_unbounded_and_refused_where_the_space_bounds_it():
    bounded = gym.make(CENTER_OUT, protocol="curl")  # a curl field does no work: the game's speed bound holds
    assert bounded.observation_space.high[8] == pytest.approx(2.4)
    assert bounded.observation_space.high[2] == pytest.approx(34.4, abs=0.05)
    joint = gym.make(CENTER_OUT, protocol="jointspace")
    assert joint.observation_space.high[8] == math.inf and joint.observation_space.high[2] < math.inf
    # A spring or a constant force can feed the arm energy, but the run's speed guard holds the bound (issue 52).
    spring = gym.make(CENTER_OUT, perturbation={"perturbation": "spring", "stiffness": 100.0})
    assert spring.observation_space.high[2] == bounded.observation_space.high[2]
    with pytest.raises(EnvArgumentError, match="needs an env made with it"):
        bounded.reset(options={"perturbation": "jointspace"})
    bounded.reset(seed=0, options={"perturbation": {"perturbation": "constant", "fx": 5.0}})
    joint.reset(seed=0, options={"perturbation": "rotation"})  # narrower bounds fit a wider space


@pytest.mark.parametrize(("kwargs", "options", "match"), [
    ({"protocol": "nope"}, None, "protocol must be a lab preset"),
    ({"protocol": 3}, None, "protocol must be"),
    ({"decision_steps": 0}, None, "decision_steps"),
    ({"time_cost": -1.0}, None, "time_cost"),
    ({"perturbation": "wobble"}, None, "perturbation 'wobble'"),
    ({"perturbation": {"perturbation": "curl", "b": 1e9}}, None, "b must be a number from -50 to 50"),
    ({"perturbation": {"perturbation": "curl", "k": 1.0}}, None, "no parameter k"),
    ({"protocol": Protocol("x", (Block("baseline", 2),))}, {"perturbation": "curl"}, "no perturbed block"),
    ({}, {"speed": 2}, "unknown reset option"),
])
def test_bad_arguments_are_refused_in_one_line(kwargs, options, match):
    with pytest.raises(EnvArgumentError, match=match):
        env = gym.make(CENTER_OUT, **kwargs)
        env.reset(seed=0, options=options)


def test_bad_actions_and_steps_out_of_turn_are_refused():
    env = gym.make(CENTER_OUT).unwrapped
    with pytest.raises(gym.error.ResetNeeded):
        env.step([0, 0, 0, 0])
    env.reset(seed=0)
    for action in ([0, 1, 2, 0], [1, 1, 1], "dfjk"):
        with pytest.raises(ValueError, match="zeros or ones"):
            env.step(action)
    levels = gym.make(CONTINUOUS).unwrapped
    levels.reset(seed=0)
    with pytest.raises(ValueError, match="finite"):
        levels.step([math.nan] * 4)


def test_rgb_array_frames_show_the_lab_view():
    from armgame.ui.lab_window import CURSOR, HOME

    env = gym.make(CENTER_OUT, render_mode="rgb_array", render_size=(320, 240))
    env.reset(seed=3)
    frame = env.render()
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
    colours = {tuple(c) for c in frame.reshape(-1, 3)}
    assert HOME in colours and CURSOR in colours  # home filled during the hold, the cursor on it
    env.close()


def test_the_docstring_example_runs():
    failed, attempted = doctest.testmod(armgame.env.center_out)
    assert attempted >= 3 and failed == 0


def test_a_viscous_matrix_option_and_a_paradigm_it_cannot_stand_for():
    """A viscous field by its matrix, as in a protocol file; the savings and spontaneous presets run two fields
    (the field and its opposite), which one perturbation option cannot replace: one line saying so."""
    from armgame.env.center_out import perturbation_option, run_protocol

    p = perturbation_option({"perturbation": "viscous", "matrix": [[-1.0, 0.5], [0.5, 1.0]]})
    assert p.matrix == ((-1.0, 0.5), (0.5, 1.0))
    with pytest.raises(EnvArgumentError, match=r"matrix\[1\]\[0\] must be a finite number from -50 to 50"):
        perturbation_option({"perturbation": "viscous", "matrix": [[-1.0, 0.5], [99.0, 1.0]]})
    for name in ("savings", "spontaneous"):
        with pytest.raises(EnvArgumentError, match=r"2 different perturbations \(curl b=2 N s/m, curl b=-2 N s/m\)"):
            run_protocol(name, "curl")
    # with its probes placed as the versioned envs always placed them (issue 29: tests/test_lab_probes.py)
    assert run_protocol("spontaneous", None) == dataclasses.replace(preset("spontaneous"), probe_schedule="random")


def test_a_lab_bot_refuses_the_v1_env_whose_observations_it_does_not_read():
    """The lab's bots read CenterOut-v0's observation (18 numbers); v1's (16) is another's to read
    (``policies.CenterOutV1BotPolicy``): refused when the policy is made, not at its first step."""
    env = gym.make("armgame/CenterOut-v1")
    with pytest.raises(ValueError, match="CenterOut-v0"):
        CenterOutBotPolicy("model", env)
    env.close()
