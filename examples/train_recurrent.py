"""Train RecurrentPPO (sb3-contrib, an LSTM policy) to play armgame: a learner with memory, for the separating tier.

    pip install -e '.[rl]' sb3-contrib
    python examples/train_recurrent.py --steps 300000 --out lstm-run --env armgame/ReachMemory-v1

``examples/train_ppo.py``'s recipe with a memory: the same vector env, budget, seed ranges, validation and test games
and the same files in ``--out`` (``result.json`` names the algorithm ``RecurrentPPO``), but sb3-contrib's
``RecurrentPPO`` with its ``MlpLstmPolicy`` in place of PPO's ``MlpPolicy``: an LSTM before the actor's and another
before the critic's two 64-unit layers (sb3-contrib's defaults), each of 64 units, PPO's width (sb3-contrib's default
is 256, several times the cost). ``n_steps=128`` and ``batch_size=256`` over 32 envs are PPO's. The separating tier
(docs/programs.md, "A tier that keeps algorithms apart") hides what a policy must remember or tell from the past;
this is a learner that can. Every game it plays, the validation and test games and the kept replay, carries the
LSTM's state from step to step and starts it afresh at the game's first step (``armgame.env.evaluate`` does so for
any model whose ``predict`` takes ``state`` and ``episode_start``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch
from sb3_contrib import RecurrentPPO
from sb3_contrib.common.recurrent.policies import RecurrentActorCriticPolicy
from stable_baselines3.common.vec_env import VecMonitor

# train_ppo.py's command line, validation games, curve and result.json: ``python examples/train_recurrent.py``
# puts examples/ first on the path.
from train_ppo import VALIDATION, Curve, arguments, save_result

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.evaluation import evaluate
from armgame.env.record import replay_of
from armgame.env.sb3 import make_sb3_vec_env


def validate(model: RecurrentPPO, env_id: str) -> np.ndarray:
    """Hits in each of 10 whole validation games played by the deterministic policy: ``evaluate`` on the validation
    seeds, the LSTM's state carried through each game."""
    return np.array(evaluate(model, env_id, seeds=VALIDATION).hits)


class LstmPolicy(RecurrentActorCriticPolicy):
    """sb3-contrib's ``MlpLstmPolicy``, the keys' log-probability taken of float actions: its rollout buffer hands
    the key ids' ``int8`` actions on as they are (SB3's own buffer casts them to float), and torch's Bernoulli
    refuses them ("result type Float can't be cast to the desired output type Char", sb3-contrib 2.9.2)."""

    def evaluate_actions(self, obs, actions, lstm_states, episode_starts):  # type: ignore[no-untyped-def]
        return super().evaluate_actions(obs, actions.float(), lstm_states, episode_starts)


def keep_a_game(model: RecurrentPPO, env_id: str, path: Path) -> int:
    """Plays game seed 0 with the deterministic policy in a single env, its LSTM state carried, and saves its
    replay; its hits."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=0)
    state, start = None, np.ones(1, dtype=bool)
    done = False
    while not done:
        action, state = model.predict(obs, state=state, episode_start=start, deterministic=True)
        start = np.zeros(1, dtype=bool)
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    replay_of(env, driver="recurrent ppo").save(path)
    return int(info["hits"])


def main(argv: list[str] | None = None) -> int:
    args = arguments(argv, __doc__.splitlines()[0], env="armgame/ReachMemory-v1", steps=300_000)

    torch.set_num_threads(1)  # as train_ppo.py: the cores are shared, and a second thread gains little here
    # Game seeds from seed * 1000 up: below the validation and test ranges, and apart for each training seed.
    envs = VecMonitor(make_sb3_vec_env(args.env, args.envs, seed=args.seed * 1000), info_keywords=("hits",))
    model = RecurrentPPO(LstmPolicy, envs, policy_kwargs={"lstm_hidden_size": 64}, n_steps=128, batch_size=256,
                         seed=args.seed, device="cpu", verbose=0)
    curve = Curve(args.env, args.eval_every, args.minutes * 60.0, args.out, validate)
    model.learn(args.steps, callback=curve)
    curve.record()
    test = evaluate(model, args.env, games=args.test_games)  # once, at the end: the test games
    print(test.summary())
    if args.out is not None:
        save_result(args, "RecurrentPPO", model, test)
        hits = keep_a_game(model, args.env, args.out / "game.json")
        print(f"its game of seed 0 ({hits} hits): armgame replay {args.out / 'game.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
