"""How strong a field the game arm's muscles can take: the measurement behind the curl preset's b and the
viscous preset's scale, checked against docs/lab.md ("How b was chosen", "The viscous field's scale").

    python benchmarks/curl_scaling.py              # about a minute on one core; exit 1 if a number differs
    python benchmarks/curl_scaling.py --b 1.5 2.5  # other fields: printed, not compared

For each curl field b (N s/m), 16 centre-out reaches (seed 3, the 8 targets twice) by two bots: the
``model`` bot, which knows the arm but not the field, and the same bot with the field in its internal model
(b^ = b, no learning). Printed per bot: hits, the mean and largest maximum perpendicular error (negative:
clockwise), and, for the knowing bot, the field it measured on its reaches (its learner's input). A good b
deflects the model bot by centimetres while the knowing bot still reaches straight. The viscous preset's
matrix is measured the same way, at its scale and at half and 1.5 times it.

Without ``--b`` every number the two paragraphs state is built from the runs and looked for in the doc's
text at its printed precision, as benchmarks/lab_claims.py does ("ok", or "DIFFERS" with the text it
should hold); a bound ("within 0.6 cm") is the measured worst rounded up, so the text never understates it.
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np
from doc_text import Claims

from armgame.game.bots import Autopilot
from armgame.game.muscles import ELBOW_MAX_TORQUE, SHOULDER_MAX_TORQUE
from armgame.lab.bots import make_lab_bot
from armgame.lab.perturbations import Perturbation
from armgame.lab.presets import preset
from armgame.lab.protocol import Block, Protocol
from armgame.lab.session import LabSession, lab_config

SEED, REACHES = 3, 16
CURL_BS = (1.0, 2.0, 3.0, 4.0, 6.0)
CHOSEN_B = 2.0
VISCOUS_SCALES = (1.0, 0.5, 1.5)  # times the preset's matrix
CLAIMS = Claims()
DOC, failures, says = CLAIMS.text, CLAIMS.failures, CLAIMS.says


def perpendicular(session: LabSession, outcome) -> float:
    hx, hy = session.home
    tx, ty = outcome.plan.position
    d = math.hypot(tx - hx, ty - hy)
    ux, uy = (tx - hx) / d, (ty - hy) / d
    side = (np.array(outcome.xs) - hx) * -uy + (np.array(outcome.ys) - hy) * ux
    return float(side[np.argmax(np.abs(side))])


def bound(value: float, digits: int) -> float:
    """A measured worst case as a text may state it: rounded up, so "within X" holds."""
    return math.ceil(value * 10 ** digits - 1e-9) / 10 ** digits


def play(perturbation: Perturbation, knows: bool):
    protocol = Protocol("scaling", (Block("exposure", REACHES, perturbation),))
    session = LabSession(lab_config(protocol, SEED), protocol)
    if perturbation.kind == "curl":
        bot = make_lab_bot("adaptive" if knows else "model")
        if knows:
            learner = bot.curl_learner
            learner.slow, learner.retention_slow = perturbation["b"], 1.0
            learner.rate_slow, learner.rate_fast = 0.0, 0.0
    else:
        bot = make_lab_bot("model")
        if knows:
            bot.known_field = matrix(perturbation)
    Autopilot(session, bot).play()
    errors = np.array([perpendicular(session, o) for o in session.outcomes])
    return session, bot, errors


def matrix(p: Perturbation) -> tuple[tuple[float, float], tuple[float, float]]:
    return (p["b11"], p["b12"]), (p["b21"], p["b22"])


def line(name: str, knows: bool, session: LabSession, errors: np.ndarray) -> str:
    return (f"{name}  {'knows the field' if knows else 'model bot      '}  hits {session.result().hits:2d}/{REACHES}"
            f"  perpendicular error mean {100 * errors.mean():+.2f} cm (size {100 * np.abs(errors).mean():.2f}), "
            f"largest {100 * np.abs(errors).max():.2f} cm")


def speeds_and_torques(session: LabSession, b: float) -> tuple[float, float, float, float]:
    """The fastest reach's peak hand speed (m/s), the mean of the reaches' peaks, and the largest joint torques
    (N m, magnitudes; shoulder, elbow) the curl field exerts over every sample of every reach: J(q)^T b R v,
    with q the arm's posture at the hand shown (no display transform here) and v by central differences."""
    dt, arm = session.config.dt, session.model
    peaks, largest = [], np.zeros(2)
    for o in session.outcomes:
        x, y = np.array(o.xs), np.array(o.ys)
        v = np.stack([np.gradient(x, dt), np.gradient(y, dt)], axis=-1)
        peaks.append(float(np.max(np.hypot(v[:, 0], v[:, 1]))))
        for hand, velocity in zip(np.stack([x, y], axis=-1), v, strict=True):
            force = b * np.array([velocity[1], -velocity[0]])  # F = b [[0, 1], [-1, 0]] v
            largest = np.maximum(largest, np.abs(arm.jacobian(arm.inverse_kinematics(hand)).T @ force))
    return max(peaks), float(np.mean(peaks)), float(largest[0]), float(largest[1])


PARTS = {2: "half", 3: "third", 4: "quarter", 5: "fifth", 6: "sixth"}


def curl() -> None:
    print(f"the curl field, seed {SEED}, {REACHES} reaches:")
    says(f"game's {SHOULDER_MAX_TORQUE:g} and {ELBOW_MAX_TORQUE:g} N m muscles")
    says(f"by measuring the bots on {REACHES} reaches (`python benchmarks/curl_scaling.py`, seed {SEED})")
    pushed, hits, straight, knowing_hits = {}, {}, [], []
    chosen = None
    for b in CURL_BS:
        for knows in (False, True):
            session, bot, errors = play(Perturbation.make("curl", b=b), knows)
            text = line(f"b = {b:4g} N s/m", knows, session, errors)
            if knows:
                text += f"  measured b {np.mean([h[1] for h in bot.history]):.3f}"
                straight.append(np.abs(errors).max())
                knowing_hits.append(session.result().hits)
            else:
                pushed[b], hits[b] = errors, session.result().hits
                if b == CHOSEN_B:
                    chosen = session
            print(text, flush=True)
    small = [b for b in CURL_BS if b < max(CURL_BS)]
    says(f"pushed on average {', '.join(f'{100 * np.abs(pushed[b]).mean():.1f}' for b in small[:-1])} and "
         f"{100 * np.abs(pushed[small[-1]]).mean():.1f} cm sideways at b = "
         f"{', '.join(f'{b:g}' for b in small[:-1])} and {small[-1]:g} N s/m")
    last = max(CURL_BS)
    says(f"at b = {last:g} it " + ("misses every target" if hits[last] == 0 else f"hits {hits[last]} of {REACHES}"))
    every = "hits every target" if min(knowing_hits) == REACHES else f"hits at least {min(knowing_hits)} targets"
    says(f"cancels it with its keys, {every} and stays within {bound(100 * max(straight), 1):.1f} cm of the straight "
         "line at every one of these b")
    e = np.abs(pushed[CHOSEN_B])
    says(f"b = {CHOSEN_B:g} N s/m deflects a reach clearly ({100 * e.mean():.1f} cm on average, up to "
         f"{100 * e.max():.1f} cm)")
    peak, mean_peak, shoulder, elbow = speeds_and_torques(chosen, CHOSEN_B)
    says(f"it pushes with about {CHOSEN_B * peak:.0f} N at the bot's fastest reach ({peak:.2f} m/s at its peak; "
         f"{mean_peak:.3f} m/s on average), and with at most {shoulder:.2f} N m at the shoulder and {elbow:.2f} N m "
         f"at the elbow over the {REACHES} reaches, a "
         f"{PARTS.get(round(SHOULDER_MAX_TORQUE / shoulder), '?')} and a "
         f"{PARTS.get(round(ELBOW_MAX_TORQUE / elbow), '?')} of the muscles' strength")


def viscous() -> None:
    print(f"the viscous preset's matrix, seed {SEED}, {REACHES} reaches (the 8 targets twice):")
    base = np.array(matrix(preset("viscous").blocks[1].perturbation))
    size = {}
    for scale in VISCOUS_SCALES:
        m = scale * base
        p = Perturbation.make("viscous", b11=m[0, 0], b12=m[0, 1], b21=m[1, 0], b22=m[1, 1])
        for knows in (False, True) if scale == 1.0 else (False,):
            session, _, errors = play(p, knows)
            print(line(f"B x {scale:g}", knows, session, errors), flush=True)
            if scale == 1.0 and knows:
                knowing = session.result().hits, np.abs(errors).max()
            elif scale == 1.0:
                model = session.result().hits, errors
            size[scale] = np.abs(errors).mean() if not knows else size.get(scale)
    hits, errors = model
    sides = ("to the right for some directions and to the left for others" if (errors < 0).any() and (errors > 0).any()
             else "all to one side")
    says(f"the `model` bot is pushed {100 * np.abs(errors).mean():.1f} cm on average, up to "
         f"{100 * np.abs(errors).max():.1f} cm, {sides}")
    says(("and hits every target" if hits == REACHES else f"and hits {hits} of {REACHES} targets") +
         "; with the field in its internal model it " +
         ("hits every target" if knowing[0] == REACHES else f"hits {knowing[0]} of {REACHES}") +
         f" and stays within {bound(100 * knowing[1], 2):.2f} cm of the line")
    says(f"Half the scale gives {100 * size[0.5]:.1f} cm on average, 1.5 times {100 * size[1.5]:.1f} cm.")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--b", type=float, nargs="+", help="other curl fields to measure (printed only)")
    args = parser.parse_args()
    if args.b:
        for b in args.b:
            for knows in (False, True):
                session, _, errors = play(Perturbation.make("curl", b=b), knows)
                print(line(f"b = {b:4g} N s/m", knows, session, errors), flush=True)
        return 0
    curl()
    viscous()
    print(f"{len(failures)} of the numbers differ from docs/lab.md")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
