"""How often the 95% intervals of issue 41's fits hold the truth (docs/lab.md, "The classic tests").

``python benchmarks/trial_fit_coverage.py --repeats 200`` draws fresh noise for each repeat from a known truth and
fits it: the trial-by-trial generalization fit (400 trials, 8 directions, the field on or off at random, an
opposite-direction lobe) and the state-space fit with process noise (350 trials: exposure, a brief counter-field,
washout). It prints each parameter's coverage; the docs quote the numbers of a 200-repeat run.
"""

from __future__ import annotations

import argparse

import numpy as np

from armgame.lab.trialfit import fit_generalization, fit_state_space, simulate_generalization, simulate_state_space

GENERALIZATION_TRUTH = {"a": 0.9, "k": -0.02, "c(0)": 0.2, "c(45)": 0.1, "c(90)": 0.02, "c(135)": 0.0, "c(180)": 0.06}
STATE_SPACE_TRUTH = {"A": 0.97, "B": 0.12, "k": -0.02, "Q": 0.05 ** 2, "R": 0.001 ** 2}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    held = {name: 0 for name in GENERALIZATION_TRUTH}
    held_ss = {name: 0 for name in STATE_SPACE_TRUTH}
    t = GENERALIZATION_TRUTH
    c = [t["c(0)"], t["c(45)"], t["c(90)"], t["c(135)"], t["c(180)"]]
    f_ss = np.concatenate([np.zeros(20), np.ones(200), -np.ones(10), np.zeros(120)])
    clamp = np.zeros(f_ss.size, dtype=bool)
    s = STATE_SPACE_TRUTH
    for repeat in range(args.repeats):
        rng = np.random.default_rng(1000 + repeat)
        target = np.concatenate([rng.permutation(8) for _ in range(50)])
        f = rng.integers(0, 2, target.size).astype(float)
        fit = fit_generalization(target, 8, f, simulate_generalization(rng, target, 8, f, t["a"], c, t["k"], 0.002))
        for name, value in t.items():
            low, high = fit.intervals[name]
            held[name] += low <= value <= high
        y = simulate_state_space(rng, f_ss, clamp, s["A"], s["B"], s["k"], s["Q"], s["R"])
        ss = fit_state_space(f_ss, clamp, y)
        for name, value in s.items():
            low, high = ss.intervals[name]
            held_ss[name] += bool(low <= value <= high)
    n = args.repeats
    print(f"{n} repeats")
    print("trial-by-trial: " + ", ".join(f"{name} {100 * k / n:.1f}%" for name, k in held.items()))
    print("state-space: " + ", ".join(f"{name} {100 * k / n:.1f}%" for name, k in held_ss.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
