"""Starting the class's server where the students can reach it, and stopping it cleanly.

uvicorn serves the app (``app.build_app``) on one address: by default the address of the network
interface that holds the default route (the one the students' laptops share with the teacher's),
found without sending a packet; ``--host 127.0.0.1`` keeps a trial on one machine. Ctrl-C stops the
server: requests in flight get ``SHUTDOWN_SECONDS`` to finish, a hand-in being written is finished,
the projector's stream is closed, and nothing is half-written.

uvicorn runs with the class's guard on its httptools protocol (``guard``: deadlines and a share of the
connections per address), and without uvicorn's proxy headers: a client's address is its socket's, never an
``X-Forwarded-For`` it wrote, unless the teacher names a proxy (``--proxy ADDRESS``); then a connection from that
address is the client the proxy appended, and never the teacher's machine (``middleware.ForwardedFor``). One server at
a time serves a folder: it holds ``server.lock`` (owner-only) for its life, and a second one says so
in one line and stops.

A rehearsal (``--rehearse``) is a class like any other but for three things: its game is the rehearsal's
15 s one (``records.rulesets.REHEARSAL``) and its rounds are short (``rounds.REHEARSAL_ROUND_SECONDS``); it
lives in a new private temporary folder, removed when the server stops; and the table's record that a
class's starter keeps (``records.teacher``) is kept in that folder too, so nothing is written anywhere else.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import os
import shlex
import shutil
import signal
import socket
import sys
import tempfile
import threading
from collections.abc import Callable
from dataclasses import dataclass
from datetime import date
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..words import plural
from .bounds import BACKLOG, CONCURRENCY, KEEP_ALIVE_SECONDS, SHUTDOWN_SECONDS
from .rounds import REHEARSAL_ROUND_SECONDS

SERVER_LOCK = "server.lock"
#: Why a rehearsal takes no folder, in one line.
REHEARSE_NO_FOLDER = ("--rehearse keeps nothing: it plays in a temporary folder removed at Ctrl-C, so it takes no "
                      "--folder (leave out --rehearse to serve the class in that folder)")


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
    held: Any = None
    #: A rehearsal's temporary folder (the class's folder is inside it), removed once the server has stopped.
    temporary: Path | None = None

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
            if self.held is not None:
                self.held.release()
            if self.temporary is not None:  # after the lock is let go: Windows removes no open file
                shutil.rmtree(self.temporary, ignore_errors=True)
            if main:
                signal.signal(signal.SIGTERM, before)

    def stop(self) -> None:
        self.server.should_exit = True


def open_class(folder: Path | None, host: str, port: int, seed: int | None, say: Callable[[str], None] = print,
               on_ready: Callable[[ClassServer], None] | None = None, lab: str | None = None,
               proxy: str | None = None, rehearse: bool = False, lab_b: str | None = None,
               split_seed: int | None = None, secret_always: bool = False) -> ClassServer:
    """The class in ``folder`` (gone on with, or new) bound to ``host:port`` (0: a free port), not yet serving.

    ``say`` gets the teacher's lines: the banner once the server takes requests, notices after. ``lab``:
    the preset the class curve shows (a new class: ``lesson`` unless given; a class gone on with keeps its
    own unless given). ``proxy``: the address of a reverse proxy whose ``X-Forwarded-For`` is believed (its rightmost
    entry; UserError unless an IP address). ``rehearse``: a rehearsal (``folder`` None), in a temporary folder removed
    when ``run`` ends. ``lab_b``: a classroom experiment's second condition beside ``lab`` (``experiment``), split by
    ``split_seed`` (None: drawn at random, and kept in the class's record). ``secret_always``: the teacher's page
    asks for the secret on this machine too."""
    import uvicorn

    from ..lab.record import register
    from .app import build_app
    from .guard import Guard, guarded_protocol
    from .intake import Clerk
    from .roster import SECRET_NAME, Roster

    curve = _curve_protocol(lab)
    second = _curve_protocol(lab_b)
    if second is not None and second == curve:
        raise UserError("--lab-b names the same protocol as --lab: an experiment needs two conditions")
    proxy = proxy_address(proxy)
    register()  # lab runs are read as replays with their task section
    temporary = records = None
    if rehearse:
        if folder is not None:
            raise UserError(REHEARSE_NO_FOLDER)
        temporary = Path(tempfile.mkdtemp(prefix="armgame-rehearsal-"))  # the user's alone (0700)
        folder, records = temporary / "class", temporary / "records"
    assert folder is not None, "a class needs its folder, or is a rehearsal"
    try:
        try:
            folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        except OSError as exc:
            raise UserError(f"--folder {folder}: cannot create it: {exc.strerror or exc}") from None
        held = _hold_folder(folder)
        try:
            roster, new = Roster.open(folder, seed)
            if (new and roster.lab is None) or (curve is not None and curve != roster.lab):
                if roster.experiment is not None:
                    raise UserError(f"the class in {folder} is an experiment of its own two conditions: go on "
                                    "with it without --lab, or start a new class in another --folder")
                roster.changed(lab=curve or "lesson")
            if second is not None and roster.experiment is None:
                if not new:
                    raise UserError(f"--lab-b: the class in {folder} has begun without an experiment; a split "
                                    "starts with a new class (another --folder)")
                import secrets

                from .experiment import Experiment

                seed_of_split = secrets.randbits(63) if split_seed is None else split_seed
                roster.changed(experiment=Experiment(roster.lab, second, seed_of_split))  # type: ignore[arg-type]
            elif second is not None and second != roster.experiment.b:  # type: ignore[union-attr]
                raise UserError(f"--lab-b: the class in {folder} splits between its own two conditions: go on "
                                "with it without --lab-b")
            clerk = Clerk(folder, roster, rehearsal=rehearse, records=records,
                          warn=lambda line: say(f"armgame class: {line}"))
            sock = _bind(host, port)
        except BaseException:
            held.release()
            raise
    except BaseException:
        if temporary is not None:
            shutil.rmtree(temporary, ignore_errors=True)
        raise
    port = sock.getsockname()[1]
    join_line = f"armgame play --join {_label(host)}:{port} --code {roster.code}"
    own = {"127.0.0.1", "::1", host, *other_addresses(host)}
    play_url = f"http://{_label(host)}:{port}/play"

    def ready() -> None:
        others = other_addresses(host) if host not in ("127.0.0.1", "localhost", "::1") else []
        if rehearse:
            say(f"armgame class REHEARSAL: code {roster.code}, seed {roster.seed}; {clerk.game.config.time_limit:g} s "
                f"games, {REHEARSAL_ROUND_SECONDS} s rounds; nothing is kept (a temporary folder, removed at Ctrl-C)")
        else:
            say(f"armgame class {'started' if new else 'goes on'}: code {roster.code}, seed {roster.seed}, "
                f"{plural(len(clerk.entries), 'game')} so far, kept in {folder}")
        say(f"  students type:  {join_line} --name NAME")
        say(f"  browser:        {play_url}   (Chromebooks, tablets: nothing to install)")
        say(f"  projector:      http://{_label(host)}:{port}/?key={roster.projector_key()}   (shows the code; "
            f"the lab's class curve: /lab)")
        if secret_always:
            say(f"  teacher only:   http://{_label(host)}:{port}/teacher   (it asks for the secret in {SECRET_NAME}, "
                f"on this machine too: --teacher-secret-always)")
        else:
            say(f"  teacher only:   http://{_label(host)}:{port}/teacher   (open it in a browser on this laptop: it "
                f"asks no secret here; another machine needs the one in {SECRET_NAME})")
        if proxy is not None:
            say(f"  behind the proxy {proxy}: a machine is the last address its X-Forwarded-For names, and nothing "
                f"that comes through the proxy is this machine (the teacher's page asks for the secret there)")
        if others:
            say(f"  this machine also answers at {', '.join(others)}, if students are on that network")
        say("  the first time, Windows or macOS may ask to allow incoming connections for Python: allow it on "
            "private networks")
        if rehearse:
            say("  Ctrl-C ends the rehearsal and removes all it kept; the real class: armgame class serve")
        else:
            say(f"  Ctrl-C stops the class; to go on with it later: armgame class serve --folder {shell_path(folder)}")
        if on_ready is not None:
            on_ready(opened)

    guard = Guard(own=frozenset(own), key=roster.projector_key(), proxy=proxy or "")
    app = build_app(clerk, join_line, on_ready=ready, say=lambda line: say(f"armgame class: {line}"), guard=guard,
                    play_url=play_url, proxy=proxy, secret_always=secret_always)
    _more_files(CONCURRENCY + 256)
    config = uvicorn.Config(app, log_level="warning", access_log=False, lifespan="on",
                            timeout_graceful_shutdown=SHUTDOWN_SECONDS, timeout_keep_alive=KEEP_ALIVE_SECONDS,
                            limit_concurrency=CONCURRENCY,
                            http=guarded_protocol(guard), proxy_headers=False)
    errors = logging.getLogger("uvicorn.error")  # configured by uvicorn.Config, just above
    if not any(isinstance(f, _QuietWhenFull) for f in errors.filters):
        errors.addFilter(_QuietWhenFull())
    opened = ClassServer(clerk, sock, _class_uvicorn(config, app.state.armgame.end_streams), join_line, new, held,
                         temporary)
    return opened


def proxy_address(proxy: str | None) -> str | None:
    """``--proxy``'s address as the class compares it, or None; UserError in one line unless it is one IP address
    (uvicorn's own list, "*" or a network, would believe a header from anyone in it).

    A proxy on this machine (127.0.0.1) is allowed: it is how a teacher puts TLS in front of the class. It is made
    safe rather than refused, since whatever comes through a proxy is never the teacher's machine
    (``middleware.ForwardedFor``): on such a laptop the teacher's page asks for the secret from the proxy's address,
    and a student's own ``X-Forwarded-For: 127.0.0.1`` is a student's."""
    if proxy is None:
        return None
    import ipaddress

    try:
        return str(ipaddress.ip_address(proxy.strip().strip("[]")))
    except ValueError:
        raise UserError(f"--proxy {proxy}: not an IP address; name the one address the reverse proxy connects from "
                        f"(e.g. --proxy 127.0.0.1 for a proxy on this laptop)") from None


def _class_uvicorn(config: Any, end_streams: Callable[[], None]) -> Any:
    """uvicorn's server, which first ends the pages' event streams when it stops: a stream never ends by
    itself, so uvicorn would wait out its grace period for it and then cancel it with a traceback per page."""
    import uvicorn

    class ClassUvicorn(uvicorn.Server):
        async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
            end_streams()
            await super().shutdown(sockets)

    return ClassUvicorn(config)


def _curve_protocol(lab: str | None) -> str | dict | None:
    """``--lab``: a preset's name as it is, a protocol file as plain data (``protocol_as_dict``, kept in the class
    record, so the curve stays the file's protocol whatever becomes of the file)."""
    from ..lab.presets import PRESETS
    from ..lab.protocol_file import load_protocol, protocol_as_dict
    from ..records.storage import user_path

    if lab is None or lab in PRESETS:
        return lab
    if not lab.endswith(".toml"):
        raise UserError(f"--lab {lab}: a preset ({', '.join(PRESETS)}) or a protocol's .toml file")
    return protocol_as_dict(load_protocol(user_path(lab, "--lab")))


def _hold_folder(folder: Path) -> Any:
    """The folder's server lock, held (``filelock``: the kernel's lock, dropped when this process ends, even by
    kill -9); UserError in one line if another server holds it."""
    import filelock

    path = folder / SERVER_LOCK
    if path.is_symlink():
        raise UserError(f"{path}: is a link, not armgame's lock file: remove it")
    lock = filelock.FileLock(str(path), timeout=0, mode=0o600, thread_local=False)
    try:
        lock.acquire()
    except filelock.Timeout:
        raise UserError(f"another armgame class serve is serving {folder}: stop it first (one server a "
                        f"class)") from None
    except OSError as exc:
        raise UserError(f"{path}: cannot lock the class's folder: {exc.strerror or exc}") from None
    with contextlib.suppress(OSError):
        os.chmod(path, 0o600)
    return lock


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


def serve(folder: Path | None, host: str, port: int, seed: int | None, say: Callable[[str], None] = print,
          lab: str | None = None, proxy: str | None = None, rehearse: bool = False,
          on_ready: Callable[[ClassServer], None] | None = None, lab_b: str | None = None,
          secret_always: bool = False) -> int:
    """Run the class in ``folder`` (a rehearsal: None) on ``host:port`` until Ctrl-C (or SIGTERM); returns an exit
    status. ``on_ready``: as ``open_class``'s."""
    opened = open_class(folder, host, port, seed, say, on_ready, lab=lab, proxy=proxy, rehearse=rehearse, lab_b=lab_b,
                        secret_always=secret_always)
    opened.run()
    if opened.temporary is not None:
        played = f"{plural(len(opened.clerk.entries), 'game')} and {plural(len(opened.clerk.lab_runs), 'lab run')}"
        if opened.temporary.exists():
            say(f"armgame class rehearsal stopped: {played}; its folder could not be removed: {opened.temporary}")
            return 1
        say(f"armgame class rehearsal stopped: {played}, none kept (its folder is removed)")
        say("  the real class: armgame class serve")
        return 0
    folder = opened.clerk.folder
    where = shell_path(folder)
    say(f"armgame class stopped: {plural(len(opened.clerk.entries), 'game')} kept in {folder}")
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

