"""What a connection may cost before it is a request: deadlines and a share per address, under uvicorn.

A connection that sends nothing, or trickles its headers a byte at a time, costs its sender nothing
and the server a socket: uvicorn counts it against ``limit_concurrency`` and has no deadline for a
request to arrive (its issue #157), and ASGI middleware runs only once headers are parsed. So the
class wraps uvicorn's own h11 protocol (``guarded_protocol``), keeping every byte of HTTP parsing
uvicorn's and h11's, and adds three rules at the socket:

* **a deadline for the request**: its headers within ``HEADER_SECONDS`` of the connection (or of the
  previous response, on a kept-alive connection), and the whole request, body included, within
  ``REQUEST_SECONDS`` of its headers; past either, the connection is closed. An idle kept-alive
  connection is closed by uvicorn's ``timeout_keep_alive``.
* **a share per address**: at most ``PER_ADDRESS`` connections from one client address at once; the
  next is closed as it opens. Thirty students each hold a few; one laptop cannot hold the server.
* **the teacher's machine is never turned away**: connections from this machine's own addresses
  (``Guard.own``: loopback and the addresses the server answers at) have no share to exceed, so the
  projector and the teacher's page always get in.

Measured (tests/test_class_siege.py): 420 idle sockets or trickled headers from one address leave the
class answering others at once; the trickler is cut off after ``HEADER_SECONDS``.
"""

from __future__ import annotations

import asyncio
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

#: Seconds for a request's headers to arrive (a browser or the client sends them in one packet).
HEADER_SECONDS = 5.0
#: Seconds for a whole request once its headers are in: a 4 MB hand-in over slow school Wi-Fi (1 MB/s).
REQUEST_SECONDS = 15.0
#: Connections one client address may hold at once (a browser opens six per server; the client one).
PER_ADDRESS = 16


@dataclass
class Guard:
    """The connections open per client address, and the addresses that are the teacher's own machine."""

    own: frozenset[str] = frozenset({"127.0.0.1", "::1"})
    per_address: int = PER_ADDRESS
    header_seconds: float = HEADER_SECONDS
    request_seconds: float = REQUEST_SECONDS
    open: Counter[str] = field(default_factory=Counter)
    refused: int = 0

    def is_own(self, address: str) -> bool:
        return address in self.own


def guarded_protocol(guard: Guard) -> type[asyncio.Protocol]:
    """uvicorn's h11 protocol with ``guard``'s deadlines and shares (see the module)."""

    class GuardedH11Protocol(H11Protocol):
        _address = ""
        _counted = False
        _deadline: asyncio.TimerHandle | None = None

        def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
            peer: Any = transport.get_extra_info("peername")
            address = str(peer[0]) if isinstance(peer, tuple) and peer else ""
            if not guard.is_own(address) and guard.open[address] >= guard.per_address:
                guard.refused += 1
                transport.abort()  # before uvicorn counts it: the share is the whole cost
                return
            self._address, self._counted = address, True
            guard.open[address] += 1
            super().connection_made(transport)
            self._await_headers()

        def connection_lost(self, exc: Exception | None) -> None:
            if not self._counted:
                return
            self._counted = False
            guard.open[self._address] -= 1
            if guard.open[self._address] <= 0:
                del guard.open[self._address]
            self._cancel_deadline()
            super().connection_lost(exc)

        def data_received(self, data: bytes) -> None:
            before = self.conn.their_state
            super().data_received(data)
            after = self.conn.their_state
            if before is h11.IDLE and after is not h11.IDLE and not self.transport.is_closing():
                self._arm(guard.request_seconds if after is not h11.DONE else None)
            elif after is h11.DONE and before is not h11.DONE:
                self._cancel_deadline()

        def on_response_complete(self) -> None:
            super().on_response_complete()
            # A new request may begin: its headers have their deadline. A body still arriving after the answer
            # (a route that never read it) keeps the request's deadline, armed when its headers came.
            if not self.transport.is_closing() and self.conn.their_state is h11.IDLE:
                self._await_headers()

        def _await_headers(self) -> None:
            self._arm(guard.header_seconds)

        def _arm(self, seconds: float | None) -> None:
            self._cancel_deadline()
            if seconds is not None:
                self._deadline = self.loop.call_later(seconds, self._too_slow)

        def _cancel_deadline(self) -> None:
            if self._deadline is not None:
                self._deadline.cancel()
                self._deadline = None

        def _too_slow(self) -> None:
            self._deadline = None
            state = self.conn.their_state
            waiting = state is h11.IDLE or state is h11.SEND_BODY
            if waiting and not self.transport.is_closing():
                if self.cycle is not None and not self.cycle.response_complete:
                    self.cycle.disconnected = True  # the app reading its body hears of it at once
                    self.cycle.message_event.set()
                self.transport.abort()

    return GuardedH11Protocol
