"""The live class's server as a teacher's laptop runs it, under a class's load, on loopback only.

    python benchmarks/class_server.py                           # classes of 30, 100 and 1,000; 3 repeats
    python benchmarks/class_server.py --sizes 30,100 --repeats 5 --json
    python benchmarks/class_server.py --sizes 30 --repeats 1 --sustained 60 --flood 0 --clerk 0 --table-sizes ''
                                                                # a quick look, about 4 s

The default run takes about 12 minutes on the 2-core machine of docs/performance.md (more under other
jobs' load): making the 4,000 games about 30 s, a class of 30 or 100 about 15 s a repeat, a class
of 1,000 about 60 s, the flood 35 s, the clerk alone 15 s and the table's costs 20 s.

The server is ``python -m armgame class serve --folder TMP --host 127.0.0.1 --port P`` in its own
process, a new class in a new temporary folder for every class and repeat. The students are
threads of ``--clients`` other processes (``class_load.py --client``), each student talking
HTTP through the students' own client code (``armgame.classroom.client._request``, whose policy
on a busy class is the one a student's machine has: wait what Retry-After says, at most a minute
in all, then keep the game for later). A class goes through:

1. **joining**: every student joins once, all at the same moment (the lesson starts);
2. **a round's end**: every student hands in one game at the same moment. "The whole class
   handed in within X s" is the time from that moment until the last student has their answer;
3. **sustained**: every student hands in ``ceil(--sustained / class)`` more games (2 at least)
   one after another, as fast as the server takes them; hand-ins per second is the games
   acknowledged over the time until the last answer.

Each hand-in's latency is measured by its client, from the request to the answer, the waits
after a 503 (busy) included; the 503s are counted. Meanwhile a projector keeps the class's
event stream open, as the page does, and asks ``GET /api/standings`` every 0.2 s; its latency
is reported. The server's peak memory is its VmHWM (Linux), else its ``ru_maxrss`` once it has
stopped (other POSIX), else n/a; its CPU time per hand-in is read from /proc where there is one.
At the end of every class the server is stopped with Ctrl-C's signal and its folder is read as
``ScoreTable``: every acknowledged game must be there under its student's name, with its replay
(the benchmark fails otherwise).

The games are the standard game (seed 10, 60 s), distinct, made before anything is timed and
the same on every run: keyboard games whose keys switch every 0.1-0.5 s as in
``class_speed.py`` (about 9 KB each), and one hand-in in twenty (``--bot-share``) the model
bot's game (about 0.5 MB), each let go of at another step near the end so that each is its
own game. The projector's figures and the clients share the machine with the server: on a
2-core machine the clients take a share of it (printed: the clients' CPU seconds).

Then, each ``--repeats`` times:

4. **the flood** (``--flood 100``): a new class where 100 clients, each joined under its own name (valid
   tokens), post forged games (a real game's claimed score raised: it does not reproduce; ten distinct
   ones each, then again) and, one post in four, a replay cut off, as fast as the server answers (no
   wait after a 503, a new connection each), for ``--flood-seconds``; meanwhile ``--flood-honest``
   students hand in their own games one after another, 0.5 s apart, through the students' client. The
   honest hand-ins' latencies (p50, p99, max) are the figure: honest students first;
5. **the clerk alone** (``--clerk 1000``), in this process, no HTTP: that many distinct honest hand-ins,
   then as many forged ones, in the server's batches (``ClerkThread.hand_in_batch``): hand-ins a second and
   the CPU time of each;
6. **the table's cost per hand-in** (``--table-sizes 10,1000,10000``): a batch of 32 games entered
   (``ScoreTable.add_many``, the clerk's write, the replays' files included) into a table already
   holding that many entries, appended to its journal and, for comparison, the whole table rewritten.

Figures are medians over ``--repeats`` with [min-max]; the machine and its load average are printed
beside them.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import os
import platform
import signal
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from class_load import (  # beside this file: benchmarks/ is not a package
    CLASS_SEED,
    FLOOD_HONEST_EVERY,
    GAME_DATE,
    Clients,
    Projector,
    Server,
    make_games,
)


def percentile(values: list[float], q: float) -> float | None:
    """The ``q``-th percentile (linear between the closest ranks), None of nothing."""
    if not values:
        return None
    ordered = sorted(values)
    at = (len(ordered) - 1) * q / 100
    low = math.floor(at)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (at - low)


def tally(records: list[dict[str, Any]], start_at: float) -> dict[str, Any]:
    """A phase's figures from its requests' records."""
    ok = [r for r in records if r["outcome"] == "ok"]
    latencies = [r["latency"] for r in ok]
    last = max((r["end"] for r in records), default=start_at)
    failed: dict[str, int] = {}
    for r in records:
        if r["outcome"] != "ok":
            failed[r["outcome"]] = failed.get(r["outcome"], 0) + 1
    return {"requests": len(records), "acknowledged": len(ok), "seconds": last - start_at,
            "per_second": len(ok) / (last - start_at) if last > start_at else None,
            "p50_s": percentile(latencies, 50), "p99_s": percentile(latencies, 99),
            "max_s": max(latencies, default=None), "busy_503": sum(r["busy"] for r in records),
            "not_acknowledged": failed, "already": sum(bool(r.get("already")) for r in ok),
            "errors": sorted({r["error"] for r in records if "error" in r})[:3]}


def check_folder(folder: Path, acked: dict[int, str], games: list[dict[str, Any]]) -> dict[str, Any]:
    """The class's folder read as a score table: every acknowledged game in it under its student's name, with
    its replay. Raises SystemExit if one is missing."""
    from armgame.records.scores import ScoreTable

    entries, damage = ScoreTable(folder).read()
    if damage is not None:
        raise SystemExit(f"class_server: the class's table is damaged: {damage}")
    kept = {e.game_sha256: e for e in entries}
    missing = [i for i, name in acked.items()
               if games[i]["digest"] not in kept or kept[games[i]["digest"]].name != name
               or not (folder / "replays" / kept[games[i]["digest"]].replay).is_file()]
    if missing:
        raise SystemExit(f"class_server: {len(missing)} acknowledged games are not in {folder} as handed in "
                         f"(games {missing[:10]}): a bug")
    return {"entries": len(entries), "acknowledged_kept": len(acked), "not_acknowledged_but_kept":
            len(entries) - len(acked)}


def one_class(size: int, games: list[dict[str, Any]], args: argparse.Namespace,
              say: Callable[[str], None]) -> dict[str, Any]:
    """One class of ``size`` students from join to the end of the sustained phase; its figures."""
    per_student = max(2, math.ceil(args.sustained / size))
    students = [{"name": f"student {s + 1:04d}", "games": [s] + [size + s * per_student + k
                                                                 for k in range(per_student)]}
                for s in range(size)]
    with tempfile.TemporaryDirectory(prefix="armgame-class-server-") as tmp:
        folder = Path(tmp) / "class"
        server = Server(folder)
        clients = projector = None
        try:
            clients = Clients(min(args.clients, size), f"127.0.0.1:{server.port}", server.code, students,
                              [g["path"] for g in games])
            joined, start, joins_how = clients.phase("join", args.timeout)
            joins = tally(joined, start) | joins_how
            if joins["acknowledged"] != size:
                raise RuntimeError(f"{size - joins['acknowledged']} students could not join: {joins['errors']}")
            projector = Projector(server.port)
            cpu0 = server.cpu_seconds()
            burst_records, start, burst_how = clients.phase("burst", args.timeout)
            burst = tally(burst_records, start) | burst_how
            cpu1 = server.cpu_seconds()
            sustained_records, start, sustained_how = clients.phase("sustained", args.timeout)
            sustained = tally(sustained_records, start) | sustained_how
            cpu2 = server.cpu_seconds()
            projector.stop()
            peak = server.peak_rss()
        finally:
            if projector is not None:
                projector.stop()
            if clients is not None:
                clients.close()
            status = server.stop()
        peak = peak if peak is not None else server.rusage_maxrss
        notices = server.notices()
        acked = {r["game"]: r["name"] for r in burst_records + sustained_records if r["outcome"] == "ok"}
        folder_check = check_folder(folder, acked, games)
    handins = burst["acknowledged"] + sustained["acknowledged"]
    server_cpu = None if None in (cpu0, cpu1, cpu2) else {
        "burst_s": cpu1 - cpu0, "sustained_s": cpu2 - cpu1, "ms_per_handin": 1000 * (cpu2 - cpu0) / max(1, handins)}
    result = {"students": size, "games_per_student_sustained": per_student, "joins": joins, "burst": burst,
              "sustained": sustained,
              "standings": {"samples": len(projector.latencies), "p50_ms": _ms(percentile(projector.latencies, 50)),
                            "p99_ms": _ms(percentile(projector.latencies, 99)),
                            "max_ms": _ms(max(projector.latencies, default=None)),
                            "refused": len(projector.failures), "failures": projector.failures[:3],
                            "events_received": projector.events},
              "server_peak_rss_mb": None if peak is None else peak / 2**20, "server_cpu": server_cpu,
              "server_exit": status, "server_notices": dict(sorted(notices.items(), key=lambda kv: -kv[1])[:5]),
              "folder": folder_check, "load_average_1min": _load()}
    say(f"  class of {size}: whole class in {burst['seconds']:.2f} s, sustained "
        f"{sustained['per_second'] or 0:.1f} hand-ins/s, {burst['busy_503'] + sustained['busy_503']} x 503, "
        f"server peak {result['server_peak_rss_mb'] or float('nan'):.0f} MB, load {_load()}")
    return result


def forge(paths: list[str], folder: Path) -> list[str]:
    """Each game with its claimed score raised by 7 (a forgery: it does not reproduce), written to ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    forged = []
    for path in paths:
        data = json.loads(Path(path).read_bytes())
        data["result"]["score"] += 7
        target = folder / Path(path).name
        target.write_bytes(json.dumps(data, indent=1, sort_keys=True).encode())
        forged.append(str(target))
    return forged


def flood_class(flooders: int, honest: int, seconds: float, games: list[dict[str, Any]], forged: list[str],
                args: argparse.Namespace, say: Callable[[str], None]) -> dict[str, Any]:
    """``flooders`` joined clients posting forged and malformed games as fast as they can for ``seconds``, while
    ``honest`` students hand in their games one after another; the honest hand-ins' latencies."""
    per_flooder = max(1, len(forged) // flooders)
    paths = [g["path"] for g in games] + forged
    students = [{"name": f"flooder {k:03d}", "flooder": True, "until": seconds,
                 "games": [len(games) + (k * per_flooder + j) % len(forged) for j in range(per_flooder)]}
                for k in range(flooders)]
    per_honest = math.ceil(seconds / FLOOD_HONEST_EVERY) + 1
    students += [{"name": f"student {h:03d}", "until": seconds,
                  "games": [h * per_honest + j for j in range(per_honest)]} for h in range(honest)]
    if honest * per_honest > len(games):
        raise SystemExit(f"class_server: the flood needs {honest * per_honest} honest games, {len(games)} were made")
    with tempfile.TemporaryDirectory(prefix="armgame-class-flood-") as tmp:
        folder = Path(tmp) / "class"
        server = Server(folder)
        clients = None
        try:
            clients = Clients(min(args.clients, len(students)), f"127.0.0.1:{server.port}", server.code, students,
                              paths)
            joined, _, _ = clients.phase("join", args.timeout)
            if sum(r["outcome"] == "ok" for r in joined) != len(students):
                raise RuntimeError(f"the flood's clients could not all join: {tally(joined, 0)['errors']}")
            load = _load()
            cpu0 = server.cpu_seconds()
            records, start, how = clients.phase("flood", seconds + args.timeout)
            cpu1 = server.cpu_seconds()
            peak = server.peak_rss()
        finally:
            if clients is not None:
                clients.close()
            status = server.stop()
        folder_check = check_folder(folder, {r["game"]: r["name"] for r in records
                                             if "flooder" not in r and r["outcome"] == "ok"}, games)
    posted: dict[str, int] = {}
    for r in records:
        for key, count in r.get("counts", {}).items():
            posted[key] = posted.get(key, 0) + count
    honest_records = [r for r in records if "flooder" not in r]
    figures = tally(honest_records, start)
    handled = sum(posted.values()) + figures["requests"] + figures["busy_503"]
    result = {"flooders": flooders, "honest": honest, "seconds": seconds, "honest_handins": figures,
              "flood_answers": dict(sorted(posted.items())), "flood_posts_per_s": sum(posted.values()) / seconds,
              "server_cpu_s": None if None in (cpu0, cpu1) else cpu1 - cpu0,
              "server_cpu_ms_per_request": None if None in (cpu0, cpu1) else 1000 * (cpu1 - cpu0) / max(1, handled),
              "server_peak_rss_mb": None if peak is None else peak / 2**20, "server_exit": status,
              "clients_cpu_s": how["clients_cpu_s"], "folder": folder_check, "load_average_1min": load}
    say(f"  flood of {flooders}: honest p50 {figures['p50_s'] or 0:.2f} s, p99 {figures['p99_s'] or 0:.2f} s, "
        f"max {figures['max_s'] or 0:.2f} s over {figures['acknowledged']} hand-ins; the flooders posted "
        f"{result['flood_posts_per_s']:.0f} a second ({result['flood_answers']}), load {_load()}")
    return result


def clerk_rate(games: list[dict[str, Any]], forged: list[str], count: int) -> dict[str, Any]:
    """The clerk alone, in this process (no HTTP): ``count`` distinct honest hand-ins, then ``count`` forged ones,
    in the server's batches (``ClerkThread.hand_in_batch``, ``BATCH`` at a time); CPU and wall time per hand-in."""
    from armgame.classroom.bounds import BATCH
    from armgame.classroom.intake import Clerk
    from armgame.classroom.roster import Player, Roster, token_digest
    from armgame.classroom.worker import ClerkThread, HandIn

    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="armgame-class-clerk-") as tmp:
        os.environ["ARMGAME_CACHE"] = str(Path(tmp) / "cache")  # the teacher's record of the table: not the user's
        roster, _ = Roster.open(Path(tmp), CLASS_SEED)
        tokens = []
        for i in range(count):
            tokens.append(f"token-{i:06d}-{'x' * 20}")
            roster.players[f"s{i}"] = Player(f"s{i}", token_digest(tokens[-1]), GAME_DATE)
        roster.save()
        roster.reindex()
        clerk = Clerk(Path(tmp), roster)
        worker = ClerkThread(clerk, lambda: None)  # its batches run here, in this thread, as its own would
        for kind, paths in (("honest", [g["path"] for g in games[:count]]),
                            ("forged", forged[:count])):
            bodies = [Path(p).read_bytes() for p in paths]
            if not bodies:
                continue
            wall0, cpu0 = time.perf_counter(), time.process_time()
            answered: dict[str, int] = {}
            for lo in range(0, len(bodies), BATCH):
                batch = [HandIn(tokens[i], bodies[i]) for i in range(lo, min(len(bodies), lo + BATCH))]
                for _, outcome in worker.hand_in_batch(batch):
                    key = "ok" if isinstance(outcome, dict) else str(getattr(outcome, "status", type(outcome)))
                    answered[key] = answered.get(key, 0) + 1
            wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
            out[kind] = {"handins": len(bodies), "answers": answered, "wall_s": wall, "cpu_s": cpu,
                         "per_s": len(bodies) / wall, "cpu_ms_per_handin": 1000 * cpu / len(bodies)}
        worker.stop()
        del os.environ["ARMGAME_CACHE"]
    out["load_average_1min"] = _load()
    return out


def table_costs(games: list[dict[str, Any]], sizes: list[int], batches: int = 5, batch: int = 32) -> dict[str, Any]:
    """The cost of entering a batch of ``batch`` games (``ScoreTable.add_many``, the clerk's write) into a table that
    already holds each of ``sizes`` entries: appended to the table's journal, and, for comparison, the whole
    table rewritten (the write before the journal). Per hand-in, median [min-max] of ``batches`` batches."""
    import inspect
    import uuid

    from armgame.records.replay import Replay
    from armgame.records.scores import ScoreTable, table_bytes

    journaled = "journal" in inspect.signature(ScoreTable.add_many).parameters
    replays = [Replay.from_bytes(Path(g["path"]).read_bytes()) for g in games[:2 * batches * batch + 1]]
    out: dict[str, Any] = {"batch": batch, "batches": batches, "sizes": {}}
    with tempfile.TemporaryDirectory(prefix="armgame-class-table-") as tmp:
        os.environ["ARMGAME_CACHE"] = str(Path(tmp) / "cache")
        try:
            for size in sizes:
                row = {}
                for how in ("journal", "rewrite") if journaled else ("rewrite",):
                    folder = Path(tmp) / f"{how}-{size}"
                    table = ScoreTable(folder, warn=lambda line: None)
                    table.new(CLASS_SEED)
                    (first,) = table.add_many([dataclasses.replace(replays[0], player="seed")])
                    # The table of ``size`` entries: the first one's line repeated, each its own id, replay and game.
                    entries = [dataclasses.replace(first, id=uuid.uuid4().hex, name=f"p{i % 997}",
                                                   replay_sha256=f"{i:064x}", game_sha256=f"{i + 1:064x}",
                                                   entered=i + 1) for i in range(size)]
                    (folder / "scores.json").write_bytes(table_bytes(entries, CLASS_SEED, size + 1))
                    table = ScoreTable(folder, warn=lambda line: None)
                    times = []
                    for b in range(batches):
                        part = [dataclasses.replace(r, player=f"q{j}") for j, r in
                                enumerate(replays[1 + b * batch:1 + (b + 1) * batch])]
                        began = time.perf_counter()
                        got = table.add_many(part, journal=True) if how == "journal" else table.add_many(part)
                        times.append((time.perf_counter() - began) / len(part))
                        assert all(not isinstance(g, Exception) for g in got), got
                    row[how] = {"ms_per_handin": 1000 * statistics.median(times), "min_ms": 1000 * min(times),
                                "max_ms": 1000 * max(times)}
                out["sizes"][str(size)] = row
        finally:
            del os.environ["ARMGAME_CACHE"]
    out["load_average_1min"] = _load()
    return out


def _ms(seconds: float | None) -> float | None:
    return None if seconds is None else 1000 * seconds


def _load() -> float | None:
    return round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None


def machine() -> dict[str, Any]:
    model = platform.processor() or platform.machine()
    with contextlib.suppress(OSError), open("/proc/cpuinfo") as f:
        model = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), model)
    import starlette
    import uvicorn

    return {"cpu": model, "cores": os.cpu_count(), "os": platform.platform(), "python": platform.python_version(),
            "uvicorn": uvicorn.__version__, "starlette": starlette.__version__, "load_average_1min": _load()}


# ------------------------------------------------------------------ the whole run

#: The figures summarised over repeats: (label, path into a class's result).
FIGURES = (
    ("joined_s", ("joins", "seconds")),
    ("whole_class_s", ("burst", "seconds")),
    ("burst_p50_s", ("burst", "p50_s")),
    ("burst_p99_s", ("burst", "p99_s")),
    ("burst_503", ("burst", "busy_503")),
    ("sustained_per_s", ("sustained", "per_second")),
    ("sustained_p50_s", ("sustained", "p50_s")),
    ("sustained_p99_s", ("sustained", "p99_s")),
    ("sustained_503", ("sustained", "busy_503")),
    ("standings_p50_ms", ("standings", "p50_ms")),
    ("standings_p99_ms", ("standings", "p99_ms")),
    ("standings_refused", ("standings", "refused")),
    ("server_peak_rss_mb", ("server_peak_rss_mb",)),
    ("server_cpu_ms_per_handin", ("server_cpu", "ms_per_handin")),
)


def summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for label, path in FIGURES:
        values = []
        for run in runs:
            value: Any = run
            for key in path:
                value = None if value is None else value.get(key)
            if value is not None:
                values.append(float(value))
        out[label] = {"median": statistics.median(values), "min": min(values), "max": max(values)} if values \
            else None
    out["real_load_per_s"] = {key: runs[0]["students"] / 60 for key in ("median", "min", "max")}
    out["not_acknowledged"] = sum(sum(r[p]["not_acknowledged"].values()) for r in runs for p in ("burst", "sustained"))
    return out


def measure(sizes: list[int], repeats: int = 3, sustained: int = 600, clients: int = 4, bot_share: float = 0.05,
            seed: int = 0, timeout: float = 300.0, say: Callable[[str], None] = lambda line: None,
            flooders: int = 0, flood_honest: int = 10, flood_seconds: float = 20.0, clerk: int = 0,
            table_sizes: list[int] | None = None) -> dict[str, Any]:
    """The figures for each class size (see the module docstring), then the flood (``flooders`` > 0), the clerk
    alone (``clerk`` hand-ins) and the table's cost per hand-in at ``table_sizes``; ``say`` gets progress lines."""
    args = argparse.Namespace(sustained=sustained, clients=clients, timeout=timeout)
    needed = max([size + size * max(2, math.ceil(sustained / size)) for size in sizes]
                 + [flood_honest * (math.ceil(flood_seconds / FLOOD_HONEST_EVERY) + 1) if flooders else 0,
                    clerk, 2 * 5 * 32 + 1 if table_sizes else 0])
    forgeries = max(10 * flooders, clerk)
    report: dict[str, Any] = {"machine": machine(), "repeats": repeats, "sustained": sustained, "clients": clients,
                              "bot_share": bot_share, "seed": seed, "classes": {}}
    with tempfile.TemporaryDirectory(prefix="armgame-class-games-") as tmp:
        began = time.perf_counter()
        games = make_games(Path(tmp), needed + forgeries, bot_share, seed)
        games, forged = games[:needed], forge([g["path"] for g in games[needed:]], Path(tmp) / "forged")
        keyboard = [g["bytes"] for g in games if not g["bot"]]
        bots = [g["bytes"] for g in games if g["bot"]]
        report["games"] = {"made": len(games), "seconds_to_make": time.perf_counter() - began, "bots": len(bots),
                           "forged": len(forged),
                           "keyboard_bytes_mean": statistics.fmean(keyboard) if keyboard else None,
                           "bot_bytes_mean": statistics.fmean(bots) if bots else None,
                           "keyboard_score_mean": statistics.fmean(g["score"] for g in games if not g["bot"])
                           if keyboard else None}
        say(f"made {len(games)} games ({len(bots)} bots') and {len(forged)} forgeries in "
            f"{report['games']['seconds_to_make']:.0f} s")
        for size in sizes:
            runs = []
            for repeat in range(repeats):
                say(f"class of {size}, repeat {repeat + 1} of {repeats}")
                runs.append(one_class(size, games, args, say))
            report["classes"][str(size)] = {**summary(runs), "runs": runs}
        if flooders:
            runs = []
            for repeat in range(repeats):
                say(f"flood of {flooders} clients, {flood_honest} honest students, repeat {repeat + 1} of {repeats}")
                runs.append(flood_class(flooders, flood_honest, flood_seconds, games, forged, args, say))
            report["flood"] = {"p50_s": _spread([r["honest_handins"]["p50_s"] for r in runs]),
                               "p99_s": _spread([r["honest_handins"]["p99_s"] for r in runs]),
                               "max_s": _spread([r["honest_handins"]["max_s"] for r in runs]), "runs": runs}
        if clerk:
            say(f"the clerk alone: {clerk} honest hand-ins, then {clerk} forged")
            report["clerk"] = [clerk_rate(games, forged, clerk) for _ in range(repeats)]
        if table_sizes:
            say(f"the table's cost per hand-in at {', '.join(map(str, table_sizes))} entries")
            report["table"] = [table_costs(games, table_sizes) for _ in range(repeats)]
    report["machine"]["load_average_1min_end"] = _load()
    return report


def _spread(values: list[float | None]) -> dict[str, float] | None:
    known = [v for v in values if v is not None]
    return {"median": statistics.median(known), "min": min(known), "max": max(known)} if known else None


def _fmt(figure: dict[str, float] | None, scale: float = 1.0, digits: int = 2) -> str:
    if figure is None:
        return "n/a"
    if figure["min"] == figure["max"]:
        return f"{figure['median'] * scale:.{digits}f}"
    return (f"{figure['median'] * scale:.{digits}f} [{figure['min'] * scale:.{digits}f}-"
            f"{figure['max'] * scale:.{digits}f}]")


def print_report(report: dict[str, Any]) -> None:
    m, g = report["machine"], report["games"]
    print(f"{m['cpu']}, {m['cores']} cores, {m['os']}, Python {m['python']}, uvicorn {m['uvicorn']}, starlette "
          f"{m['starlette']}; load average {m['load_average_1min']} at the start, {m['load_average_1min_end']} at "
          f"the end")
    print(f"games: keyboard {g['keyboard_bytes_mean'] or 0:,.0f} bytes on average, {g['bots']} of {g['made']} "
          f"the bot's ({g['bot_bytes_mean'] or 0:,.0f} bytes); the students in {report['clients']} client processes "
          f"(fewer for fewer students); median [min-max] of {report['repeats']}")
    rows = [
        ("the class joined (all at once), s", "joined_s", 1, 2),
        ("round's end: the whole class handed in within, s", "whole_class_s", 1, 2),
        ("  a hand-in's latency p50, s", "burst_p50_s", 1, 2),
        ("  a hand-in's latency p99, s", "burst_p99_s", 1, 2),
        ("  503s (busy) seen", "burst_503", 1, 0),
        ("sustained: hand-ins per second", "sustained_per_s", 1, 1),
        ("  (one game a student a minute would be)", "real_load_per_s", 1, 1),
        ("  a hand-in's latency p50, s", "sustained_p50_s", 1, 2),
        ("  a hand-in's latency p99, s", "sustained_p99_s", 1, 2),
        ("  503s (busy) seen", "sustained_503", 1, 0),
        ("GET /api/standings under that load, p50 ms", "standings_p50_ms", 1, 1),
        ("GET /api/standings under that load, p99 ms", "standings_p99_ms", 1, 1),
        ("  of them refused or failed", "standings_refused", 1, 0),
        ("server's peak memory (VmHWM), MB", "server_peak_rss_mb", 1, 0),
        ("server's CPU per hand-in, ms", "server_cpu_ms_per_handin", 1, 1),
    ]
    sizes = list(report["classes"])
    width = max(len(r[0]) for r in rows)
    print(f"{'students':<{width}}  " + "  ".join(f"{s:>24}" for s in sizes))
    for label, key, scale, digits in rows:
        print(f"{label:<{width}}  " + "  ".join(f"{_fmt(report['classes'][s][key], scale, digits):>24}"
                                                for s in sizes))
    if "flood" in report:
        f = report["flood"]
        run = f["runs"][0]
        print(f"flood: {run['flooders']} clients posting forged and malformed games as fast as they can for "
              f"{run['seconds']:g} s, {run['honest']} honest students handing in a game every "
              f"{FLOOD_HONEST_EVERY:g} s: an honest hand-in's latency p50 {_fmt(f['p50_s'])} s, p99 "
              f"{_fmt(f['p99_s'])} s, max {_fmt(f['max_s'])} s")
        for r in f["runs"]:
            h = r["honest_handins"]
            print(f"  {h['acknowledged']} of {h['requests']} honest hand-ins acknowledged ({h['busy_503']} x 503); "
                  f"the flood posted {r['flood_posts_per_s']:.0f} a second, answered {r['flood_answers']}; server CPU "
                  f"{r['server_cpu_ms_per_request'] or float('nan'):.2f} ms a request, peak "
                  f"{r['server_peak_rss_mb'] or float('nan'):.0f} MB; clients' CPU {r['clients_cpu_s']:.0f} s; load "
                  f"{r['load_average_1min']}")
    for c in report.get("clerk", []):
        print("the clerk alone (no HTTP): " + "; ".join(
            f"{kind} {c[kind]['per_s']:.0f} hand-ins a second, {c[kind]['cpu_ms_per_handin']:.2f} ms of CPU each "
            f"({c[kind]['answers']})" for kind in ("honest", "forged")) + f"; load {c['load_average_1min']}")
    for t in report.get("table", []):
        print(f"entering a batch of {t['batch']}, ms per hand-in (median [min-max] of {t['batches']} batches): " +
              "; ".join(f"{size} entries: " + ", ".join(
                  f"{how} {v['ms_per_handin']:.2f} [{v['min_ms']:.2f}-{v['max_ms']:.2f}]" for how, v in row.items())
                  for size, row in t["sizes"].items()) + f"; load {t['load_average_1min']}")
    for s in sizes:
        c = report["classes"][s]
        run = c["runs"][0]
        print(f"class of {s}: {run['burst']['acknowledged']} + {run['sustained']['acknowledged']} hand-ins a repeat "
              f"({run['games_per_student_sustained']} a student sustained), not acknowledged in all: "
              f"{c['not_acknowledged']}; every acknowledged game found in the folder; clients' CPU "
              f"{run['burst']['clients_cpu_s'] + run['sustained']['clients_cpu_s']:.1f} s in the first repeat")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="30,100,1000", help="class sizes, comma-separated (default: 30,100,1000)")
    parser.add_argument("--repeats", type=int, default=3, help="repeats of each class, for the spread (default: 3)")
    parser.add_argument("--sustained", type=int, default=600,
                        help="hand-ins of the sustained phase, shared out (2 a student at least; default: 600)")
    parser.add_argument("--clients", type=int, default=4, help="client processes the students run in (default: 4)")
    parser.add_argument("--bot-share", type=float, default=0.05, help="share of bot games (default: 0.05)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the students' keys (default: 0)")
    parser.add_argument("--timeout", type=float, default=300.0, help="the most a phase may take, s (default: 300)")
    parser.add_argument("--flood", type=int, default=100,
                        help="clients flooding forged games, all joined (default: 100; 0: no flood)")
    parser.add_argument("--flood-honest", type=int, default=10,
                        help="honest students handing in during the flood (default: 10)")
    parser.add_argument("--flood-seconds", type=float, default=20.0, help="the flood's length, s (default: 20)")
    parser.add_argument("--clerk", type=int, default=1000,
                        help="hand-ins of the clerk alone, in this process (default: 1000; 0: none)")
    parser.add_argument("--table-sizes", default="10,1000,10000",
                        help="table sizes the cost of entering is measured at ('': none; default: 10,1000,10000)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    try:
        sizes = [int(s) for s in args.sizes.split(",")]
    except ValueError:
        parser.error("--sizes: whole numbers separated by commas")
    if not (sizes and all(1 <= s <= 2000 for s in sizes) and 1 <= args.repeats <= 20 and 1 <= args.clients <= 64
            and 0 <= args.sustained <= 100_000 and 0 <= args.bot_share <= 1 and 1 <= args.timeout <= 3600):
        parser.error("need class sizes 1 to 2000 (a class's most), 1 <= --repeats <= 20, 1 <= --clients <= 64, "
                     "0 <= --sustained <= 100000, 0 <= --bot-share <= 1, 1 <= --timeout <= 3600")
    # SIGTERM ends the run as Ctrl-C does, so every server and client process is stopped on the way out.
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        table_sizes = [int(t) for t in args.table_sizes.split(",") if t.strip()]
    except ValueError:
        parser.error("--table-sizes: whole numbers separated by commas")
    if not (0 <= args.flood <= 500 and 0 <= args.flood_honest <= 100 and 1 <= args.flood_seconds <= 600
            and 0 <= args.clerk <= 10_000 and all(1 <= t <= 100_000 for t in table_sizes)):
        parser.error("need 0 <= --flood <= 500, 0 <= --flood-honest <= 100, 1 <= --flood-seconds <= 600, "
                     "0 <= --clerk <= 10000, table sizes 1 to 100000")
    report = measure(sizes, args.repeats, args.sustained, args.clients, args.bot_share, args.seed, args.timeout,
                     say=lambda line: print(line, file=sys.stderr, flush=True), flooders=args.flood,
                     flood_honest=args.flood_honest, flood_seconds=args.flood_seconds, clerk=args.clerk,
                     table_sizes=table_sizes)
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print_report(report)
    return 0


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


if __name__ == "__main__":
    sys.exit(main())
