"""The bots' cost with their forward model compiled (``_cbots.c``) and in Python, in one run.

    python benchmarks/bot_speed.py              # 3 interleaved repeats of each case, CPU seconds
    python benchmarks/bot_speed.py --repeats 5

Cases: a 60 s game of the model bot (``armgame play --headless --bot model``), and the lab's
``curl`` preset (120 trials) run by the adapting bot (``armgame lab curl --bot adaptive --headless``).
Each is timed with the compiled loop and with ``InternalModel.predict_in_python``, taking turns within
every repeat; CPU time (``time.process_time``), so the other jobs of a shared machine count less.
Both ways must press the same keys: the script checks the timelines are equal.
"""

from __future__ import annotations

import argparse
import statistics
import time

from armgame.bench.run import machine_info
from armgame.game import bots
from armgame.game.bots import Autopilot, make_bot, play_bot
from armgame.game.rules import GameConfig
from armgame.lab.bots import make_lab_bot
from armgame.lab.presets import preset
from armgame.lab.session import LabSession, lab_config


def game() -> list:
    return play_bot(GameConfig(seed=10), make_bot("model")).timeline


def lab() -> list:
    protocol = preset("curl")
    session = LabSession(lab_config(protocol, 10), protocol)
    Autopilot(session, make_lab_bot("adaptive")).play()
    return session.timeline


def timed(case, compiled: bool) -> tuple[float, list]:
    saved = bots._c_predict
    bots._c_predict = saved if compiled else None
    try:
        start = time.process_time()
        timeline = case()
        return time.process_time() - start, timeline
    finally:
        bots._c_predict = saved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    if bots._c_predict is None:
        raise SystemExit("the compiled forward model was not built (pip install -e . with a C compiler)")
    info = machine_info(None)
    print(f"{info['cpu']}, {info['cores']} cores, load average {info['load']}, Python {info['python']}, "
          f"numpy {info['numpy']}")
    for name, case in (("model bot, 60 s game", game), ("adaptive bot, lab curl (120 trials)", lab)):
        c_times, py_times, ratios = [], [], []
        for _ in range(args.repeats):
            c, c_line = timed(case, True)
            py, py_line = timed(case, False)
            assert c_line == py_line, "the compiled and the Python loop pressed different keys"
            c_times.append(c)
            py_times.append(py)
            ratios.append(py / c)
        print(f"{name}: compiled {min(c_times):.2f} s, Python {min(py_times):.2f} s CPU (fastest of "
              f"{args.repeats}); ratio median {statistics.median(ratios):.1f}x "
              f"[{min(ratios):.1f}-{max(ratios):.1f}]; the same keys both ways")


if __name__ == "__main__":
    main()
