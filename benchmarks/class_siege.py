"""What one laptop holding sockets does to the class: uvicorn's own settings against the class's guard.

    python benchmarks/class_siege.py            # 420 idle sockets, then 60 trickling ones, from 127.0.0.2

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


def main() -> int:
    if sys.platform != "linux":
        raise SystemExit("the laptop and the classmate are other loopback addresses: Linux only")
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--idle", type=int, default=420)
    parser.add_argument("--trickling", type=int, default=60)
    parser.add_argument("--seconds", type=float, default=12.0)
    args = parser.parse_args()
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
