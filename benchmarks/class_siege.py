"""What one laptop holding sockets does to the class: uvicorn's own settings against the class's guard.

    python benchmarks/class_siege.py            # 420 idle sockets, then 60 trickling ones, from 127.0.0.2
    python benchmarks/class_siege.py --memory   # one address's whole share of memory attacks, 40 tricklers

``--memory`` (issue 54): ``armgame class serve`` in its own process; one laptop (127.0.0.2) spends its 16
connections on every attack on the server's memory at once (12 pipelining ``GET /api/standings`` as fast as
the server reads and never reading an answer, each opened again when closed; 2 sending one request of 6.3
million headers; 2 one header of 16 MiB), while 40 machines (127.0.3.x), each with its name, trickle hand-in
bodies a byte a second and send again when cut, and an honest student (127.0.0.3) hands in a game every
0.5 s. Printed: the server's resident memory at its highest (sampled, and the kernel's VmHWM) and the honest
hand-ins' latency (p50, p99, max).

For each server (uvicorn as the class ran before the guard: its h11 protocol, ``limit_concurrency`` 400,
``timeout_keep_alive`` 5 s; then the class's guard, ``armgame.classroom.guard``), one laptop (127.0.0.2)
opens the sockets and holds them (idle: nothing sent; trickling: a byte of headers every 0.5 s), and a
classmate (127.0.0.3) asks for the standings every 0.5 s for ``--seconds``. Printed: the classmate's
answers (statuses) and their latency, and how many of the laptop's sockets the server still held at the
end. Loopback only (Linux: every 127.x address is this machine), bounded in count and time.

Why a guard and not uvicorn's settings: ``timeout_keep_alive`` covers only the wait between requests,
not a request being received (uvicorn's issue #157), and ``limit_concurrency`` counts the idle sockets,
so the class answers 503 to everyone while they are held; ASGI middleware runs only after headers.
"""

from __future__ import annotations

import argparse
import contextlib
import http.client
import os
import socket
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from armgame.classroom.serve import open_class

LAPTOP, CLASSMATE = "127.0.0.2", "127.0.0.3"


def siege(guarded: bool, idle: int, trickling: int, seconds: float) -> dict[str, object]:
    ready = threading.Event()
    with tempfile.TemporaryDirectory() as tmp:
        opened = open_class(Path(tmp) / "class", "127.0.0.1", 0, None, say=lambda line: None,
                            on_ready=lambda _: ready.set())
        if not guarded:  # the class as it ran before: uvicorn's own h11 protocol and its limit
            opened.server.config.http = "h11"
            opened.server.config.limit_concurrency = 400
        thread = threading.Thread(target=opened.run, daemon=True)
        thread.start()
        assert ready.wait(20)
        held: list[socket.socket] = []
        stop = threading.Event()

        def hold() -> None:
            for i in range(idle + trickling):
                with contextlib.suppress(OSError):
                    s = socket.create_connection(("127.0.0.1", opened.port), timeout=2, source_address=(LAPTOP, 0))
                    if i >= idle:
                        s.send(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n")
                    held.append(s)
            while not stop.wait(0.5):
                for s in held[idle:]:
                    with contextlib.suppress(OSError):
                        s.send(b"X")

        holder = threading.Thread(target=hold, daemon=True)
        holder.start()
        time.sleep(1.0)
        statuses: list[int] = []
        latencies: list[float] = []
        until = time.monotonic() + seconds
        while time.monotonic() < until:
            started = time.perf_counter()
            try:
                conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=5,
                                                  source_address=(CLASSMATE, 0))
                conn.request("GET", "/api/standings")
                statuses.append(conn.getresponse().status)
                conn.close()
            except OSError:
                statuses.append(0)
            latencies.append(time.perf_counter() - started)
            time.sleep(0.5)
        alive = 0
        for s in held:
            s.setblocking(False)
            try:
                alive += s.recv(1) != b""
            except BlockingIOError:
                alive += 1
            except OSError:
                pass
        stop.set()
        holder.join(5)
        for s in held:
            s.close()
        opened.stop()
        thread.join(20)
    return {"ok": sum(s == 200 for s in statuses), "asked": len(statuses),
            "refused": sorted({s for s in statuses if s != 200}), "median_ms": 1000 * statistics.median(latencies),
            "held_at_end": alive, "opened": len(held)}


def _rss_kib(pid: int, field: str = "VmRSS") -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    return 0


def memory(seconds: float) -> dict[str, object]:
    """The ``--memory`` run (see the module): the server's memory and an honest student's hand-ins."""
    import json

    from class_server import free_port, serve_process, tapped_game

    stop = threading.Event()
    with tempfile.TemporaryDirectory() as tmp:
        port = free_port()
        proc, code = serve_process(Path(tmp) / "class", port)
        try:
            def post(path: str, body: bytes, headers: dict, source: str) -> tuple[int, dict]:
                conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30, source_address=(source, 0))
                try:
                    conn.request("POST", path, body, {"Content-Type": "application/json", **headers})
                    response = conn.getresponse()
                    return response.status, json.loads(response.read() or b"{}")
                finally:
                    conn.close()

            def joined(name: str, source: str) -> str:
                return post("/api/join", json.dumps({"code": code, "name": name}).encode(), {}, source)[1]["token"]

            tricklers = {f"127.0.3.{i}": joined(f"Bot {i}", f"127.0.3.{i}") for i in range(1, 41)}
            honest = joined("Ann", CLASSMATE)
            get = b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n" * 20_000

            def attack(kind: str) -> None:
                while not stop.is_set():
                    with contextlib.suppress(OSError):
                        s = socket.create_connection(("127.0.0.1", port), timeout=2, source_address=(LAPTOP, 0))
                        with s:
                            if kind == "pipeline":
                                while not stop.is_set():
                                    s.sendall(get)
                            head = b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                            s.sendall(head + (b"X-Big: " if kind == "big" else b""))
                            line = b"a" * 65536 if kind == "big" else b"a:b\r\n" * 13107
                            for _ in range(16 * 16 if kind == "big" else 6_300_000 // 13107):
                                if stop.is_set():
                                    break
                                s.sendall(line)
                    stop.wait(0.05)

            def trickle(source: str, token: str) -> None:
                while not stop.is_set():
                    with contextlib.suppress(OSError):
                        s = socket.create_connection(("127.0.0.1", port), timeout=2, source_address=(source, 0))
                        with s:
                            s.sendall(f"POST /api/handin HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: "
                                      f"application/json\r\nAuthorization: Bearer {token}\r\nX-Armgame-Code: "
                                      f"{code}\r\nContent-Length: 9000\r\n\r\n".encode())
                            while not stop.wait(1.0):
                                s.sendall(b" ")
                    stop.wait(0.05)

            threads = [threading.Thread(target=attack, args=(kind,), daemon=True)
                       for kind in ["pipeline"] * 12 + ["headers"] * 2 + ["big"] * 2]
            threads += [threading.Thread(target=trickle, args=item, daemon=True) for item in tricklers.items()]
            before = _rss_kib(proc.pid)
            for t in threads:
                t.start()
            peak, latencies, statuses = before, [], []
            until, n = time.monotonic() + seconds, 0
            while time.monotonic() < until:
                peak = max(peak, _rss_kib(proc.pid))
                started = time.perf_counter()
                with contextlib.suppress(OSError):
                    status, _ = post("/api/handin", tapped_game(n, player="Ann").to_bytes(),
                                     {"Authorization": f"Bearer {honest}", "X-Armgame-Code": code}, CLASSMATE)
                    statuses.append(status)
                latencies.append(time.perf_counter() - started)
                n += 1
                for _ in range(5):
                    peak = max(peak, _rss_kib(proc.pid))
                    time.sleep(0.1)
            hwm = _rss_kib(proc.pid, "VmHWM")
        finally:
            stop.set()
            proc.send_signal(2)
            with contextlib.suppress(Exception):
                proc.communicate(timeout=20)
    latencies.sort()
    return {"before_mib": before / 1024, "peak_mib": peak / 1024, "hwm_mib": hwm / 1024, "handins": len(latencies),
            "ok": statuses.count(200), "p50": statistics.median(latencies),
            "p99": latencies[min(len(latencies) - 1, int(0.99 * len(latencies)))], "max": latencies[-1]}


def main() -> int:
    if sys.platform != "linux":
        raise SystemExit("the laptop and the classmate are other loopback addresses: Linux only")
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--idle", type=int, default=420)
    parser.add_argument("--trickling", type=int, default=60)
    parser.add_argument("--seconds", type=float, default=12.0)
    parser.add_argument("--memory", action="store_true", help="the memory attacks and 40 trickling machines")
    args = parser.parse_args()
    if args.memory:
        print(f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; one address's 16 connections on the memory "
              f"attacks, 40 machines trickling hand-ins, an honest hand-in every 0.5 s for {args.seconds:g} s")
        r = memory(args.seconds)
        print(f"server memory: {r['before_mib']:.0f} MiB before, {r['peak_mib']:.0f} MiB at its highest sampled, "
              f"VmHWM {r['hwm_mib']:.0f} MiB")
        print(f"honest hand-ins: {r['ok']} of {r['handins']} acknowledged; p50 {r['p50']:.2f} s, p99 {r['p99']:.2f} s, "
              f"max {r['max']:.2f} s")
        return 0
    print(f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; the laptop holds {args.idle} idle and "
          f"{args.trickling} trickling sockets; the classmate asks every 0.5 s for {args.seconds:g} s")
    for name, guarded in (("uvicorn alone (limit 400)", False), ("the class's guard", True)):
        r = siege(guarded, args.idle, args.trickling, args.seconds)
        print(f"{name:27} classmate answered {r['ok']:>3} of {r['asked']} (other statuses: {r['refused'] or 'none'}), "
              f"median {r['median_ms']:.1f} ms; the laptop's sockets still held at the end: {r['held_at_end']} of "
              f"{r['opened']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
