"""Starting the class's server where the students can reach it, and stopping it cleanly.

uvicorn serves the app (``app.build_app``) on one address: by default the address of the network
interface that holds the default route (the one the students' laptops share with the teacher's),
found without sending a packet; ``--host 127.0.0.1`` keeps a trial on one machine. Ctrl-C stops the
server: requests in flight get ``GRACE_SECONDS`` to finish, a hand-in being written is finished,
the projector's stream is closed, and nothing is half-written.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import os
import shlex
import signal
import socket
import sys
import threading
from collections.abc import Callable
from dataclasses import dataclass
from datetime import date
from pathlib import Path
from typing import Any

from ..errors import UserError

GRACE_SECONDS = 3
#: Connections served at once; past it uvicorn answers 503 itself. A lecture hall's round's end is 1,000
#: students at the same moment: at 400, six in ten were sent away for 2 s, again and again (the clerk's own
#: queue, bounded in bytes and one hand-in a player, is what keeps memory bounded). The process's limit of
#: open files is raised to fit where the system allows (``_more_files``).
CONCURRENCY = 2500
#: Connections the system holds for the server to accept (capped by the system's own, 4,096 on Linux, 128 on
#: macOS unless raised). Past it a new connection's first packet is dropped and its client sends it again a
#: second later, then three: at 128, a round's end of 1,000 students at once, or a flood of clients, cost an
#: honest student seconds before the server even saw their game.
BACKLOG = 2048


def lan_address() -> str:
    """The address of the interface with the default route (a UDP socket's connect sends nothing)."""
    with contextlib.suppress(OSError), socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.connect(("192.0.2.1", 9))  # TEST-NET-1: never routed anywhere, only chosen a route for
        address = s.getsockname()[0]
        if address and not address.startswith("0."):
            return address
    return "127.0.0.1"


def other_addresses(main: str) -> list[str]:
    """This machine's other IPv4 addresses (a laptop on wire and Wi-Fi has two): named, in case."""
    found: set[str] = set()
    with contextlib.suppress(OSError):
        for info in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET):
            found.add(str(info[4][0]))
    return sorted(a for a in found if a != main and not a.startswith("127."))


def default_folder() -> Path:
    """A new folder for a new class, under the per-user data folder: ``classes/2026-11-25``, ``-2``..."""
    from ..records.scores import user_data_dir

    base = user_data_dir() / "classes"
    stem = date.today().isoformat()
    for n in range(1, 1000):
        folder = base / (stem if n == 1 else f"{stem}-{n}")
        if not folder.exists() and not folder.is_symlink():
            return folder
    raise UserError(f"{base}: a thousand classes today already; give --folder")


@dataclass
class ClassServer:
    """A class ready to serve: its clerk, its listening socket and the uvicorn server over the app."""

    clerk: Any
    sock: socket.socket
    server: Any
    join_line: str
    new: bool

    @property
    def port(self) -> int:
        return int(self.sock.getsockname()[1])

    def run(self) -> None:
        """Serve until Ctrl-C, SIGTERM or ``stop``; the socket is closed after.

        uvicorn stops gracefully on SIGINT and SIGTERM, then raises the signal again for the handler
        that was there before it. For a class that is the normal end, not an interruption: SIGTERM's
        handler is made to raise KeyboardInterrupt as SIGINT's does, and both end the run quietly."""
        main = threading.current_thread() is threading.main_thread()
        before = signal.signal(signal.SIGTERM, _interrupt) if main else None
        try:
            self.server.run(sockets=[self.sock])
        except KeyboardInterrupt:
            pass
        finally:
            self.sock.close()
            if main:
                signal.signal(signal.SIGTERM, before)

    def stop(self) -> None:
        self.server.should_exit = True


def open_class(folder: Path, host: str, port: int, seed: int | None, say: Callable[[str], None] = print,
               on_ready: Callable[[ClassServer], None] | None = None) -> ClassServer:
    """The class in ``folder`` (gone on with, or new) bound to ``host:port`` (0: a free port), not yet serving.

    ``say`` gets the teacher's lines: the banner once the server takes requests, notices after."""
    import uvicorn

    from ..lab.record import register
    from .app import build_app
    from .intake import Clerk
    from .roster import Roster

    register()  # lab runs are read as replays with their task section
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"--folder {folder}: cannot create it: {exc.strerror or exc}") from None
    roster, new = Roster.open(folder, seed)
    clerk = Clerk(folder, roster)
    sock = _bind(host, port)
    port = sock.getsockname()[1]
    join_line = f"armgame play --join {_label(host)}:{port} --code {roster.code}"

    def ready() -> None:
        others = other_addresses(host) if host not in ("127.0.0.1", "localhost", "::1") else []
        say(f"armgame class {'started' if new else 'goes on'}: code {roster.code}, seed {roster.seed}, "
            f"{len(clerk.entries)} games so far, kept in {folder}")
        say(f"  students type:  {join_line} --name NAME")
        say(f"  projector:      http://{_label(host)}:{port}/   (the lab's class curve: /lab)")
        say(f"  teacher only:   http://{_label(host)}:{port}/teacher   secret: {roster.secret}   "
            f"(never on the projector)")
        if others:
            say(f"  this machine also answers at {', '.join(others)}, if students are on that network")
        say("  the first time, Windows or macOS may ask to allow incoming connections for Python: allow it on "
            "private networks")
        say(f"  Ctrl-C stops the class; to go on with it later: armgame class serve --folder {shell_path(folder)}")
        if on_ready is not None:
            on_ready(opened)

    app = build_app(clerk, join_line, on_ready=ready, say=lambda line: say(f"armgame class: {line}"))
    _more_files(CONCURRENCY + 256)
    config = uvicorn.Config(app, log_level="warning", access_log=False, lifespan="on",
                            timeout_graceful_shutdown=GRACE_SECONDS, timeout_keep_alive=5,
                            limit_concurrency=CONCURRENCY, h11_max_incomplete_event_size=16 * 1024)
    errors = logging.getLogger("uvicorn.error")  # configured by uvicorn.Config, just above
    if not any(isinstance(f, _QuietWhenFull) for f in errors.filters):
        errors.addFilter(_QuietWhenFull())
    opened = ClassServer(clerk, sock, uvicorn.Server(config), join_line, new)
    return opened


def _more_files(wanted: int) -> None:
    """Raise this process's soft limit of open files to ``wanted`` (each connection is one), within its hard
    limit; where there is no such limit (Windows) or it cannot be raised, it stays as it is."""
    try:
        import resource
    except ImportError:
        return
    with contextlib.suppress(ValueError, OSError):
        soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        target = wanted if hard == resource.RLIM_INFINITY else min(wanted, hard)
        if soft != resource.RLIM_INFINITY and soft < target:
            resource.setrlimit(resource.RLIMIT_NOFILE, (target, hard))


class _QuietWhenFull(logging.Filter):
    """uvicorn warns once for every connection past its limit: thousands of lines when a lecture hall hands in at
    once (benchmarks/class_server.py), scrolling the code and the secret out of the teacher's terminal. Each of
    those machines is answered 503 and comes back by itself: nothing for the teacher to act on."""

    def filter(self, record: logging.LogRecord) -> bool:
        return record.getMessage() != "Exceeded concurrency limit."


def serve(folder: Path, host: str, port: int, seed: int | None, say: Callable[[str], None] = print) -> int:
    """Run the class in ``folder`` on ``host:port`` until Ctrl-C (or SIGTERM); returns an exit status."""
    opened = open_class(folder, host, port, seed, say)
    opened.run()
    where = shell_path(folder)
    say(f"armgame class stopped: {len(opened.clerk.entries)} games kept in {folder}")
    say(f"  the standings, one row a student:  armgame scores --scores {where}")
    if opened.clerk.lab_runs:
        lab = shell_path(folder / "lab")
        say(f"  the lab's class curve:             armgame analyze --class {lab} --out class-curve")
    say(f"  to go on with the class:           armgame class serve --folder {where}")
    return 0


def shell_path(path: Path) -> str:
    """``path`` as it can be pasted into this platform's shell: quoted if it holds a space (macOS's data folder is
    under "Application Support") or anything else the shell would read."""
    text = str(path)
    if os.name == "nt":
        return f'"{text}"' if any(c in text for c in ' &()[]{}^=;!\'+,`~') else text
    return shlex.quote(text)


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def _label(host: str) -> str:
    return f"[{host}]" if ":" in host else host


def _bind(host: str, port: int) -> socket.socket:
    """A listening socket on exactly ``host:port`` (0: any free port); one line if it cannot be had."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except socket.gaierror as exc:
        raise UserError(f"--host {host}: not an address of this machine ({exc.strerror})") from None
    family, kind, proto, _, where = infos[0]
    sock = socket.socket(family, kind, proto)
    if sys.platform != "win32":  # Windows' SO_REUSEADDR would let two classes share the port
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(where)
        sock.listen(BACKLOG)
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            raise UserError(f"port {port} on {host} is in use (is a class already running?): choose another "
                            f"with --port") from None
        if exc.errno == errno.EADDRNOTAVAIL:
            raise UserError(f"--host {host}: not an address of this machine") from None
        raise UserError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    sock.set_inheritable(True)
    return sock

