"""What the class's endpoints share while it serves (``ClassState``, the app's ``app.state.armgame``).

The clerk and its thread (``worker.ClerkThread``), and the bounds on what may wait for it: at most
``QUEUE_LIMIT`` jobs, ``HANDIN_QUEUE`` hand-ins and ``QUEUE_BYTES`` of their bodies (past them, 503 and
``BUSY``: the client comes back), one hand-in a player (``TOKEN_SHARE``), a forger's next one after
``COOL_DOWN``; the wrong codes, secrets and tokens counted per address (``Guesses``) and the joins per
address and for the class (``Window``); the pages' data, rebuilt on the clerk's thread after every change
(``publish``), and the event streams told of it. The bounds are ``bounds``'s, each with its reason.
"""

from __future__ import annotations

import asyncio
import hmac
import json
import time
from collections import Counter, OrderedDict, deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TypeVar

from starlette.requests import Request

from . import views
from .bounds import (
    CLASS_JOINS_PER_MINUTE,
    COOL_DOWN,
    FREE_GUESSES,
    GUESS_WAIT,
    HANDIN_QUEUE,
    JOINS_PER_MINUTE,
    MAX_GUESS_WAIT,
    MAX_TRACKED_ADDRESSES,
    QUEUE_BYTES,
    QUEUE_LIMIT,
    SMALL_UPLOADS,
    TOKEN_SHARE,
    UPLOADS,
)
from .errors import RefusedError
from .guard import Guard
from .handins import Answer
from .intake import Clerk
from .roster import token_digest
from .wire import BUSY
from .worker import ClerkThread

#: The key of an ASGI scope whose request came through the teacher's proxy (``middleware.ForwardedFor``): its
#: client is the address the proxy named, and it is never the teacher's machine (``ClassState.teachers_machine``).
FORWARDED = "armgame.forwarded"


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


T = TypeVar("T")


@dataclass
class ClassState:
    """What the endpoints share (``request.app.state.armgame``): the clerk and its thread, the bounds on what
    waits for it, the guesses and joins counted per address, and what the pages read (built on that thread)."""

    clerk: Clerk
    join_line: str
    guard: Guard = field(default_factory=Guard)
    play_url: str = ""
    #: ``serve --teacher-secret-always``: no machine is the teacher's without the secret, this one neither (a lab
    #: PC that others use: whoever else is on it would be the teacher).
    secret_always: bool = False
    #: Called once the server takes requests; ``say`` gets one-line notices for the teacher.
    on_ready: Callable[[], None] | None = None
    say: Callable[[str], None] = lambda line: None
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
    small_uploads: asyncio.Semaphore = field(default_factory=lambda: asyncio.Semaphore(SMALL_UPLOADS))
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
            standings = views.standings(self.clerk)
            standings["play"] = self.play_url
            self.snapshot = json.dumps({**standings, "join": None}, ensure_ascii=True).encode()
            self.projector_snapshot = json.dumps({**standings, "join": self.join_line}, ensure_ascii=True).encode()
        if self.clerk.lab_version != self.seen_lab_version:  # a game handed in leaves the curve as it was
            self.seen_lab_version = self.clerk.lab_version
            self.lab = json.dumps(views.lab_curve(self.clerk), ensure_ascii=True, allow_nan=False).encode()

    def end_streams(self) -> None:
        """On the server's loop, as it begins to stop: every event stream ends now, so the pages' connections
        close at once and the stop never waits out its grace for them (nor cancels them with a traceback)."""
        self.stopping.set()
        self.changed.set()

    def teachers_machine(self, request: Request) -> bool:
        """Whether ``request`` is the teacher's machine's: its connection comes from one of this machine's own
        addresses (``Guard.own``), and not through the proxy, whose word is never the teacher's (a header can
        be the client's, passed on); never under ``secret_always``. Anything on this machine is the teacher:
        every user and program on it, which is why a shared PC serves with ``--teacher-secret-always``."""
        return not self.secret_always and not request.scope.get(FORWARDED) \
            and self.guard.is_own(client_address(request))

    def projector(self, request: Request) -> bool:
        """Whether ``request`` is the projector's (its link's key) or the teacher's machine's."""
        key = request.query_params.get("key", "")
        return self.teachers_machine(request) or (
            len(key) <= 64 and hmac.compare_digest(key.encode(), self.clerk.roster.projector_key().encode()))

    async def run(self, job: Callable[[], T]) -> T:
        """``job()`` on the clerk's thread, if the queue has room (``QUEUE_LIMIT`` jobs); the pages are told of
        any change."""
        if self.waiting >= QUEUE_LIMIT:
            raise RefusedError(503, BUSY)
        assert self.worker is not None, "the class is not serving"
        self.waiting += 1
        try:
            return await asyncio.wrap_future(self.worker.submit(job))
        finally:
            self.waiting -= 1
            self._tell_pages()

    async def hand_in(self, token: str, body: bytes, ticket: str | None = None) -> Answer:
        """The replay ``body`` checked and entered on the clerk's thread (``ClerkThread.hand_in``), if the queue
        has room (``HANDIN_QUEUE`` hand-ins and ``QUEUE_BYTES`` of their bodies); the pages are told of any
        change. ``ticket``: the game's start ticket (``Clerk.start_ticket``), if its client sent one."""
        if self.handins >= HANDIN_QUEUE or self.queued_bytes + len(body) > QUEUE_BYTES:
            raise RefusedError(503, BUSY)
        assert self.worker is not None, "the class is not serving"
        self.handins += 1
        self.queued_bytes += len(body)
        try:
            return await asyncio.wrap_future(self.worker.hand_in(token, body, ticket))
        finally:
            self.handins -= 1
            self.queued_bytes -= len(body)
            self._tell_pages()

    def _tell_pages(self) -> None:
        """The event streams waiting on ``changed`` look again (and wait on a new one)."""
        self.changed.set()
        self.changed = asyncio.Event()

    @contextmanager
    def hand_in_share(self, token: str) -> Iterator[None]:
        """A joined player's hand-in's place (``_check_token`` found the token a player's), taken before its
        body is read, with the refusals that cost nothing: a player who already has ``TOKEN_SHARE`` hand-ins
        waiting or whose last one did not reproduce less than ``COOL_DOWN`` s ago (503: the client hands it in
        again in a moment). The clerk checks the token again (a name may be released meanwhile) and a closed
        class, which only the body tells: it refuses a game and takes a lab run."""
        digest = token_digest(token)
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


def client_address(request: Request) -> str:
    return request.client.host if request.client else "unknown"
