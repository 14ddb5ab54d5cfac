"""docs/lab.md's "The classic tests": the frames table, measured again (two bot runs, about 20 s). Exit 1 if a row
differs from the page."""

from __future__ import annotations

import re
import sys
from pathlib import Path

from armgame.game.bots import Autopilot, MotorNoise
from armgame.lab.analysis import trial_rows
from armgame.lab.bots import make_lab_bot
from armgame.lab.designs import frames_summary
from armgame.lab.presets import HUMAN_NOISE, preset
from armgame.lab.session import LabSession, lab_config

DOCS = Path(__file__).resolve().parent.parent / "docs" / "lab.md"


def main() -> int:
    text = re.sub(r"\s+", " ", DOCS.read_text(encoding="utf-8"))
    bad = 0
    for frame in ("hand", "joint"):
        protocol = preset("frames")
        session = LabSession(lab_config(protocol, 10), protocol)
        Autopilot(session, make_lab_bot("adaptive", noise=MotorNoise(HUMAN_NOISE, 10), frame=frame)).play()
        (summary,) = frames_summary(session, trial_rows(session))
        row = f"| `{frame}` | {summary['hand']:+.2f} | {summary['joint']:+.2f} | {summary['reads_as']} |"
        ok = row in text
        bad += not ok
        print(("ok   " if ok else "DIFF ") + row)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
