"""What perturbations cost: the game, and the lab's session with no field, a curl field and a rotation.

    python benchmarks/lab_speed.py [--base DIR]

Every case runs the same 60 s busy key timeline (benchmarks/game_speed.py's) headless; the
timings are interleaved and each figure is the fastest of its repeats, so load elsewhere on a
shared machine skews them alike. ``--base DIR`` adds the game as built by another checkout
(e.g. ``git archive`` of the commit before loads existed) and the game as built by this one, each
run in a fresh child process the same way: the game's own loop must not have moved.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.lab.perturbations import Perturbation
from armgame.lab.protocol import Block, Protocol
from armgame.lab.session import LabSession, lab_config

sys.path.insert(0, str(Path(__file__).resolve().parent))
from game_speed import busy_timeline

SECONDS = 60.0
_CHILD = """
import sys, time
sys.path[:0] = [{checkout!r}, {checkout!r} + "/benchmarks"]
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from game_speed import busy_timeline
session = GameSession(GameConfig(time_limit=60.0))
timeline = busy_timeline(session.config.dt, 60.0)
start = time.perf_counter()
session.play(timeline)
print(time.perf_counter() - start)
"""


def _protocol(p: Perturbation) -> Protocol:
    # Trials that never end early (nobody aims at the targets), so every case steps the whole minute.
    return Protocol("bench", (Block("exposure", 40, p),), timeout=10.0)


def cases() -> dict[str, object]:
    return {
        "game": lambda: GameSession(GameConfig(time_limit=SECONDS)),
        "lab, no perturbation": lambda: _lab(Perturbation()),
        "lab, curl field": lambda: _lab(Perturbation.make("curl", b=2.0)),
        "lab, rotation": lambda: _lab(Perturbation.make("rotation", angle=30.0)),
    }


def _lab(p: Perturbation) -> LabSession:
    protocol = _protocol(p)
    return LabSession(lab_config(protocol, 1), protocol)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--base", help="another checkout whose game to time alongside")
    args = parser.parse_args()
    makers = cases()
    timeline = busy_timeline(GameConfig().dt, SECONDS)
    best = {name: float("inf") for name in makers}
    here = str(Path(__file__).resolve().parent.parent)
    children = {"game, child process (this checkout)": here, "game, child process (base)": args.base} \
        if args.base else {}
    best.update({name: float("inf") for name in children})
    for _ in range(args.repeats):
        for name, make in makers.items():
            session = make()
            start = time.perf_counter()
            session.play(timeline, round(SECONDS / session.config.dt))
            best[name] = min(best[name], time.perf_counter() - start)
        for name, checkout in children.items():
            out = subprocess.run([sys.executable, "-c", _CHILD.format(checkout=checkout)], capture_output=True,
                                 text=True, check=True)
            best[name] = min(best[name], float(out.stdout))
    game = best["game"]
    print(json.dumps({name: {"wall_seconds": round(t, 4), "times_real_time": round(SECONDS / t, 1),
                             "cost_vs_game": round(t / game, 3)} for name, t in best.items()}, indent=1))
    # Timings move with the machine and its load, so docs/lab.md's "Cost" takes them from this line, in its
    # words, with the machine named; nothing compares them.
    if children:
        print(f"the game from this checkout and from the base, each in a fresh process, "
              f"{best['game, child process (this checkout)']:.3f} and {best['game, child process (base)']:.3f} s")
    cost = {name: best[f"lab, {name}"] / game for name in ("no perturbation", "rotation", "curl field")}
    slowest = max(best[f"lab, {name}"] for name in cost)
    print(f"the lab's session costs {cost['no perturbation']:.2f} times as much with no perturbation, "
          f"{cost['rotation']:.2f} with a rotation, and {cost['curl field']:.1f} with a curl field; "
          f"{SECONDS / slowest:.0f} times faster than real time at its slowest")


if __name__ == "__main__":
    main()
