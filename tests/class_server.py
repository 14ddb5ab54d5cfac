"""A live class on loopback for the tests: served on a thread of the test's process, stopped after."""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import re
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

from armgame.classroom.serve import ClassServer, open_class
from armgame.game.bots import Autopilot, make_bot
from armgame.game.rules import GameConfig
from armgame.game.session import DOWN, UP, GameSession, InputEvent
from armgame.records.replay import Replay


@contextlib.contextmanager
def running_class(folder: Path | None, seed: int | None = None, lines: list[str] | None = None,
                  lab: str | None = None, rehearse: bool = False, port: int = 0,
                  **options: object) -> Iterator[ClassServer]:
    """The class in ``folder`` served on 127.0.0.1 (``port``, else a free one) until the block ends (``lab``: its
    curve's protocol, as ``--lab``; ``rehearse``: a rehearsal, ``folder`` None, as ``--rehearse``; ``options``: more of
    ``open_class``'s, as ``proxy``, ``lab_b`` and ``split_seed`` (a classroom experiment's second condition, as
    ``--lab-b``, and the seed of its split))."""
    ready = threading.Event()
    said = lines if lines is not None else []
    opened = open_class(folder, "127.0.0.1", port, seed, say=said.append, on_ready=lambda _: ready.set(), lab=lab,
                        rehearse=rehearse, **options)
    thread = threading.Thread(target=opened.run, daemon=True)
    thread.start()
    try:
        assert ready.wait(20), "the class did not start"
        yield opened
    finally:
        opened.stop()
        thread.join(20)
        assert not thread.is_alive(), "the class did not stop"


def final_answer(standing):
    """What a window's hand-in (``commands.play._class_standing``'s) came to, once the class has answered."""
    for _ in range(500):
        final = standing.later()
        if final is not None:
            return final
        time.sleep(0.02)
    raise AssertionError("no answer from the class")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def serve_process(folder: Path, port: int, *options: str, env: dict[str, str] | None = None
                  ) -> tuple[subprocess.Popen, str]:
    """``armgame class serve`` on 127.0.0.1:``port`` in its own process (``options``: more of its own);
    (process, code) once it takes requests. The caller ends it (Ctrl-C: ``send_signal(SIGINT)``)."""
    proc = subprocess.Popen([sys.executable, "-m", "armgame", "class", "serve", "--folder", str(folder), "--host",
                             "127.0.0.1", "--port", str(port), *options], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env)
    first = proc.stdout.readline()
    found = re.search(r"code ([A-Z]{4})", first)
    assert found, first + proc.stdout.read()
    while "Ctrl-C stops the class" not in proc.stdout.readline():  # the banner's last line: it takes requests
        assert proc.poll() is None, "the class stopped as it started"
    return proc, found.group(1)


@functools.cache
def _bot_timeline(seed: int) -> tuple[InputEvent, ...]:
    session = GameSession(GameConfig(seed=seed))
    Autopilot(session, make_bot("model")).play()
    return tuple(session.timeline)


def keyboard_game(seconds: float, seed: int = 10, player: str | None = None, driven: str = "keyboard",
                  duration: float = 60.0) -> Replay:
    """A whole standard game (on a clock of ``duration`` s: a rehearsal's is 15) whose keys were the model bot's
    for its first ``seconds`` and then none: the longer, the higher the score, and each length another game.
    Cheap: the bot plays once per seed."""
    session = keyboard_session(seconds, seed, duration)
    return Replay.from_session(session, driven, None if driven == "keyboard" else "test", player)


def keyboard_session(seconds: float, seed: int = 10, duration: float = 60.0) -> GameSession:
    """``keyboard_game``'s game as the session that played it (for the end screen's callbacks)."""
    session = GameSession(GameConfig(seed=seed, time_limit=duration))
    last = round(seconds / session.config.dt)
    events = [e for e in _bot_timeline(seed) if e.step < last]
    events += [InputEvent(last, m.key, UP) for m in session.config.muscles]  # whatever was held, let go
    session.play(events)
    return session


def tapped_game(n: int, seed: int = 10, player: str | None = None) -> Replay:
    """The ``n``-th of many different whole games, each cheap: the shoulder flexor tapped from step n + 1
    for 50 steps (a different start, a different path: another game). None of the first thousand hits a
    target, so their result is the untouched game's (``tapped_games`` makes many at once from that)."""
    session = GameSession(GameConfig(seed=seed))
    session.play(_taps(n))
    return Replay.from_session(session, "keyboard", None, player)


def tapped_games(count: int, players: list[str], seed: int = 10) -> list[bytes]:
    """The replays of ``tapped_game(0..count-1)`` (player ``players[i % len(players)]``), played once: each
    claims the first game's result, none hit (whoever takes them replays each: a wrong claim is refused)."""
    first = tapped_game(0, seed)
    return [dataclasses.replace(first, timeline=tuple(_taps(i)), player=players[i % len(players)]).to_bytes()
            for i in range(count)]


def _taps(n: int) -> list[InputEvent]:
    return [InputEvent(n + 1, "d", DOWN), InputEvent(n + 51, "d", UP)]
