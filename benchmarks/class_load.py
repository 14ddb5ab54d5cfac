"""The class's load for ``class_server.py``: the games a class hands in, the server in its own process, the
students in client processes and the projector.

``python benchmarks/class_load.py --client`` is one client process (``Clients`` starts them): its students
from stdin's first line, then a phase at a time. Each student talks HTTP through the students' own client code
(``armgame.classroom.client``), whose policy on a busy class is a student's machine's.
"""

from __future__ import annotations

import contextlib
import dataclasses
import http.client
import json
import math
import os
import queue
import random
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from pathlib import Path
from typing import Any

CLASS_SEED = 10
#: A replay's date, fixed so that the bytes sent are the same on every run.
GAME_DATE = "2026-01-05T09:00:00.000000+00:00"
STANDINGS_EVERY = 0.2
#: From the word go (every client's students ready) to the moment they start: the word's way down the pipes.
GO_LEAD = 0.1
#: Steps between the ends of two bot games' keys (4 ms each): 1,500 bot games at most.
BOT_SHIFT = 10
START_SECONDS = 60.0
STOP_SECONDS = 30.0
#: Seconds between an honest student's hand-ins during the flood (each one's latency is measured).
FLOOD_HONEST_EVERY = 0.5
#: One hand-in in four of a flooder's: a replay cut off (not JSON).
FLOOD_MALFORMED = b'{"format": "armgame-replay", "format_version": 1, "timeline": [[1, "d", "do'


# ------------------------------------------------------------------ the games

def is_bot(index: int, share: float) -> bool:
    """Whether game ``index`` is a bot's: evenly spread, ``share`` of them."""
    return math.floor((index + 1) * share) > math.floor(index * share)


def make_games(folder: Path, count: int, bot_share: float, seed: int) -> list[dict[str, Any]]:
    """``count`` distinct standard games written to ``folder`` (``NNNNN.json``); each one's path, identity,
    size and kind. Deterministic: the same bytes for the same arguments."""
    from armgame.game.bots import Autopilot, make_bot
    from armgame.game.rules import GameConfig
    from armgame.game.session import UP, GameSession, InputEvent
    from armgame.records.identity import game_digest
    from armgame.records.replay import Replay

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from class_speed import student_timeline  # a student's keys, as the class's other benchmark makes them

    config = GameConfig(seed=CLASS_SEED)
    bot_timeline: list[Any] = []
    if any(is_bot(i, bot_share) for i in range(count)):
        session = GameSession(config)
        Autopilot(session, make_bot("model")).play()
        bot_timeline = list(session.timeline)
    folder.mkdir(parents=True, exist_ok=True)
    games: list[dict[str, Any]] = []
    seen: set[str] = set()
    tries = {"bot": 0, "keyboard": 0}
    while len(games) < count:
        index = len(games)
        kind = "bot" if is_bot(index, bot_share) else "keyboard"
        tries[kind] += 1
        if tries[kind] > 2 * count + 100 or tries["bot"] * BOT_SHIFT >= config.total_steps:
            raise SystemExit(f"class_server: cannot make {count} distinct games of which {bot_share:.0%} bots': "
                             f"ask for fewer")
        session = GameSession(config)
        if kind == "bot":
            # The k-th bot game: the model bot's keys, all let go BOT_SHIFT * k steps before the end (its own game).
            last = config.total_steps - BOT_SHIFT * tries["bot"]
            events = [e for e in bot_timeline if e.step < last]
            events += [InputEvent(last, m.key, UP) for m in config.muscles]
            session.play(events)
            replay = Replay.from_session(session, "bot", "model")
        else:
            session.play(student_timeline(random.Random(f"{seed}-{tries[kind]}"), config.dt, config.time_limit))
            replay = Replay.from_session(session, "keyboard")
        replay = dataclasses.replace(replay, date=GAME_DATE)
        digest = game_digest(replay)
        if digest in seen:  # the same game by effect: it would count once, so it is not a new game
            continue
        seen.add(digest)
        data = replay.to_bytes()
        path = folder / f"{index:05d}.json"
        path.write_bytes(data)
        games.append({"path": str(path), "digest": digest, "bytes": len(data), "bot": replay.driven == "bot",
                      "score": replay.result.score})
    return games


# ------------------------------------------------------------------ the server

def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class Server:
    """``armgame class serve`` in its own process; its output drained on a thread (never blocks it)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.rusage_maxrss: int | None = None
        for attempt in range(3):  # the free port found may be taken before the server binds it: another then
            self.lines: queue.Queue[str | None] = queue.Queue()
            self.said: list[str] = []
            self.banner = 0
            self.port = free_port()
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "armgame", "class", "serve", "--folder", str(folder), "--host", "127.0.0.1",
                 "--port", str(self.port)], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT, text=True, errors="replace")
            self.drainer = threading.Thread(target=self._drain, daemon=True)
            self.drainer.start()
            try:
                self.code = self._wait_ready()
                return
            except RuntimeError:
                self.stop()  # never left running, whatever it was doing
                if attempt == 2 or not any("is in use" in line for line in self.said):
                    raise

    def _drain(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.put(line.rstrip("\n"))
        self.lines.put(None)

    def _wait_ready(self) -> str:
        code = None
        deadline = time.monotonic() + START_SECONDS
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=max(0.01, deadline - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                break
            self.said.append(line)
            found = re.search(r"code ([A-Z]{4})", line)
            if found and code is None:
                code = found.group(1)
            if "Ctrl-C stops the class" in line and code is not None:  # the banner's last line
                self.banner = len(self.said)
                return code
        raise RuntimeError("the class's server did not start:\n" + "\n".join(self.said))

    def notices(self) -> dict[str, int]:
        """What the server printed after its banner (uvicorn's warnings too), each line with its count; its last
        lines ("armgame class stopped: ..." and the commands that read the class afterwards) left out."""
        while True:
            try:
                line = self.lines.get_nowait()
            except queue.Empty:
                break
            if line is not None:
                self.said.append(line)
        counts: dict[str, int] = {}
        said = self.said[self.banner:]
        stopped = next((i for i, line in enumerate(said) if line.startswith("armgame class stopped:")), len(said))
        for line in said[:stopped]:
            counts[line] = counts.get(line, 0) + 1
        return counts

    def cpu_seconds(self) -> float | None:
        """The server's CPU time so far (user and system), where /proc tells it."""
        try:
            fields = Path(f"/proc/{self.proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            return None
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def peak_rss(self) -> int | None:
        """The server's peak resident memory in bytes so far (VmHWM), where /proc tells it."""
        try:
            status = Path(f"/proc/{self.proc.pid}/status").read_text()
        except OSError:
            return self.rusage_maxrss
        found = re.search(r"^VmHWM:\s+(\d+)\s+kB", status, re.MULTILINE)
        return int(found.group(1)) * 1024 if found else self.rusage_maxrss

    def stop(self) -> int | None:
        """Ctrl-C's signal, then a kill if it has not stopped within ``STOP_SECONDS``; its exit status."""
        try:
            return self._stop()
        finally:
            self.drainer.join(STOP_SECONDS)  # the output read to its end before its pipe is closed
            assert self.proc.stdout is not None
            self.proc.stdout.close()

    def _stop(self) -> int | None:
        if self.proc.poll() is not None:
            return self.proc.returncode
        if sys.platform == "win32":
            self.proc.terminate()
        else:
            self.proc.send_signal(signal.SIGINT)
        if hasattr(os, "wait4") and not Path("/proc/self/status").exists():
            # Without /proc the peak memory is known only from the rusage of the reaped process.
            deadline = time.monotonic() + STOP_SECONDS
            while time.monotonic() < deadline:
                pid, status, usage = os.wait4(self.proc.pid, os.WNOHANG)
                if pid:
                    scale = 1 if sys.platform == "darwin" else 1024  # macOS counts bytes, the others KiB
                    self.rusage_maxrss = usage.ru_maxrss * scale
                    self.proc.returncode = os.waitstatus_to_exitcode(status)
                    return self.proc.returncode
                time.sleep(0.05)
        try:
            return self.proc.wait(STOP_SECONDS)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(STOP_SECONDS)
            return None


# ------------------------------------------------------------------ the students (in --client processes)

def student_thread(address: Any, code: str, student: dict[str, Any], phase: str, go: threading.Event,
                   start: list[float], games: dict[int, bytes], out: list[dict[str, Any]]) -> None:
    """One student's share of ``phase``, once ``go`` is set, from the moment ``start[0]`` (``time.time``); a record
    per request in ``out``."""
    from armgame.classroom import client

    busy = [0]

    def counted_sleep(seconds: float) -> None:  # the client sleeps once for every 503 it is answered
        busy[0] += 1
        time.sleep(seconds)

    def request(path: str, body: bytes, headers: dict[str, str]) -> dict[str, Any]:
        busy[0] = 0
        began = time.perf_counter()
        record: dict[str, Any] = {}
        try:
            answer = client._request(address, path, body, headers, sleep=counted_sleep)
            record.update(outcome="ok", answer=answer)
        except client.RefusalError as exc:
            record.update(outcome=f"refused {exc.status}", error=str(exc)[:200])
        except client.UnreachableError as exc:
            record.update(outcome="unreachable", error=str(exc)[:200])
        except Exception as exc:  # reported, never hidden: the benchmark's figures would be wrong without it
            record.update(outcome=f"error {type(exc).__name__}", error=str(exc)[:200])
        record.update(latency=time.perf_counter() - began, end=time.time(), busy=busy[0])
        return record

    if not go.wait(START_SECONDS):
        return
    time.sleep(max(0.0, start[0] - time.time()))
    if phase == "join":
        record = request("/api/join", json.dumps({"code": code, "name": student["name"]}).encode(),
                         {"Content-Type": "application/json"})
        answer = record.pop("answer", None)
        if answer is not None:
            student["token"] = str(answer.get("token"))
        out.append(record)
        return
    if phase == "flood":
        flood_thread(address, code, student, start[0], games, out, request)
        return
    if student.get("flooder"):
        return  # a flooder hands in nothing honest
    indices = student["games"][:1] if phase == "burst" else student["games"][1:]
    for index in indices:
        if "token" not in student:
            return
        headers = {"Content-Type": "application/json", "Authorization": f"Bearer {student['token']}",
                   "X-Armgame-Code": code}
        out.append(handed_in(request, games[index], index, headers, student))


def handed_in(request: Callable[..., dict[str, Any]], game: bytes, index: int, headers: dict[str, str],
              student: dict[str, Any]) -> dict[str, Any]:
    """One game handed in by ``student`` through ``request``: its record, the answer checked to be theirs."""
    record = request("/api/handin", game, headers)
    answer = record.pop("answer", None)
    if answer is not None and not (answer.get("ok") and answer.get("name") == student["name"]):
        record["outcome"] = "wrong answer"
        record["error"] = json.dumps(answer)[:200]
    record.update(game=index, name=student["name"], already=bool(answer and answer.get("already")))
    return record


def flood_thread(address: Any, code: str, student: dict[str, Any], start_at: float, games: dict[int, bytes],
                 out: list[dict[str, Any]], request: Callable[..., dict[str, Any]]) -> None:
    """The flood phase: a flooder posts forged and malformed games as fast as the server answers (no wait after a
    503, a new connection each) until ``student["until"]`` s after ``start_at``, with a record of its counts; an
    honest student hands in its games one after another, ``FLOOD_HONEST_EVERY`` s apart, through the students'
    own client (waits after a 503 included), each with its latency."""
    if "token" not in student:
        return
    headers = {"Content-Type": "application/json", "Authorization": f"Bearer {student['token']}",
               "X-Armgame-Code": code}
    end = start_at + student["until"]
    if student.get("flooder"):
        counts: dict[str, int] = {}
        n = 0
        while time.time() < end:
            body = games[student["games"][n % len(student["games"])]] if n % 4 else FLOOD_MALFORMED
            n += 1
            req = urllib.request.Request(f"http://{address.label}/api/handin", data=body, method="POST",
                                         headers=headers)
            try:
                with urllib.request.urlopen(req, timeout=30) as response:
                    response.read()
                    status = str(response.status)
            except urllib.error.HTTPError as exc:
                exc.read()
                exc.close()
                status = str(exc.code)
            except OSError as exc:
                status = type(exc).__name__
            counts[status] = counts.get(status, 0) + 1
        out.append({"flooder": student["name"], "counts": counts})
        return
    for index in student["games"]:
        if time.time() >= end:
            break
        out.append(handed_in(request, games[index], index, headers, student))
        time.sleep(FLOOD_HONEST_EVERY)


def client_main() -> int:
    """A ``--client`` process: its students from stdin's first line, then for each phase its name (the students
    are made ready: a line back) and its moment (they go: their records back on a line)."""
    from armgame.classroom import client

    threading.stack_size(512 * 1024)  # hundreds of threads that only wait on sockets
    spec = json.loads(sys.stdin.readline())
    address = client.ClassAddress.parse(spec["address"])
    students: list[dict[str, Any]] = spec["students"]
    games = {int(i): Path(path).read_bytes() for i, path in spec["games"]}
    print(json.dumps({"ready": True}), flush=True)
    for line in sys.stdin:
        command = json.loads(line)
        if command["phase"] == "quit":
            return 0
        out: list[dict[str, Any]] = []
        go, start = threading.Event(), [0.0]
        threads = [threading.Thread(target=student_thread, daemon=True,
                                    args=(address, spec["code"], s, command["phase"], go, start, games, out))
                   for s in students]
        for t in threads:
            t.start()
        print(json.dumps({"armed": True}), flush=True)
        start[0] = json.loads(sys.stdin.readline())["start_at"]
        late = time.time() - start[0]  # above 0: this process's students started after the moment
        before = time.process_time()  # the whole process's, every thread's
        go.set()
        deadline = time.monotonic() + command["timeout"]
        for t in threads:
            t.join(max(0.0, deadline - time.monotonic()))
        cpu = time.process_time() - before
        print(json.dumps({"records": list(out), "unfinished": sum(t.is_alive() for t in threads), "cpu": cpu,
                          "late": late}), flush=True)
    return 0


class Clients:
    """The ``--client`` processes, each with its share of the class."""

    def __init__(self, n: int, address: str, code: str, students: list[dict[str, Any]], games: list[str]) -> None:
        self.procs: list[subprocess.Popen] = []
        self.drainers: list[threading.Thread] = []
        self.answers: list[queue.Queue[str | None]] = []
        for k in range(n):
            mine = students[k::n]
            if not mine:
                continue
            proc = subprocess.Popen([sys.executable, __file__, "--client"], stdin=subprocess.PIPE,
                                    stdout=subprocess.PIPE, text=True)
            answers: queue.Queue[str | None] = queue.Queue()
            drainer = threading.Thread(target=self._drain, args=(proc, answers), daemon=True)
            drainer.start()
            self.drainers.append(drainer)
            self.procs.append(proc)
            self.answers.append(answers)
            self._send(proc, {"address": address, "code": code, "students": mine,
                              "games": [[i, games[i]] for s in mine for i in s["games"]]})
        try:
            self._collect(START_SECONDS)
        except BaseException:
            self.close()  # none left running
            raise

    @staticmethod
    def _drain(proc: subprocess.Popen, answers: queue.Queue[str | None]) -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            answers.put(line)
        answers.put(None)

    @staticmethod
    def _send(proc: subprocess.Popen, message: dict[str, Any]) -> None:
        assert proc.stdin is not None
        proc.stdin.write(json.dumps(message) + "\n")
        proc.stdin.flush()

    def _collect(self, timeout: float) -> list[dict[str, Any]]:
        deadline = time.monotonic() + timeout
        replies = []
        for answers in self.answers:
            try:
                line = answers.get(timeout=max(0.01, deadline - time.monotonic()))
            except queue.Empty:
                line = None
            if line is None:
                raise RuntimeError("a client process did not answer in time (or ended)")
            replies.append(json.loads(line))
        return replies

    def phase(self, name: str, timeout: float) -> tuple[list[dict[str, Any]], float, dict[str, float]]:
        """Every student's requests of phase ``name``, all started at one moment once every client process has its
        threads ready; (the records, that moment, {the clients' CPU seconds, how late the last process started})."""
        for proc in self.procs:
            self._send(proc, {"phase": name, "timeout": timeout})
        self._collect(START_SECONDS)
        start_at = time.time() + GO_LEAD
        for proc in self.procs:
            self._send(proc, {"start_at": start_at})
        replies = self._collect(GO_LEAD + timeout + 10)
        if any(r["unfinished"] for r in replies):
            raise RuntimeError(f"{sum(r['unfinished'] for r in replies)} students did not finish the {name} within "
                               f"{timeout:g} s")
        return ([rec for r in replies for rec in r["records"]], start_at,
                {"clients_cpu_s": sum(r["cpu"] for r in replies), "start_late_s": max(r["late"] for r in replies)})

    def close(self) -> None:
        for proc in self.procs:
            with contextlib.suppress(OSError, ValueError):
                self._send(proc, {"phase": "quit"})
        for proc in self.procs:
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(10)
        for proc, drainer in zip(self.procs, self.drainers, strict=True):
            drainer.join(10)
            for pipe in (proc.stdin, proc.stdout):
                with contextlib.suppress(OSError):
                    pipe.close()


# ------------------------------------------------------------------ the projector

class Projector:
    """The projector's page, from this process: the event stream held open, and ``GET /api/standings``
    every ``STANDINGS_EVERY`` s, each timed."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.latencies: list[float] = []
        self.failures: list[str] = []
        self.events = 0
        self.done = threading.Event()
        self.connection: http.client.HTTPConnection | None = None
        self.threads = [threading.Thread(target=self._poll, daemon=True),
                        threading.Thread(target=self._stream, daemon=True)]
        for t in self.threads:
            t.start()

    def _poll(self) -> None:
        url = f"http://127.0.0.1:{self.port}/api/standings"
        while not self.done.wait(STANDINGS_EVERY):
            began = time.perf_counter()
            try:
                with urllib.request.urlopen(url, timeout=15) as response:
                    json.loads(response.read())
                self.latencies.append(time.perf_counter() - began)
            except (OSError, ValueError, http.client.HTTPException) as exc:
                self.failures.append(f"{type(exc).__name__}: {exc}"[:200])

    def _stream(self) -> None:
        connection = self.connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=20)  # beats: 15 s
        try:
            connection.request("GET", "/events")
            response = connection.getresponse()
            while not self.done.is_set():
                line = response.readline()
                if not line:
                    break
                if line.startswith(b"event: standings"):
                    self.events += 1
        except (OSError, http.client.HTTPException) as exc:
            if not self.done.is_set():
                self.failures.append(f"events: {type(exc).__name__}: {exc}"[:200])
        finally:
            connection.close()

    def stop(self) -> None:
        """Both stopped; the stream closed from here (else the server would wait its grace for it to end)."""
        self.done.set()
        if self.connection is not None and self.connection.sock is not None:
            with contextlib.suppress(OSError):
                self.connection.sock.shutdown(socket.SHUT_RDWR)
        for t in self.threads:
            t.join(20)


# ------------------------------------------------------------------ one class


if __name__ == "__main__":
    if sys.argv[1:] != ["--client"]:
        raise SystemExit("class_load.py is class_server.py's client process: python benchmarks/class_server.py")
    sys.exit(client_main())
