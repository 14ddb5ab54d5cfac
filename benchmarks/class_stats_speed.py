"""The class's statistics recomputed for 100 students, against issue 50's goal: within 100 ms of a new run.

    python benchmarks/class_stats_speed.py [--students 100] [--repeats 20]

What the projector recomputes when a run arrives is ``classroom.views.lab_curve`` (the class curve, then
``lab.classstats.class_stats``: the intervals per trial, each student's numbers, the answer, the generalization by
direction) and its JSON; this times exactly that, on the clerk's state, for the ``lesson`` preset (24 trials) and
the ``generalization`` preset (88 trials, with probes). The students are a few adapting-bot runs (seeds 1 to 4,
each verified once) handed out again under 100 names, each reach's error moved by up to 2 mm so no two students
are alike. The fitted rates are not in it: they belong to the teacher's CSV (a tenth of a second a run, made once
per run and kept). Each figure is the median and the slowest of the repeats after the first (which
imports scipy.stats, once a server's life, and is shown apart); the machine and its load matter, so
the output names both.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import tempfile
import time
from pathlib import Path

from armgame.classroom.intake import Clerk
from armgame.classroom.labruns import LabRun
from armgame.classroom.roster import Roster
from armgame.classroom.views import lab_curve
from armgame.commands import read_lab_replays
from armgame.lab.presets import preset

GOAL_MS = 100.0


def bot_rows(name: str, seed: int, folder: Path) -> list[dict[str, object]]:
    """One adapting bot's run of preset ``name``, recorded, then verified and measured as the class does."""
    import contextlib
    import io

    from armgame.cli import main as armgame
    from armgame.commands.analyze import lab_replay, verified_run

    path = folder / f"{name}-{seed}.json"
    with contextlib.redirect_stdout(io.StringIO()):
        assert armgame(["lab", name, "--bot", "adaptive", "--headless", "--seed", str(seed), "--record",
                        str(path)]) == 0
    return verified_run(path, lab_replay(path))[0]


def clerk_of(name: str, students: int, folder: Path) -> Clerk:
    roster, _ = Roster.open(folder, None)
    roster.changed(lab=name)
    clerk = Clerk(folder, roster)
    runs = [bot_rows(name, seed, folder) for seed in (1, 2, 3, 4)]
    rng = random.Random(0)
    protocol = preset(name)
    for i in range(students):
        rows = [{**r, "max_perpendicular_error_m": float(r["max_perpendicular_error_m"]) + rng.uniform(-2e-3, 2e-3)}
                for r in runs[i % len(runs)]]
        clerk.lab_runs.append(LabRun(f"student {i + 1}", False, protocol, rows, folder / f"{i}.json"))
    return clerk


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    read_lab_replays()
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    for name in ("lesson", "generalization"):
        with tempfile.TemporaryDirectory() as tmp:
            clerk = clerk_of(name, args.students, Path(tmp))
            times = []
            for _ in range(args.repeats + 1):
                start = time.perf_counter()
                data = json.dumps(lab_curve(clerk), ensure_ascii=True, allow_nan=False).encode()
                times.append((time.perf_counter() - start) * 1000)
            first, times = times[0], times[1:]  # the server's first recompute imports scipy.stats, once
            shown = json.loads(data)
            print(f"{name}: {args.students} students, {len(shown['trials'])} trials, {len(data)} bytes: "
                  f"median {statistics.median(times):.1f} ms, slowest {max(times):.1f} ms "
                  f"(goal {GOAL_MS:.0f} ms: {'met' if max(times) < GOAL_MS else 'NOT met'}; "
                  f"the first, imports and all, {first:.0f} ms); "
                  f"{shown['stats']['answer']}")


if __name__ == "__main__":
    main()
