"""``records/_ctimeline.c`` gives what the Python passes give: the same events read (or the same refusal) and the
same identities, on random timelines made to reach every branch, the odd ones the C hands back included; and the
class record written from kept lines is ``dump_json``'s bytes."""

from __future__ import annotations

import dataclasses
import json
import random

import pytest

from armgame.classroom.roster import Player, Roster
from armgame.game.rules import GameConfig
from armgame.game.session import DOWN, UP, GameSession, InputEvent
from armgame.records import identity
from armgame.records import replay as replay_module
from armgame.records.replay import Replay
from armgame.records.storage import dump_json

native = pytest.mark.skipif(identity._CTIMELINE is None, reason="built without a C compiler: the Python passes only")

KEYS = ("d", "f", "j", "k", "space", "tab")


def _base() -> Replay:
    session = GameSession(GameConfig(seed=4, time_limit=2.0))
    session.play([InputEvent(3, "d", DOWN), InputEvent(40, "d", UP)])
    return Replay.from_session(session, "keyboard")


def _timeline(rng: random.Random, last: int) -> list[InputEvent]:
    """Events a program could put in a replay: runs of one step, repeats, keys let go that were up, resets
    and tab presses, now and then a key the game ignores or an action neither down nor up, a step going back
    or past the game's end, or one past int64."""
    events, step = [], 0
    for _ in range(rng.randrange(0, 120)):
        step += rng.choice((0, 0, 0, 1, 2, 7))
        key = rng.choice((*KEYS, "d", "f", "j", "k"))
        action = rng.choice((DOWN, UP))
        odd = rng.random()
        if odd < 0.01:
            key = "q"
        elif odd < 0.02:
            action = "sideways"
        elif odd < 0.03:
            step = max(0, step - 5)
        elif odd < 0.035:
            step = last + rng.randrange(0, 3)
        elif odd < 0.037:
            step = 2**70
        events.append(InputEvent(step, key, action))
    return events


def _python(monkeypatch: pytest.MonkeyPatch, call):
    with monkeypatch.context() as m:
        m.setattr(identity, "_CTIMELINE", None)
        m.setattr(replay_module, "_CTIMELINE", None)
        return call()


@native
def test_the_identity_forms_in_c_are_the_python_ones(monkeypatch):
    base = _base()
    last = base.config.total_steps
    rng = random.Random(42)
    taken = 0
    for _ in range(400):
        replay = dataclasses.replace(base, timeline=tuple(_timeline(rng, last)))
        taken += identity._native_digests(replay) is not None
        assert identity.game_digests(replay) == _python(monkeypatch, lambda r=replay: identity.game_digests(r))
        assert identity.game_digest(replay) == _python(monkeypatch, lambda r=replay: identity.game_digest(r))
    assert 100 < taken < 400  # most timelines the C takes; the odd ones it hands back to Python


def _item(rng: random.Random, previous: int, last: int) -> object:
    step = previous + rng.choice((0, 0, 1, 3))
    item: list[object] = [step, rng.choice(KEYS), rng.choice((DOWN, UP))]
    odd = rng.random()
    if odd < 0.004:
        item[0] = True
    elif odd < 0.008:
        item[0] = float(step)
    elif odd < 0.012:
        item[0] = previous - 1
    elif odd < 0.016:
        item[0] = last + 1
    elif odd < 0.02:
        item[0] = 2**64
    elif odd < 0.024:
        item[1] = "Q"
    elif odd < 0.028:
        item[2] = "DOWN"
    elif odd < 0.032:
        item = item[:2]
    elif odd < 0.036:
        item = tuple(item)
    return item


@native
def test_a_timeline_read_in_c_is_the_python_read_or_its_refusal(monkeypatch):
    config = GameConfig(seed=4)
    last = config.total_steps
    rng = random.Random(7)
    refused = 0
    for _ in range(300):
        items: list[object] = []
        previous = 0
        for _ in range(rng.randrange(0, 80)):
            items.append(_item(rng, previous, last))
            previous = items[-1][0] if isinstance(items[-1], list) and type(items[-1][0]) is int else previous

        def read(items=items):
            try:
                return replay_module._timeline_from_list(items, config, last)
            except ValueError as exc:
                return str(exc)

        got, expected = read(), _python(monkeypatch, read)
        assert got == expected
        if isinstance(got, tuple):
            assert all(type(e) is InputEvent for e in got)
            assert [(e.step, e.key, e.action) for e in got] == [tuple(i) for i in items]  # type: ignore[arg-type]
        else:
            refused += 1
    assert 50 < refused < 250


@native
def test_a_replay_read_in_c_is_equal_and_hashes_equal(monkeypatch):
    data = _base().to_bytes()
    read = Replay.from_bytes(data)
    assert read == _python(monkeypatch, lambda: Replay.from_bytes(data))
    assert hash(read.timeline) == hash(_python(monkeypatch, lambda: Replay.from_bytes(data)).timeline)


def test_the_class_record_is_dump_jsons_bytes(tmp_path):
    """``Roster.save`` writes each player's lines once and keeps them; the file is still ``dump_json`` of the
    record, players in key order, names that quote, escape and spell '"players": {}' included."""
    roster, _ = Roster.open(tmp_path, 10)
    names = ["Ann B", 'Zoë "F"', "李小龍", "a\\b", "Дарья", 'players": {}', "Ämil", "zed"]
    for i, name in enumerate(names):
        roster.add(f"{9 - i}{name.casefold()}", Player(name, f"{i:064x}", "2026-01-01T00:00:00+00:00", "127.0.0.2"))
        data = roster.path.read_bytes()
        assert dump_json(json.loads(data)) == data
    roster.remove("9ann b")
    assert dump_json(json.loads(roster.path.read_bytes())) == roster.path.read_bytes()
    assert "Ann B" not in roster.path.read_text(encoding="utf-8")
