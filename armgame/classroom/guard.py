"""What a connection may cost before it is a request: deadlines and a share per address, under uvicorn.

A connection that sends nothing, or trickles its headers a byte at a time, costs its sender nothing
and the server a socket: uvicorn counts it against ``limit_concurrency`` and has no deadline for a
request to arrive (its issue #157), and ASGI middleware runs only once headers are parsed. So the
class wraps uvicorn's own httptools protocol (``guarded_protocol``), keeping every byte of HTTP parsing
uvicorn's and httptools' (llhttp, in C: uvicorn's h11 protocol, pure Python, was a third of the
server's time at a round's end), and adds three rules at the socket:

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

from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol

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

    def admit(self, address: str) -> bool:
        """Count a new connection from ``address``, or refuse it (False) when the address has its share."""
        if not self.is_own(address) and self.open[address] >= self.per_address:
            self.refused += 1
            return False
        self.open[address] += 1
        return True

    def release(self, address: str) -> None:
        self.open[address] -= 1
        if self.open[address] <= 0:
            del self.open[address]


def _peer_address(transport: asyncio.BaseTransport) -> str:
    peer: Any = transport.get_extra_info("peername")
    return str(peer[0]) if isinstance(peer, tuple) and peer else ""



def guarded_protocol(guard: Guard) -> type[asyncio.Protocol]:
    """uvicorn's httptools protocol with ``guard``'s deadlines and shares (see the module)."""

    class GuardedHttpToolsProtocol(HttpToolsProtocol):
        _address = ""
        _counted = False
        _deadline: asyncio.TimerHandle | None = None
        # What the client owes: "headers" (a request to begin or finish its headers), "body", or "nothing".
        _owes = "headers"

        def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
            address = _peer_address(transport)
            if not guard.admit(address):
                transport.abort()  # before uvicorn counts it: the share is the whole cost
                return
            self._address, self._counted = address, True
            super().connection_made(transport)
            self._arm(guard.header_seconds)

        def connection_lost(self, exc: Exception | None) -> None:
            if not self._counted:
                return
            self._counted = False
            guard.release(self._address)
            self._arm(None)
            super().connection_lost(exc)

        def on_message_begin(self) -> None:
            super().on_message_begin()
            self._owes = "headers"
            if self._deadline is None:  # a request pipelined behind an answer still being written
                self._arm(guard.header_seconds)

        def on_headers_complete(self) -> None:
            super().on_headers_complete()
            self._owes = "body"
            self._arm(guard.request_seconds)

        def on_message_complete(self) -> None:
            super().on_message_complete()
            self._owes = "nothing"
            self._arm(None)

        def on_response_complete(self) -> None:
            super().on_response_complete()
            # The next request's headers have their deadline from now; a body still arriving after the answer
            # (a route that never read it) keeps the deadline armed when its headers came.
            if not self.transport.is_closing() and self._owes == "nothing" and not self.pipeline:
                self._owes = "headers"
                self._arm(guard.header_seconds)

        def _arm(self, seconds: float | None) -> None:
            if self._deadline is not None:
                self._deadline.cancel()
                self._deadline = None
            if seconds is not None:
                self._deadline = self.loop.call_later(seconds, self._too_slow)

        def _too_slow(self) -> None:
            self._deadline = None
            if self._owes != "nothing" and not self.transport.is_closing():
                if self.cycle is not None and not self.cycle.response_complete:
                    self.cycle.disconnected = True  # the app reading its body hears of it at once
                    self.cycle.message_event.set()
                self.transport.abort()

    return GuardedHttpToolsProtocol
