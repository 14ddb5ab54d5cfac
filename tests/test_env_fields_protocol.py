"""Issue 52, items 3 and 4: CenterOut as physical as Reach under every lab field, and the protocol's holes
(training seeds, stateful and recurrent policies in ``evaluate``, ``verify``'s hit steps)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import armgame.env
from armgame.env import suite
from armgame.env.center_out import CenterOutEnv
from armgame.env.center_out_v1 import CenterOutV1Env
from armgame.env.reach import drawn_seed
from armgame.lab.perturbations import KINDS, Perturbation
from armgame.lab.protocol import Block, Protocol

#: The issue's runaways: energy-feeding and non-symmetric matrices at the lab's range's extremes.
ISSUE_FIELDS = (Perturbation.make("viscous", b11=50.0, b22=50.0),
                Perturbation.make("viscous", b11=50.0, b12=50.0, b21=50.0, b22=50.0),
                Perturbation.make("joint_viscous", w11=5.0, w12=5.0, w21=5.0, w22=5.0))


def pump(observation: np.ndarray) -> np.ndarray:
    """Each joint's muscle that pushes the way it turns: all the energy the muscles can feed (resonant)."""
    return np.array([observation[2] > 0, observation[2] <= 0, observation[3] > 0, observation[3] <= 0], dtype=np.int8)


def bang(step: int) -> np.ndarray:
    flex = (step // 5) % 2 == 0
    return np.array([flex, not flex, flex, not flex], dtype=np.int8)


def extremes() -> list[Perturbation]:
    """Every force field the lab offers at its range's extremes: each parameter alone at either end, all of them
    at either end together, and the matrices' feeding, damping and non-symmetric shapes."""
    out: list[Perturbation] = []
    for cls in KINDS.values():
        if not cls.is_force:
            continue
        params = cls.parameters()
        for end in ("low", "high"):
            out.append(cls(**{p.name: getattr(p, end) for p in params}))
            for p in params:
                out.append(cls(**{p.name: getattr(p, end)}))
        if len(params) == 4:  # a matrix field: [[m, m], [-m, m]], [[m, -m], [m, -m]]
            m = params[0].high
            out.append(cls(m, m, -m, m))
            out.append(cls(m, -m, m, -m))
    return list(dict.fromkeys(out))


def play_whole(env: gym.Env, policy: str, seed: int) -> dict:
    """An episode to its end; every observation inside the declared Box (``step`` raising fails the test)."""
    observation, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    space = env.observation_space
    assert space.contains(observation)
    step, done = 0, False
    while not done:
        action = env.action_space.sample() if policy == "random" else bang(step) if policy == "bang" \
            else pump(observation)
        observation, _, terminated, truncated, info = env.step(action)
        assert space.contains(observation), (step, observation, info)
        assert np.isfinite(observation).all()
        done, step = terminated or truncated, step + 1
    if "stopped" in info:
        assert terminated and not truncated
    return info


def one_block(perturbation: Perturbation, trials: int) -> Protocol:
    return Protocol("fields", (Block("exposure", trials, perturbation),))


@pytest.mark.parametrize("perturbation", ISSUE_FIELDS, ids=lambda p: p.label())
def test_the_issues_runaway_fields_stay_in_the_box_and_stop_in_one_line(perturbation):
    # Before the guard these ran to 546-5.3e15 rad/s against a bound of 34.4 and raised NonFiniteStateError.
    env = gym.make("armgame/CenterOut-v1", protocol=one_block(perturbation, 2), episode_trials=2,
                   observation_dtype="float64")
    info = play_whole(env, "pump", 0)
    assert info["stopped"].startswith("the force field drove a joint past 34.4 rad/s")
    # v0 runs a person's task: its go cue waits for the hand to rest at home, as a person's would.
    v0 = CenterOutEnv(protocol=one_block(perturbation, 1), time_cost=0.0)
    observation, _ = v0.reset(seed=0)
    for _ in range(60):
        observation, *_ = v0.step(np.zeros(4, dtype=np.int8))
    assert v0.session.phase == "reach"
    done = False
    while not done:
        observation, _, terminated, truncated, info = v0.step(pump(observation))
        assert v0.observation_space.contains(observation)
        done = terminated or truncated
    assert terminated and "stopped" in info


def test_every_center_out_field_declares_finite_speeds():
    for perturbation in extremes():
        env = CenterOutV1Env(protocol=one_block(perturbation, 1))
        assert np.isfinite(env.observation_space.high[2:4]).all(), perturbation.label()


@pytest.mark.slow
@pytest.mark.parametrize("policy", ["random", "bang", "pump"])
def test_every_lab_field_at_its_extremes_plays_whole_episodes_inside_the_box(policy):
    stopped = []
    for perturbation in extremes():
        for dtype in ("float32", "float64"):
            env = gym.make("armgame/CenterOut-v1", protocol=one_block(perturbation, 8), episode_trials=8,
                           observation_dtype=dtype)
            for seed in range(2):
                stopped.append("stopped" in play_whole(env, policy, seed))
            env.close()
    assert len(stopped) > 100


# ------------------------------------------------------------------ item 4: the protocol's holes
def test_unseeded_resets_draw_training_seeds_only():
    for env_id in ("armgame/Reach-v0", "armgame/Reach-v1", "armgame/ReachHard-v1", "armgame/CenterOut-v0",
                   "armgame/CenterOut-v1"):
        env = gym.make(env_id)
        env.reset(seed=3)
        seeds = []
        for _ in range(40):
            env.reset()
            seeds.append(env.unwrapped.session.config.seed)
        assert all(0 <= s < suite.TRAINING_SEED_LIMIT for s in seeds), (env_id, max(seeds))
        assert len(set(seeds)) == 40
    envs = gym.make_vec("armgame/Reach-v1", num_envs=4, vectorization_mode="vector_entry_point")
    envs.reset(seed=5)
    assert all(envs.unwrapped._game_seed(i, None) < suite.TRAINING_SEED_LIMIT for i in range(4) for _ in range(50))
    generator = np.random.default_rng(0)
    assert max(drawn_seed(generator) for _ in range(1000)) < suite.TRAINING_SEED_LIMIT


class CarriedBot:
    """A stand-in for a recurrent SB3 model (``predict(obs, state=None, episode_start=None, deterministic=...)``): it
    plays the model bot only while its state comes back as it gave it, starting afresh at each ``episode_start``;
    with its state lost it holds no key, and hits nothing."""

    def __init__(self) -> None:
        self.env = gym.make("armgame/Reach-v1", time_limit=2.0, observation_dtype="float64")
        self.bots: dict[int, object] = {}
        self.resets = 0

    def reset(self) -> None:
        self.resets += 1

    def predict(self, observation, state=None, episode_start=None, deterministic=False):
        from armgame.env.policies import BotPolicy

        batch = np.atleast_2d(observation)
        if episode_start is None:
            return np.zeros((len(batch), 4), dtype=np.int8).reshape((*np.shape(observation)[:-1], 4)), None
        state = np.zeros(len(batch), dtype=np.int64) if state is None else np.array(state)
        actions = []
        for i, obs in enumerate(batch):
            if episode_start[i]:
                self.bots[i] = BotPolicy("model", self.env)
                state[i] = 0
            elif state[i] == 0:  # a state lost: this game's bot is forgotten
                self.bots.pop(i, None)
            bot = self.bots.get(i)
            actions.append(bot(obs) if bot is not None else np.zeros(4, dtype=np.int8))
            state[i] += 1
        actions = np.array(actions)
        return (actions if np.ndim(observation) == 2 else actions[0]), state


@pytest.mark.parametrize("with_reset", [False, True])
def test_evaluate_carries_a_recurrent_state_through_each_game_and_resets_it(with_reset):
    model = CarriedBot()
    if not with_reset:  # the batched path (no reset()): the state goes through SB3's signature
        model.reset = None
    seeds = [armgame.env.suite.EVALUATION_SEED_START + i for i in range(3)]
    result = armgame.env.evaluate(model, "armgame/Reach-v1", seeds=seeds, time_limit=2.0,
                                  observation_dtype="float64")
    bot = armgame.env.evaluate("model", "armgame/Reach-v1", seeds=seeds, time_limit=2.0, observation_dtype="float64")
    assert sum(bot.hits) > 0 and result.hits == bot.hits
    if with_reset:
        assert model.resets == 3


# ------------------------------------------------------------------ item 4: verify compares every hit's step
def a_dwell_game(tmp_path):
    """A ReachHold-v1 game (dwell 50 steps) whose replay, edited to a dwell of 1, scores the same 2 hits earlier."""
    from armgame.env.policies import bot_policy
    from armgame.env.record import replay_of

    env = gym.make("armgame/ReachHold-v1", time_limit=3.0)
    policy = bot_policy("model", env)
    observation, info = env.reset(seed=0)
    done = False
    while not done:
        observation, _, terminated, truncated, info = env.step(policy(observation))
        done = terminated or truncated
    assert info["hits"] == 2
    path = tmp_path / "game.json"
    replay_of(env, driver="model bot").save(path)
    return path


def test_a_dwell_edited_to_the_same_count_is_refused_in_one_line(tmp_path, capsys):
    import json

    from armgame.cli import main

    path = a_dwell_game(tmp_path)
    assert main(["verify", str(path)]) == 0
    capsys.readouterr()
    data = json.loads(path.read_text())
    data["task"]["hold_steps"] = 1  # an easier ruleset: the bot's two hits come sooner, and still two
    path.write_text(json.dumps(data))
    assert main(["verify", str(path)]) == 1
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and "DIFFERS" in out and "dwell 1 steps" in out
    assert "the same score, hits, resets and steps, but hit 1 recorded at step" in out


def test_a_counts_only_section_is_refused_in_one_line(tmp_path, capsys):
    import json

    from armgame.cli import main

    path = a_dwell_game(tmp_path)
    data = json.loads(path.read_text())
    data["task"]["version"] = 1  # what 0.5 wrote: no hit steps, so the edit above would pass
    del data["task"]["hit_steps"]
    data["task"]["hold_steps"] = 1
    path.write_text(json.dumps(data))
    assert main(["verify", str(path)]) == 2
    captured = capsys.readouterr()
    line = (captured.out + captured.err).strip()
    assert "\n" not in line and "task.version 1" in line and "records no hit steps" in line
