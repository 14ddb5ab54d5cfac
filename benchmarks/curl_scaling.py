"""How strong a curl field the game arm's muscles can take: the measurement behind the curl preset's b.

    python benchmarks/curl_scaling.py [--b 1 2 3 4 6]

For each b (N s/m), 16 centre-out reaches (seed 3) by two bots: the ``model`` bot, which knows
the arm but not the field, and the same bot with the field in its internal model (b^ = b, no
learning). Printed per bot: hits, the mean and largest maximum perpendicular error (negative:
clockwise), and, for the knowing bot, the field it measured on its reaches (its learner's input).
A good b deflects the model bot by centimetres while the knowing bot still reaches straight.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from armgame.game.bots import Autopilot
from armgame.lab.bots import make_lab_bot
from armgame.lab.protocol import Block, Perturbation, Protocol
from armgame.lab.session import LabSession, lab_config


def perpendicular(session: LabSession, outcome) -> float:
    hx, hy = session.home
    tx, ty = outcome.plan.position
    d = math.hypot(tx - hx, ty - hy)
    ux, uy = (tx - hx) / d, (ty - hy) / d
    side = (np.array(outcome.xs) - hx) * -uy + (np.array(outcome.ys) - hy) * ux
    return float(side[np.argmax(np.abs(side))])


def run(b: float, knows: bool) -> str:
    protocol = Protocol("scaling", (Block("exposure", 16, Perturbation.make("curl", b=b)),))
    session = LabSession(lab_config(protocol, 3), protocol)
    bot = make_lab_bot("adaptive" if knows else "model")
    if knows:
        learner = bot.curl_learner
        learner.slow, learner.retention_slow, learner.rate_slow, learner.rate_fast = b, 1.0, 0.0, 0.0
    Autopilot(session, bot).play()
    errors = np.array([perpendicular(session, o) for o in session.outcomes])
    line = (f"b = {b:4g} N s/m  {'knows the field' if knows else 'model bot      '}  hits {session.result().hits:2d}/16"
            f"  perpendicular error mean {100 * errors.mean():+.2f} cm, largest {100 * np.abs(errors).max():.2f} cm")
    if knows:
        line += f"  measured b {np.mean([h[1] for h in bot.history]):.3f}"
    return line


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--b", type=float, nargs="+", default=[1.0, 2.0, 3.0, 4.0, 6.0])
    for b in parser.parse_args().b:
        for knows in (False, True):
            print(run(b, knows), flush=True)


if __name__ == "__main__":
    main()
