"""The suite's reference scores: mean hits per game on the first 100 evaluation seeds, by policy.

Made by ``python benchmarks/reference_scores.py references FOLDER`` from that benchmark's runs (its
``bots`` and ``ppo`` steps; docs/programs.md's reference table is its ``table`` step of the same
runs). ``armgame.env.evaluation.normalised_score`` scales by ``random`` (0) and ``model`` (1);
``random_first`` and ``model_first`` are the first games' hits, which ``tests/test_env_suite.py``
replays. ``ppo`` is the mean over ``ppo_seeds``, each a training seed's policy evaluated on the same
games.
"""

from __future__ import annotations

from typing import Any

REFERENCE_HITS: dict[str, dict[str, Any]] = {
    "armgame/Reach-v1": {
        "random": 0.53, "naive": 20.03, "model": 53.21, "ppo": 68.145, "ppo_seeds": [67.23, 69.06], "random_first":
        [0, 1, 0, 0, 1], "model_first": [53, 52, 54, 55, 55]
    },
    "armgame/ReachContinuous-v1": {
        "random": 0.37, "naive": 20.03, "model": 53.21, "random_first": [0, 0, 0, 0, 0], "model_first": [53, 52, 54,
        55, 55]
    },
    "armgame/CenterOut-v1": {
        "random": 0.28, "naive": 1.57, "model": 8.0, "random_first": [2, 0, 1, 0, 0], "model_first": [8, 8, 8, 8, 8]
    },
    "armgame/CenterOutContinuous-v1": {
        "random": 0.43, "naive": 1.57, "model": 8.0, "random_first": [0, 0, 0, 1, 1], "model_first": [8, 8, 8, 8, 8]
    },
    "armgame/ReachHold-v1": {
        "random": 0.46, "naive": 8.29, "model": 45.87, "ppo": 60.805, "ppo_seeds": [60.92, 60.69], "random_first":
        [0, 1, 0, 0, 1], "model_first": [45, 45, 47, 47, 47]
    },
    "armgame/ReachHoldContinuous-v1": {
        "random": 0.39, "naive": 8.29, "model": 45.87, "random_first": [0, 0, 0, 0, 0], "model_first": [45, 45, 47,
        47, 47]
    },
    "armgame/ReachNoisy-v1": {
        "random": 0.8, "naive": 20.76, "model": 51.39, "ppo": 68.575, "ppo_seeds": [67.05, 70.1], "random_first":
        [0, 1, 2, 0, 0], "model_first": [52, 48, 54, 52, 52]
    },
    "armgame/ReachNoisyContinuous-v1": {
        "random": 0.61, "naive": 20.76, "model": 51.39, "random_first": [0, 0, 0, 1, 0], "model_first": [52, 48, 54,
        52, 52]
    },
    "armgame/ReachDelay-v1": {
        "random": 0.53, "naive": 14.36, "model": 30.75, "ppo": 60.755, "ppo_seeds": [60.28, 61.23], "random_first":
        [0, 1, 0, 0, 1], "model_first": [26, 32, 31, 33, 35]
    },
    "armgame/ReachDelayContinuous-v1": {
        "random": 0.37, "naive": 14.36, "model": 30.75, "random_first": [0, 0, 0, 0, 0], "model_first": [26, 32, 31,
        33, 35]
    },
    "armgame/ReachField-v1": {
        "random": 0.51, "naive": 19.2, "model": 45.63, "ppo": 75.685, "ppo_seeds": [77.02, 74.35], "random_first":
        [1, 1, 0, 0, 1], "model_first": [45, 44, 46, 50, 48]
    },
    "armgame/ReachFieldContinuous-v1": {
        "random": 0.43, "naive": 19.2, "model": 45.63, "random_first": [0, 0, 0, 2, 0], "model_first": [45, 44, 46,
        50, 48]
    },
    "armgame/ReachHard-v1": {
        "random": 0.21, "naive": 0.17, "model": 7.24, "ppo": 30.35, "ppo_seeds": [30.35], "random_first": [0, 0, 0,
        0, 0], "model_first": [7, 9, 9, 10, 8]
    },
    "armgame/ReachHardContinuous-v1": {
        "random": 0.23, "naive": 0.17, "model": 7.24, "random_first": [0, 0, 0, 0, 0], "model_first": [7, 9, 9, 10,
        8]
    },
    "armgame/CenterOutHold-v1": {
        "random": 0.0, "naive": 0.0, "model": 8.0, "random_first": [0, 0, 0, 0, 0], "model_first": [8, 8, 8, 8, 8]
    },
    "armgame/CenterOutHoldContinuous-v1": {
        "random": 0.02, "naive": 0.0, "model": 8.0, "random_first": [0, 0, 0, 0, 0], "model_first": [8, 8, 8, 8, 8]
    },
}
