"""The generalization preset's figures in docs/lab.md: the adapting bot's adaptation index by angle from the
trained direction, each direction's baseline subtracted, with the local and the global learner.

    python benchmarks/generalization.py --seeds 10 1 2

Each run is ``armgame lab generalization --bot adaptive --headless --representation R --seed S``, in-process, with
the preset's motor noise (``PRESET_MOTOR_NOISE``). ``benchmarks/lab_claims.py`` checks docs/lab.md's table of them.
"""

from __future__ import annotations

import argparse
import math

from armgame.game.bots import Autopilot, MotorNoise
from armgame.lab.analysis import baseline_offsets, generalization, trial_rows
from armgame.lab.bots import make_lab_bot
from armgame.lab.presets import PRESET_MOTOR_NOISE, preset
from armgame.lab.session import LabSession, lab_config


def run(representation: str, seed: int) -> tuple[list[dict[str, object]], dict[float, float]]:
    protocol = preset("generalization")
    session = LabSession(lab_config(protocol, seed), protocol)
    noise = MotorNoise(PRESET_MOTOR_NOISE["generalization"], seed)
    Autopilot(session, make_lab_bot("adaptive", representation=representation, noise=noise)).play()  # type: ignore[arg-type]
    rows = trial_rows(session)
    return generalization(session, rows), baseline_offsets(session, rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[10, 1, 2])
    args = parser.parse_args()
    for seed in args.seeds:
        for representation in ("local", "global"):
            table, offsets = run(representation, seed)
            cells = " ".join(f"{g['angle_deg']:+g}:{g['index_less_baseline']:+.2f}" for g in table
                             if math.isfinite(float(g["index_less_baseline"])))  # type: ignore[arg-type]
            print(f"seed {seed:>3} {representation:>6}: {cells}")
        print(f"seed {seed:>3} baseline offsets: "
              + " ".join(f"{deg:g}:{value:+.2f}" for deg, value in offsets.items()))


if __name__ == "__main__":
    main()
