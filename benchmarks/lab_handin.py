"""A class's lab runs handed in at the same moment: how long after the last one the server has verified them all.

    python benchmarks/lab_handin.py                        # 30 students, 5 repeats, and where the clerk's time goes
    python benchmarks/lab_handin.py --students 30 --repeats 7 --json

The issue's bar (issue 50): the server verifies 30 lab runs handed in at the same moment within 2 s of the last
one. The runs are what a class's browsers hand in after the ``lesson`` lab: made before anything is timed, each
``LabSession(..., sine="arm")`` (the browser's run: ``labengine.js`` plays it bit for bit) of the ``lesson`` preset
on a person's clock (``lab_config(person=True)``, as ``/api/labplan`` serves it), played by the adapting bot and
relabelled as a person's (``driven="keyboard"``, the student's name), each on its own seed so that each is its own
run (about 110 KB each).

Each repeat is a new class (``armgame class serve`` in its own process, a new temporary folder, the lesson's curve),
the students joined one by one first. Then every student's thread, its connection to the server already open,
posts its run to ``/api/handin`` at one moment. The figure is the time from the last request sent (its body
written to the socket) to the last answer; the time from the first request sent is printed beside it. Every answer
must be ``lab run handed in: in the class curve`` and ``/api/lab`` must then count every student (the benchmark
fails otherwise). The students' threads are in this process and share the machine with the server.

Then, in this process and without HTTP, the clerk's work on the same runs is timed piece by piece, as
``Clerk.lab_run`` does it: reading the replay, its identity, the re-simulation (``LabTask.verify``), the trial
rows for the curve (``trial_rows``), the durable write (``write_run``), and once per batch the class curve the
pages read (``views.lab_curve``); and the clerk's whole batch (``ClerkThread.hand_in_batch``). Figures are medians
over ``--repeats`` with [min-max]; the machine and its load average are printed beside them.
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import statistics
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from class_load import GAME_DATE, Server  # beside this file: benchmarks/ is not a package


def _bench_module(name: str) -> Any:
    """``benchmarks/NAME.py`` by its path: tests/class_server.py shares a name with benchmarks/class_server.py, and
    whichever was imported first in a process would stand in for the other."""
    import importlib.util

    path = Path(__file__).resolve().parent / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"armgame_bench_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_server_bench = _bench_module("class_server")
_load, _spread, machine = _server_bench._load, _server_bench._spread, _server_bench.machine

PROTOCOL = "lesson"
#: The runs' seeds: the first student's, then one more for each.
FIRST_SEED = 1000
IN_THE_CURVE = "lab run handed in: in the class curve"


def make_runs(count: int, first_seed: int = FIRST_SEED) -> list[tuple[str, bytes]]:
    """``count`` browser lab runs of the lesson (``sine="arm"``, a person's clock) by the adapting bot, each on its
    own seed and relabelled as a person's: (name, replay bytes)."""
    from armgame.game.bots import Autopilot
    from armgame.lab.bots import make_lab_bot
    from armgame.lab.presets import preset
    from armgame.lab.record import LabTask
    from armgame.lab.session import LabSession, lab_config
    from armgame.records.replay import Replay

    protocol = preset(PROTOCOL)
    runs = []
    for i in range(count):
        name = f"student {i + 1:02d}"
        session = LabSession(lab_config(protocol, first_seed + i, person=True), protocol, sine="arm")
        Autopilot(session, make_lab_bot("adaptive")).play()
        replay = Replay(session.config, tuple(session.timeline), session.result(), "keyboard", None, name, GAME_DATE,
                        task=LabTask.of(session))
        runs.append((name, replay.to_bytes()))
    return runs


def _join(port: int, code: str, name: str) -> str:
    req = urllib.request.Request(f"http://127.0.0.1:{port}/api/join", method="POST",
                                 data=json.dumps({"code": code, "name": name}).encode(),
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=30) as r:
        return str(json.loads(r.read())["token"])


def one_class(runs: list[tuple[str, bytes]]) -> dict[str, Any]:
    """A new class, its students joined, then every run posted at one moment: the figures of that moment."""
    with tempfile.TemporaryDirectory(prefix="armgame-lab-handin-") as tmp:
        server = Server(Path(tmp) / "class")
        try:
            tokens = [_join(server.port, server.code, name) for name, _ in runs]
            ready = threading.Barrier(len(runs) + 1)
            records: list[dict[str, Any]] = [{} for _ in runs]

            def student(i: int) -> None:
                connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=60)
                connection.connect()
                headers = {"Content-Type": "application/json", "Authorization": f"Bearer {tokens[i]}",
                           "X-Armgame-Code": server.code}
                ready.wait()
                connection.request("POST", "/api/handin", runs[i][1], headers)
                sent = time.perf_counter()
                response = connection.getresponse()
                body = response.read()
                records[i] = {"sent": sent, "answered": time.perf_counter(), "status": response.status,
                              "message": json.loads(body).get("message", json.loads(body).get("error"))}
                connection.close()

            threads = [threading.Thread(target=student, args=(i,), daemon=True) for i in range(len(runs))]
            for t in threads:
                t.start()
            cpu0 = server.cpu_seconds()
            ready.wait()
            began = time.perf_counter()
            for t in threads:
                t.join(120)
            cpu1 = server.cpu_seconds()
            with urllib.request.urlopen(f"http://127.0.0.1:{server.port}/api/lab", timeout=30) as r:
                lab = json.loads(r.read())
        finally:
            server.stop()
    wrong = [r for r in records if r.get("status") != 200 or r.get("message") != IN_THE_CURVE]
    if wrong or lab["students"] != len(runs):
        raise SystemExit(f"lab_handin: {len(wrong)} of {len(runs)} runs were not taken into the class curve "
                         f"({wrong[:2]}), /api/lab counts {lab['students']}: a bug")
    last_sent = max(r["sent"] for r in records)
    last_answer = max(r["answered"] for r in records)
    return {"after_last_sent_s": last_answer - last_sent, "after_first_sent_s": last_answer - min(r["sent"] for r in
                                                                                                 records),
            "from_the_moment_s": last_answer - began, "sending_s": last_sent - began,
            "server_cpu_s": None if None in (cpu0, cpu1) else cpu1 - cpu0, "load_average_1min": _load()}


def clerk_pieces(runs: list[tuple[str, bytes]]) -> dict[str, Any]:
    """The clerk's work on ``runs`` in this process, piece by piece as ``Clerk.lab_run`` does it (ms, all runs
    together), and the clerk's whole batch of them (``ClerkThread.hand_in_batch``)."""
    from armgame.classroom import views
    from armgame.classroom.intake import Clerk
    from armgame.classroom.labruns import lab_identity, write_run
    from armgame.classroom.roster import Player, Roster, token_digest
    from armgame.classroom.worker import ClerkThread, HandIn
    from armgame.lab.analysis import trial_rows
    from armgame.lab.record import register
    from armgame.records.replay import Replay

    register()
    pieces = dict.fromkeys(("read", "identity", "verify", "trial_rows", "write"), 0.0)
    with tempfile.TemporaryDirectory(prefix="armgame-lab-clerk-") as tmp:
        os.environ["ARMGAME_CACHE"] = str(Path(tmp) / "cache")  # the teacher's record of the table: not the user's
        try:
            for folder in ("pieces", "clerk"):
                (Path(tmp) / folder).mkdir()
            for name, data in runs:
                t0 = time.perf_counter()
                replay = Replay.from_bytes(data, "the replay")
                t1 = time.perf_counter()
                identity = lab_identity(replay)
                t2 = time.perf_counter()
                ok, _, session = replay.task.verify(replay.config, replay.timeline, replay.result)
                assert ok, "a run made here does not verify"
                t3 = time.perf_counter()
                trial_rows(session)
                t4 = time.perf_counter()
                write_run(Path(tmp) / "pieces", name, replay, identity, True)
                t5 = time.perf_counter()
                for piece, seconds in zip(pieces, (t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4), strict=True):
                    pieces[piece] += seconds
            roster, _ = Roster.open(Path(tmp) / "clerk", None)
            tokens = [f"token-{i:06d}-{'x' * 20}" for i in range(len(runs))]
            for (name, _), token in zip(runs, tokens, strict=True):
                roster.players[name] = Player(name, token_digest(token), GAME_DATE)
            roster.changed(lab=PROTOCOL)  # as a new class is served: the lesson's curve
            roster.reindex()
            clerk = Clerk(Path(tmp) / "clerk", roster)
            worker = ClerkThread(clerk, lambda: None)
            t0 = time.perf_counter()
            outcomes = worker.hand_in_batch([HandIn(token, data) for token, (_, data) in zip(tokens, runs,
                                                                                            strict=True)])
            t1 = time.perf_counter()
            views.lab_curve(clerk)
            t2 = time.perf_counter()
            worker.stop()
            assert all(isinstance(o, dict) and o["message"] == IN_THE_CURVE for _, o in outcomes), outcomes[:2]
        finally:
            del os.environ["ARMGAME_CACHE"]
    return {**{f"{k}_ms": 1000 * v for k, v in pieces.items()}, "batch_ms": 1000 * (t1 - t0),
            "lab_curve_ms": 1000 * (t2 - t1), "load_average_1min": _load()}


def measure(students: int = 30, repeats: int = 5, say=lambda line: None) -> dict[str, Any]:
    began = time.perf_counter()
    runs = make_runs(students)
    report: dict[str, Any] = {"machine": machine(), "students": students, "repeats": repeats,
                              "run_bytes_mean": statistics.fmean(len(d) for _, d in runs),
                              "seconds_to_make": time.perf_counter() - began}
    say(f"made {students} lab runs of the {PROTOCOL} in {report['seconds_to_make']:.1f} s")
    classes = []
    for repeat in range(repeats):
        classes.append(one_class(runs))
        say(f"  repeat {repeat + 1} of {repeats}: the last answer {classes[-1]['after_last_sent_s']:.2f} s after the "
            f"last run sent, load {_load()}")
    pieces = []
    for repeat in range(repeats):
        pieces.append(clerk_pieces(runs))
        say(f"  the clerk alone, repeat {repeat + 1} of {repeats}: the batch {pieces[-1]['batch_ms']:.0f} ms")
    report["classes"] = classes
    report["clerk"] = pieces
    report["summary"] = {key: _spread([c[key] for c in classes]) for key in classes[0] if key.endswith("_s")}
    report["summary"] |= {key: _spread([p[key] for p in pieces]) for key in pieces[0] if key.endswith("_ms")}
    report["machine"]["load_average_1min_end"] = _load()
    return report


def _fmt(figure: dict[str, float] | None, digits: int = 2) -> str:
    if figure is None:
        return "n/a"
    return f"{figure['median']:.{digits}f} [{figure['min']:.{digits}f}-{figure['max']:.{digits}f}]"


def print_report(report: dict[str, Any]) -> None:
    m, s = report["machine"], report["summary"]
    n = report["students"]
    print(f"{m['cpu']}, {m['cores']} cores, {m['os']}, Python {m['python']}, uvicorn {m['uvicorn']}; load average "
          f"{m['load_average_1min']} at the start, {m['load_average_1min_end']} at the end")
    print(f"{n} lab runs of the {PROTOCOL} ({report['run_bytes_mean'] / 1000:.0f} KB each) posted at one moment; "
          f"median [min-max] of {report['repeats']} classes")
    print(f"  the last answer after the last run sent:  {_fmt(s['after_last_sent_s'])} s")
    print(f"  the last answer after the first run sent: {_fmt(s['after_first_sent_s'])} s")
    print(f"  sending every run took:                   {_fmt(s['sending_s'])} s")
    print(f"  the server's CPU for them:                {_fmt(s['server_cpu_s'])} s")
    print(f"the clerk alone on the {n} runs (no HTTP), ms for all of them:")
    for key, label in (("read_ms", "reading the replays"), ("identity_ms", "their identities"),
                       ("verify_ms", "re-simulating them (LabTask.verify)"), ("trial_rows_ms", "their trial rows"),
                       ("write_ms", "writing them durably"), ("batch_ms", "the clerk's whole batch"),
                       ("lab_curve_ms", "the class curve after it")):
        print(f"  {label + ':':<40} {_fmt(s[key], 0)}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--students", type=int, default=30, help="lab runs handed in at once (default: 30)")
    parser.add_argument("--repeats", type=int, default=5, help="classes, for the spread (default: 5)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if not (1 <= args.students <= 200 and 1 <= args.repeats <= 50):
        parser.error("need 1 <= --students <= 200 and 1 <= --repeats <= 50")
    report = measure(args.students, args.repeats, say=lambda line: print(line, file=sys.stderr, flush=True))
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print_report(report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
