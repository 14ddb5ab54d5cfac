"""Issue 52, item 4, with a real recurrent model: ``evaluate`` carries sb3-contrib's ``RecurrentPPO``'s LSTM state
through each game and starts it afresh at each game's first step.

sb3-contrib (and torch) are not in the test extra, so this file is skipped where they are absent, as in the default
test venv; it runs where the rl extra and sb3-contrib are installed (``pip install -e '.[rl]' sb3-contrib``), in the
slow tier (``python -m pytest -m slow tests/test_env_recurrent.py``).
``tests/test_env_fields_protocol.py`` tests the same with a stand-in of the same ``predict`` signature everywhere.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import armgame.env
from armgame.env import evaluation
from armgame.env.suite import EVALUATION_SEED_START

pytest.importorskip("sb3_contrib")  # the rl extra and sb3-contrib, not the test extra: run where they are installed

ENV_ID = "armgame/ReachPositions-v1"  # the keys of an untrained LSTM turn on its inputs here, and on its state
ARGS = {"time_limit": 1.0}  # 50 steps a game: every game of a batch ends at the same step
SEEDS = [EVALUATION_SEED_START + i for i in range(3)]


def untrained_lstm():  # type: ignore[no-untyped-def]
    """A small untrained RecurrentPPO whose deterministic keys turn on the LSTM's state: a lost or stale state changes
    them. (At its initial weights the state moves few keys; its recurrent weights tripled, it moves most.)"""
    import torch
    from sb3_contrib import RecurrentPPO

    model = RecurrentPPO("MlpLstmPolicy", gym.make(ENV_ID, **ARGS), policy_kwargs={"lstm_hidden_size": 16},
                         n_steps=16, batch_size=16, seed=0, device="cpu")
    with torch.no_grad():
        model.policy.lstm_actor.weight_hh_l0.mul_(3.0)
    return model


class Watched:
    """The model's ``predict`` as it is, each call's arguments and answer kept; ``reset`` (None: none) decides
    whether ``evaluate`` plays its games one at a time (with one) or together (without)."""

    def __init__(self, model, with_reset: bool) -> None:  # type: ignore[no-untyped-def]
        self.model, self.calls = model, []
        self.reset = (lambda: None) if with_reset else None

    def predict(self, observation, state=None, episode_start=None, deterministic=False):  # type: ignore[no-untyped-def]
        action, new_state = self.model.predict(observation, state=state, episode_start=episode_start,
                                               deterministic=deterministic)
        self.calls.append((np.array(observation), state, None if episode_start is None else np.array(episode_start),
                           np.array(action), new_state))
        return action, new_state


def by_hand(model, seed: int) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Game ``seed``'s keys, the LSTM's state carried as sb3-contrib's docs carry it: fresh at the first step."""
    env = gym.make(ENV_ID, **ARGS)
    observation, _ = env.reset(seed=seed)
    state, start, keys, done = None, np.ones(1, dtype=bool), [], False
    while not done:
        action, state = model.predict(observation, state=state, episode_start=start, deterministic=True)
        start = np.zeros(1, dtype=bool)
        keys.append(np.array(action))
        observation, _, terminated, truncated, _ = env.step(action)
        done = terminated or truncated
    return np.array(keys)


def keys_of_games(watched: Watched, steps: int) -> list[np.ndarray]:
    """Each game's keys as ``evaluate`` asked the model for them, in the seeds' order: every ``steps`` calls play
    one batch of games (one game, one at a time), a column of the calls' actions each."""
    actions = [np.atleast_2d(call[3]) for call in watched.calls]
    games = []
    for start in range(0, len(actions), steps):
        block = np.array(actions[start:start + steps])  # steps x games x keys
        games += [block[:, i] for i in range(block.shape[1])]
    return games


@pytest.mark.slow  # some seconds of torch a case: past the README's minute, where sb3-contrib is installed
@pytest.mark.parametrize("with_reset", [False, True], ids=["together", "one-by-one"])
def test_evaluate_carries_recurrent_ppos_state_through_each_game(with_reset, monkeypatch):
    model = untrained_lstm()
    expected = [by_hand(model, seed) for seed in SEEDS]
    assert not np.array_equal(expected[0], expected[1])  # the games are told apart: a mix-up of them shows
    # The keys turn on the state: played with it dropped at every step, game 0 goes otherwise.
    dropped = gym.make(ENV_ID, **ARGS)
    observation, _ = dropped.reset(seed=SEEDS[0])
    first = [model.predict(observation, deterministic=True)[0]]
    for _ in range(len(expected[0]) - 1):
        observation = dropped.step(first[-1])[0]
        first.append(model.predict(observation, deterministic=True)[0])
    assert not np.array_equal(np.array(first), expected[0])

    monkeypatch.setattr(evaluation, "BATCH", 2)  # games 0 and 1 together, game 2 after them in a batch of its own
    watched = Watched(model, with_reset)
    result = armgame.env.evaluate(watched, ENV_ID, seeds=SEEDS, **ARGS)
    steps = len(expected[0])
    played = keys_of_games(watched, steps)
    assert len(played) == len(SEEDS)
    for game, keys in enumerate(played):
        assert np.array_equal(keys, expected[game]), f"game {game}'s keys"
    # Each call is given the state the last one returned, and episode_start is true at a game's first step only.
    for i, (_, state, start, _, _) in enumerate(watched.calls):
        first_step = i % steps == 0
        assert start is not None and bool(start.all()) == first_step and (first_step or not start.any())
        if not first_step:
            assert state is watched.calls[i - 1][4]
    # The last game plays the same alone as after the others, key for key.
    watched_alone = Watched(model, with_reset)
    alone = armgame.env.evaluate(watched_alone, ENV_ID, seeds=SEEDS[2:], **ARGS)
    assert np.array_equal(keys_of_games(watched_alone, steps)[0], played[2]) and alone.hits == result.hits[2:]
