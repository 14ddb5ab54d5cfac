"""CenterOut's reference controller (``armgame.env.center_out_reference``): the hit each plan predicts is the lab's
hit, to the physics step, and it hits every trial of an episode sooner after the go cue than the model bot does."""

from __future__ import annotations

import pytest

gym = pytest.importorskip("gymnasium")

from armgame.env import ceiling  # noqa: E402
from armgame.env.center_out_reference import CenterOutShootingController  # noqa: E402
from armgame.env.errors import EnvArgumentError  # noqa: E402
from armgame.env.policies import bot_policy  # noqa: E402

pytestmark = pytest.mark.skipif(ceiling._shoot is None, reason="the compiled kernel is not built")

#: A training seed (below the test range).
SEED = 7


def _reach_steps(env_id: str, trials: int, policy_of) -> tuple[list[int], list[int], list[int], list[bool]]:
    """An episode of ``trials`` trials: (each trial's physics steps from its go cue to its end, each trial's end
    step, the hit steps the controller's plans made at a go cue predicted, each trial's hit)."""
    env = gym.make(env_id, episode_trials=trials)
    observation, _ = env.reset(seed=SEED)
    policy = policy_of(env)
    predicted: list[int] = []
    done = False
    while not done:
        action = policy(observation)
        if isinstance(policy, CenterOutShootingController) and policy.position == 1:  # a plan made at a go cue
            predicted.append(policy.plan_step + policy.predicted_steps)
        observation, _, terminated, truncated, _ = env.step(action)
        done = terminated or truncated
    outcomes = env.unwrapped.session.outcomes
    env.close()
    return [o.end_step - o.go_step for o in outcomes], [o.end_step for o in outcomes], predicted, \
        [o.hit for o in outcomes]


@pytest.mark.parametrize(("env_id", "trials"), [
    ("armgame/CenterOut-v1", 3),  # the fast tier's: three of the eight directions, half a second of search
    # The whole episode's eight directions, through levels and the wait in home: 1.5 s or more.
    pytest.param("armgame/CenterOutHoldContinuous-v1", 8, marks=pytest.mark.slow)])
def test_each_plan_hits_where_the_lab_scores_it_and_sooner_than_the_model_bot(env_id, trials):
    """Open loop (``replan=0``: each go cue's plan runs to its hit) and aiming at the target's edge (``margin=0``),
    the lab ends every trial with a hit at the step the plan predicted (a wrong moment, rate, radius, hold time or
    stay count in the rollouts fails here), and each trial's go cue to hit is shorter than the model bot's on the
    same trial."""
    steps, ends, predicted, hits = _reach_steps(env_id, trials, lambda env: CenterOutShootingController(env, replan=0,
                                                                                                margin=0.0))
    assert hits == [True] * trials
    assert predicted == ends
    bot_steps, _, _, bot_hits = _reach_steps("armgame/CenterOut-v1", trials,
                                                 lambda env: bot_policy("model", env))
    assert bot_hits == [True] * trials
    assert all(mine < theirs for mine, theirs in zip(steps, bot_steps, strict=True)), (steps, bot_steps)


def test_it_refuses_an_env_that_is_not_center_out():
    with pytest.raises(EnvArgumentError, match="plays the CenterOut ids"):
        CenterOutShootingController(gym.make("armgame/Reach-v1"))
