"""A class under a flood: hand-ins checked and verified together, each verdict the single session's; a player's
share of the queue; each game's identity computed once; the table's journal, durable without a rewrite."""

from __future__ import annotations

import dataclasses
import http.client
import io
import json
import os
import threading
import time
import urllib.error
import urllib.request

import pytest
from class_server import keyboard_game, running_class, tapped_game

from armgame.classroom import client, handins
from armgame.classroom import state as class_state
from armgame.classroom.errors import RefusedError
from armgame.classroom.intake import Clerk
from armgame.classroom.roster import Roster, token_digest
from armgame.classroom.worker import ClerkThread, HandIn
from armgame.game.session import DOWN, InputEvent
from armgame.records import entry as entry_module
from armgame.records import identity
from armgame.records import scores as scores_module
from armgame.records.replay import Replay
from armgame.records.scores import ScoreTable
from armgame.records.tablefile import JOURNAL_NAME, TABLE_NAME

PLAYERS = ("Ann", "Bo", "Cy")


def _clerk(folder) -> tuple[Clerk, dict[str, str]]:
    folder.mkdir()
    roster, _ = Roster.open(folder, 10)
    clerk = Clerk(folder, roster)
    return clerk, {name: clerk.join(name, None)[1] for name in PLAYERS}  # type: ignore[misc]


def _with_reset(replay: Replay) -> Replay:
    """``replay``'s game with a reset pressed at step 10, replayed: the same game but one reset more."""
    from armgame.game.session import GameSession

    session = GameSession(replay.config)
    session.play(sorted([*replay.timeline, InputEvent(10, "space", DOWN)], key=lambda e: e.step))
    return Replay.from_session(session, "keyboard", None, replay.player)


def _forged(replay: Replay, **result) -> Replay:
    return dataclasses.replace(replay, result=dataclasses.replace(replay.result, **result))


def _mix() -> list[tuple[str, bytes]]:
    """Honest, forged, duplicate and malformed hand-ins, by player name."""
    honest = [keyboard_game(s, player=p) for s, p in ((20, "Ann"), (30, "Bo"), (12, "Cy"))]
    reset = _with_reset(keyboard_game(25))
    assert reset.result.resets >= 1 and reset.result.hits >= 1
    hidden = _forged(reset, resets=reset.result.resets - 1, score=reset.result.score + reset.config.reset_cost)
    inflated = _forged(honest[1], hits=honest[1].result.hits + 2, score=honest[1].result.score + 200)
    lowered = _forged(keyboard_game(40), score=1)
    stopped = keyboard_game(8, seed=3)  # another seed than the class's
    return [("Ann", honest[0].to_bytes()), ("Bo", honest[1].to_bytes()), ("Cy", hidden.to_bytes()),
            ("Ann", honest[0].to_bytes()),  # the same game again, same player: already
            ("Cy", honest[1].to_bytes()),  # Bo's game by another: refused
            ("Bo", inflated.to_bytes()), ("Ann", lowered.to_bytes()), ("Cy", b"{not json"),
            ("Bo", stopped.to_bytes()), ("Cy", honest[2].to_bytes()), ("Ann", tapped_game(7).to_bytes()),
            ("Cy", hidden.to_bytes())]  # the same forgery again (its result remembered)


def _batch(clerk: Clerk, hand_ins: list[tuple[str, bytes]]) -> list[object]:
    """The clerk thread's one batch of ``hand_ins``: each outcome, in their order."""
    worker = ClerkThread(clerk, lambda: None)
    try:
        batch = [HandIn(token, body) for token, body in hand_ins]
        outcomes = dict(worker.hand_in_batch(batch))  # here, as the clerk's thread runs a batch
    finally:
        worker.stop()
    return [outcomes[h.future] for h in batch]


def _verdict(outcome: object) -> tuple:
    if isinstance(outcome, RefusedError):
        return outcome.status, outcome.message
    assert isinstance(outcome, dict), outcome
    return "ok", outcome["name"], outcome["score"], outcome["already"]


@pytest.mark.slow  # every hand-in verified twice: about 2.5 s
def test_batch_verification_gives_exactly_the_single_verdicts(tmp_path):
    mix = _mix()
    single, tokens = _clerk(tmp_path / "single")
    expected = []
    for name, data in mix:
        try:
            expected.append(_verdict(single.hand_in(tokens[name], data)))
        except RefusedError as exc:
            expected.append(_verdict(exc))
    batched, tokens = _clerk(tmp_path / "batched")
    assert [_verdict(o) for o in _batch(batched, [(tokens[n], d) for n, d in mix])] == expected
    assert [v[0] for v in expected].count("ok") == 6 and 422 in [v[0] for v in expected]
    # The verdicts themselves, result for result: the batch's lanes against each game's own verify().
    games = [Replay.from_bytes(d) for _, d in mix if d.startswith(b"{\n")]
    games = [g for g in games if g.config.seed == 10]
    fresh, _ = _clerk(tmp_path / "fresh")
    assert fresh.handins._verify_games([(g, identity.game_digest(g)) for g in games]) == [g.verify() for g in games]


def test_a_forgery_that_hides_a_reset_is_refused_with_the_single_sessions_score(tmp_path):
    """verify() stops once the game scores more resets than claimed; the batch plays it to its end. The refusal
    names the score where verify() stopped, as before."""
    reset = _with_reset(keyboard_game(25))
    hidden = _forged(reset, resets=reset.result.resets - 1, score=reset.result.score + reset.config.reset_cost)
    ok, recomputed = hidden.verify()
    assert not ok and recomputed.score != reset.result.score  # stopped early: a test that can tell the two apart
    clerk, tokens = _clerk(tmp_path / "class")
    (outcome,) = clerk.check_many([(tokens["Cy"], hidden.to_bytes())])
    assert isinstance(outcome, RefusedError) and f"it replays to {recomputed.score})" in outcome.message


def test_each_games_identity_is_computed_once(tmp_path, monkeypatch):
    calls = []
    real = identity.game_digests

    def counted(replay):
        calls.append(replay.timeline)
        return real(replay)

    for module in (identity, scores_module, entry_module, handins):
        if hasattr(module, "game_digests"):
            monkeypatch.setattr(module, "game_digests", counted)
    clerk, tokens = _clerk(tmp_path / "class")
    games = [keyboard_game(s, player="Ann").to_bytes() for s in (5, 9, 14)]
    assert all(isinstance(o, dict) and o["ok"] for o in _batch(clerk, [(tokens["Ann"], d) for d in games]))
    assert len(calls) == 3


def test_each_stored_replays_bytes_are_hashed_once(tmp_path, monkeypatch):
    """The bytes a hand-in's replay is stored as are hashed once: for its file's name and its entry's digest."""
    import hashlib

    stored, real = [], hashlib.sha256

    def counted(data=b"", *args, **kwargs):
        stored.append(bytes(data))
        return real(data, *args, **kwargs)

    clerk, tokens = _clerk(tmp_path / "class")
    replays = [keyboard_game(s, player="Ann") for s in (5, 9)]
    monkeypatch.setattr(hashlib, "sha256", counted)
    assert all(isinstance(o, dict) and o["ok"] for o in _batch(clerk, [(tokens["Ann"], r.to_bytes()) for r in replays]))
    monkeypatch.undo()
    for replay in replays:
        data = replay.with_player("Ann").to_bytes()
        assert stored.count(data) == 1, f"the stored bytes were hashed {stored.count(data)} times"


def test_the_journal_is_durable_without_rewriting_the_table(tmp_path):
    table = ScoreTable(tmp_path / "t", warn=lambda line: None)
    table.new(10)
    first = table.add_many([keyboard_game(5, player="Ann")], journal=True)[0]
    before = os.stat(table.path)
    entered = table.add_many([keyboard_game(9, player="Bo"), keyboard_game(5, player="Cy")], journal=True)
    after = os.stat(table.path)
    assert (before.st_ino, before.st_mtime_ns, before.st_size) == (after.st_ino, after.st_mtime_ns, after.st_size)
    assert "already in the table: entered by Ann" in str(entered[1])  # Ann's game under Cy's name
    assert (tmp_path / "t" / JOURNAL_NAME).is_file()
    reopened = ScoreTable(tmp_path / "t", warn=lambda line: None)
    entries, damage = reopened.read()
    assert damage is None and {e.id for e in entries} == {first.id, entered[0].id}
    assert sorted(e.entered for e in entries) == [1, 2]
    # A line cut off by a kill mid-append was never acknowledged: not read, no damage, cut off at the next append.
    with open(tmp_path / "t" / JOURNAL_NAME, "ab") as f:
        f.write(b'{"name": "Half", "sco')
    entries, damage = ScoreTable(tmp_path / "t", warn=lambda line: None).read()
    assert damage is None and len(entries) == 2
    third = table.add_many([keyboard_game(13, player="Cy")], journal=True)[0]
    entries, damage = ScoreTable(tmp_path / "t", warn=lambda line: None).read()
    assert damage is None and {e.id for e in entries} == {first.id, entered[0].id, third.id}  # type: ignore[union-attr]
    # compact(): one whole table again, the journal gone, every entry kept in its order of entry.
    reopened.compact()
    assert not (tmp_path / "t" / JOURNAL_NAME).exists()
    kept = json.loads((tmp_path / "t" / TABLE_NAME).read_text())["entries"]
    assert sorted(e["entered"] for e in kept) == [1, 2, 3]


def test_a_whole_write_takes_the_journal_in_and_a_kill_before_its_removal_loses_nothing(tmp_path):
    table = ScoreTable(tmp_path / "t", warn=lambda line: None)
    table.new(10)
    table.add_many([keyboard_game(5, player="Ann")], journal=True)
    journal = (tmp_path / "t" / JOURNAL_NAME).read_bytes()
    table.add(keyboard_game(9, player="Bo"))  # another writer's whole write (armgame scores --add)
    assert not (tmp_path / "t" / JOURNAL_NAME).exists()
    (tmp_path / "t" / JOURNAL_NAME).write_bytes(journal)  # as if killed between the write and the removal
    entries, damage = ScoreTable(tmp_path / "t", warn=lambda line: None).read()
    assert damage is None and sorted(e.name for e in entries) == ["Ann", "Bo"]


def _post(port: int, token: str, code: str, data: bytes) -> tuple[int, dict, dict]:
    request = urllib.request.Request(f"http://127.0.0.1:{port}/api/handin", data=data, method="POST",
                                     headers={"Authorization": f"Bearer {token}", "X-Armgame-Code": code,
                                              "Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(request, timeout=30) as response:
            return response.status, json.loads(response.read()), {k.lower(): v for k, v in response.headers.items()}
    except urllib.error.HTTPError as exc:
        return exc.code, json.loads(exc.read()), {k.lower(): v for k, v in exc.headers.items()}


def test_a_flooders_second_hand_in_while_one_waits_is_told_busy_at_once(tmp_path, monkeypatch):
    with running_class(tmp_path / "class") as opened:
        state = opened.server.config.app.state.armgame
        code = opened.clerk.roster.code
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "m1"))
        flooder = client.join(address, code, "Flo")
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "m2"))
        honest = client.join(address, code, "Ann")
        gate = threading.Event()
        state.worker.submit(lambda: gate.wait(30))  # the clerk busy: hand-ins wait in its queue
        waiting: list = []
        first = threading.Thread(target=lambda: waiting.append(
            _post(opened.port, flooder.token, code, tapped_game(1, player="Flo").to_bytes())))
        first.start()
        other = None
        try:
            deadline = time.monotonic() + 20
            while token_digest(flooder.token) not in state.shares and time.monotonic() < deadline:
                time.sleep(0.01)
            status, answer, headers = _post(opened.port, flooder.token, code, tapped_game(2, player="Flo").to_bytes())
            assert status == 503 and answer["error"] == class_state.BUSY and headers.get("retry-after")
            other = threading.Thread(target=lambda: waiting.append(
                _post(opened.port, honest.token, code, tapped_game(3, player="Ann").to_bytes())))
            other.start()
            while token_digest(honest.token) not in state.shares and time.monotonic() < deadline:
                time.sleep(0.01)
            assert token_digest(honest.token) in state.shares  # another player's hand-in has its place
            status, answer, _ = _post(opened.port, "no-such-token", code, b"{}")
            assert status == 401 and "join first" in answer["error"]
        finally:
            gate.set()  # the clerk goes on, whatever the test found
            first.join(30)
            if other is not None:
                other.join(30)
    assert sorted(w[0] for w in waiting) == [200, 200]


def test_the_client_says_busy_never_the_wi_fi_hint(monkeypatch):
    address = client.ClassAddress.parse("127.0.0.1:9")
    monkeypatch.setattr(client, "BUSY_PATIENCE", 3.0)

    def unavailable(request, timeout):  # the server's own connection limit: a 503 that is not JSON
        raise urllib.error.HTTPError(request.full_url, 503, "Service Unavailable", {"Retry-After": "1"},
                                     io.BytesIO(b"Service Unavailable"))

    monkeypatch.setattr(urllib.request, "urlopen", unavailable)
    with pytest.raises(client.RefusalError) as refused:
        client._request(address, "/api/handin", b"{}", {}, sleep=lambda s: None)
    assert refused.value.status == 503 and str(refused.value) == client.BUSY

    def lost(request, timeout):  # connected, but the answer never came
        raise http.client.RemoteDisconnected("Remote end closed connection without response")

    monkeypatch.setattr(urllib.request, "urlopen", lost)
    with pytest.raises(client.RefusalError) as refused:
        client._request(address, "/api/handin", b"{}", {}, sleep=lambda s: None)
    assert "busy" in str(refused.value) and "Wi-Fi" not in str(refused.value)


def test_a_refused_forgery_makes_its_players_next_hand_in_wait(tmp_path, monkeypatch):
    with running_class(tmp_path / "class") as opened:
        code = opened.clerk.roster.code
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "m1"))
        forger = client.join(address, code, "Flo")
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "m2"))
        honest = client.join(address, code, "Ann")
        forged = _forged(tapped_game(4, player="Flo"), score=50)
        assert _post(opened.port, forger.token, code, forged.to_bytes())[0] == 422
        status, answer, _ = _post(opened.port, forger.token, code, tapped_game(5, player="Flo").to_bytes())
        assert status == 503 and answer["error"] == class_state.BUSY  # its next game waits COOL_DOWN seconds
        assert _post(opened.port, honest.token, code, tapped_game(6, player="Ann").to_bytes())[0] == 200
        state = opened.server.config.app.state.armgame
        state.cooling[token_digest(forger.token)] = time.monotonic()  # the cool-down over
        assert _post(opened.port, forger.token, code, tapped_game(5, player="Flo").to_bytes())[0] == 200
