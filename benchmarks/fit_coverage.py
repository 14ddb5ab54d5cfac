"""How often the fit's 95% profile-likelihood intervals hold the true rates, and how often AIC and BIC pick
the model that made the data (armgame/lab/fit.py; the figures are in docs/lab.md, "Fitting the learner").

Two truths, each drawn ``--repeats`` times with fresh Gaussian noise and fitted by both models
(``fit.compare``):

* ``two-rate``: the adapting bot's default rates (A_f 0.59, A_s 0.992, B_f 0.21, B_s 0.02), errors seen
  through a gain of -2 cm per unit of field with 0.1 cm of noise, 112 trials (8 null, 60 field, 4 opposite
  field, 40 field): the schedule of tests/test_lab_fit.py;
* ``one-rate``: A 0.95, B 0.1, the same gain and noise, 88 trials (8 null, 60 field, 20 null).

    python benchmarks/fit_coverage.py --repeats 200     # about 5 minutes on one core; exit 1 if a figure differs

At the doc's draws (``--repeats 200 --seed 1``) each truth's row of docs/lab.md's table is built from the
figures measured and looked for in its text, as benchmarks/lab_claims.py does: a change to the fit that
moves a coverage by one draw in 200 must be written into the doc.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from doc_text import LAB_DOC

from armgame.lab.fit import SYMBOLS, compare
from armgame.lab.learner import TwoRateLearner, simulate

TRUTHS = {
    "two-rate": (TwoRateLearner(0.59, 0.992, 0.21, 0.02), np.r_[np.zeros(8), np.ones(60), -np.ones(4), np.ones(40)],
                 {"retention_fast": 0.59, "retention_slow": 0.992, "rate_fast": 0.21, "rate_slow": 0.02}),
    "one-rate": (TwoRateLearner.single_rate(0.95, 0.1), np.r_[np.zeros(8), np.ones(60), np.zeros(20)],
                 {"retention": 0.95, "rate": 0.1}),
}
GAIN, NOISE = -0.02, 0.001
# How docs/lab.md's table names each truth and its schedule (the numbers in it are measured).
LABELS = {"two-rate": ("two-rate, the bot's default rates", "a counter-field"),
          "one-rate": ("one-rate, A {retention:g}, B {rate:g}", "exposure, washout")}
DOC_RUN = {"repeats": 200, "seed": 1}
DOC = LAB_DOC


def percent(share: float) -> str:
    return "100%" if share == 1.0 else f"{100.0 * share:.1f}%"


def doc_row(truth: str, trials: int, values: dict[str, float], covered: dict[str, float],
            picked: dict[str, float]) -> str:
    label, schedule = LABELS[truth]
    cover = ", ".join(f"{SYMBOLS[name]} {percent(share)}"
                      for name, share in covered.items())
    return (f"| {label.format(**values)} | {trials} errors ({schedule}), gain {100 * GAIN:g} cm, noise "
            f"{100 * NOISE:g} cm | {cover} | AIC {percent(picked['aic'])}, BIC {percent(picked['bic'])} |")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=200)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    compared = vars(args) == DOC_RUN  # other draws give other figures: printed, not compared
    differ = 0
    for truth, (learner, f, values) in TRUTHS.items():
        rng = np.random.default_rng(args.seed)
        clamped = np.zeros(f.size, bool)
        error = simulate(learner, f, clamped)["error"]
        truth_values = {**values, "gain": GAIN}
        covered = dict.fromkeys(truth_values, 0)
        picked = {"aic": 0, "bic": 0}
        start = time.perf_counter()
        for _ in range(args.repeats):
            y = GAIN * error + rng.normal(0.0, NOISE, f.size)
            comparison = compare(f, clamped, y)
            fit = comparison.full if truth == "two-rate" else comparison.simple
            for name, value in truth_values.items():
                low, high = fit.intervals[name]
                covered[name] += low <= value <= high
            for by in picked:
                picked[by] += comparison.preferred(by) == truth
        n = args.repeats
        cover = ", ".join(f"{name} {100.0 * c / n:.1f}%" for name, c in covered.items())
        print(f"{truth} truth, {f.size} trials, {n} draws ({time.perf_counter() - start:.0f} s): 95% profile "
              f"intervals cover {cover}; AIC picks {truth} {100.0 * picked['aic'] / n:.1f}%, BIC "
              f"{100.0 * picked['bic'] / n:.1f}%", flush=True)
        row = doc_row(truth, f.size, values, {k: c / n for k, c in covered.items()},
                      {k: c / n for k, c in picked.items()})
        if compared:
            ok = row in DOC
            differ += not ok
            print(f"  {'ok     ' if ok else 'DIFFERS'} {row}", flush=True)
    if not compared:
        print(f"not compared with docs/lab.md: its table is of --repeats {DOC_RUN['repeats']} --seed {DOC_RUN['seed']}")
        return 0
    print(f"{differ} of the rows differ from docs/lab.md")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
