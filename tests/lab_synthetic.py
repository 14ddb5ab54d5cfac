"""A synthetic adaptation experiment for the lab's figure tests: the two-rate learner drives a reach model.

Each reach is a minimum-jerk movement to one of 8 targets 0.10 m from home whose path bows sideways
by ``BOW`` metres per unit of uncompensated field (``f - x``, with ``f`` 1 when the field is on and
``x`` the learner's estimate), plus a little noise; the trials table is then measured from those
paths by ``reach_metrics``, as the lab measures a replay.
"""

import math

import numpy as np

from armgame.lab.learner import TwoRateLearner
from armgame.lab.metrics import Reach, reach_metrics

HOME = (0.0, 0.45)
DISTANCE = 0.10
BOW = 0.03
DT = 0.005


def targets(count=8):
    return [(HOME[0] + DISTANCE * math.cos(2 * math.pi * k / count),
             HOME[1] + DISTANCE * math.sin(2 * math.pi * k / count)) for k in range(count)]


def protocol(baseline=16, exposure=64, washout=24, catch=(30, 46, 62)):
    """(block, perturbation) per trial; ``catch`` are exposure trials (1-based, overall) with the field off."""
    plan = [("baseline", "none")] * baseline + [("exposure", "curl")] * exposure + [("washout", "none")] * washout
    return [(block, "none" if n in catch else field) for n, (block, field) in enumerate(plan, start=1)]


def reach_path(target, bow, rng, duration=0.5):
    t = np.arange(0.0, 1.0, DT)
    s = np.clip((t - 0.3) / duration, 0.0, 1.0)
    p = 10 * s**3 - 15 * s**4 + 6 * s**5
    home, aim = np.array(HOME), np.array(target) - np.array(HOME)
    left = np.array([-aim[1], aim[0]]) / np.hypot(*aim)
    hand = home + np.outer(p, aim) + np.outer(bow * np.sin(np.pi * p) + rng.normal(0, 2e-4), left)
    return t, hand


def student(seed=0, learner=None, plan=None, bow=BOW):
    """One student's trials table rows and hand paths (trial -> (n, 2) array)."""
    rng = np.random.default_rng(seed)
    learner = learner or TwoRateLearner()
    plan = plan or protocol()
    places = targets()
    rows, paths = [], {}
    for n, (block, perturbation) in enumerate(plan, start=1):
        field = 1.0 if perturbation == "curl" else 0.0
        k = (n - 1) % len(places)
        target = places[k]
        t, hand = reach_path(target, bow * (field - learner.estimate) * (1 + 0.1 * rng.normal()), rng)
        m = reach_metrics(Reach(t, hand, HOME, target, go_time=0.1, hit=True))
        rows.append({"block": block, "trial": n, "target_deg": 360.0 * k / len(places),
                     "perturbation": perturbation, **m.as_dict(), "hit": bool(rng.random() > 0.05)})
        paths[n] = hand
        learner.update(field - learner.estimate)
    return rows, paths
