"""The class's ASGI application: Starlette routes in front of the clerk thread.

Every request is hostile until checked, and what it can cost is bounded before any work starts
(a connection's own costs, before it is a request, are ``guard``'s):

* only the class's own pages can change anything: a state-changing request must be JSON
  (``Content-Type: application/json``, which a page on another site cannot send without a
  preflight the class never grants), and its ``Origin`` and ``Sec-Fetch-Site``, where sent, must
  be the class's own; every request must name the class by an address, never by a domain name
  (``Host``), so a hostile page cannot rebind its own name to the class;
* wrong join codes, wrong teacher's secrets and wrong tokens are counted apart, per client address
  (``Guesses``): ``FREE_GUESSES`` of each, then a wait that doubles with every further wrong one,
  so a four-letter code (160,000 of them) is beyond guessing (about a dozen tries an hour from an
  address) while a student who mistyped it waits a minute; a right answer clears the count, and
  the teacher's own machine is never locked out of the teacher's routes;
* new names are limited per address (``JOINS_PER_MINUTE``) and for the whole class
  (``CLASS_JOINS_PER_MINUTE``); the teacher sees which names came from one address, removes them
  at once, and can lock the roster;
* a body over its limit is refused from its declared length, or cut off as it arrives (413);
  a body slower than ``BODY_SECONDS`` is cut off (408); at most ``UPLOADS`` bodies are read at
  once, ``UPLOADS_PER_ADDRESS`` from one address, and a hand-in's code and token are checked
  from its headers before its body is read, so memory stays under ``UPLOADS * MAX_HANDIN_BYTES``
  (and the queued bodies under ``QUEUE_BYTES``) whatever arrives;
* changes go to one worker thread (the ``Clerk``), never the event loop; at most ``QUEUE_LIMIT``
  jobs and ``HANDIN_QUEUE`` hand-ins wait for it, one hand-in a player (``TOKEN_SHARE``, checked
  before the body is read, with the token and a closed class), and past that a client is told to
  come back (503 with Retry-After): its replay stays on its machine, and the client hands it in again;
* a hand-in is answered only after the clerk has written it durably (fsynced file and folder);
* the projector's event stream sends the latest standings, never a backlog, to at most
  ``MAX_STREAMS`` pages, ``STREAMS_PER_ADDRESS`` from one address; the projector's own page
  (its link's key, or the teacher's machine) always gets its stream;
* the join code is in no answer a stranger can fetch: the standings carry it only to the projector's
  link (``?key=``, printed in the teacher's terminal) and to the teacher's machine.

Responses are JSON (``{"ok": false, "error": "one line"}`` when refused) or the static pages,
served with a content security policy that allows no inline script: names reach a page only as
data that its script sets as text.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import gc
import hmac
import ipaddress
import json
import math
import queue
import socket
import sys
import threading
import time
from collections import Counter, OrderedDict, deque
from collections.abc import AsyncIterator, Callable, Iterator
from concurrent.futures import Future
from contextlib import asynccontextmanager, contextmanager
from dataclasses import dataclass, field
from typing import Any

from starlette.applications import Starlette
from starlette.requests import ClientDisconnect, Request
from starlette.responses import Response, StreamingResponse
from starlette.routing import Route

from ..errors import UserError
from . import page
from .guard import Guard
from .intake import AGAIN, CLOSED, MAX_HANDIN_BYTES, NOT_JOINED, Clerk, RefusedError
from .roster import token_digest

#: Jobs (a join, the teacher's requests) waiting for the clerk at once; past it, 503 and the client comes back.
#: A join rewrites the roster, so a lecture hall's joins are let in a few at a time.
QUEUE_LIMIT = 64
#: Hand-ins waiting for the clerk at once. One checked and entered in a batch costs the clerk 2.5 ms (a bot's
#: game 60 ms): room for a lecture hall's round's end (``benchmarks/class_server.py``), where a queue of 64
#: sent nine students in ten away for 2 s, again and again.
HANDIN_QUEUE = 1024
#: The bodies those waiting hand-ins hold, in bytes at the most (a bot's game is 0.5 MB, a student's 9 KB).
QUEUE_BYTES = 64 * 1024 * 1024
#: Hand-ins of one player (one token) waiting at once: a client that floods the class has one in the queue,
#: and its next is told the class is busy before its body is read, so a flooder's backlog never sits in
#: front of an honest student's game.
TOKEN_SHARE = 1
#: Seconds a player's next hand-in is told the class is busy after one of theirs did not reproduce its score
#: (422, found only by re-simulating it): a forger's next game waits its turn behind the honest students'
#: instead of taking the clerk's time at once. An honest student's game is never refused so. A body that is
#: not a class's game (400, 413) is refused before any re-simulation, cheaply, and does not count.
COOL_DOWN = 2.0
#: Hand-ins checked, re-simulated (one batch) and entered (one table write) together at the most.
BATCH = 64
#: Seconds a hand-in waits for one of the ``UPLOADS`` slots before it is told the class is busy.
UPLOAD_WAIT = 5.0
#: What a student is told when the class cannot take their game yet (their client hands it in again).
BUSY = "the class is busy: your game is kept and will be handed in in a moment"
UPLOADS = 16
UPLOADS_PER_ADDRESS = 2
#: Within the connection's own deadline (``guard.REQUEST_SECONDS``), so the app answers 408 first.
BODY_SECONDS = 12.0
MAX_JSON_BYTES = 4096
MAX_STREAMS = 64
STREAMS_PER_ADDRESS = 4
HEARTBEAT_SECONDS = 15.0
#: Wrong answers of one kind an address may give before it waits; then ``GUESS_WAIT`` seconds, doubled
#: for every further wrong one (at most ``MAX_GUESS_WAIT``).
FREE_GUESSES = 5
GUESS_WAIT = 60.0
MAX_GUESS_WAIT = 3600.0
MAX_TRACKED_ADDRESSES = 10_000
JOINS_PER_MINUTE = 3
CLASS_JOINS_PER_MINUTE = 120
SECURITY_HEADERS = {
    "Content-Security-Policy": "default-src 'none'; script-src 'self'; style-src 'self'; connect-src 'self'; "
                               "img-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'",
    "Cross-Origin-Resource-Policy": "same-origin",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-store",
}


class Guesses:
    """Wrong answers of one kind (codes, secrets or tokens) per client address: ``FREE_GUESSES``, then a
    wait that doubles with each further wrong one; a right answer clears the address. Bounded in
    addresses kept (the oldest forgotten first)."""

    def __init__(self, free: int = FREE_GUESSES, wait: float = GUESS_WAIT,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.free, self.wait, self.clock = free, wait, clock
        self.seen: OrderedDict[str, tuple[int, float]] = OrderedDict()  # address: (wrong so far, blocked until)

    def blocked_for(self, address: str) -> float:
        """Seconds ``address`` must still wait before its answer is looked at (0: none)."""
        until = self.seen.get(address, (0, 0.0))[1]
        return max(0.0, until - self.clock())

    def blocked(self, address: str) -> bool:
        return self.blocked_for(address) > 0.0

    def failed(self, address: str) -> None:
        wrong, _ = self.seen.pop(address, (0, 0.0))
        wrong += 1
        until = 0.0
        if wrong >= self.free:
            until = self.clock() + min(MAX_GUESS_WAIT, self.wait * 2 ** min(wrong - self.free, 20))
        self.seen[address] = (wrong, until)
        while len(self.seen) > MAX_TRACKED_ADDRESSES:
            self.seen.popitem(last=False)

    def succeeded(self, address: str) -> None:
        self.seen.pop(address, None)


class Window:
    """Events per key in a sliding window (joins per address): bounded in keys kept."""

    def __init__(self, limit: int, seconds: float = 60.0, clock: Callable[[], float] = time.monotonic) -> None:
        self.limit, self.seconds, self.clock = limit, seconds, clock
        self.seen: OrderedDict[str, deque[float]] = OrderedDict()

    def full(self, key: str) -> bool:
        times = self.seen.get(key)
        if times is None:
            return False
        while times and times[0] <= self.clock() - self.seconds:
            times.popleft()
        return len(times) >= self.limit

    def add(self, key: str) -> None:
        times = self.seen.setdefault(key, deque())
        self.seen.move_to_end(key)
        times.append(self.clock())
        while len(self.seen) > MAX_TRACKED_ADDRESSES:
            self.seen.popitem(last=False)


class ClerkThread:
    """The clerk's one thread. Jobs run in the order they came; hand-ins waiting together are checked
    one by one and entered together (``Clerk.enter``: one table write for a burst, each answer sent
    only after that write). ``after`` runs on the thread after every job (the pages' data rebuilt)."""

    def __init__(self, clerk: Clerk, after: Callable[[], None]) -> None:
        self.clerk, self.after = clerk, after
        self.jobs: queue.SimpleQueue[tuple[str, Any, Future | None]] = queue.SimpleQueue()
        self.thread = threading.Thread(target=self._serve, name="armgame-clerk", daemon=True)
        self.thread.start()

    def submit(self, kind: str, work: Any) -> Future:
        """``kind`` "job": ``work()`` is run; "hand-in": ``work`` is (token, body) to check and enter."""
        future: Future = Future()
        self.jobs.put((kind, work, future))
        return future

    def stop(self) -> None:
        """The jobs already queued are finished (a hand-in being written is never cut), then the thread ends."""
        self.jobs.put(_STOP)
        self.thread.join()
        try:  # the journal of the games taken, into the table's one file (read either way if this fails)
            self.clerk.table.compact()
        except Exception as exc:
            print(f"armgame class: the table's journal stays beside it: {exc}", file=sys.stderr)

    def _serve(self) -> None:
        held = None
        while True:
            job = held if held is not None else self.jobs.get()
            held = None
            if job is _STOP:
                return
            if job[0] == "job":
                outcomes = [(job[2], _outcome(job[1]))]
            else:
                batch = [job]
                while len(batch) < BATCH:  # what arrived meanwhile goes in the same write
                    try:
                        more = self.jobs.get_nowait()
                    except queue.Empty:
                        break
                    if more[0] != "hand-in":
                        held = more
                        break
                    batch.append(more)
                outcomes = self._hand_in(batch)
            try:
                self.after()  # before any answer goes out: a client that asks next sees its own game
            except Exception as exc:
                print(f"armgame class: the pages' data could not be rebuilt: {exc}", file=sys.stderr)
            for future, outcome in outcomes:
                if isinstance(outcome, BaseException):
                    future.set_exception(outcome)
                else:
                    future.set_result(outcome)

    def _hand_in(self, batch: list[tuple[str, Any, Future]]) -> list[tuple[Future, Any]]:
        """Each hand-in's answer (or the exception to raise in its request): the batch checked together
        (``Clerk.check_many``: its games re-simulated in one batch), then entered together; a game the batch
        held twice is checked again after that, as the next batch would (``AGAIN``)."""
        # The cyclic garbage collector paused for the batch: reading a bot's game makes 15,000 events and their
        # lists, no cycle among them, and the collections they set off (each also walking every object the
        # server holds) were a third of such a hand-in's cost (104 ms against 65 ms, measured in-process).
        # Reference counting still frees them; what cycles there are wait for the next collection.
        collecting = gc.isenabled()
        gc.disable()
        try:
            return self._hand_in_batch(batch)
        finally:
            if collecting:
                gc.enable()

    def _hand_in_batch(self, batch: list[tuple[str, Any, Future]]) -> list[tuple[Future, Any]]:
        outcomes: list[tuple[Future, Any]] = []
        while batch:
            again = []
            checked = []
            found_all = _outcome(lambda batch=batch: self.clerk.check_many([work for _, work, _ in batch]))
            if isinstance(found_all, BaseException):
                found_all = [found_all] * len(batch)
            for job, found in zip(batch, found_all, strict=True):
                if found is AGAIN:
                    again.append(job)
                elif isinstance(found, BaseException | dict):
                    outcomes.append((job[2], found))
                else:
                    checked.append((found, job[2]))
            if checked:
                answers = _outcome(lambda checked=checked: self.clerk.enter([c for c, _ in checked]))
                if isinstance(answers, BaseException):
                    answers = [answers] * len(checked)
                outcomes += [(future, answer) for (_, future), answer in zip(checked, answers, strict=True)]
            batch = again
        return outcomes


_STOP: tuple[str, Any, Future | None] = ("stop", None, None)


def _outcome(work: Callable[[], Any]) -> Any:
    """What ``work()`` returns, or the exception it raised (for the request that asked for it)."""
    try:
        return work()
    except BaseException as exc:
        return exc


@dataclass
class ClassState:
    """What the routes share: the clerk and its thread, and what the pages read (built on that thread)."""

    clerk: Clerk
    join_line: str
    guard: Guard = field(default_factory=Guard)
    play_url: str = ""
    worker: ClerkThread | None = None
    waiting: int = 0  # jobs
    handins: int = 0
    #: Hand-ins waiting (their bodies being read or queued) by token digest, and the bytes queued.
    shares: dict[str, int] = field(default_factory=dict)
    queued_bytes: int = 0
    #: Token digests whose hand-in was refused, and until when (``time.monotonic``) their next one is busy.
    cooling: dict[str, float] = field(default_factory=dict)
    codes: Guesses = field(default_factory=Guesses)
    secrets: Guesses = field(default_factory=Guesses)
    tokens: Guesses = field(default_factory=Guesses)
    joins: Window = field(default_factory=lambda: Window(JOINS_PER_MINUTE))
    class_joins: Window = field(default_factory=lambda: Window(CLASS_JOINS_PER_MINUTE))
    uploads: asyncio.Semaphore = field(default_factory=lambda: asyncio.Semaphore(UPLOADS))
    uploading: Counter[str] = field(default_factory=Counter)
    streams: int = 0
    streaming: Counter[str] = field(default_factory=Counter)
    #: What anyone may read, and what the projector's link and the teacher's machine read (the join line).
    snapshot: bytes = b"{}"
    projector_snapshot: bytes = b"{}"
    lab: bytes = b"{}"
    seen_version: int = -1
    seen_lab_version: int = -1
    changed: asyncio.Event = field(default_factory=asyncio.Event)
    stopping: asyncio.Event = field(default_factory=asyncio.Event)

    def publish(self) -> None:
        """On the clerk's thread: the pages' data, rebuilt after a change (never read half-built)."""
        if self.clerk.version != self.seen_version:
            self.seen_version = self.clerk.version
            standings = self.clerk.standings()
            standings["play"] = self.play_url
            self.snapshot = json.dumps({**standings, "join": None}, ensure_ascii=True).encode()
            self.projector_snapshot = json.dumps({**standings, "join": self.join_line}, ensure_ascii=True).encode()
        if self.clerk.lab_version != self.seen_lab_version:  # a game handed in leaves the curve as it was
            self.seen_lab_version = self.clerk.lab_version
            self.lab = json.dumps(self.clerk.lab_curve(), ensure_ascii=True, allow_nan=False).encode()

    def end_streams(self) -> None:
        """On the server's loop, as it begins to stop: every event stream ends now, so the pages' connections
        close at once and the stop never waits out its grace for them (nor cancels them with a traceback)."""
        self.stopping.set()
        self.changed.set()

    def projector(self, request: Request) -> bool:
        """Whether ``request`` is the projector's (its link's key) or the teacher's machine's."""
        key = request.query_params.get("key", "")
        return self.guard.is_own(_address(request)) or (
            len(key) <= 64 and hmac.compare_digest(key.encode(), self.clerk.roster.projector_key().encode()))

    async def run(self, job: Callable[[], Any], kind: str = "job") -> Any:
        """``job`` on the clerk's thread (or, for "hand-in", ``job`` is (token, body)), if the queue has
        room (``QUEUE_LIMIT`` jobs; ``HANDIN_QUEUE`` hand-ins and ``QUEUE_BYTES`` of their bodies); the pages
        are told of any change."""
        handin = kind == "hand-in"
        size = len(job[1]) if handin else 0  # type: ignore[index]
        if (self.handins >= HANDIN_QUEUE or self.queued_bytes + size > QUEUE_BYTES) if handin \
                else self.waiting >= QUEUE_LIMIT:
            raise RefusedError(503, BUSY)
        assert self.worker is not None, "the class is not serving"
        self.waiting += not handin
        self.handins += handin
        self.queued_bytes += size
        try:
            return await asyncio.wrap_future(self.worker.submit(kind, job))
        finally:
            self.waiting -= not handin
            self.handins -= handin
            self.queued_bytes -= size
            self.changed.set()
            self.changed = asyncio.Event()

    @contextmanager
    def hand_in_share(self, token: str) -> Iterator[None]:
        """A joined player's hand-in's place (``_check_token`` found the token a player's), taken before its
        body is read, with the refusals that cost nothing: a closed class (403), a player who already has
        ``TOKEN_SHARE`` hand-ins waiting or whose last one did not reproduce less than ``COOL_DOWN`` s ago (503:
        the client hands it in again in a moment). The clerk checks the token and the class again: a name may
        be released meanwhile."""
        digest = token_digest(token)
        if self.clerk.roster.closed:
            raise RefusedError(403, CLOSED)
        if self.shares.get(digest, 0) >= TOKEN_SHARE:
            raise RefusedError(503, BUSY)
        if digest in self.cooling:
            if self.cooling[digest] > time.monotonic():
                raise RefusedError(503, BUSY)
            del self.cooling[digest]
        self.shares[digest] = self.shares.get(digest, 0) + 1
        try:
            yield
        except RefusedError as exc:
            if exc.status == 422:
                self.cooling[digest] = time.monotonic() + COOL_DOWN
            raise
        finally:
            if self.shares[digest] <= 1:
                del self.shares[digest]
            else:
                self.shares[digest] -= 1


def _json(data: object, status: int = 200, headers: dict[str, str] | None = None) -> Response:
    body = json.dumps(data, ensure_ascii=True, allow_nan=False).encode()
    return Response(body, status, {**SECURITY_HEADERS, **(headers or {})}, media_type="application/json")


def _refusal(exc: RefusedError) -> Response:
    headers = {"Retry-After": str(getattr(exc, "retry_after", 2))} if exc.status in (429, 503) else {}
    if exc.status in (400, 401, 403, 408, 413, 415, 429, 503):  # a body may be left unread: the connection ends
        headers["Connection"] = "close"
    return _json({"ok": False, "error": exc.message}, exc.status, headers)


def _address(request: Request) -> str:
    return request.client.host if request.client else "unknown"


def _bearer(request: Request) -> str | None:
    value = request.headers.get("authorization", "")
    scheme, _, token = value.partition(" ")
    return token.strip() or None if scheme.lower() == "bearer" and len(token) <= 200 else None


def _waiting(guesses: Guesses, address: str, what: str) -> None:
    wait = guesses.blocked_for(address)
    if wait > 0:
        refusal = RefusedError(429, f"too many wrong {what} from this machine: wait {math.ceil(wait)} s, then check "
                                    f"it again")
        refusal.retry_after = math.ceil(wait)  # type: ignore[attr-defined]
        raise refusal


@functools.cache
def _own_names() -> frozenset[str]:
    """The names this machine answers to besides its addresses (asked once, not at every request)."""
    host = socket.gethostname().lower()
    return frozenset({"localhost", host, host + ".local"})


def _named_by_address(host: str) -> bool:
    """Whether a ``Host`` header names this server by an address (or localhost), never by a domain name a
    hostile page could point at the class (DNS rebinding)."""
    name = host.rsplit(":", 1)[0] if not host.endswith("]") else host
    name = name.strip("[]").lower()
    if name in _own_names():
        return True
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def _same_site(request: Request) -> None:
    """A request the class's own pages or the student's client could have sent (see the module); else refused."""
    if not _named_by_address(request.headers.get("host", "")):
        raise RefusedError(421, "this class answers at its address only (as printed in the teacher's terminal)")
    if request.method == "GET":
        return
    media = request.headers.get("content-type", "").split(";", 1)[0].strip().lower()
    if media != "application/json":
        raise RefusedError(415, "the class takes JSON only (Content-Type: application/json)")
    if request.headers.get("sec-fetch-site", "same-origin") not in ("same-origin", "none"):
        raise RefusedError(403, "the class takes changes from its own pages only")
    origin = request.headers.get("origin")
    if origin is not None and origin not in (f"http://{request.headers.get('host', '')}",
                                             f"https://{request.headers.get('host', '')}"):
        raise RefusedError(403, "the class takes changes from its own pages only")


async def _body(request: Request, limit: int) -> bytes:
    """The request's body, at most ``limit`` bytes, within ``BODY_SECONDS``; else RefusedError."""
    declared = request.headers.get("content-length")
    if declared is not None and (not declared.isdigit() or int(declared) > limit):
        raise RefusedError(413, f"the body is larger than a class takes ({limit:,} bytes)")
    chunks, size = [], 0
    try:
        async with asyncio.timeout(BODY_SECONDS):
            async for chunk in request.stream():
                size += len(chunk)
                if size > limit:
                    raise RefusedError(413, f"the body is larger than a class takes ({limit:,} bytes)")
                chunks.append(chunk)
    except TimeoutError:
        raise RefusedError(408, f"the body took longer than {BODY_SECONDS:g} s to arrive") from None
    except ClientDisconnect:
        raise RefusedError(400, "the client went away before its body arrived") from None
    return b"".join(chunks)


async def _json_body(request: Request) -> dict[str, Any]:
    data = await _body(request, MAX_JSON_BYTES)
    try:
        value = json.loads(data)
    except (ValueError, RecursionError):
        raise RefusedError(400, "the body is not JSON") from None
    if not isinstance(value, dict):
        raise RefusedError(400, "the body must be a JSON object")
    return value


def _check_code(state: ClassState, request: Request, typed: object) -> None:
    address = _address(request)
    _waiting(state.codes, address, "codes")
    if not isinstance(typed, str) or len(typed) > 20 or not state.clerk.roster.code_matches(typed):
        state.codes.failed(address)
        raise RefusedError(403, "wrong class code: check the code on the projector")
    state.codes.succeeded(address)


def _check_secret(state: ClassState, request: Request) -> None:
    """The teacher's routes: the teacher's own machine is the teacher (no secret to type, so none is ever shown
    where the room can read it; never made to wait); any other machine needs the secret, from the Authorization
    header, its wrong guesses counted apart."""
    address = _address(request)
    if state.guard.is_own(address):
        return
    _waiting(state.secrets, address, "secrets")
    secret = _bearer(request)
    if secret is None or not state.clerk.roster.secret_matches(secret):
        state.secrets.failed(address)
        raise RefusedError(403, "the teacher's secret is needed for this on another machine than the teacher's (it "
                                "is in the file teacher.secret in the class's folder)")
    state.secrets.succeeded(address)


def _check_token(state: ClassState, request: Request) -> str:
    """The hand-in's token, a joined player's, from its headers (before any body is read)."""
    address = _address(request)
    _waiting(state.tokens, address, "tokens")
    token = _bearer(request)
    if token is None or state.clerk.roster.player_of(token) is None:
        state.tokens.failed(address)
        raise RefusedError(401, NOT_JOINED)
    state.tokens.succeeded(address)
    return token


def _refusals(handler: Callable[[Request], Any]) -> Callable[[Request], Any]:
    async def wrapped(request: Request) -> Response:
        try:
            _same_site(request)
            return await handler(request)
        except RefusedError as exc:
            return _refusal(exc)
        except UserError as exc:  # a file the clerk could not write: one line, nothing entered; no path for the room
            print(f"armgame class: {request.method} {request.url.path}: {exc}"[:300], file=sys.stderr)
            return _refusal(RefusedError(503, "the class could not write this down (the teacher's terminal says "
                                              "why); nothing was entered, and your machine keeps what it sent"))
        except Exception as exc:  # a bug: the request gets one line, the teacher's terminal one line, the class goes on
            print(f"armgame class: {request.method} {request.url.path}: {type(exc).__name__}: {exc}"[:300],
                  file=sys.stderr)
            return _refusal(RefusedError(500, "the class could not take this request (the teacher's terminal says "
                                              "why); nothing was entered"))
    return wrapped


@contextlib.contextmanager
def _share(counter: Counter[str], address: str, limit: int, own: bool, what: str) -> Iterator[None]:
    """One of ``address``'s ``limit`` places in ``counter`` for the block (the teacher's machine: no limit)."""
    if not own and counter[address] >= limit:
        raise RefusedError(503, what)
    counter[address] += 1
    try:
        yield
    finally:
        counter[address] -= 1
        if counter[address] <= 0:
            del counter[address]


def build_app(clerk: Clerk, join_line: str, on_ready: Callable[[], None] | None = None,
              say: Callable[[str], None] = lambda line: None, guard: Guard | None = None,
              play_url: str = "") -> Starlette:
    """The class's app over ``clerk`` (already open on its folder); ``join_line`` is what students type;
    ``on_ready`` is called once the server takes requests; ``say`` gets one-line notices for the teacher;
    ``guard`` knows the teacher's own machine's addresses (``guard.Guard``); ``play_url`` is the browser
    game's address (``/play``) as students reach it, for the projector's QR code."""
    state = ClassState(clerk, join_line, guard or Guard(), play_url)

    async def load_lab() -> None:
        for problem in await state.run(clerk.load_lab):
            say(f"left out of the class curve: {problem}")

    async def round_clock() -> None:
        """A round's end is a change no request makes: looked for every second while a round is on, so the
        projector shows its winners as its clock runs out."""
        while not state.stopping.is_set():
            await asyncio.sleep(1.0)
            if clerk.roster.round is not None and not clerk.round_over:
                with contextlib.suppress(RefusedError):
                    await state.run(clerk.round_ended)

    @asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        state.worker = ClerkThread(clerk, state.publish)
        await state.run(lambda: None)  # the first snapshot
        if on_ready is not None:
            on_ready()
        # The lab runs already in the folder are checked again in the background: the page is up at once.
        loading = asyncio.ensure_future(load_lab())
        ticking = asyncio.ensure_future(round_clock())
        try:
            yield
        finally:
            state.stopping.set()
            state.changed.set()
            loading.cancel()
            ticking.cancel()
            state.worker.stop()  # a hand-in being written is finished, never cut

    async def home(request: Request) -> Response:
        return page.response("standings.html", SECURITY_HEADERS)

    async def lab_page(request: Request) -> Response:
        return page.response("lab.html", SECURITY_HEADERS)

    async def teacher_page(request: Request) -> Response:
        return page.response("teacher.html", SECURITY_HEADERS)

    async def play_page(request: Request) -> Response:
        return page.response("play.html", SECURITY_HEADERS)

    async def play_qr(request: Request) -> Response:
        if not play_url:
            raise RefusedError(404, "no such page")
        return Response(page.qr_svg(play_url), 200, SECURITY_HEADERS, media_type="image/svg+xml")

    async def asset(request: Request) -> Response:
        return page.response(request.path_params["name"], SECURITY_HEADERS)

    async def standings(request: Request) -> Response:
        data = state.projector_snapshot if state.projector(request) else state.snapshot
        return Response(data, 200, SECURITY_HEADERS, media_type="application/json")

    async def lab(request: Request) -> Response:
        return Response(state.lab, 200, SECURITY_HEADERS, media_type="application/json")

    async def events(request: Request) -> Response:
        address = _address(request)
        projector = state.projector(request)
        own = state.guard.is_own(address)
        if state.streams >= MAX_STREAMS and not projector:
            raise RefusedError(503, "too many pages are open on this class")
        if not own and state.streaming[address] >= STREAMS_PER_ADDRESS:
            raise RefusedError(503, "too many pages of this class are open on this machine: close one")
        state.streams += 1
        state.streaming[address] += 1

        async def stream() -> AsyncIterator[bytes]:
            try:
                sent = None
                while not state.stopping.is_set():
                    current = state.projector_snapshot if projector else state.snapshot
                    if current is not sent:
                        sent = current
                        yield b"event: standings\ndata: " + sent + b"\n\n"
                        yield b"event: lab\ndata: " + state.lab + b"\n\n"
                    changed = state.changed
                    try:
                        await asyncio.wait_for(changed.wait(), HEARTBEAT_SECONDS)
                    except TimeoutError:
                        yield b": still here\n\n"
            finally:
                state.streams -= 1
                state.streaming[address] -= 1
                if state.streaming[address] <= 0:
                    del state.streaming[address]

        return StreamingResponse(stream(), headers={**SECURITY_HEADERS, "X-Accel-Buffering": "no"},
                                 media_type="text/event-stream")

    async def join(request: Request) -> Response:
        address = _address(request)
        body = await _json_body(request)
        _check_code(state, request, body.get("code"))
        token = body.get("token")
        if token is not None and (not isinstance(token, str) or len(token) > 200):
            raise RefusedError(400, "token must be a string")
        own = state.guard.is_own(address)
        known = token is not None and clerk.roster.player_of(token) is not None
        if not known and not own:
            if state.joins.full(address):
                raise RefusedError(429, f"this machine has joined {JOINS_PER_MINUTE} names in the last minute: one "
                                        f"name a student; ask the teacher if you need another")
            if state.class_joins.full("class"):
                raise RefusedError(503, "many names are joining at once: try again in a moment")
        player, new_token = await state.run(lambda: clerk.join(body.get("name"), token, address))
        if new_token is not None and not own:
            state.joins.add(address)
            state.class_joins.add("class")
        return _json({"ok": True, "name": player.name, "token": new_token or token, "seed": clerk.roster.seed,
                      "closed": clerk.roster.closed,
                      "message": f"joined the class as {player.name}" if new_token is None
                      else f"joined the class as {player.name} (the name is now this machine's)"})

    async def hand_in(request: Request) -> Response:
        address = _address(request)
        _check_code(state, request, request.headers.get("x-armgame-code"))
        token = _check_token(state, request)
        with state.hand_in_share(token), _share(state.uploading, address, UPLOADS_PER_ADDRESS,
                                                 state.guard.is_own(address), BUSY):
            # the token's and the machine's places taken before the body is read: a flooder's next costs nothing
            try:
                async with asyncio.timeout(UPLOAD_WAIT):
                    await state.uploads.acquire()
            except TimeoutError:
                raise RefusedError(503, BUSY) from None
            try:
                data = await _body(request, MAX_HANDIN_BYTES)
            finally:
                state.uploads.release()
            return _json(await state.run((token, data), "hand-in"))

    def teacher_action(act: Callable[[dict[str, Any]], str]) -> Callable[[Request], Any]:
        """A teacher's change: the secret (or the teacher's machine), the JSON body, ``act(body)`` on the clerk's
        thread, its one line back."""
        async def route(request: Request) -> Response:
            _check_secret(state, request)
            body = await _json_body(request)
            return _json({"ok": True, "message": await state.run(lambda: act(body))})
        return route

    def start_or_stop_round(body: dict[str, Any]) -> str:
        return clerk.stop_round() if body.get("stop") is True else clerk.start_round(body.get("minutes"))

    teacher_hide = teacher_action(lambda b: clerk.hide(b.get("name"), bool(b.get("hidden", True))))
    teacher_release = teacher_action(lambda b: clerk.release(b.get("name")))
    teacher_rename = teacher_action(lambda b: clerk.rename(b.get("name"), b.get("to")))
    teacher_remove = teacher_action(lambda b: clerk.remove(b.get("names")))
    teacher_close = teacher_action(lambda b: clerk.close(bool(b.get("closed", True))))
    teacher_lock = teacher_action(lambda b: clerk.lock(bool(b.get("locked", True))))
    teacher_lab = teacher_action(lambda b: clerk.choose_lab(b.get("protocol")))
    teacher_round = teacher_action(start_or_stop_round)

    async def teacher_standings(request: Request) -> Response:
        _check_secret(state, request)
        return _json(await state.run(lambda: clerk.standings(teacher=True)))

    async def teacher_roster(request: Request) -> Response:
        _check_secret(state, request)
        return _json(await state.run(clerk.roster_view))

    def csv_route(make: Callable[[], str], filename: str) -> Callable[[Request], Any]:
        async def route(request: Request) -> Response:
            _check_secret(state, request)
            text = await state.run(make)
            return Response(text.encode("utf-8"), 200, {**SECURITY_HEADERS, "Content-Disposition":
                                                        f'attachment; filename="{filename}"'},
                            media_type="text/csv; charset=utf-8")
        return route

    async def teacher_lab_png(request: Request) -> Response:
        """The class curve as the lab's figure draws it (a PNG for a report), where matplotlib is installed."""
        _check_secret(state, request)
        from ..lab.figures import class_figure_png, require_matplotlib

        try:
            require_matplotlib()
        except UserError:
            raise RefusedError(503, "the lab curve's picture needs matplotlib on the teacher's machine: pip install "
                                    "'armgame[plot]' (the lab's CSV needs nothing)") from None

        def draw() -> bytes | None:  # on the clerk's thread: the curve as it is now, and one drawing at a time
            curve = clerk.class_curve()
            return class_figure_png(curve.trials, metric=curve.metric) if curve.students else None
        png = await state.run(draw)
        if png is None:
            raise RefusedError(404, "no class curve yet: no volunteer's run of the class's protocol")
        return Response(png, 200, {**SECURITY_HEADERS, "Content-Disposition":
                                   'attachment; filename="class-lab-curve.png"'}, media_type="image/png")

    routes = [
        Route("/", _refusals(home)),
        Route("/lab", _refusals(lab_page)),
        Route("/teacher", _refusals(teacher_page)),
        Route("/play", _refusals(play_page)),
        Route("/play.svg", _refusals(play_qr)),
        Route("/static/{name}", _refusals(asset)),
        Route("/api/standings", _refusals(standings)),
        Route("/api/lab", _refusals(lab)),
        Route("/events", _refusals(events)),
        Route("/api/join", _refusals(join), methods=["POST"]),
        Route("/api/handin", _refusals(hand_in), methods=["POST"]),
        Route("/api/teacher/hide", _refusals(teacher_hide), methods=["POST"]),
        Route("/api/teacher/release", _refusals(teacher_release), methods=["POST"]),
        Route("/api/teacher/remove", _refusals(teacher_remove), methods=["POST"]),
        Route("/api/teacher/rename", _refusals(teacher_rename), methods=["POST"]),
        Route("/api/teacher/close", _refusals(teacher_close), methods=["POST"]),
        Route("/api/teacher/lock", _refusals(teacher_lock), methods=["POST"]),
        Route("/api/teacher/lab", _refusals(teacher_lab), methods=["POST"]),
        Route("/api/teacher/round", _refusals(teacher_round), methods=["POST"]),
        Route("/api/teacher/standings", _refusals(teacher_standings)),
        Route("/api/teacher/roster", _refusals(teacher_roster)),
        Route("/api/teacher/games.csv", _refusals(csv_route(clerk.games_csv, "class-games.csv"))),
        Route("/api/teacher/lab.csv", _refusals(csv_route(clerk.lab_csv, "class-lab-reaches.csv"))),
        Route("/api/teacher/lab.png", _refusals(teacher_lab_png)),
    ]
    app = Starlette(routes=routes, lifespan=lifespan)
    app.state.armgame = state
    return app
