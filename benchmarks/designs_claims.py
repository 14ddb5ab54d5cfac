"""docs/lab.md's "The classic tests": the frames table, measured again (two bot runs), and what each run's learner
held at the end of exposure, read by the frames index's calibration (the learner frozen there: about 15 s in all).
Exit 1 if a row or a reading differs from the page."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

from armgame.game.bots import Autopilot, MotorNoise
from armgame.lab.analysis import trial_rows
from armgame.lab.bots import make_lab_bot
from armgame.lab.designs import frames_summary, held_field_indices
from armgame.lab.presets import HUMAN_NOISE, preset
from armgame.lab.session import LabSession, lab_config

DOCS = Path(__file__).resolve().parent.parent / "docs" / "lab.md"


def main() -> int:
    text = re.sub(r"\s+", " ", DOCS.read_text(encoding="utf-8"))
    bad = 0
    held = {}
    for frame in ("hand", "joint"):
        protocol = preset("frames")
        session = LabSession(lab_config(protocol, 10), protocol)
        bot = make_lab_bot("adaptive", noise=MotorNoise(HUMAN_NOISE, 10), frame=frame)
        autopilot = Autopilot(session, bot)
        exposure = next(i for i, b in enumerate(protocol.blocks) if not b.perturbation.is_null)
        through = sum(b.trials for b in protocol.blocks[:exposure + 1])
        while len(bot.matrix_history) < through:  # it has learned from the last exposure trial, and no more
            autopilot.advance(1)
        held[frame] = held_field_indices(protocol, frame, np.asarray(bot.matrix_estimate))
        autopilot.play()
        (summary,) = frames_summary(session, trial_rows(session))
        row = f"| `{frame}` | {summary['hand']:+.2f} | {summary['joint']:+.2f} | {summary['reads_as']} |"
        ok = row in text
        bad += not ok
        print(("ok   " if ok else "DIFF ") + row)
    h, j = held["hand"], held["joint"]
    claim = (f"the hand learner's matrix reads {h['trained', 'hand']:.2f} where it learned and "
             f"{h['test', 'hand']:.2f} at the test posture, the joint learner's {j['trained', 'joint']:.2f} and "
             f"{j['test', 'joint']:.2f}")
    ok = claim in text
    bad += not ok
    print(("ok   " if ok else "DIFF ") + claim)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
