"""The student's side of a live class: join, hand in, and keep what could not be handed in.

Kept in the user's own folder (``client_folder``)::

    memberships.json          per class (by its code): every name joined under, each its token; the class's
                              seed and its game's clock (a rehearsal's games are 15 s) (``memberships``:
                              bounded, read as hostile, private)
    outbox/<code>/*.json      replays the class could not be reached for, handed in at the next join

A class is known by its code, not its address: the teacher's laptop has another address in
another room, and a game kept in one lesson is handed in when the student joins the next.

The token is what makes a name this machine's: the class keeps only its hash, and the first
machine to join under a name gets it. Plain HTTP through the standard library (``urllib``): a
student's laptop needs nothing beyond armgame's own install. Every call has a timeout; a class
that is busy (503) or asks to slow down (429) is asked again after the wait it names, a bounded
number of times; a class that cannot be reached leaves the replay in the outbox and says so in
one line that names the likely cause (a school network that keeps laptops apart).
"""

from __future__ import annotations

import contextlib
import hashlib
import http.client
import ipaddress
import json
import math
import os
import re
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import UserError
from ..records.storage import DataFileError, atomic_write_bytes, read_limited, user_path
from . import memberships
from .bounds import BUSY_PATIENCE, CLIENT_TIMEOUT, LOST_ANSWER_PAUSE, MAX_HANDIN_BYTES, MAX_OUTBOX, TICKET_TIMEOUT
from .wire import BUSY, CODE_ALPHABET, CODE_LENGTH, normal_code

CLIENT_ENV = "ARMGAME_CLASS_CLIENT"
DEFAULT_PORT = 8765
#: The requests asked again when the class took them but their answer never came: a game counts once.
_ASKED_AGAIN_SAFELY = frozenset({"/api/handin"})
_HOST = re.compile(r"[A-Za-z0-9]([A-Za-z0-9.-]{0,252})")


def client_folder() -> Path:
    """``$ARMGAME_CLASS_CLIENT``, else ``class`` in armgame's per-user data folder."""
    env = os.environ.get(CLIENT_ENV)
    if env:
        return user_path(env, f"${CLIENT_ENV}")
    from ..files import user_data_dir

    return user_data_dir() / "class"


@dataclass(frozen=True)
class ClassAddress:
    host: str
    port: int

    @classmethod
    def parse(cls, text: str, what: str = "--join") -> ClassAddress:
        """``HOST:PORT`` (or ``HOST``, the default port; ``[v6]:PORT`` for an IPv6 address)."""
        text = text.strip()
        for prefix in ("http://", "https://"):
            text = text.removeprefix(prefix)
        text = text.rstrip("/")
        host, port_text = text, str(DEFAULT_PORT)
        if text.startswith("["):
            host, _, rest = text[1:].partition("]")
            if rest.startswith(":"):
                port_text = rest[1:]
            elif rest:
                raise UserError(f"{what} {text!r}: expected HOST:PORT, e.g. 192.168.1.20:{DEFAULT_PORT}")
        elif text.count(":") == 1:
            host, port_text = text.split(":")
        try:
            port = int(port_text)
        except ValueError:
            port = -1
        if not 1 <= port <= 65535:
            raise UserError(f"{what} {text!r}: the port must be a number from 1 to 65535 (HOST:PORT, as the "
                            f"projector shows)")
        try:
            ipaddress.ip_address(host)
        except ValueError:
            if not _HOST.fullmatch(host):
                raise UserError(f"{what} {text!r}: {host!r} is not an address or a machine's name") from None
        return cls(host, port)

    @property
    def label(self) -> str:
        return f"[{self.host}]:{self.port}" if ":" in self.host else f"{self.host}:{self.port}"

    def url(self, path: str) -> str:
        return f"http://{self.label}{path}"


def check_code(text: str, what: str = "--code") -> str:
    code = normal_code(text)
    if len(code) != CODE_LENGTH:
        raise UserError(f"{what} {text!r}: a class code is {CODE_LENGTH} letters, as the projector shows it")
    never = sorted({c for c in code if c not in CODE_ALPHABET})
    if never:  # "BBBB": a letter no code holds, because a projector's font would make it another
        raise UserError(f"{what} {text!r}: no class code holds {', '.join(never)} (codes leave out letters and digits "
                        f"a projector's font confuses, such as B and 8, O and 0): check the code on the projector")
    return code


class UnreachableError(UserError):
    """The class could not be reached; the message names the address and the likely cause."""


class BadAnswerError(UnreachableError):
    """An answer that is not the class's (cut off as the server stopped, or another program at that address):
    what became of a hand-in is not known, so it is kept to be handed in again (a game counts once)."""


class RefusalError(UserError):
    """The class answered no; the message is its one line."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


def _request(address: ClassAddress, path: str, body: bytes, headers: dict[str, str],
             sleep: Callable[[float], None] = time.sleep) -> dict:
    """POST ``body``; the JSON answer. Asks a busy class again (bounded); raises UnreachableError or RefusalError.

    Busy is a 503, and for a hand-in also a class that took the connection but whose answer did not come (cut
    off, or later than ``CLIENT_TIMEOUT`` under a lecture hall's load): that is not a network problem, and asking
    again is safe (a game handed in twice counts once; a join asked again would find its name taken, so a
    join is not). Only a connection that could not be made is unreachable, with the hint about school
    networks."""
    waited = 0.0
    while True:
        req = urllib.request.Request(address.url(path), data=body, method="POST", headers=headers)
        try:
            with urllib.request.urlopen(req, timeout=CLIENT_TIMEOUT) as response:
                return _answer(response.read(1 << 20))
        except urllib.error.HTTPError as exc:
            answer = _answer(exc.read(1 << 20), quiet=True)
            message = str(answer.get("error") or (BUSY if exc.code == 503
                                                  else f"the class answered {exc.code} {exc.reason}"))
            if exc.code == 503 and waited < BUSY_PATIENCE:
                pause = _retry_after(exc.headers.get("Retry-After"))
                sleep(pause)
                waited += pause
                continue
            raise RefusalError(exc.code, message) from None
        except urllib.error.URLError as exc:  # the connection (or the request's sending) failed
            reason = getattr(exc, "reason", exc) or type(exc).__name__
            raise UnreachableError(
                f"cannot reach the class at {address.label} ({getattr(reason, 'strerror', None) or reason}): is the "
                f"class started, and is this machine on the teacher's network? (school Wi-Fi often keeps laptops "
                f"apart: docs/teaching.md, 'When students cannot join')") from None
        except (OSError, http.client.HTTPException) as exc:  # connected, but no answer: the class is busy
            if path not in _ASKED_AGAIN_SAFELY:
                raise UnreachableError(f"the class at {address.label} took the request but its answer did not "
                                       f"come ({type(exc).__name__}): it may be busy; try again in a moment") from None
            if waited >= BUSY_PATIENCE:
                raise RefusalError(503, BUSY) from exc
            sleep(LOST_ANSWER_PAUSE)
            waited += LOST_ANSWER_PAUSE


def _retry_after(value: str | None) -> float:
    try:
        return min(max(float(value or 2), 0.5), 10.0)
    except ValueError:
        return 2.0


def _answer(data: bytes, quiet: bool = False) -> dict:
    try:
        value = json.loads(data)
    except (ValueError, RecursionError):
        value = None
    if not isinstance(value, dict):
        if quiet:
            return {}
        raise BadAnswerError("the class's answer was cut off or is not armgame's (is that address an armgame "
                             "class?)")
    return value


# ------------------------------------------------------------------ memberships

@dataclass(frozen=True)
class Membership:
    """This machine in a class: where, the code, the name it joined under, its token, the class's seed."""

    address: ClassAddress
    code: str
    name: str
    token: str
    seed: int
    #: The class took no more games when this machine joined (the teacher closed it).
    closed: bool = False
    #: The class's game's clock, in seconds: the standard 60, or a rehearsal's 15 (the class takes only its own).
    duration: float = 60.0
    #: The class is a rehearsal (``armgame class serve --rehearse``): nothing it takes is kept.
    rehearsal: bool = False
    #: In a classroom experiment, the protocol the class hands this machine's lab to run (checked as any protocol
    #: file is, ``lab.protocol_file.protocol_from_dict``), or None: run the one typed.
    protocol: object = None

    @property
    def key(self) -> str:
        return self.code


def _memberships_path() -> Path:
    return client_folder() / "memberships.json"


def last_class() -> tuple[str, str, str] | None:
    """The class this machine joined last, as (address, code, name), for the menu to offer again (None: none,
    or a memberships file that cannot be read: the join itself says why)."""
    try:
        classes = memberships.read(_memberships_path())
    except DataFileError:
        return None
    if not classes:
        return None
    code, joined = max(classes.items(), key=lambda kv: kv[1].at)
    return joined.address, code, joined.names[0].name


def _remember(m: Membership) -> None:
    path = _memberships_path()
    classes = memberships.joined(memberships.read(path), m.code, m.address.label, m.seed, m.name, m.token,
                                 round(time.time(), 3), m.duration)
    memberships.write(path, classes)


def join(address: ClassAddress, code: str, name: str | None, lab: bool = False) -> Membership:
    """Join the class (or rejoin: the token kept from the last time this machine joined under the name proves
    it is this machine's; every name it joined the class under keeps its own).

    ``name`` None: the name this machine joined under last time. ``lab``: the join says it is for the lab,
    which a closed class still takes (the teacher's volunteers). Raises UnreachableError or RefusalError."""
    from ..valid import check_name, check_pattern

    code = check_code(code)
    known = memberships.read(_memberships_path()).get(code)
    if name is None:
        if known is None:
            raise UserError(f"--name is needed: this machine has not joined the class with code {code} before")
        name = known.names[0].name
    try:
        name = check_name(name, "--name")
    except ValueError as exc:
        raise UserError(str(exc)) from None
    mine = known.name(name) if known is not None else None
    body = json.dumps({"code": code, "name": name, **({"token": mine.token} if mine else {}),
                       **({"for": "lab"} if lab else {})}).encode()
    answer = _request(address, "/api/join", body, {"Content-Type": "application/json"})
    try:
        membership = Membership(address, code, check_name(answer["name"], "name"),
                                check_pattern("token", answer["token"], memberships.TOKEN), int(answer["seed"]),
                                answer.get("closed") is True, _duration(answer.get("duration", 60.0)),
                                answer.get("rehearsal") is True, _class_protocol(answer.get("lab")) if lab else None)
    except (KeyError, TypeError, ValueError):  # what is kept is what a later read takes
        raise BadAnswerError("the class's answer is not armgame's (is that address an armgame class?)") from None
    _remember(membership)
    return membership


def _class_protocol(value: object):
    """The protocol a class's join answer hands the lab (None: none), checked as a protocol file's is: ValueError
    otherwise (a hostile class's answer is no protocol)."""
    if value is None:
        return None
    if not isinstance(value, dict):
        raise ValueError("the class's lab protocol must be an object")
    from ..lab.protocol_file import protocol_from_dict

    return protocol_from_dict(value, "the class's lab protocol")


def offline(address: ClassAddress, code: str, name: str | None) -> Membership | None:
    """The membership this machine had in the class, to play while it cannot be reached (its games wait
    in the outbox); None if it never joined under that name (``name`` None: the last name it joined under)."""
    known = memberships.read(_memberships_path()).get(check_code(code))
    mine = known.name(name) if known is not None else None
    if known is None or mine is None:
        return None
    return Membership(address, check_code(code), mine.name, mine.token, known.seed, duration=known.duration)


def _duration(value: object) -> float:
    """The class's game's clock from its answer (a class from before it was sent: 60 s); ValueError if not a game's."""
    from ..limits import MAX_GAME_SECONDS

    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or \
            not 0 < value <= MAX_GAME_SECONDS:
        raise ValueError(f"not a game's length: {value!r}")
    return float(value)


# ------------------------------------------------------------------ handing in

@dataclass(frozen=True)
class HandIn:
    """What became of a replay: handed in (``answer``), refused (``refused``), or kept to hand in later."""

    message: str
    answer: dict | None = None
    kept: Path | None = None
    refused: bool = False


def outbox(m: Membership) -> Path:
    slug = re.sub(r"[^A-Za-z0-9]+", "-", m.key).strip("-")
    return client_folder() / "outbox" / slug


def start_ticket(m: Membership) -> str | None:
    """The class's start ticket for a game beginning now (a round counts a game begun during it: the hand-in sends
    it back), or None if the class did not give one at once (an older class; unreachable): never a wait longer
    than ``TICKET_TIMEOUT``, never an error. The game is played either way."""
    req = urllib.request.Request(m.address.url("/api/start"), data=b"{}", method="POST", headers={
        "Content-Type": "application/json", "Authorization": f"Bearer {m.token}", "X-Armgame-Code": m.code})
    try:
        with urllib.request.urlopen(req, timeout=TICKET_TIMEOUT) as response:
            ticket = _answer(response.read(4096), quiet=True).get("ticket")
    except urllib.error.HTTPError as exc:  # an older class (404), or this name is no longer this machine's
        exc.close()
        return None
    except (OSError, http.client.HTTPException, ValueError):
        return None
    return ticket if isinstance(ticket, str) and 0 < len(ticket) <= 64 and ticket.isascii() else None


def hand_in(m: Membership, data: bytes, keep: bool = True, ticket: str | None = None) -> HandIn:
    """Hand ``data`` (a replay's bytes) in, with the start ``ticket`` of its game if it has one (``start_ticket``).
    UnreachableError: kept in the outbox (``keep``) for the next join (without its ticket: a kept game counts on the
    board, never in a round)."""
    if len(data) > MAX_HANDIN_BYTES:
        return HandIn(f"not handed in: the replay is larger than a class takes ({MAX_HANDIN_BYTES:,} bytes)",
                      refused=True)
    headers = {"Content-Type": "application/json", "Authorization": f"Bearer {m.token}", "X-Armgame-Code": m.code,
               **({"X-Armgame-Start": ticket} if ticket else {})}
    try:
        answer = _request(m.address, "/api/handin", data, headers)
    except RefusalError as exc:
        if exc.status == 503 and keep:  # still busy after a minute: nothing lost, it goes at the next join
            return _kept(m, data, "the class is busy")
        return HandIn(f"not handed in: {exc}", refused=True)
    except UnreachableError:
        if not keep:
            raise
        # This machine joined, so the network reached the class: a class that does not answer now is busy or
        # stopped for a moment, not a matter of the Wi-Fi.
        return _kept(m, data, f"the class at {m.address.label} did not answer (busy, or stopped for a moment)")
    return HandIn(str(answer.get("message", "handed in")), answer)


def _kept(m: Membership, data: bytes, why: str) -> HandIn:
    folder = outbox(m)
    path = folder / f"{hashlib.sha256(data).hexdigest()[:20]}.json"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        if len(list(folder.glob("*.json"))) >= MAX_OUTBOX:
            raise DataFileError(f"{folder} already holds {MAX_OUTBOX} replays")
        atomic_write_bytes(path, data, "replay")
    except (OSError, DataFileError) as exc:
        return HandIn(f"not handed in ({why}); and the replay could not be kept: {exc}", refused=True)
    return HandIn(f"not handed in yet: {why}; your game is kept and will be handed in the next time you join",
                  kept=path)


def send_outbox(m: Membership) -> list[str]:
    """Hand in what the outbox holds for this class; a line for each. What is handed in or refused leaves
    the outbox (a refusal is final: the file is kept beside, renamed .refused); unreachable stays."""
    folder = outbox(m)
    if not folder.is_dir():
        return []
    lines = []
    for path in sorted(folder.glob("*.json")):
        try:
            data = read_limited(path, MAX_HANDIN_BYTES, "kept replay", follow=False)
        except DataFileError as exc:
            lines.append(f"{path.name}: {exc}")
            continue
        try:
            result = hand_in(m, data, keep=False)
        except UnreachableError:
            break
        lines.append(f"a game kept from before: {result.message}")
        with contextlib.suppress(OSError):
            if result.refused:
                path.replace(path.with_suffix(".refused"))
            else:
                path.unlink()
    return lines
