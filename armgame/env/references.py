"""The suite's reference scores: mean hits per game on the first 100 evaluation seeds, by policy.

Made by ``python benchmarks/reference_scores.py references FOLDER`` from that benchmark's runs (its
``bots`` and ``ppo`` steps; docs/programs.md's reference table is its ``table`` step of the same
runs). ``armgame.env.evaluation.normalised_score`` scales by random play (0) and the id's reference (1,
``REFERENCES_V3``, protocol 3, each row with its own 0), or under protocol 2 by ``random`` and the id's ceiling
(``CEILINGS``; protocol 1 scaled by ``model``);
``random_first`` and ``model_first`` are the first games' hits, which ``tests/test_env_suite.py``
replays. ``ppo`` is the mean over ``ppo_seeds``, each a training seed's policy evaluated on the same
games.

The bots' rows of the CenterOut ids were measured again when ``evaluate`` began to give every game a fresh
bot (issue 40: one bot's clock had run on from game to game): the naive bot's CenterOut rows changed (1.57
to 1.41 hits; CenterOutHold's 0.0 to 0.12, hits in 12 of 100 games), the model bot's did not, and neither
did the Reach rows, whose bots always recognised a new game by its clock. The normalised scores, which
use random play and the model bot, are unchanged.
"""

from __future__ import annotations

from typing import Any

REFERENCE_HITS: dict[str, dict[str, Any]] = {
    "armgame/Reach-v1": {
        "random": 0.53, "naive": 20.03, "model": 53.21, "ppo": 69.6867, "ppo_seeds": [67.23, 69.06, 72.77],
        "random_first": [0, 1, 0, 0, 1], "model_first": [53, 52, 54, 55, 55]
    },
    "armgame/ReachContinuous-v1": {
        "random": 0.37, "naive": 20.03, "model": 53.21, "ppo": 68.7133, "ppo_seeds": [68.45, 68.21, 69.48],
        "random_first": [0, 0, 0, 0, 0], "model_first": [53, 52, 54, 55, 55]
    },
    "armgame/CenterOut-v1": {
        "random": 0.28, "naive": 1.41, "model": 8.0, "ppo": 8.0, "ppo_seeds": [8.0, 8.0, 8.0], "random_first": [2,
        0, 1, 0, 0], "model_first": [8, 8, 8, 8, 8]
    },
    "armgame/CenterOutContinuous-v1": {
        "random": 0.43, "naive": 1.41, "model": 8.0, "ppo": 8.0, "ppo_seeds": [8.0, 8.0, 8.0], "random_first": [0,
        0, 0, 1, 1], "model_first": [8, 8, 8, 8, 8]
    },
    "armgame/ReachHold-v1": {
        "random": 0.46, "naive": 8.29, "model": 45.87, "ppo": 61.3, "ppo_seeds": [60.92, 60.69, 62.29],
        "random_first": [0, 1, 0, 0, 1], "model_first": [45, 45, 47, 47, 47]
    },
    "armgame/ReachHoldContinuous-v1": {
        "random": 0.39, "naive": 8.29, "model": 45.87, "ppo": 62.4033, "ppo_seeds": [61.6, 62.27, 63.34],
        "random_first": [0, 0, 0, 0, 0], "model_first": [45, 45, 47, 47, 47]
    },
    "armgame/ReachNoisy-v1": {
        "random": 0.8, "naive": 20.76, "model": 51.39, "ppo": 68.5867, "ppo_seeds": [67.05, 70.1, 68.61],
        "random_first": [0, 1, 2, 0, 0], "model_first": [52, 48, 54, 52, 52]
    },
    "armgame/ReachNoisyContinuous-v1": {
        "random": 0.61, "naive": 20.76, "model": 51.39, "ppo": 66.6433, "ppo_seeds": [63.76, 70.13, 66.04],
        "random_first": [0, 0, 0, 1, 0], "model_first": [52, 48, 54, 52, 52]
    },
    "armgame/ReachDelay-v1": {
        "random": 0.53, "naive": 14.36, "model": 30.75, "ppo": 62.7867, "ppo_seeds": [60.28, 61.23, 66.85],
        "random_first": [0, 1, 0, 0, 1], "model_first": [26, 32, 31, 33, 35]
    },
    "armgame/ReachDelayContinuous-v1": {
        "random": 0.37, "naive": 14.36, "model": 30.75, "ppo": 53.46, "ppo_seeds": [48.81, 63.54, 48.03],
        "random_first": [0, 0, 0, 0, 0], "model_first": [26, 32, 31, 33, 35]
    },
    "armgame/ReachField-v1": {
        "random": 0.51, "naive": 19.2, "model": 45.63, "ppo": 76.4333, "ppo_seeds": [77.02, 74.35, 77.93],
        "random_first": [1, 1, 0, 0, 1], "model_first": [45, 44, 46, 50, 48]
    },
    "armgame/ReachFieldContinuous-v1": {
        "random": 0.43, "naive": 19.2, "model": 45.63, "ppo": 69.0533, "ppo_seeds": [60.72, 76.12, 70.32],
        "random_first": [0, 0, 0, 2, 0], "model_first": [45, 44, 46, 50, 48]
    },
    "armgame/ReachHard-v1": {
        "random": 0.21, "naive": 0.17, "model": 7.24, "ppo": 28.6733, "ppo_seeds": [30.35, 35.45, 20.22],
        "random_first": [0, 0, 0, 0, 0], "model_first": [7, 9, 9, 10, 8]
    },
    "armgame/ReachHardContinuous-v1": {
        "random": 0.23, "naive": 0.17, "model": 7.24, "ppo": 38.9067, "ppo_seeds": [37.6, 38.99, 40.13],
        "random_first": [0, 0, 0, 0, 0], "model_first": [7, 9, 9, 10, 8]
    },
    "armgame/CenterOutHold-v1": {
        "random": 0.0, "naive": 0.12, "model": 8.0, "ppo": 7.88, "ppo_seeds": [8.0, 8.0, 7.64], "random_first": [0,
        0, 0, 0, 0], "model_first": [8, 8, 8, 8, 8]
    },
    "armgame/CenterOutHoldContinuous-v1": {
        "random": 0.02, "naive": 0.12, "model": 8.0, "ppo": 8.0, "ppo_seeds": [8.0, 8.0, 8.0], "random_first": [0, 0,
        0, 0, 0], "model_first": [8, 8, 8, 8, 8]
    },
}


# Protocol 2's ceilings (``python benchmarks/reference_scores.py ceilings``, from the committed results under
# benchmarks/results; tests/test_env_suite.py holds them to those files): each id's best mean hits on the 100
# test games by a policy that knows the task or has learnt it, and which. The normalised score's 1.
CEILINGS: dict[str, dict[str, Any]] = {
    "armgame/Reach-v1": {
        "hits": 74.282, "by": "PPO, 4,000,000 env steps, 5 seeds"},
    "armgame/ReachContinuous-v1": {
        "hits": 74.282, "by": "Reach-v1's ceiling"},
    "armgame/CenterOut-v1": {
        "hits": 8.0, "by": "every trial of the episode hit"},
    "armgame/CenterOutContinuous-v1": {
        "hits": 8.0, "by": "every trial of the episode hit"},
    "armgame/ReachHold-v1": {
        "hits": 65.858, "by": "PPO, 4,000,000 env steps, 5 seeds"},
    "armgame/ReachHoldContinuous-v1": {
        "hits": 65.858, "by": "ReachHold-v1's ceiling"},
    "armgame/ReachNoisy-v1": {
        "hits": 73.61, "by": "PPO, 4,000,000 env steps, 5 seeds"},
    "armgame/ReachNoisyContinuous-v1": {
        "hits": 73.61, "by": "ReachNoisy-v1's ceiling"},
    "armgame/ReachDelay-v1": {
        "hits": 72.16, "by": "the shooting controller (100 games, Reach-v1's games)"},
    "armgame/ReachDelayContinuous-v1": {
        "hits": 72.16, "by": "the shooting controller (100 games, Reach-v1's games)"},
    "armgame/ReachField-v1": {
        "hits": 81.672, "by": "PPO, 4,000,000 env steps, 5 seeds"},
    "armgame/ReachFieldContinuous-v1": {
        "hits": 81.672, "by": "ReachField-v1's ceiling"},
    "armgame/ReachHard-v1": {
        "hits": 52.624, "by": "PPO, 10,000,000 env steps, 5 seeds"},
    "armgame/ReachHardContinuous-v1": {
        "hits": 52.624, "by": "ReachHard-v1's ceiling"},
    "armgame/CenterOutHold-v1": {
        "hits": 8.0, "by": "every trial of the episode hit"},
    "armgame/CenterOutHoldContinuous-v1": {
        "hits": 8.0, "by": "every trial of the episode hit"},
}


# Protocol 3's reference (``python benchmarks/reference_scores.py references-v3``, from benchmarks/results/ceiling,
# benchmarks/results/reference and benchmarks/results/center-out-time; tests/test_hit_bound.py holds it to those
# files): per Reach id, the shooting controller at its strongest settings tried, its mean hits on the test games
# played (``games``; 95 % interval over games), the code, and the CPU seconds a decision cost in that run; the
# separating tier's ids (``armgame.env.suite.TIER``) take their suite game's; per CenterOut id, the model bot's hits
# a minute (``unit``). ``random`` is each id's 0, in its unit (docs/programs.md, "Protocol 3's reference").
REFERENCES_V3: dict[str, dict[str, Any]] = {
    'armgame/Reach-v1': {
        'hits': 72.16,
        'low': 71.552,
        'high': 72.768,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00264,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/Reach-v1',
        'unit': 'hits a game',
        'random': 0.53,
    },
    'armgame/ReachHold-v1': {
        'hits': 64.57,
        'low': 64.209,
        'high': 64.931,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00304,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/ReachHold-v1',
        'unit': 'hits a game',
        'random': 0.46,
    },
    'armgame/ReachNoisy-v1': {
        'hits': 70.63,
        'low': 69.957,
        'high': 71.303,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController(replan=1)',
        'cpu_per_decision': 0.00394,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/ReachNoisy-v1',
        'unit': 'hits a game',
        'random': 0.8,
    },
    'armgame/ReachField-v1': {
        'hits': 69.99,
        'low': 69.308,
        'high': 70.672,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController(replan=1)',
        'cpu_per_decision': 0.00516,
        'machine': 'AMD EPYC; x86_64, 3.11.7, armgame 0.5.0',
        'games_of': 'armgame/ReachField-v1',
        'unit': 'hits a game',
        'random': 0.51,
    },
    'armgame/ReachHard-v1': {
        'hits': 55.57,
        'low': 55.109,
        'high': 56.031,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController(replan=1, coarse=15, fine=4)',
        'cpu_per_decision': 0.01109,
        'machine': 'AMD EPYC; x86_64, 3.11.7, armgame 0.5.0',
        'games_of': 'armgame/ReachHard-v1',
        'unit': 'hits a game',
        'random': 0.21,
    },
    'armgame/ReachContinuous-v1': {
        'hits': 72.16,
        'low': 71.552,
        'high': 72.768,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00264,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/Reach-v1',
        'unit': 'hits a game',
        'random': 0.37,
    },
    'armgame/ReachDelay-v1': {
        'hits': 72.16,
        'low': 71.552,
        'high': 72.768,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00264,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/Reach-v1',
        'unit': 'hits a game',
        'random': 0.53,
    },
    'armgame/ReachDelayContinuous-v1': {
        'hits': 72.16,
        'low': 71.552,
        'high': 72.768,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00264,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/Reach-v1',
        'unit': 'hits a game',
        'random': 0.37,
    },
    'armgame/ReachHoldContinuous-v1': {
        'hits': 64.57,
        'low': 64.209,
        'high': 64.931,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00304,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/ReachHold-v1',
        'unit': 'hits a game',
        'random': 0.39,
    },
    'armgame/ReachNoisyContinuous-v1': {
        'hits': 70.63,
        'low': 69.957,
        'high': 71.303,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController(replan=1)',
        'cpu_per_decision': 0.00394,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/ReachNoisy-v1',
        'unit': 'hits a game',
        'random': 0.61,
    },
    'armgame/ReachFieldContinuous-v1': {
        'hits': 69.99,
        'low': 69.308,
        'high': 70.672,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController(replan=1)',
        'cpu_per_decision': 0.00516,
        'machine': 'AMD EPYC; x86_64, 3.11.7, armgame 0.5.0',
        'games_of': 'armgame/ReachField-v1',
        'unit': 'hits a game',
        'random': 0.43,
    },
    'armgame/ReachHardContinuous-v1': {
        'hits': 55.57,
        'low': 55.109,
        'high': 56.031,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController(replan=1, coarse=15, fine=4)',
        'cpu_per_decision': 0.01109,
        'machine': 'AMD EPYC; x86_64, 3.11.7, armgame 0.5.0',
        'games_of': 'armgame/ReachHard-v1',
        'unit': 'hits a game',
        'random': 0.23,
    },
    'armgame/ReachMemory-v1': {
        'hits': 72.16,
        'low': 71.552,
        'high': 72.768,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00264,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/Reach-v1',
        'unit': 'hits a game',
        'random': 0.53,
    },
    'armgame/ReachMemoryHold-v1': {
        'hits': 64.57,
        'low': 64.209,
        'high': 64.931,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00304,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/ReachHold-v1',
        'unit': 'hits a game',
        'random': 0.46,
    },
    'armgame/ReachPositions-v1': {
        'hits': 72.16,
        'low': 71.552,
        'high': 72.768,
        'games': 100,
        'code': 'armgame.env.ceiling.ShootingController()',
        'cpu_per_decision': 0.00264,
        'machine': 'processor not recorded; x86_64, 3.11.7, armgame 0.4.0',
        'games_of': 'armgame/Reach-v1',
        'unit': 'hits a game',
        'random': 0.53,
    },
    'armgame/CenterOut-v1': {
        'hits': 45.682,
        'low': 45.341,
        'high': 46.023,
        'games': 100,
        'unit': 'hits a minute',
        'random': 0.5694,
        'code': 'armgame.env.center_out_reference.CenterOutShootingController()',
        'cpu_per_decision': 0.002971,
        'machine': 'AMD EPYC; x86_64',
        'games_of': 'armgame/CenterOut-v1',
    },
    'armgame/CenterOutContinuous-v1': {
        'hits': 45.682,
        'low': 45.341,
        'high': 46.023,
        'games': 100,
        'unit': 'hits a minute',
        'random': 0.8778,
        'code': 'armgame.env.center_out_reference.CenterOutShootingController()',
        'cpu_per_decision': 0.002975,
        'machine': 'AMD EPYC; x86_64',
        'games_of': 'armgame/CenterOutContinuous-v1',
    },
    'armgame/CenterOutHold-v1': {
        'hits': 45.682,
        'low': 45.341,
        'high': 46.023,
        'games': 100,
        'unit': 'hits a minute',
        'random': 0.0,
        'code': 'armgame.env.center_out_reference.CenterOutShootingController()',
        'cpu_per_decision': 0.002942,
        'machine': 'AMD EPYC; x86_64',
        'games_of': 'armgame/CenterOutHold-v1',
    },
    'armgame/CenterOutHoldContinuous-v1': {
        'hits': 45.682,
        'low': 45.341,
        'high': 46.023,
        'games': 100,
        'unit': 'hits a minute',
        'random': 0.0015,
        'code': 'armgame.env.center_out_reference.CenterOutShootingController()',
        'cpu_per_decision': 0.002939,
        'machine': 'AMD EPYC; x86_64',
        'games_of': 'armgame/CenterOutHoldContinuous-v1',
    },
}


# The separating tier's bots (``python benchmarks/reference_scores.py references benchmarks/results/tier-bots``, the
# 100 test games; tests/test_env_tier.py holds it to those files): random play is the 0 of their protocol 3 score.
# They have no protocol 2 ceiling. The game's bots read the observation, so they lose what it hides.
TIER_HITS: dict[str, dict[str, Any]] = {
    'armgame/ReachMemory-v1': {
        'random': 0.53,
        'naive': 0.79,
        'model': 1.02,
        'random_first': [0, 1, 0, 0, 1],
        'model_first': [1, 1, 1, 0, 1],
    },
    'armgame/ReachMemoryHold-v1': {
        'random': 0.46,
        'naive': 0.78,
        'model': 0.96,
        'random_first': [0, 1, 0, 0, 1],
        'model_first': [1, 1, 1, 0, 1],
    },
    'armgame/ReachPositions-v1': {
        'random': 0.53,
        'naive': 8.36,
        'model': 10.04,
        'random_first': [0, 1, 0, 0, 1],
        'model_first': [10, 14, 4, 10, 16],
    },
}
