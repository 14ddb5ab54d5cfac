"""Gymnasium environments over the game: how programs play armgame (optional extra ``[gym]``).

This package owns the Gymnasium face of the game and nothing of the game itself: the env
classes, their spaces and rewards, the registration of their ids, the vector envs, and
``policies.BotPolicy``, which lets the game's own bots play through an env. The rules, the
muscles and the physics stay in ``armgame.game``; frames come from ``armgame.ui``'s renderer.

Importing this package registers, with ``gymnasium.register``:

* ``armgame/Reach-v1`` and ``armgame/ReachContinuous-v1`` (``reach_v1.ReachV1Env``): the game for
  learners: the hand, its velocity and the hand-to-target vector observed (float32, bounded), a
  dense reward (``features``), keys as ``MultiBinary(4)`` or muscle levels as ``Box(-1, 1, (4,))``;
* ``armgame/CenterOut-v1`` and ``armgame/CenterOutContinuous-v1`` (``center_out_v1.CenterOutV1Env``):
  the lab's centre-out task, trials that start on their own, episodes of a few trials;
* the suite (``suite``): ``armgame/ReachHold-v1``, ``ReachNoisy-v1``, ``ReachDelay-v1``,
  ``ReachField-v1``, ``ReachHard-v1`` (Reach-v1 with a dwell, motor noise, a feedback delay, a force
  field, and all four on smaller targets: ``variants``) and ``armgame/CenterOutHold-v1`` (the go cue
  waits for a stop at home), each with a ``Continuous`` twin; ``evaluate`` (``evaluation.evaluate``,
  exported here) scores a policy on the held-out evaluation seeds against the reference scores
  (``references``), ``aggregate_runs`` summarises training seeds (IQM, stratified bootstrap:
  ``statistics``), and ``record.replay_of`` writes any env's game as a replay ``armgame verify`` checks;
* the separating tier (``suite.TIER``): ``armgame/ReachMemory-v1``, ``ReachMemoryHold-v1`` and
  ``ReachPositions-v1``, Reach-v1's and ReachHold-v1's games with the target seen only 0.1 s after it
  appears, or only positions observed;
* ``armgame/Reach-v0``, ``armgame/ReachContinuous-v0``, ``armgame/CenterOut-v0``,
  ``armgame/CenterOutContinuous-v0``: the first versions, unchanged (``reach``, ``center_out``).

Every id but the two CenterOut-v0 ones has a vector entry point, so ``gymnasium.make_vec(id,
num_envs=N)`` gives one vector env: for Reach, from 4 games (2 with noise or a field:
``vector.batch_min_envs``), ``vector.ReachVectorEnv`` stepping N games as numpy arrays on
``BatchGameSession`` (below that, for the score reward, and for noise and fields without the compiled kernel,
``vector_common.SingleEnvsVectorEnv``, Gymnasium's ``SyncVectorEnv`` of single envs); for
CenterOut-v1, ``center_out_batch.center_out_vector_env`` (the batch in C, else ``SyncVectorEnv``). ``sb3`` adapts
them to Stable-Baselines3 (and is the only module that imports it). ``import armgame`` imports neither
gymnasium nor this package, and nothing here imports pygame until an env renders::

    import gymnasium as gym
    import armgame.env  # noqa: F401  (registers the ids)
    env = gym.make("armgame/Reach-v1")

Gymnasium also imports the module named before a colon, so ``gym.make("armgame.env:armgame/Reach-v1")``
works without the import line.
"""

from __future__ import annotations

import gymnasium

from .evaluation import Evaluation, aggregate_runs, evaluate
from .suite import CENTER_OUT_SUITE, SUITE, TIER

__all__ = ["CENTER_OUT_IDS", "CENTER_OUT_SUITE", "CENTER_OUT_V1_IDS", "ENV_IDS", "SUITE", "V1_IDS", "Evaluation",
           "aggregate_runs", "evaluate"]

ENV_IDS = ("armgame/Reach-v0", "armgame/ReachContinuous-v0")
CENTER_OUT_IDS = ("armgame/CenterOut-v0", "armgame/CenterOutContinuous-v0")
V1_IDS = ("armgame/Reach-v1", "armgame/ReachContinuous-v1")
CENTER_OUT_V1_IDS = ("armgame/CenterOut-v1", "armgame/CenterOutContinuous-v1")


def _register() -> None:
    for env_id, continuous in zip(ENV_IDS, (False, True), strict=True):
        if env_id in gymnasium.registry:  # a re-import (importlib.reload) must not warn
            continue
        gymnasium.register(
            id=env_id,
            entry_point="armgame.env.reach:ReachEnv",
            vector_entry_point="armgame.env.vector:reach_vector_env",
            kwargs={"continuous": continuous},
            # The game ends itself at its time limit (a truncation); no TimeLimit wrapper on top.
            max_episode_steps=None,
            nondeterministic=False,
        )
    for env_id, continuous in zip(V1_IDS, (False, True), strict=True):
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point="armgame.env.reach_v1:ReachV1Env",
                               vector_entry_point="armgame.env.vector:reach_v1_vector_env",
                               kwargs={"continuous": continuous}, max_episode_steps=None, nondeterministic=False)
    for env_id, continuous in zip(CENTER_OUT_IDS, (False, True), strict=True):
        if env_id not in gymnasium.registry:
            # One episode is one protocol run; it ends itself (terminated, or truncated by the lab's clock).
            gymnasium.register(id=env_id, entry_point="armgame.env.center_out:CenterOutEnv",
                               kwargs={"continuous": continuous}, max_episode_steps=None, nondeterministic=False)

    for env_id, continuous in zip(CENTER_OUT_V1_IDS, (False, True), strict=True):
        if env_id not in gymnasium.registry:
            # An episode is a few trials or a block: it ends itself (terminated).
            gymnasium.register(id=env_id, entry_point="armgame.env.center_out_v1:CenterOutV1Env",
                               vector_entry_point="armgame.env.center_out_batch:center_out_vector_env",
                               kwargs={"continuous": continuous}, max_episode_steps=None, nondeterministic=False)
    suites = ((SUITE, "armgame.env.reach_v1:ReachV1Env", "armgame.env.vector:reach_v1_vector_env"),
              (CENTER_OUT_SUITE, "armgame.env.center_out_v1:CenterOutV1Env",
               "armgame.env.center_out_batch:center_out_vector_env"))
    for suite, entry_point, vector_entry_point in suites:
        for name, arguments in suite.items():
            for continuous in (False, True):
                env_id = f"armgame/{name}{'Continuous' if continuous else ''}-v1"
                if env_id not in gymnasium.registry:
                    gymnasium.register(id=env_id, entry_point=entry_point, vector_entry_point=vector_entry_point,
                                       kwargs={"continuous": continuous, **arguments}, max_episode_steps=None,
                                       nondeterministic=False)
    # The separating tier: key ids only (suite.TIER).
    for name, arguments in TIER.items():
        env_id = f"armgame/{name}-v1"
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point="armgame.env.reach_v1:ReachV1Env",
                               vector_entry_point="armgame.env.vector:reach_v1_vector_env",
                               kwargs={"continuous": False, **arguments}, max_episode_steps=None,
                               nondeterministic=False)

_register()
