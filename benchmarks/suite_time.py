"""How long the README's test command takes, on an idle machine and on a busy one.

    python benchmarks/suite_time.py --out benchmarks/results/suite_time.json   # idle x2, 2 and 4 busy programs
    python benchmarks/suite_time.py --busy 0 --repeats 1                       # one idle run, printed

The README promises a time for ``python -m pytest`` that a newcomer can hold it to. A newcomer's machine is
often busy (a browser, an IDE indexing, another build), so the suite is timed twice over: with nothing else
running, and beside ``--busy`` programs that each keep one core busy (a Python loop each, started before the
suite and stopped after it), which is what a load average of cores + busy looks like to the suite. Each run is
the README's command as a newcomer types it, in a fresh process, from the checkout; the runs are interleaved
(idle, 2 busy, 4 busy, idle, ...) so a host that slows down over the minutes touches every condition. The JSON
keeps every run's wall time, the tests it counted, and the load average before it, beside the machine's facts.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COMMAND = [sys.executable, "-m", "pytest", "-q"]


def spin(stop: multiprocessing.synchronize.Event) -> None:
    """One core kept busy until ``stop`` is set."""
    x = 0
    while not stop.is_set():
        for _ in range(100_000):
            x += 1


def load_average() -> float | None:
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else None


def one_run(busy: int) -> dict[str, object]:
    """The README's test command once, beside ``busy`` spinning processes: its wall time and what it counted."""
    stop = multiprocessing.Event()
    spinners = [multiprocessing.Process(target=spin, args=(stop,), daemon=True) for _ in range(busy)]
    for p in spinners:
        p.start()
    try:
        time.sleep(2 if busy else 0)  # the spinners up to speed before the clock starts
        before = load_average()
        start = time.perf_counter()
        done = subprocess.run(COMMAND, cwd=ROOT, capture_output=True, text=True)
        wall = time.perf_counter() - start
    finally:
        stop.set()
        for p in spinners:
            p.join(10)
    last = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else ""
    counted = {word: int(n) for n, word in re.findall(r"(\d+) (passed|failed|skipped|errors?)", last)}
    if done.returncode != 0:
        raise SystemExit(f"suite_time: the suite failed ({last or done.stderr.strip()[-200:]})")
    return {"busy": busy, "wall_s": round(wall, 1), "load_before": before, "counted": counted}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--busy", type=int, nargs="+", default=[0, 2, 4],
                        help="busy programs beside the suite, one condition each (default: 0 2 4)")
    parser.add_argument("--repeats", type=int, default=2, help="runs of each condition (default: 2)")
    parser.add_argument("--out", type=Path, help="write the runs as JSON here")
    args = parser.parse_args(argv)
    if args.repeats < 1 or any(b < 0 or b > 64 for b in args.busy):
        parser.error("--repeats must be at least 1 and --busy between 0 and 64")
    runs = []
    for repeat in range(args.repeats):
        for busy in args.busy:
            run = one_run(busy)
            runs.append(run)
            print(f"repeat {repeat + 1}, {busy} busy: {run['wall_s']:.1f} s (load before {run['load_before']}), "
                  f"{run['counted']}", flush=True)
    from armgame.bench.run import _cpu_name

    facts = {"processor": _cpu_name(), "cores": os.cpu_count(),
             "python": platform.python_version(), "system": platform.system(),
             "date": time.strftime("%Y-%m-%d")}
    result = {"command": "python -m pytest", "machine": facts, "runs": runs}
    if args.out is not None:
        args.out.write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
