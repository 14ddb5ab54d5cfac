"""What a connection may cost before it is a request: deadlines, bounds and a share per address, under uvicorn.

A connection that sends nothing, or trickles its headers a byte at a time, costs its sender nothing
and the server a socket: uvicorn counts it against ``limit_concurrency`` and has no deadline for a
request to arrive (its issue #157), and ASGI middleware runs only once headers are parsed. So the
class wraps uvicorn's own httptools protocol (``guarded_protocol``), keeping every byte of HTTP parsing
uvicorn's and httptools' (llhttp, in C: uvicorn's h11 protocol, pure Python, was a third of the
server's time at a round's end), and adds these rules at the socket (each bound a field of ``Guard``):

* **a deadline for the request**: its headers within ``header_seconds`` of the connection (or of the
  previous response, on a kept-alive connection), and the whole request, body included, within
  ``request_seconds`` of its headers; past either, the connection is closed. An idle kept-alive
  connection is closed by uvicorn's ``timeout_keep_alive``. The deadline also runs while requests wait
  behind the one being answered, and while an answer waits for the client to read it: a connection
  whose queue never drains is closed ``request_seconds`` after it last moved.
* **bounded memory a connection**: at most ``pipeline`` requests wait behind the one being answered
  (HTTP/1.1 pipelining; no browser pipelines). Once they do, the connection's reading is paused, and it
  resumes as answers are written; a request begun past the queue in input already read is not queued:
  the connection is closed once the queued ones are answered. A request's head (its line and headers)
  holds at most ``max_headers`` headers and ``max_header_bytes`` bytes, or it is answered 431 and the
  connection closed (uvicorn's ``h11_max_incomplete_event_size`` reaches only its h11 protocol, and
  httptools gathers a header's value whole before uvicorn sees it, so the head is counted as it is fed).
* **a share per address**: at most ``per_address`` connections from one client address at once; the
  next is closed as it opens. Thirty students each hold a few; one laptop cannot hold the server.
* **the teacher's machine and the projector are never turned away**: connections from this machine's own
  addresses (``Guard.own``: loopback and the addresses the server answers at) have no share to exceed,
  and other machines hold at most ``connections`` at once, below uvicorn's ``limit_concurrency``
  (``serve.CONCURRENCY``), whatever the number of addresses (IPv6 gives a laptop millions). Past it, a
  new connection from another machine is on probation: at most ``probation`` of them, the oldest closed
  for a newer, each answered 503 unless its first request carries the projector's link's key.

Measured (tests/test_class_siege.py): 420 idle sockets or trickled headers from one address leave the
class answering others at once; the trickler is cut off after ``header_seconds``; a pipelined flood holds
at most ``pipeline`` requests; a 6-million-header request is refused at its 101st header.
``benchmarks/class_siege.py --memory`` measures the server's memory under all of them at once.
"""

from __future__ import annotations

import asyncio
import hmac
from collections import Counter
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import parse_qs

import httptools
from uvicorn.protocols.http.flow_control import HIGH_WATER_LIMIT, FlowControl
from uvicorn.protocols.http.httptools_impl import STATUS_LINE, HttpToolsProtocol

from .bounds import (
    CONNECTIONS,
    HEADER_SECONDS,
    HELD_BYTES,
    LINGER_SECONDS,
    MAX_HEADER_BYTES,
    MAX_HEADERS,
    PER_ADDRESS,
    PIPELINE,
    PROBATION,
    REQUEST_SECONDS,
    SLICE,
)


@dataclass
class Guard:
    """What a connection may cost (every bound a field: the deadlines, the queue, the head, the shares), the
    connections open per client address, and the addresses that are the teacher's own machine."""

    own: frozenset[str] = frozenset({"127.0.0.1", "::1"})
    #: The projector's link's key (``Roster.projector_key``): a connection on probation that asks with it stays.
    key: str = ""
    #: The reverse proxy's address (``--proxy``): every student's connections arrive from it, so it has no share of
    #: ``per_address`` to exceed (the proxy's own per-client limits are the share then: nginx's ``limit_conn``).
    proxy: str = ""
    per_address: int = PER_ADDRESS
    header_seconds: float = HEADER_SECONDS
    request_seconds: float = REQUEST_SECONDS
    pipeline: int = PIPELINE
    max_headers: int = MAX_HEADERS
    max_header_bytes: int = MAX_HEADER_BYTES
    connections: int = CONNECTIONS
    probation: int = PROBATION
    open: Counter[str] = field(default_factory=Counter)
    #: Connections from other machines than the teacher's now (on probation and the projector's apart).
    others: int = 0
    #: Connections on probation, oldest first (each a callable that closes it).
    waiting: dict[object, Any] = field(default_factory=dict)
    refused: int = 0
    #: Requests answered 431 (a head past ``max_headers`` or ``max_header_bytes``).
    too_large: int = 0
    #: The most requests that waited on one connection, and the most input bytes one held back, since the start.
    deepest: int = 0
    held_most: int = 0

    def is_own(self, address: str) -> bool:
        return address in self.own

    def admit(self, address: str) -> bool:
        """Count a new connection from ``address``, or refuse it (False) when the address has its share."""
        if not self.is_own(address) and address != self.proxy and self.open[address] >= self.per_address:
            self.refused += 1
            return False
        self.open[address] += 1
        return True

    def release(self, address: str) -> None:
        self.open[address] -= 1
        if self.open[address] <= 0:
            del self.open[address]

    def is_projector(self, query: bytes) -> bool:
        """Whether a request's query string carries the projector's link's key."""
        if not self.key:
            return False
        keys = parse_qs(query.decode("latin-1"), max_num_fields=8).get("key", [""])
        return any(hmac.compare_digest(k.encode("latin-1")[:64], self.key.encode()) for k in keys)


class _Flow(FlowControl):
    """uvicorn's flow control, but reading stays paused while the guard holds input back (uvicorn resumes reading
    whenever a request's app waits for its body)."""

    holding = False

    def resume_reading(self) -> None:
        if not self.holding:
            super().resume_reading()


def _peer_address(transport: asyncio.BaseTransport) -> str:
    peer: Any = transport.get_extra_info("peername")
    return str(peer[0]) if isinstance(peer, tuple) and peer else ""


def guarded_protocol(guard: Guard) -> type[asyncio.Protocol]:
    """uvicorn's httptools protocol with ``guard``'s deadlines, bounds and shares (see the module)."""

    class GuardedHttpToolsProtocol(HttpToolsProtocol):
        _address = ""
        _counted = False
        # How the connection is counted: "own" (the teacher's machine), "other", "probation" or "projector".
        _kind = "other"
        _deadline: asyncio.TimerHandle | None = None
        # What the client owes: "headers" (a request to begin or finish its headers), "body", or "nothing".
        _owes = "headers"
        # Input read but not yet parsed, while the queue is full; the head being read, in bytes and headers.
        _held = b""
        _head_bytes = 0
        _head_count = 0
        # Why the head is refused (431), once it is; and whether the connection reads no more (refused or past
        # its queue): its input is dropped from then on.
        _too_large = ""
        _stopped = False
        _running: Any = None  # the request being answered (uvicorn's ``cycle`` is the newest, maybe queued)

        def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
            address = _peer_address(transport)
            if not guard.admit(address):
                transport.abort()  # before uvicorn counts it: the share is the whole cost
                return
            self._address, self._counted = address, True
            if guard.is_own(address):
                self._kind = "own"
            elif guard.others < guard.connections:
                guard.others += 1
            else:
                self._kind = "probation"
                guard.waiting[self] = transport.abort
                while len(guard.waiting) > guard.probation:
                    guard.waiting.pop(next(iter(guard.waiting)))()  # the oldest, closed
            super().connection_made(transport)
            self.flow = _Flow(transport)
            self._arm(guard.header_seconds)

        def connection_lost(self, exc: Exception | None) -> None:
            if not self._counted:
                return
            self._counted = False
            guard.release(self._address)
            if self._kind == "other":
                guard.others -= 1
            guard.waiting.pop(self, None)
            self._arm(None)
            self._held = b""
            self._end_running()
            self.pipeline.clear()
            super().connection_lost(exc)

        # ------------------------------------------------------------------ input, fed a slice at a time
        def data_received(self, data: bytes) -> None:
            if self._stopped:
                return
            if self._held:  # read before the pause took hold
                self._held += data
                if len(self._held) > HELD_BYTES:
                    self.transport.abort()
                return
            self._take(data)

        def _take(self, data: bytes) -> None:
            """Feed ``data`` to uvicorn's parser, in slices while a head is read or requests wait, holding the
            rest back once the queue is full."""
            view, at = memoryview(data), 0
            while at < len(view) and not self._stopped and not self.transport.is_closing():
                if len(self.pipeline) >= guard.pipeline or (self.pipeline and len(self.cycle.body) >= HIGH_WATER_LIMIT):
                    self._held = bytes(view[at:])
                    guard.held_most = max(guard.held_most, len(self._held))
                    self.flow.holding = True
                    self.flow.pause_reading()
                    if self._deadline is None:
                        self._arm(guard.request_seconds)
                    return
                in_head = self._owes == "headers"
                size = SLICE if in_head or self.pipeline else len(view) - at
                piece = view[at:at + size]
                at += len(piece)
                super().data_received(piece)  # type: ignore[arg-type]
                if not self._too_large and in_head and self._owes == "headers":
                    self._head_bytes += len(piece)
                    if self._head_bytes > guard.max_header_bytes:
                        self._too_large = f"the request's headers are longer than {guard.max_header_bytes:,} bytes"
                if self._too_large:
                    self._refuse_head()

        def _release(self) -> None:
            """An answer was written: the input held back is fed, and reading resumes, if the queue has room."""
            if self._stopped or self.transport.is_closing() or len(self.pipeline) >= guard.pipeline:
                return
            held, self._held = self._held, b""
            self.flow.holding = False
            if held:
                self._take(held)
            if not self.flow.holding and not self._stopped:
                self.flow.resume_reading()

        def _refuse_head(self) -> None:
            """431 and close (a request's head past its bounds): its input is read and dropped for a moment, so
            the client reads the answer rather than a reset."""
            self._stop()
            guard.too_large += 1
            if (self._running is not None and not self._running.response_complete) or self.pipeline:
                self.transport.abort()  # an answer is being written: a second one cannot be put in its way
                return
            text = f"{self._too_large} ({guard.max_headers} headers and {guard.max_header_bytes:,} bytes at most)"
            body = text.encode()
            self.transport.write(b"".join([STATUS_LINE[431], b"content-type: text/plain; charset=utf-8\r\n",
                                           b"content-length: %d\r\nconnection: close\r\n\r\n" % len(body), body]))
            if self.transport.can_write_eof():
                self.transport.write_eof()
            self.flow.holding = False
            self.flow.resume_reading()
            self._arm(min(LINGER_SECONDS, guard.header_seconds))

        def _stop(self) -> None:
            self._stopped = True
            self._held = b""
            self.flow.holding = True
            self.flow.pause_reading()

        # ------------------------------------------------------------------ uvicorn's parser callbacks
        def on_message_begin(self) -> None:
            if self._stopped or self._too_large:
                return
            super().on_message_begin()
            if self._owes == "nothing" or self._deadline is None:  # pipelined behind a request not yet answered
                self._arm(guard.header_seconds)
            self._owes = "headers"
            self._head_bytes = self._head_count = 0

        def on_url(self, url: bytes) -> None:
            if not self._too_large and not self._stopped:
                super().on_url(url)

        def on_header(self, name: bytes, value: bytes) -> None:
            if self._too_large or self._stopped:
                return
            self._head_count += 1
            if self._head_count > guard.max_headers:
                self._too_large = f"the request has more than {guard.max_headers} headers"
                return
            super().on_header(name, value)

        def on_headers_complete(self) -> None:
            if self._too_large or self._stopped:
                return
            if self.cycle is not None and not self.cycle.response_complete and len(self.pipeline) >= guard.pipeline:
                # Past the queue, in input already read: not queued; the queued ones are answered, then the
                # connection is closed (a client that pipelines asks again on a new one).
                self.cycle.keep_alive = False
                self._stop()
                if self._deadline is None:
                    self._arm(guard.request_seconds)
                return
            if self._kind == "probation":
                if guard.is_projector(httptools.parse_url(self.url).query or b""):
                    guard.waiting.pop(self, None)
                    self._kind = "projector"
                else:
                    self.limit_concurrency = 0  # uvicorn answers it 503 and closes: the class is full
            super().on_headers_complete()
            guard.deepest = max(guard.deepest, len(self.pipeline))
            self._owes = "body"
            self._arm(guard.request_seconds)

        def on_body(self, body: bytes) -> None:
            if not self._too_large and not self._stopped:
                super().on_body(body)

        def on_message_complete(self) -> None:
            if self._too_large or self._stopped:
                return
            super().on_message_complete()
            self._owes = "nothing"
            # A request waiting in the queue keeps a deadline: the queue must move within it.
            self._arm(guard.request_seconds if self.pipeline or self.flow.write_paused else None)

        def _start_asgi_task(self, cycle: Any, app: Any) -> None:
            self._running = cycle
            super()._start_asgi_task(cycle, app)

        # ------------------------------------------------------------------ answers
        def on_response_complete(self) -> None:
            super().on_response_complete()
            if self.transport.is_closing():
                return
            # The next request's headers have their deadline from now; a body still arriving after the answer
            # (a route that never read it) keeps the deadline armed when its headers came.
            if self._owes == "nothing" and not self.pipeline and not self._held and not self._stopped:
                self._owes = "headers"
                self._arm(guard.header_seconds)
            elif self.pipeline or self._held or self._stopped:
                self._arm(guard.request_seconds)  # the queue moved: its deadline counts from now
            if self._held:
                self.loop.call_soon(self._release)

        def pause_writing(self) -> None:
            super().pause_writing()
            if self._deadline is None:  # an answer the client does not read is on the clock too
                self._arm(guard.request_seconds)

        def resume_writing(self) -> None:
            super().resume_writing()
            if self._owes == "nothing" and not self.pipeline and not self._held and not self._stopped:
                self._arm(None)

        # ------------------------------------------------------------------ the deadline
        def _arm(self, seconds: float | None) -> None:
            if self._deadline is not None:
                self._deadline.cancel()
                self._deadline = None
            if seconds is not None:
                self._deadline = self.loop.call_later(seconds, self._too_slow)

        def _too_slow(self) -> None:
            self._deadline = None
            waiting = (self._owes != "nothing" or self.pipeline or self._held or self._stopped
                       or self.flow.write_paused)
            if waiting:  # a refused connection's linger over, or a close waiting on a client that reads nothing
                self._end_running()
                self.transport.abort()

        def _end_running(self) -> None:
            """The apps still running on this connection hear at once that it is gone (uvicorn tells only the
            newest request's, which may be one still queued)."""
            for cycle in (self._running, self.cycle):
                if cycle is not None and not cycle.response_complete:
                    cycle.disconnected = True
                    cycle.message_event.set()

    return GuardedHttpToolsProtocol
