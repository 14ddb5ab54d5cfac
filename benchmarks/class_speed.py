"""Scoring a class: 1,000 scripted 60 s games one after another against one batch, and their verification.

    python benchmarks/class_speed.py                 # 1,000 games, 100 timed one by one, 3 repeats
    python benchmarks/class_speed.py --games 300 --sample 300 --repeats 5 --json
    python benchmarks/class_speed.py --kernel numpy  # the batch without the compiled kernel

The scripts are seeded random key timelines like a student's: every 0.1-0.5 s one of the
four muscle keys changes (pressed if up, released if down), and one switch in a hundred is
followed by a reset. Every game is the standard one (seed 10, 60 s), as in a class.

"One after another" is ``GameSession(config).play(timeline)`` per game, timed on the first
``--sample`` games and scaled to all of them (the games cost the same to a few per cent), twice:
with the session's compiled loop (where built) and with its Python loop (as an install without a
C compiler runs, and as every game ran before the loop was compiled). "Batched" is
``replay_many`` for all the games, as ``armgame play --headless --script`` plays a class: one
``BatchGameSession(exact=False)``, whose games decided on a knife edge are played again alone
(``--exact``: the exact kernel, bit for bit the single session), timed whole; the results of
the sampled games are checked equal to the sequential ones. Verification is the same comparison
for replays: ``Replay.verify`` one by one against ``records.batch_verify.verify_replays``
(recomputation only, files already read); the last line is the batch's verification over its play,
within each repeat.

Each ratio is measured within one repeat, so both sides see the same machine load; the
spread over repeats is printed beside the median. CPU-time ratios are printed too: on a
loaded machine they move less than wall-clock ones.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import random
import statistics
import sys
import time
from collections.abc import Callable, Iterator

import numpy as np

from armgame.game import session as session_module
from armgame.game.batch import KERNELS, compiled, replay_many
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, InputEvent
from armgame.records.batch_verify import verify_replays
from armgame.records.replay import Replay

CLASS_SEED = 10  # armgame play's default: everyone in the class sees the same targets


def student_timeline(rng: random.Random, dt: float, seconds: float) -> list[InputEvent]:
    """Keys switching every 0.1-0.5 s, a reset after one switch in a hundred."""
    events: list[InputEvent] = []
    held: set[str] = set()
    t = 0.0
    while True:
        t += rng.uniform(0.1, 0.5)
        if t >= seconds:
            return events
        step = round(t / dt)
        key = rng.choice("dfjk")
        events.append(InputEvent(step, key, "up" if key in held else "down"))
        held ^= {key}
        if rng.random() < 0.01:
            events.append(InputEvent(step, "space", "down"))


def timed(work: Callable[[], object]) -> tuple[float, float, object]:
    """(wall s, CPU s, result) of one call."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = work()
    return time.perf_counter() - wall, time.process_time() - cpu, result


def machine() -> dict[str, object]:
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            model = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), model)
    except OSError:
        pass
    return {"cpu": model, "cores": os.cpu_count(), "python": platform.python_version(), "numpy": np.__version__,
            "load_average_1min": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None,
            "compiled_kernel_built": compiled.AVAILABLE}


#: The single session's loops built here: the compiled one first, where it was built.
LOOPS = ("compiled", "python") if session_module._c_game_steps is not None else ("python",)


@contextlib.contextmanager
def single_loop(loop: str) -> Iterator[None]:
    """Sessions made inside run ``loop``: "python" as on an install without a C compiler."""
    built = session_module._c_game_steps
    if loop == "python":
        session_module._c_game_steps = None
    try:
        yield
    finally:
        session_module._c_game_steps = built


def one_repeat(configs: list[GameConfig], timelines: list[list[InputEvent]], sample: int,
               kernel: str | None, exact: bool) -> dict[str, float]:
    n = len(configs)
    scale = n / sample
    out: dict[str, float] = {}
    batch_wall, batch_cpu, batch_results = timed(lambda: replay_many(configs, timelines, exact=exact, kernel=kernel))
    replays = [Replay(c, tuple(t), r, "script", f"student{i:04d}.txt", f"student {i}")
               for i, (c, t, r) in enumerate(zip(configs, timelines, batch_results, strict=True))]
    vbatch_wall, vbatch_cpu, vbatch = timed(lambda: verify_replays(replays, kernel=kernel))
    if not all(ok for ok, _ in vbatch):
        sys.exit("class_speed: batched verification refused a game the batch played: a bug")
    out |= {"batched_wall_s": batch_wall, "verify_batched_wall_s": vbatch_wall,
            "verify_over_play_wall": vbatch_wall / batch_wall, "verify_over_play_cpu": vbatch_cpu / batch_cpu}
    for loop in LOOPS:
        with single_loop(loop):
            # Games one after another (a sample, scaled), then the same games verified as replays one by one.
            seq_wall, seq_cpu, seq_results = timed(lambda: [GameSession(c).play(t) for c, t in
                                                            zip(configs[:sample], timelines[:sample], strict=True)])
            vseq_wall, vseq_cpu, vseq = timed(lambda: [r.verify() for r in replays[:sample]])
        if batch_results[:sample] != seq_results:
            sys.exit(f"class_speed: the batch and the single sessions ({loop} loop) disagree: a bug")
        if vbatch[:sample] != vseq:
            sys.exit(f"class_speed: batched verification disagrees with Replay.verify ({loop} loop): a bug")
        out |= {
            f"sequential_{loop}_wall_s": seq_wall * scale, f"ratio_{loop}_wall": seq_wall * scale / batch_wall,
            f"ratio_{loop}_cpu": seq_cpu * scale / batch_cpu,
            f"verify_sequential_{loop}_wall_s": vseq_wall * scale,
            f"verify_ratio_{loop}_wall": vseq_wall * scale / vbatch_wall,
            f"verify_ratio_{loop}_cpu": vseq_cpu * scale / vbatch_cpu,
        }
    out["mean_score"] = float(np.mean([r.score for r in batch_results]))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--games", type=int, default=1000, help="games in the class (default: 1000)")
    parser.add_argument("--sample", type=int, default=100,
                        help="games timed one after another, scaled to --games (default: 100)")
    parser.add_argument("--seconds", type=float, default=60.0, help="length of each game (default: 60)")
    parser.add_argument("--repeats", type=int, default=3, help="repeats, for the spread (default: 3)")
    parser.add_argument("--exact", action="store_true",
                        help="play the batch with the exact kernel (verification runs as armgame verify does)")
    parser.add_argument("--kernel", choices=[k for k in KERNELS if k], default=None,
                        help="the batch's kernel (default: compiled where built, else numpy)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if not (1 <= args.sample <= args.games <= 100_000 and 1 <= args.repeats <= 20 and 0 < args.seconds <= 600):
        parser.error("need 1 <= --sample <= --games <= 100000, 1 <= --repeats <= 20, 0 < --seconds <= 600")
    config = GameConfig(seed=CLASS_SEED, time_limit=args.seconds)
    configs = [config] * args.games
    timelines = [student_timeline(random.Random(i), config.dt, args.seconds) for i in range(args.games)]
    runs = [one_repeat(configs, timelines, args.sample, args.kernel, args.exact) for _ in range(args.repeats)]
    kernel = (args.kernel or ("compiled" if compiled.AVAILABLE else "numpy")) + (" exact" if args.exact else "")

    def summary(key: str) -> dict[str, float]:
        values = [run[key] for run in runs]
        return {"median": statistics.median(values), "min": min(values), "max": max(values)}

    report = {"games": args.games, "sample": args.sample, "kernel": kernel, "seconds": args.seconds,
              "repeats": args.repeats,
              "events_per_game": sum(map(len, timelines)) / args.games, "machine": machine(),
              **{key: summary(key) for key in runs[0]}, "runs": runs}
    if args.json:
        print(json.dumps(report, indent=1))
        return 0
    m = report["machine"]
    print(f"{args.games} scripted {args.seconds:g} s games ({report['events_per_game']:.0f} key events each), "
          f"{args.repeats} repeats; {m['cpu']}, {m['cores']} cores, load {m['load_average_1min']}, "
          f"Python {m['python']}, numpy {m['numpy']}; batch kernel: {kernel}")
    for label, prefix in (("play", ""), ("verify", "verify_")):
        batch = report[f"{prefix}batched_wall_s"]
        print(f"{label:>6}: batched {batch['median']:5.2f} s [{batch['min']:.2f}-{batch['max']:.2f}]")
        for loop in LOOPS:
            seq = report[f"{prefix}sequential_{loop}_wall_s"]
            wall, cpu = report[f"{prefix}ratio_{loop}_wall"], report[f"{prefix}ratio_{loop}_cpu"]
            print(f"        one after another, {loop} loop: {seq['median']:6.1f} s (first {args.sample} timed, "
                  f"scaled); batched is {wall['median']:.1f}x wall [{wall['min']:.1f}-{wall['max']:.1f}], "
                  f"{cpu['median']:.1f}x CPU [{cpu['min']:.1f}-{cpu['max']:.1f}]")
    ratio, cpu = report["verify_over_play_wall"], report["verify_over_play_cpu"]
    print(f"verify / play, batched: {ratio['median']:.2f}x wall [{ratio['min']:.2f}-{ratio['max']:.2f}], "
          f"{cpu['median']:.2f}x CPU [{cpu['min']:.2f}-{cpu['max']:.2f}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
