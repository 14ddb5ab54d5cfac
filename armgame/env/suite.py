"""The benchmark suite: the harder ids, their vector env, and the seeds kept for evaluation.

``SUITE`` maps each harder Reach id to the ``armgame/Reach-v1`` arguments it fixes
(``armgame.env.variants``), ``CENTER_OUT_SUITE`` each harder CenterOut id to
``armgame/CenterOut-v1``'s; ``armgame.env`` registers them. Their vector entry points are
``Reach-v1``'s and ``CenterOut-v1``'s (``vector.reach_v1_vector_env`` gives the native vector env for
``ReachHold`` and ``ReachDelay``, whose dwell and delay the batch keeps per game, and Gymnasium's
``SyncVectorEnv`` of single envs for the others: the batch kernel steps no noise or field), so
``gymnasium.make_vec`` and the SB3 adapter take the suite's ids as they take ``Reach-v1``.

Three disjoint ranges of game seeds make the protocol (docs/programs.md, "The protocol"):

* **training**: below ``TRAINING_SEED_LIMIT`` (10^9); the examples seed their games there;
* **validation**: ``VALIDATION_SEEDS`` (10^9 + 10^6 to 10^9 + 2 10^6 - 1): what a training run watches
  to choose a checkpoint, stop early or tune, so the test games never steer a choice;
* **test**: ``EVALUATION_SEEDS`` (10^9 to 10^9 + 10^6 - 1): ``armgame.env.evaluate`` plays them, once a
  run is over, so scores in different papers are scores on the same games.
"""

from __future__ import annotations

from typing import Any

#: The harder Reach ids and the arguments each fixes; each has a ``Continuous`` twin.
#: Chosen so that the model bot still scores (docs/programs.md's reference table) while each
#: breaks one thing a policy of the plain game relies on.
SUITE: dict[str, dict[str, Any]] = {
    # A hit needs the hand to stay 0.2 s in the target: the hand must stop, not fly through.
    "ReachHold": {"hold_time": 0.2},
    # Signal-dependent force noise of 30 % (a coefficient of variation), correlated over 50 ms.
    "ReachNoisy": {"motor_noise": 0.3},
    # The observation is 100 ms old (5 decisions): a visual reaction time's worth.
    "ReachDelay": {"observation_delay": 5},
    # The lab's curl field at the hand all game long (b = 2 N s/m).
    "ReachField": {"field": "curl", "field_strength": 2.0},
    # All four at once, and targets of 3 cm.
    "ReachHard": {"hold_time": 0.2, "motor_noise": 0.3, "observation_delay": 5, "field": "curl",
                  "field_strength": 2.0, "target_radius": 0.03},
}

#: The separating tier (issue 52): Reach ids whose observation hides part of the game's state, which the game
#: itself does not change, so each plays a suite game (``TIER_GAMES``) and its reference is that game's. A
#: policy that acts on the present observation alone cannot do what the reference does, which plans from the
#: true state, while an agent that remembers what it saw can know all the reference knows. Key ids only (no
#: ``Continuous`` twins); not in ``suite_ids()``, so protocol 2's ids and tables stay as published.
TIER: dict[str, dict[str, Any]] = {
    # The target is seen for 0.1 s (5 observations) after it appears, then hidden: where to go must be remembered.
    "ReachMemory": {"target_shown": 0.1},
    # The same with a 0.2 s stay in the target: the stop needs the target's distance, which the hand's motion
    # toward it does not carry.
    "ReachMemoryHold": {"target_shown": 0.1, "hold_time": 0.2},
    # Positions only: no velocities (joints' or hand's) and no muscle activations observed; they must be told
    # from the positions seen over the last few decisions and the keys pressed.
    "ReachPositions": {"positions_only": True},
}

#: Which suite game each tier id plays: the same game, hit for hit, with less of it observed.
TIER_GAMES: dict[str, str] = {"ReachMemory": "Reach", "ReachMemoryHold": "ReachHold", "ReachPositions": "Reach"}

#: The harder CenterOut ids and the ``armgame/CenterOut-v1`` arguments each fixes; each has a ``Continuous`` twin.
CENTER_OUT_SUITE: dict[str, dict[str, Any]] = {
    # A person's rule: the go cue waits for the cursor to stay in home (0.5 to 1.0 s), so every trial
    # needs a stop at home as well as the 0.2 s stay in the target.
    "CenterOutHold": {"trial_start": "hold"},
}

#: The protocol these seeds, ``evaluate`` and ``aggregate_runs`` make (docs/programs.md, "The protocol"): name it
#: in a paper. 1: three seed ranges, a fresh policy each game, normalised by random play (0) and the model bot
#: (1). 2: the same, normalised by each id's ceiling (1; ``armgame.env.references.CEILINGS``: the best mean hits
#: measured on the test games, by the shooting controller, PPO at a budget where its curve has flattened, or the
#: most a CenterOut episode holds). 3 (issue 52): the same, normalised by each id's fixed reference (1;
#: ``armgame.env.references.REFERENCES_V3``: the shooting controller's mean hits on a Reach id, the model bot's
#: hits a minute on a CenterOut id, where every trial is hit and speed is what still ranks), never a mean of the
#: runs being scored, so a run above the reference scores above 1. Protocol 2's figures are kept beside it.
PROTOCOL_VERSION = 3
#: The protocols ``normalised_score`` still computes: a published figure keeps its meaning.
PROTOCOLS = (2, 3)

#: Game seeds kept for evaluation: ``armgame.env.evaluate`` plays from here; training never should.
EVALUATION_SEED_START = 10**9
EVALUATION_SEED_COUNT = 10**6
EVALUATION_SEEDS = range(EVALUATION_SEED_START, EVALUATION_SEED_START + EVALUATION_SEED_COUNT)
#: Training examples (``examples/train_ppo.py``) seed their games below this.
TRAINING_SEED_LIMIT = EVALUATION_SEED_START
#: Game seeds for validation (a run's curve, early stopping, tuning): neither trained on nor the test games.
VALIDATION_SEED_START = EVALUATION_SEED_START + EVALUATION_SEED_COUNT
VALIDATION_SEED_COUNT = 10**6
VALIDATION_SEEDS = range(VALIDATION_SEED_START, VALIDATION_SEED_START + VALIDATION_SEED_COUNT)


def tier_ids() -> tuple[str, ...]:
    """The separating tier's ids, in ``TIER``'s order."""
    return tuple(f"armgame/{name}-v1" for name in TIER)


def suite_ids() -> tuple[str, ...]:
    """Every harder id, key and continuous, in ``SUITE``'s and then ``CENTER_OUT_SUITE``'s order."""
    return tuple(f"armgame/{name}{kind}-v1" for name in (*SUITE, *CENTER_OUT_SUITE) for kind in ("", "Continuous"))
