"""How long the lesson's lab takes: the adapting bot's run in a real window, and a person's at the keys.

    python benchmarks/lab_slot.py                  # the lesson preset at 1x, 2x and 4x, SDL's dummy video
    python benchmarks/lab_slot.py --protocol curl --speeds 1 8

The bot's run is measured as a class sees it: the lab window (cards, each reach's path for 1.2 s, the
last screen) paced in real time at 60 frames a second, from the window's opening to the learning curve
on its last screen, at each speed its - and + keys offer. A person's run cannot be measured here, so it
is worked out from the protocol's own timing: per reach, the wait at home (0.5 to 1 s), the reach, the
hold on the target and the path shown after it, with a person's reach taken as 1.5 s (the bot's is
about 0.75 s) and at worst the time-out; the cards are read at the pace a volunteer takes them.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pygame

from armgame.commands.lab import load_protocol_argument
from armgame.game.bots import Autopilot
from armgame.game.session import RealTimeDriver
from armgame.lab.bots import make_lab_bot
from armgame.lab.session import LabSession, lab_config
from armgame.ui.frontend import open_window
from armgame.ui.lab_window import BOT_CARD_SECONDS, FEEDBACK_SECONDS, LabWindow

#: A person's reach with the muscle keys, go cue to the target (s): the reaction and a slow, corrected
#: movement; a volunteer new to the keys misses some (the time-out is the worst case).
PERSON_REACH = 1.5
#: Reading the first card (what to do, the keys) and each block's card, for a volunteer (s).
PERSON_FIRST_CARD, PERSON_BLOCK_CARD = 25.0, 5.0


def bot_run(protocol, seed: int, speed: float) -> tuple[float, float, int]:
    """Wall time of the adapting bot's run in a window (s), its session time (s), and its frames."""
    session = LabSession(lab_config(protocol, seed), protocol)
    screen = open_window((1024, 768))
    window = LabWindow(session, screen, fps=60, driver=RealTimeDriver(Autopilot(session, make_lab_bot("adaptive"))),
                       mode="AUTOPILOT: adaptive")
    window.speed = speed
    limiter = pygame.time.Clock()
    start = last = time.perf_counter()
    frames = 0
    while not window.ended:
        now = time.perf_counter()
        window.frame(now - last)
        last = now
        frames += 1
        limiter.tick(60)
    wall = time.perf_counter() - start
    pygame.display.quit()
    return wall, session.time, frames


def person_estimate(protocol) -> tuple[float, float, float]:
    """A person's run from the protocol's timing (s): typical, worst (every reach timed out) with the mean wait
    at home, and worst with the longest wait at home every trial."""
    delay = sum(protocol.delay) / 2
    typical = protocol.trials * (delay + PERSON_REACH + protocol.hold_time + FEEDBACK_SECONDS)
    worst = protocol.trials * (delay + protocol.timeout + FEEDBACK_SECONDS)
    longest = protocol.trials * (protocol.delay[1] + protocol.timeout + FEEDBACK_SECONDS)
    cards = PERSON_FIRST_CARD + PERSON_BLOCK_CARD * (len(protocol.blocks) - 1)
    return typical + cards, worst + cards, longest + cards


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--protocol", default="lesson")
    parser.add_argument("--seed", type=int, default=10)
    parser.add_argument("--speeds", type=float, nargs="+", default=[1.0, 2.0, 4.0])
    args = parser.parse_args()
    protocol = load_protocol_argument(args.protocol)
    print(f"{protocol.name}: {protocol.trials} trials in {len(protocol.blocks)} blocks; the bot's cards "
          f"{BOT_CARD_SECONDS:g} s, each path {FEEDBACK_SECONDS:g} s, both divided by the speed")
    walls = []
    for speed in args.speeds:
        wall, simulated, frames = bot_run(protocol, args.seed, speed)
        walls.append(wall)
        print(f"  adapting bot at {speed:g}x: {wall:.1f} s in the window ({wall / 60:.2f} min; {simulated:.1f} s "
              f"of reaching, {frames} frames at {frames / wall:.0f} a second)")
    typical, worst = person_estimate(protocol)
    print(f"  a person at the keys (worked out): about {typical:.0f} s ({typical / 60:.1f} min), at most "
          f"{worst:.0f} s ({worst / 60:.1f} min) if every reach times out")
    # The wall times depend on the machine and its load, so they are printed in docs/lab.md's form to copy,
    # not compared; the person's column is the protocol's arithmetic, which tests/test_lab_claims.py checks.
    print(f"docs/lab.md's row: | `{protocol.name}` | {protocol.trials} | {', '.join(f'{w:.0f}' for w in walls)} s | "
          f"{person_cell(protocol)} |")


def person_cell(protocol) -> str:
    """A person's run in docs/lab.md's window-time table."""
    typical, worst, longest = person_estimate(protocol)
    return (f"about {typical / 60:.0f} min, at most {worst / 60:.1f} min (every reach timed out, the mean wait at "
            f"home; {longest / 60:.2f} with the longest)")


if __name__ == "__main__":
    main()
