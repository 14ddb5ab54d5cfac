"""The clerk's one thread: every change to the class runs on it, in the order it came.

Two kinds of work are queued (``ClerkThread.submit`` and ``ClerkThread.hand_in``), each with the
future its request awaits:

* a ``Job``: a callable run on the thread (a join, the teacher's changes, the views the teacher asks
  for), its value or its exception sent back as it is;
* a ``HandIn``: a token and a body. Hand-ins waiting together are taken as one batch (up to ``BATCH``):
  checked together (``Clerk.check_many``: their games re-simulated in one batch), then entered together
  (``Clerk.enter``: one table write for a burst), each answer sent only after that write.

``after`` runs on the thread after every job or batch and before its answers go out (the app rebuilds the
pages' data there), so a client that asks next sees its own change. Nothing here knows HTTP: the bounds on
what may wait are the app's (``app.ClassState``).
"""

from __future__ import annotations

import gc
import queue
import sys
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Generic, TypeVar

from .bounds import BATCH
from .handins import AGAIN, Answer, Checked
from .intake import Clerk

T = TypeVar("T")
#: What a request is sent back: the value its work returned, or the exception it raised (raised in the request).
Outcome = object


@dataclass(frozen=True, eq=False)
class Job(Generic[T]):
    """``run()`` on the clerk's thread; its value (or exception) to ``future``."""

    run: Callable[[], T]
    future: Future[T] = field(default_factory=Future)


@dataclass(frozen=True, eq=False)
class HandIn:
    """A joined player's replay (``body``, under ``token``) to check and enter; its answer to ``future``."""

    token: str
    body: bytes
    #: The game's start ticket (``Clerk.start_ticket``), for the round; None if its client sent none.
    ticket: str | None = None
    future: Future[Answer] = field(default_factory=Future)


class ClerkThread:
    """The clerk's one thread. Jobs run in the order they came; hand-ins waiting together are checked
    one by one and entered together (``Clerk.enter``: one table write for a burst, each answer sent
    only after that write). ``after`` runs on the thread after every job (the pages' data rebuilt)."""

    def __init__(self, clerk: Clerk, after: Callable[[], None]) -> None:
        self.clerk, self.after = clerk, after
        self.work: queue.SimpleQueue[Job | HandIn | None] = queue.SimpleQueue()  # None: stop
        self.thread = threading.Thread(target=self._serve, name="armgame-clerk", daemon=True)
        self.thread.start()

    def submit(self, run: Callable[[], T]) -> Future[T]:
        """``run()`` on the clerk's thread, after the work already queued."""
        job = Job(run)
        self.work.put(job)
        return job.future

    def hand_in(self, token: str, body: bytes, ticket: str | None = None) -> Future[Answer]:
        """The replay ``body`` handed in under ``token`` (with its start ``ticket``), checked and entered on the
        clerk's thread."""
        hand_in = HandIn(token, body, ticket)
        self.work.put(hand_in)
        return hand_in.future

    def stop(self) -> None:
        """The work already queued is finished (a hand-in being written is never cut), then the thread ends."""
        self.work.put(None)
        self.thread.join()
        try:  # the journal of the games taken, into the table's one file (read either way if this fails)
            self.clerk.table.compact()
        except Exception as exc:
            print(f"armgame class: the table's journal stays beside it: {exc}", file=sys.stderr)

    def _serve(self) -> None:
        held: Job | HandIn | None = None
        while True:
            work = held if held is not None else self.work.get()
            held = None
            if work is None:
                return
            if isinstance(work, Job):
                outcomes: list[tuple[Future, Outcome]] = [(work.future, _outcome(work.run))]
            else:
                batch = [work]
                while len(batch) < BATCH:  # what arrived meanwhile goes in the same write
                    try:
                        more = self.work.get_nowait()
                    except queue.Empty:
                        break
                    if not isinstance(more, HandIn):
                        held = more
                        break
                    batch.append(more)
                outcomes = self.hand_in_batch(batch)
            try:
                self.after()  # before any answer goes out: a client that asks next sees its own game
            except Exception as exc:
                print(f"armgame class: the pages' data could not be rebuilt: {exc}", file=sys.stderr)
            for future, outcome in outcomes:
                if isinstance(outcome, BaseException):
                    future.set_exception(outcome)
                else:
                    future.set_result(outcome)

    def hand_in_batch(self, batch: Sequence[HandIn]) -> list[tuple[Future, Outcome]]:
        """Each hand-in's answer (or the exception to raise in its request), with its future, as the thread
        runs a batch (call it on the clerk's thread: the benchmark and the tests run it in theirs): checked
        together (``Clerk.check_many``: its games re-simulated in one batch), then entered together; a game
        the batch held twice is checked again after that, as the next batch would (``AGAIN``)."""
        # The cyclic garbage collector paused for the batch: reading a bot's game makes 15,000 events and their
        # lists, no cycle among them, and the collections they set off (each also walking every object the
        # server holds) were a third of such a hand-in's cost (104 ms against 65 ms, measured in-process).
        # Reference counting still frees them; what cycles there are wait for the next collection.
        collecting = gc.isenabled()
        gc.disable()
        try:
            return self._hand_in_batch(list(batch))
        finally:
            if collecting:
                gc.enable()

    def _hand_in_batch(self, batch: list[HandIn]) -> list[tuple[Future, Outcome]]:
        outcomes: list[tuple[Future, Outcome]] = []
        while batch:
            again = []
            checked: list[tuple[Checked, HandIn]] = []
            found_all = _outcome(lambda batch=batch: self.clerk.check_many([(h.token, h.body) for h in batch]))
            if isinstance(found_all, BaseException):
                found_all = [found_all] * len(batch)
            for hand_in, found in zip(batch, found_all, strict=True):
                if found is AGAIN:
                    again.append(hand_in)
                elif isinstance(found, BaseException):
                    outcomes.append((hand_in.future, found))
                elif found.answer is not None:  # answered without entering anything
                    outcomes.append((hand_in.future, found.answer))
                else:
                    checked.append((found, hand_in))
            if checked:
                answers = _outcome(lambda checked=checked: self.clerk.enter([c for c, _ in checked],
                                                                            [h.ticket for _, h in checked]))
                if isinstance(answers, BaseException):
                    answers = [answers] * len(checked)
                outcomes += [(h.future, answer) for (_, h), answer in zip(checked, answers, strict=True)]
            batch = again
        return outcomes


def _outcome(work: Callable[[], T]) -> T | BaseException:
    """What ``work()`` returns, or the exception it raised (for the request that asked for it)."""
    try:
        return work()
    except BaseException as exc:
        return exc
