"""A hand-in's passes over its timeline, with the C twins (``records/_ctimeline.c``, ``game/_cevents.c``) and
without them (the Python passes an install without a compiler runs): what a class's server spends on one game.

    python benchmarks/timeline_passes.py            # the model bot's standard game and a student's, 20 repeats
    python benchmarks/timeline_passes.py --repeats 50 --json

Two games of the standard game (seed 10, 60 s): the model bot's (15,000 events, 0.5 MB) and a student's keys
switching every 0.1-0.5 s (``class_speed.student_timeline``, about 200 events). For each, four passes as the
class's clerk runs them: **reading** (``Replay.from_bytes`` of its file), **its identities**
(``identity.game_digests``, both versions), **the batch's columns** (``schedule._event_columns``) and
**writing it again** (``Replay.to_bytes`` of the replay read, as the table writes it). Each pass is timed with
the C passes and with them set aside, alternately within each repeat (so both see the same load), the garbage
collector paused as the clerk pauses it for a batch, and the results are checked equal. Median [min-max] of
``--repeats``, in ms; the ratio is of the medians.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import random
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def games() -> dict[str, bytes]:
    from class_speed import student_timeline

    from armgame.game.bots import Autopilot, make_bot
    from armgame.game.rules import GameConfig
    from armgame.game.session import GameSession
    from armgame.records.replay import Replay

    config = GameConfig(seed=10)
    bot = GameSession(config)
    Autopilot(bot, make_bot("model")).play()
    student = GameSession(config)
    student.play(student_timeline(random.Random(1), config.dt, config.time_limit))
    return {"the model bot's game": Replay.from_session(bot, "bot", "model").to_bytes(),
            "a student's game": Replay.from_session(student, "keyboard").to_bytes()}


def passes(data: bytes) -> dict[str, Callable[[], Any]]:
    from armgame.game.batch import schedule
    from armgame.records import identity
    from armgame.records.replay import Replay

    read = Replay.from_bytes(data)
    codes = {"space": 4, "tab": 5} | {m.key: i for i, m in enumerate(read.config.muscles)}
    return {
        "reading": lambda: Replay.from_bytes(data),
        "its identities": lambda: identity.game_digests(read),
        "the batch's columns": lambda: schedule._event_columns([read.timeline], codes),
        "writing it again": lambda: Replay.from_bytes(data).to_bytes(),
    }


class WithoutC:
    """The C passes set aside for the block: the Python twins run, as without a compiler."""

    def __enter__(self) -> WithoutC:
        from armgame.game.batch import schedule
        from armgame.records import identity, replay

        self.saved = [(identity, "_CTIMELINE", identity._CTIMELINE), (replay, "_CTIMELINE", replay._CTIMELINE),
                      (schedule, "_C_EVENT_COLUMNS", schedule._C_EVENT_COLUMNS)]
        for module, name, _ in self.saved:
            setattr(module, name, None)
        return self

    def __exit__(self, *exc: object) -> None:
        for module, name, value in self.saved:
            setattr(module, name, value)


def timed(call: Callable[[], Any]) -> float:
    """One call's time, the garbage collector paused as the class's clerk pauses it for a batch."""
    gc.collect()
    gc.disable()
    try:
        started = time.perf_counter()
        call()
        return 1000 * (time.perf_counter() - started)
    finally:
        gc.enable()


def same(a: Any, b: Any) -> bool:
    if isinstance(a, tuple) and a and isinstance(a[0], np.ndarray):
        return all(x.dtype == y.dtype and np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    return a == b


def measure(repeats: int) -> dict[str, Any]:
    from armgame.records import identity

    if identity._CTIMELINE is None:
        raise SystemExit("timeline_passes: armgame was installed without its C passes (no compiler): nothing to "
                         "compare")
    out: dict[str, Any] = {"repeats": repeats, "load_average_1min": os.getloadavg()[0] if hasattr(os, "getloadavg")
                           else None, "games": {}}
    for game, data in games().items():
        rows: dict[str, Any] = {}
        for name, call in passes(data).items():
            with_c, without = [], []
            first = call()
            with WithoutC():
                if not same(call(), first):
                    raise SystemExit(f"timeline_passes: {name} of {game} differs without the C passes")
            for _ in range(repeats):
                with_c.append(timed(call))
                with WithoutC():
                    without.append(timed(call))
            rows[name] = {"with_c_ms": with_c, "python_ms": without}
        out["games"][game] = {"bytes": len(data), "passes": rows}
    return out


def spread(values: list[float]) -> str:
    return f"{statistics.median(values):.2f} [{min(values):.2f}-{max(values):.2f}]"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--json", action="store_true", help="the raw figures as JSON")
    args = parser.parse_args(argv)
    if not 1 <= args.repeats <= 10_000:
        parser.error("--repeats: from 1 to 10000")
    report = measure(args.repeats)
    if args.json:
        print(json.dumps(report, indent=1))
        return 0
    print(f"load average {report['load_average_1min']}; median [min-max] of {args.repeats}, ms")
    for game, figures in report["games"].items():
        print(f"{game} ({figures['bytes']:,} bytes)")
        for name, row in figures["passes"].items():
            ratio = statistics.median(row["python_ms"]) / statistics.median(row["with_c_ms"])
            print(f"  {name:<22} Python {spread(row['python_ms']):<22} C {spread(row['with_c_ms']):<22} {ratio:.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
