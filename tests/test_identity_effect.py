"""A game's identity is what its steps apply (issue 26, item 1): input that changes nothing leaves the
digest alone, anything the session can tell apart changes it, old tables keep their digests, and one
owner (``identity.FirstEntries``) says which entry of a game counts."""

import hashlib
import json
import random
from dataclasses import replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from armgame import __version__
from armgame.cli import main
from armgame.game.rules import GameConfig
from armgame.game.session import DOWN, UP, GameSession, InputEvent
from armgame.records.identity import IDENTITY_VERSION, FirstEntries, applied_input, game_digest
from armgame.records.replay import Replay
from armgame.records.scores import ScoreTable, TableError, entry_order, replay_claims
from armgame.records.storage import atomic_write_bytes

MUSCLE_KEYS = ("d", "f", "j", "k")
KEYS = (*MUSCLE_KEYS, "space", "tab")
#: 1 s games of large targets (a hit now and then) over three seeds: 250 steps each, about a millisecond.
STEPS = 250
DATE = "2025-01-01T00:00:00+00:00"


@pytest.fixture(autouse=True)
def _private_folders(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "default-scores"))
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "private" / "cache"))


def played(events, stop: int = STEPS, seed: int = 0) -> tuple[Replay, tuple]:
    """The replay of ``events`` (as a file may hold them, no-ops and all) and what the session ends with:
    the result, the arm's state and the muscles' activations."""
    config = GameConfig(seed=seed, time_limit=STEPS * 0.004, target_radius=0.15)
    session = GameSession(config)
    result = session.play(events, stop)
    outcome = ({k: v for k, v in result.as_dict().items() if k != "version"}, session.state,
               tuple(session.muscles.activation))
    return Replay(config, tuple(events), result, player="p", date=DATE), outcome


EVENTS = st.lists(st.tuples(st.integers(0, STEPS), st.sampled_from(KEYS), st.sampled_from((DOWN, UP))),
                  max_size=14)


def timeline(drawn, stop: int) -> list[InputEvent]:
    return [InputEvent(*e) for e in sorted(drawn, key=lambda e: e[0]) if e[0] <= stop]


def with_noops(events: list[InputEvent], stop: int, rnd: random.Random) -> list[InputEvent]:
    """``events`` edited by changes that apply nothing: the order of a step's events (each key's own kept),
    repeats of muscle keys, ups of keys that are up, tab, the release of space, a tap within one step,
    muscle keys at a stopped game's last step, and anything at the clock's end."""
    groups: dict[int, list[InputEvent]] = {}
    for e in events:
        groups.setdefault(e.step, []).append(e)
    for _ in range(rnd.randint(0, 3)):
        groups.setdefault(rnd.randint(0, stop), [])
    out: list[InputEvent] = []
    held: set[str] = set()
    for step in sorted(groups):
        by_key: dict[str, list[InputEvent]] = {}
        for e in groups[step]:
            by_key.setdefault(e.key, []).append(e)
        queues = list(by_key.values())
        step_events = [InputEvent(step, k, UP) for k in MUSCLE_KEYS if k not in held and rnd.random() < 0.2]
        while queues:  # a random interleaving: only one key's own order is its effect
            queue = rnd.choice(queues)
            e = queue.pop(0)
            step_events += [e, e] if e.key in MUSCLE_KEYS and rnd.random() < 0.3 else [e]
            if not queue:
                queues.remove(queue)
        for _ in range(rnd.randint(0, 2)):  # tab, pressed or released; space released (its press acts)
            key, action = rnd.choice((("tab", DOWN), ("tab", UP), ("space", UP)))
            step_events.insert(rnd.randint(0, len(step_events)), InputEvent(step, key, action))
        for e in step_events:
            if e.key in MUSCLE_KEYS:
                (held.add if e.action == DOWN else held.discard)(e.key)
        if rnd.random() < 0.4:
            key = rnd.choice(MUSCLE_KEYS)
            step_events += [InputEvent(step, key, UP), InputEvent(step, key, DOWN)] if key in held else \
                [InputEvent(step, key, DOWN), InputEvent(step, key, UP)]
        if step == stop < STEPS and rnd.random() < 0.5:  # no step follows a stopped game's last muscle change
            key = rnd.choice(MUSCLE_KEYS)
            step_events.append(InputEvent(step, key, UP if key in held else DOWN))
        out += step_events
    if stop == STEPS:
        out += [InputEvent(STEPS, rnd.choice(KEYS), DOWN) for _ in range(rnd.randint(0, 2))]  # the clock has ended
    return out


@settings(max_examples=60, deadline=None)
@given(drawn=EVENTS, stop=st.one_of(st.just(STEPS), st.integers(1, STEPS)), seed=st.integers(0, 2),
       rnd=st.randoms(use_true_random=False))
def test_input_that_changes_nothing_leaves_the_digest(drawn, stop, seed, rnd):
    events = timeline(drawn, stop)
    edited = with_noops(events, stop, rnd)
    original, outcome = played(events, stop, seed)
    copy, copy_outcome = played(edited, stop, seed)
    assert copy_outcome == outcome  # the session agrees these edits do nothing: tab, a tap, order, repeats
    assert game_digest(copy) == game_digest(original)


def mutated(events: list[InputEvent], stop: int, rnd: random.Random) -> tuple[list[InputEvent], int]:
    """``events`` with a few edits that may or may not change the game."""
    events = list(events)
    for _ in range(rnd.randint(1, 3)):
        kind = rnd.choice(("shift", "drop", "double", "rekey", "reset", "stop"))
        if kind == "stop":
            stop = max(1, min(STEPS, stop + rnd.choice((-1, 1))))
            continue
        if kind == "reset" or not events:
            events.append(InputEvent(rnd.randint(0, stop), "space", DOWN))
            continue
        i = rnd.randrange(len(events))
        e = events[i]
        if kind == "shift":
            events[i] = replace(e, step=max(0, min(stop, e.step + rnd.choice((-1, 1)))))
        elif kind == "drop":
            del events[i]
        elif kind == "double":
            events.insert(i, e)
        else:
            events[i] = replace(e, key=rnd.choice(KEYS))
    events.sort(key=lambda e: e.step)
    return [e for e in events if e.step <= stop], stop


@settings(max_examples=60, deadline=None)
@given(drawn=EVENTS, stop=st.one_of(st.just(STEPS), st.integers(1, STEPS)), seed=st.integers(0, 2),
       rnd=st.randoms(use_true_random=False))
def test_games_the_session_tells_apart_have_different_digests(drawn, stop, seed, rnd):
    events = timeline(drawn, stop)
    other, other_stop = mutated(events, stop, rnd)
    a, outcome_a = played(events, stop, seed)
    b, outcome_b = played(other, other_stop, seed)
    if outcome_a != outcome_b:
        assert game_digest(a) != game_digest(b)


def test_what_the_session_counts_identity_counts():
    """The session's rules, read in session.py, that the form follows."""
    press = [InputEvent(10, "d", DOWN), InputEvent(60, "d", UP)]
    base, outcome = played(press)
    # Two space presses at one step are two resets (the score pays each): not one game.
    one, one_outcome = played([*press, InputEvent(30, "space", DOWN)])
    two, two_outcome = played([*press, InputEvent(30, "space", DOWN), InputEvent(30, "space", DOWN)])
    assert (one_outcome[0]["resets"], two_outcome[0]["resets"]) == (1, 2)
    assert len({game_digest(base), game_digest(one), game_digest(two)}) == 3
    assert applied_input(two).resets == ((30, 2),)
    # Tab only hides the arm; a tap within one step is undone before the step reads the keys.
    quiet, quiet_outcome = played([InputEvent(5, "tab", DOWN), *press, InputEvent(20, "j", DOWN),
                                   InputEvent(20, "j", UP), InputEvent(40, "tab", DOWN)])
    assert quiet_outcome == outcome and game_digest(quiet) == game_digest(base)
    # A held key's release and press at one step change nothing either; a press a step later does.
    again, again_outcome = played([*press[:1], InputEvent(30, "d", UP), InputEvent(30, "d", DOWN), press[1]])
    later, later_outcome = played([InputEvent(11, "d", DOWN), press[1]])
    assert again_outcome == outcome and game_digest(again) == game_digest(base)
    assert later_outcome != outcome and game_digest(later) != game_digest(base)
    # A game stopped at step 100: a reset pressed there still counts, a key pressed there runs no step.
    stopped, stopped_outcome = played(press, 100)
    reset, reset_outcome = played([*press, InputEvent(100, "space", DOWN)], 100)
    key, key_outcome = played([*press, InputEvent(100, "k", DOWN)], 100)
    assert reset_outcome[0]["resets"] == 1 and game_digest(reset) != game_digest(stopped)
    assert key_outcome[:2] == stopped_outcome[:2] and game_digest(key) == game_digest(stopped)
    assert applied_input(base).held == ((10, 1), (60, 0))


def test_key_bindings_are_not_the_game():
    config = GameConfig(seed=0, time_limit=1.0)
    from armgame.game.muscles import remap_keys

    asdf = replace(config, muscles=remap_keys(config.muscles, "asdf"))
    a = Replay(config, (InputEvent(3, "f", DOWN),), GameSession(config).play([InputEvent(3, "f", DOWN)]), date=DATE)
    b = Replay(asdf, (InputEvent(3, "s", DOWN),), GameSession(asdf).play([InputEvent(3, "s", DOWN)]), date=DATE)
    assert game_digest(a) == game_digest(b)


# ------------------------------------------------------------------ tables entered before the bump

#: The game below by identity version 1, as armgame computed it before issue 26 (an old table holds it).
V1_DIGEST = "85d77b689133377405c95bed55418866011e20d806bef5cb34defa45a91bbabf"


def old_game(player: str = "Old") -> Replay:
    session = GameSession(GameConfig(seed=10))
    session.advance(50)
    session.key_event("tab", "down")
    session.advance(50)
    session.key_event("f", "down")
    session.key_event("j", "down")
    session.advance(300)
    session.key_event("f", "up")
    session.key_event("space", "down")
    session.advance(session.total_steps)
    return replace(Replay.from_session(session, "keyboard", None, player), date=DATE)


def _stored_digest(table: ScoreTable, digest: str) -> None:
    table.compact()  # a class's games are in the table's journal until its server stops: into scores.json
    data = json.loads(table.path.read_text())
    data["entries"][0]["game_sha256"] = digest
    table.path.write_text(json.dumps(data))


def test_an_entry_taken_before_the_bump_still_names_its_game(tmp_path, capsys):
    table = ScoreTable(tmp_path / "t")
    table.add(old_game())
    assert IDENTITY_VERSION == 2 and json.loads(table.path.read_text())["entries"][0]["game_sha256"] != V1_DIGEST
    _stored_digest(table, V1_DIGEST)  # as the table was written before the bump
    (entry,) = table.all_entries()
    assert table.check(entry).ok
    assert main(["scores", "--scores", str(table.folder)]) == 0
    out = capsys.readouterr().out
    assert "flagged:" not in out and "Old " in out
    assert main(["verify", str(table.folder)]) == 0
    # A copy of that old game is refused at the door, by the digest the old entry holds.
    with pytest.raises(TableError, match="already in the table: entered by Old"):
        table.add(replace(old_game("Thief"), date="2025-01-02T00:00:00+00:00"))
    # Another game's digest (of either version) is not this replay's: flagged.
    _stored_digest(table, game_digest(replace(old_game(), timeline=old_game().timeline[1:3])))
    (entry,) = table.all_entries()
    assert table.check(entry).label == "NOT ITS REPLAY"
    capsys.readouterr()


def test_a_cached_verdict_of_another_identity_version_is_recomputed(tmp_path, capsys):
    table = ScoreTable(tmp_path / "t")
    entry = table.add(old_game())
    path = table.replay_path(entry)
    forged = json.loads(path.read_text())
    forged["result"].update(score=99, hits=99)
    atomic_write_bytes(path, json.dumps(forged).encode())
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    data = json.loads(table.path.read_text())
    data["entries"][0].update(score=99, hits=99, replay_sha256=digest)
    table.path.write_text(json.dumps(data))
    claims = replay_claims(Replay.load(path))
    cache = tmp_path / "private" / "cache"
    cache.mkdir(parents=True, mode=0o700)

    def listed_with(planted_claims: dict) -> str:
        (cache / f"verified-{__version__}.json").write_text(json.dumps(
            {"format": "armgame-verified", "version": __version__,
             "items": {digest: {"ok": True, "label": "ok", "detail": "", "claims": planted_claims}}}))
        assert main(["scores", "--scores", str(table.folder), "--cache", str(cache)]) == 0
        return capsys.readouterr().out

    stale = {**claims, "identity": IDENTITY_VERSION - 1}
    assert "NOT REPRODUCED" in listed_with(stale)  # not believed: recomputed, and the forgery found
    # The user's own cache of this version is believed (that is its purpose): only the version differed.
    assert "NOT REPRODUCED" not in listed_with(claims)


# ------------------------------------------------------------------ one owner of "which entry counts"

def test_first_entries_counts_the_first_that_checks_out():
    first: FirstEntries[str] = FirstEntries()
    assert first.copy_of("forged", "file-f", "game-1", ok=False) is None  # planted first, with the honest digest
    assert first.copy_of("honest", "file-h", "game-1", ok=True) is None  # still counts
    assert first.copy_of("copy", "file-c", "game-1", ok=True) == "honest"
    assert first.counted_file("file-h") == "honest" and first.counted("game-1") == "honest"
    assert first.copy_of("again", "file-h", None, ok=True) == "honest"  # the same file: the later is the copy
    assert first.counted_file("file-f") is None


def test_a_forged_entry_naming_an_honest_replay_file_never_pushes_it_out(tmp_path, capsys):
    table = ScoreTable(tmp_path / "t")
    table.add(old_game("Honest"))
    data = json.loads(table.path.read_text())
    # Planted before it in the order of entry, naming its replay file, under another name and score.
    data["entries"][0]["entered"] = 2
    data["entries"].append({**data["entries"][0], "id": "f" * 32, "name": "Forger", "entered": 1, "score": 7,
                            "hits": 7})
    table.path.write_text(json.dumps(data))
    assert [e.name for e in sorted(table.all_entries(), key=entry_order)] == ["Forger", "Honest"]
    assert main(["scores", "--scores", str(table.folder)]) == 0
    out = capsys.readouterr().out
    ranked, flagged = out.split("1 flagged:")
    assert "Honest " in ranked and "Forger (7" in flagged and "NOT ITS REPLAY" in flagged
    assert main(["verify", str(table.folder)]) == 1
    out = capsys.readouterr().out
    assert "Honest: score 0" in out and "DUPLICATE" not in out and "1 flagged" in out


def test_a_live_class_knows_a_game_entered_before_the_bump(tmp_path):
    """The class's clerk looks a hand-in up by every identity version's digest, as the table's door does."""
    from armgame.classroom.errors import RefusedError
    from armgame.classroom.intake import Clerk
    from armgame.classroom.roster import Roster

    folder = tmp_path / "class"
    folder.mkdir()
    roster, _ = Roster.open(folder, 10)
    clerk = Clerk(folder, roster)
    old, token = clerk.join("Old", None)
    other, other_token = clerk.join("Bo", None)
    data = old_game().to_bytes()
    assert clerk.hand_in(token, data)["already"] is False
    _stored_digest(clerk.table, V1_DIGEST)  # the class's table as an armgame before the bump wrote it
    clerk = Clerk(folder, roster)  # the class goes on after a restart
    assert clerk.hand_in(token, data)["already"] is True
    with pytest.raises(RefusedError, match="already handed in by Old"):
        clerk.hand_in(other_token, data)
    assert old.name == "Old" and other.name == "Bo"


def test_both_forms_in_one_pass_are_the_two_passes():
    """``game_digests`` of a game that ran to its end takes ``applied_input`` and version 1's events in one pass
    (``_both_forms``): the same values as the two passes, on timelines of every shape (no-ops, repeats, events at
    and past the end, a key no muscle has, an action neither down nor up, even out of order)."""
    from armgame.records import identity

    base, _ = played([])
    rng = random.Random(5)
    keys = (*KEYS, "x")
    for _ in range(3_000):
        lo = rng.choice((0, STEPS - 20))
        steps = sorted(rng.randint(lo, rng.choice((lo + 4, STEPS + 3))) for _ in range(rng.randint(0, 30)))
        if rng.random() < 0.1:
            rng.shuffle(steps)
        actions = (DOWN, UP, "x") if rng.random() < 0.05 else (DOWN, UP)
        replay = replace(base, timeline=tuple(InputEvent(s, rng.choice(keys), rng.choice(actions)) for s in steps))
        applied, events = identity._both_forms(replay)
        assert applied == applied_input(replay)
        assert events == identity._form_v1(replay)["timeline"]
        assert identity.game_digests(replay) == (game_digest(replay), identity._digest(identity._form_v1(replay)))


def test_config_digest_remembers_the_object_not_an_equal_one():
    """``config_digest`` remembers a configuration's digest by the object: an equal configuration whose JSON
    differs (-0.0 for 0.0) keeps its own digest, asked in either order, as many times as asked."""
    from armgame.records.rulesets import canonical_config, config_digest

    plain = GameConfig(start_posture=(0.0, 1.0))
    signed = GameConfig(start_posture=(-0.0, 1.0))
    assert plain == signed and canonical_config(plain) != canonical_config(signed)
    for _ in range(3):
        for config in (plain, signed, GameConfig(start_posture=(-0.0, 1.0))):
            assert config_digest(config) == hashlib.sha256(canonical_config(config)).hexdigest()
    for seed in range(200):  # more than it keeps: the oldest go, the answers stay the same
        assert config_digest(replace(plain, seed=seed)) == config_digest(plain)
    assert config_digest(signed) != config_digest(plain)
