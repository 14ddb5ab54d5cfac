"""The teacher's record wins (issue 26, item 2), and no entry is ever lost to a hostile counter (item 3).

A class shares a table folder; the teacher's account started the table, so it keeps its own record of the
table's seed and of the order the games it entered came in (``records.teacher``). Each test is an edit a
classmate can make to the shared file, seen from the teacher's account (the record wins, and says so in
one line) and from a student's (the table as it says, as before)."""

import hashlib
import json
import os
from dataclasses import replace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import armgame.records.tablefile as tablefile_module
from armgame.cli import main
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.records.listing import listing
from armgame.records.replay import Replay
from armgame.records.scores import ScoreTable, TableError, entry_order
from armgame.records.teacher import TeacherRecord


@pytest.fixture(autouse=True)
def _private_folders(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "default-scores"))
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "teacher" / "cache"))


def played(player: str, seed: int = 3, press: int = 100, time_limit: float | None = None) -> Replay:
    """A keyboard game with one key press at step ``press``: standard (60 s) unless ``time_limit``."""
    config = GameConfig(seed=seed) if time_limit is None else GameConfig(seed=seed, time_limit=time_limit)
    session = GameSession(config)
    session.advance(press)
    session.key_event("f", "down")
    session.advance(200)
    session.key_event("f", "up")
    session.advance(session.total_steps)
    return Replay.from_session(session, "keyboard", None, player)


def class_table(tmp_path, seed: int = 3) -> ScoreTable:
    """A class's table started by the teacher's account (``$ARMGAME_CACHE``), ranking ``seed``."""
    assert main(["scores", "--scores", str(tmp_path / "class"), "--new", "--seed", str(seed)]) == 0
    return ScoreTable(tmp_path / "class", warn=lambda m: None)


def edit(table: ScoreTable, change) -> None:
    """A classmate's hand edit of the shared file."""
    data = json.loads(table.path.read_text())
    change(data)
    table.path.write_text(json.dumps(data))


def as_student(monkeypatch, tmp_path) -> None:
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "student" / "cache"))


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ------------------------------------------------------------------ the seed

def test_a_changed_seed_is_reported_and_the_teachers_seed_ranks(tmp_path, capsys, monkeypatch):
    table = class_table(tmp_path, seed=3)
    table.add(played("ann", seed=3))
    table.add(played("bob", seed=8))
    edit(table, lambda d: d.update(seed=8))
    code, out, err = run(capsys, "scores", "--scores", str(table.folder), "--no-check")
    assert code == 0 and "seed 3" in out and out.index("ann") < out.index("Practice") < out.index("bob")
    assert err.splitlines() == ["armgame scores: the table's seed was changed from 3 to 8; ranking seed 3 (this "
                                "account's record of the table)"]
    as_student(monkeypatch, tmp_path)  # no record of the table: as the table says
    code, out, err = run(capsys, "scores", "--scores", str(table.folder), "--no-check")
    assert "seed 8" in out and out.index("bob") < out.index("Practice") < out.index("ann") and err == ""
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "teacher" / "cache"))
    notes = []
    ScoreTable(table.folder, warn=notes.append).add(played("cleo", seed=3, press=7))  # the teacher's save puts 3 back
    assert json.loads(table.path.read_text())["seed"] == 3
    assert notes == ["the table's seed was changed from 3 to 8: this account's record of the table puts seed 3 back"]


@pytest.mark.parametrize("bad", ["three", -1, 2**64, 1.5, None, [3], "missing"])
def test_a_seed_that_is_not_valid_is_reported_and_kept_never_replaced_by_the_default(tmp_path, capsys, bad):
    table = ScoreTable(tmp_path / "own", warn=(notes := []).append)  # a student's own table: no record
    table.add(played("ann", seed=10, time_limit=0.4))
    edit(table, lambda d: d.pop("seed") if bad == "missing" else d.update(seed=bad))
    code, out, err = run(capsys, "scores", "--scores", str(table.folder), "--no-check")
    assert code == 0 and "seed 10" in out
    assert len(err.splitlines()) == 1 and "the table's seed " in err and "ranked as the default seed 10" in err
    table.add(played("bob", seed=10, time_limit=0.4, press=7))
    data = json.loads(table.path.read_text())
    assert data.get("seed", "missing") == bad  # kept: no save turns it into 10
    assert len(notes) == 1 and "kept as it is" in notes[0] and not list(table.folder.glob("scores.json.corrupt-*"))
    assert {e.name for e in table.all_entries()} == {"ann", "bob"}


def test_a_seed_that_is_not_valid_on_the_teachers_table_is_the_records(tmp_path, capsys):
    table = class_table(tmp_path, seed=3)
    table.add(played("ann", seed=3))
    edit(table, lambda d: d.update(seed="easy"))
    code, out, err = run(capsys, "scores", "--scores", str(table.folder), "--no-check")
    assert code == 0 and "seed 3" in out and "is not valid" in err and "ranking seed 3" in err
    table.add(played("bob", seed=3, press=7))
    assert json.loads(table.path.read_text())["seed"] == 3


def test_a_damaged_head_is_never_saved_with_the_default_seed(tmp_path):
    table = ScoreTable(tmp_path / "own", warn=(notes := []).append)
    table.add(played("ann", seed=10, time_limit=0.4))
    text = table.path.read_text()
    head, rest = text.split('"entries"', 1)
    table.path.write_text(head.replace('"seed": 10', '"seed": ten') + '"entries"' + rest)  # not JSON now
    table.add(played("bob", seed=10, time_limit=0.4, press=7))
    data = json.loads(table.path.read_text())
    assert "seed" not in data  # the table says it has none (each listing says so) rather than a chosen one
    assert any("seed cannot be read" in n for n in notes) and len(list(table.folder.glob("scores.json.corrupt-*"))) == 1
    assert {e.name for e in table.all_entries()} == {"ann", "bob"}


# ------------------------------------------------------------------ the order of entry

def _plant_copy(table: ScoreTable, of, how: str) -> None:
    """A classmate's copy of ``of``'s game under their name, dated 1970, planted to come first."""
    copied = replace(played(of.name, seed=3, press=50).with_player("thief"), date="1970-01-01T00:00:00+00:00")
    path = table.save_replay(copied)
    sha = hashlib.sha256(path.read_bytes()).hexdigest()

    def change(data):
        honest = next(e for e in data["entries"] if e["id"] == of.id)
        copy = {**honest, "id": "c" * 32, "name": "thief", "date": copied.date, "replay": path.name,
                "replay_sha256": sha, "entered": 1}
        honest["entered"] = 2
        if how == "no entered":
            del copy["entered"]
        if how == "old format":
            data["format_version"] = 1
            for e in (honest, copy):
                for key in ("entered", "entered_at", "game_sha256", "complete", "ruleset", "config_sha256"):
                    e.pop(key, None)
            del data["seed"], data["next_entry"]
        data["entries"].append(copy)

    edit(table, change)


@pytest.mark.parametrize("how", ["entered 1", "no entered", "old format"])
def test_a_planted_copy_never_pushes_out_a_game_the_teacher_entered(tmp_path, capsys, monkeypatch, how):
    table = class_table(tmp_path, seed=10 if how == "old format" else 3)  # a format 1 table ranks seed 10
    seed = table.seed
    ann = table.add(played("ann", seed=seed, press=50))
    if how == "old format":  # its copy is the same game, of the table's seed
        _plant_copy_old(table, ann)
    else:
        _plant_copy(table, ann, how)
    code, out, err = run(capsys, "scores", "--scores", str(table.folder))
    assert code == 0
    ranked = out.split("Ranked")[1].split("flagged")[0]
    assert "ann" in ranked and "thief (" in out and "DUPLICATE: the same game as ann's entry" in out
    assert "placed by the table before a tied or identical game it entered" in err
    code, out, err = run(capsys, "verify", str(table.folder))
    assert code == 1 and "thief: score" in out and "DUPLICATE" in out.split("thief: score")[1].splitlines()[0]
    assert "ann: score" in out and "ok" in out.split("ann: score")[1].splitlines()[0]
    if how == "entered 1":  # a student's account has no record: the table's own order, as before
        as_student(monkeypatch, tmp_path)
        code, out, err = run(capsys, "scores", "--scores", str(table.folder))
        assert "DUPLICATE: the same game as thief's entry" in out


def _plant_copy_old(table: ScoreTable, of) -> None:
    copied = replace(played(of.name, seed=table.seed, press=50).with_player("thief"),
                     date="1970-01-01T00:00:00+00:00")
    path = table.save_replay(copied)
    sha = hashlib.sha256(path.read_bytes()).hexdigest()

    def change(data):
        honest = next(e for e in data["entries"] if e["id"] == of.id)
        data["entries"].append({**honest, "id": "c" * 32, "name": "thief", "date": copied.date, "replay": path.name,
                                "replay_sha256": sha})
        data["format_version"] = 1
        for e in data["entries"]:
            for key in ("entered", "entered_at", "game_sha256", "complete", "ruleset", "config_sha256"):
                e.pop(key, None)
        del data["seed"], data["next_entry"]

    edit(table, change)


def test_the_record_orders_what_it_knows_and_says_what_the_table_lost(tmp_path, capsys):
    table = class_table(tmp_path)
    first, second, third = (table.add(played(n, press=p, time_limit=0.4)) for n, p in (("a", 1), ("b", 2), ("c", 3)))

    def swap_and_drop(data):
        by_id = {e["id"]: e for e in data["entries"]}
        by_id[first.id]["entered"], by_id[second.id]["entered"] = 9, 1
        data["entries"].remove(by_id[third.id])

    edit(table, swap_and_drop)
    reader = ScoreTable(table.folder, warn=(notes := []).append)
    assert [e.id for e in sorted(reader.all_entries(), key=entry_order)] == [first.id, second.id]
    assert len(notes) == 2 and "was changed for 2 of the 2 entries" in notes[0]
    assert "1 of the 3 games this account entered in the table is no longer in it" in notes[1]


# ------------------------------------------------------------------ where the record lives

def test_a_record_nobody_else_may_write_only(tmp_path, capsys):
    table = class_table(tmp_path)
    table.add(played("ann"))
    edit(table, lambda d: d.update(seed=8))
    record = next((tmp_path / "teacher" / "cache").glob("table-*.json"))
    assert record.stat().st_mode & 0o077 == 0
    os.chmod(record.parent, 0o777)  # a folder others may write: anyone could have planted the record
    code, out, err = run(capsys, "scores", "--scores", str(table.folder), "--no-check")
    assert "seed 8" in out and len(err.splitlines()) == 1 and "is not trusted" in err and "ignored" in err
    os.chmod(record.parent, 0o700)
    record.write_text("{not json")
    code, out, err = run(capsys, "scores", "--scores", str(table.folder), "--no-check")
    assert code == 0 and "seed 8" in out and len(err.splitlines()) == 1 and "cannot be read" in err


def test_no_record_in_or_beside_the_table(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "class" / "cache"))
    code, _, err = run(capsys, "scores", "--scores", str(tmp_path / "class"), "--new", "--seed", "3")
    assert code == 0 and "cannot be kept" in err and "in or beside the table's folder" in err
    assert not (tmp_path / "class" / "cache").exists() or not list((tmp_path / "class" / "cache").glob("table-*"))


def test_a_replaced_folder_is_reported_and_a_new_table_keeps_the_old_record_aside(tmp_path, capsys):
    table = class_table(tmp_path)
    table.add(played("ann"))
    (tmp_path / "class").rename(tmp_path / "old")
    (tmp_path / "class").mkdir()
    (tmp_path / "class" / "scores.json").write_bytes((tmp_path / "old" / "scores.json").read_bytes())
    code, out, err = run(capsys, "scores", "--scores", str(tmp_path / "class"), "--no-check")
    assert code == 0 and "ann" in out and "was replaced or restored" in err and "applied all the same" in err
    (tmp_path / "class" / "scores.json").unlink()
    code, _, err = run(capsys, "scores", "--scores", str(tmp_path / "class"), "--new", "--seed", "4")
    assert code == 0 and "earlier record of the table" in err and "kept as" in err
    assert len(list((tmp_path / "teacher" / "cache").glob("table-*.json.replaced-*"))) == 1
    assert TeacherRecord(tmp_path / "class", tmp_path / "teacher" / "cache").load().seed == 4


# ------------------------------------------------------------------ 3. no entry is ever lost

def _hostile(table: ScoreTable, **head) -> None:
    edit(table, lambda d: d.update(head))


@pytest.mark.parametrize("plant", ["entered at the limit", "next_entry at the limit", "next_entry not valid"])
def test_a_hostile_counter_is_repaired_once_and_every_game_kept(tmp_path, plant):
    table = ScoreTable(tmp_path / "own", warn=(notes := []).append)
    table.add(played("first", time_limit=0.2, press=1))
    if plant == "entered at the limit":
        edit(table, lambda d: d["entries"][0].update(entered=10**9))
    elif plant == "next_entry at the limit":
        _hostile(table, next_entry=10**9)
    else:
        _hostile(table, next_entry="soon")
    added = [table.add(played(f"p{i}", time_limit=0.2, press=2 + i)) for i in range(5)]
    entries = table.all_entries()
    assert {e.id for e in added} <= {e.id for e in entries} and len(entries) == 6
    assert not list(table.folder.glob("scores.json.corrupt-*"))
    assert len(notes) == 1 and ("renumbered" in notes[0] or "set after its last entry" in notes[0])
    assert [e.name for e in sorted(entries, key=entry_order)] == ["first", *(f"p{i}" for i in range(5))]


def test_a_table_that_would_not_read_back_is_never_written(tmp_path, monkeypatch):
    table = ScoreTable(tmp_path / "own", warn=lambda m: None)
    table.add(played("ann", time_limit=0.2))
    before = table.path.read_bytes()
    real = tablefile_module.table_bytes
    monkeypatch.setattr(tablefile_module, "table_bytes",
                        lambda *a, **k: real(*a, **k).replace(b'"name": "', b'"name": " ', 1))
    with pytest.raises(TableError, match="does not read back"):
        table.add(played("bob", time_limit=0.2, press=9))
    assert table.path.read_bytes() == before and not list(table.folder.glob("scores.json.corrupt-*"))


_JSON = st.one_of(st.none(), st.booleans(), st.text(max_size=5), st.floats(allow_nan=False, allow_infinity=False),
                  st.integers(-2, 3), st.integers(10**9 - 3, 10**9 + 2), st.just(2**63), st.just([1]))
_COUNTER = st.one_of(st.integers(1, 5), st.integers(10**9 - 6, 10**9), st.integers(1, 10**9))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow])
@given(seed=st.one_of(st.just("absent"), st.integers(0, 20), _JSON),
       next_entry=st.one_of(st.just("absent"), _COUNTER, _JSON),
       entered=st.lists(st.one_of(st.just("absent"), _COUNTER), min_size=0, max_size=4),
       version=st.sampled_from([1, 2, 3]), games=st.integers(1, 3), teacher=st.booleans())
def test_every_game_added_after_planted_head_and_counters_is_listed(tmp_path_factory, seed, next_entry, entered,
                                                                    version, games, teacher):
    root = tmp_path_factory.mktemp("t")
    os.environ["ARMGAME_CACHE"] = str(root / "private")
    folder = root / "table"
    if teacher:
        assert main(["scores", "--scores", str(folder), "--new", "--seed", "3"]) == 0
    table = ScoreTable(folder, warn=lambda m: None)
    planted = [table.add(played(f"planted {i}", time_limit=0.12, press=i)) for i in range(len(entered))]
    data = json.loads(table.path.read_text()) if planted else {"format": "armgame-scores", "entries": []}
    data["format_version"] = version
    for key, value in (("seed", seed), ("next_entry", next_entry)):
        data.pop(key, None)
        if value != "absent":
            data[key] = value
    for e, value in zip(data["entries"], entered, strict=True):
        e.pop("entered", None)
        if value != "absent":
            e["entered"] = value
    folder.mkdir(parents=True, exist_ok=True)
    table.path.write_text(json.dumps(data))
    added = [table.add(played(f"new {i}", time_limit=0.12, press=10 + i)) for i in range(games)]
    lists, flagged = listing(table, table.all_entries(), None, check=False, per_player=False)
    listed = {row.best[0].id for rows in lists.values() for row in rows}
    assert {e.id for e in added + planted} <= listed and not flagged
    assert not list(folder.glob("scores.json.corrupt-*"))  # the planted values were repaired, nothing set aside
    after = json.loads(table.path.read_text())
    if teacher:
        assert after["seed"] == 3 and table.seed == 3
    elif seed != "absent" and not (type(seed) is int and 0 <= seed < 2**63) and version == 3:
        assert after["seed"] == seed  # a seed that is not valid is kept as found


def test_a_burst_of_games_entered_at_once_is_recorded_in_its_order(tmp_path):
    """The live class's clerk enters many hand-ins with one write (``add_many``): the record knows each."""
    table = class_table(tmp_path)
    games = [played(f"s{i}", press=10 + i, time_limit=0.2) for i in range(3)]
    entered = table.add_many([*games, games[0].with_player("copier")])
    assert isinstance(entered[3], TableError)  # the same game again: refused, and never recorded
    record = TeacherRecord(table.folder, tmp_path / "teacher" / "cache").load()
    assert [record.entries[e.id].order for e in entered[:3]] == [1, 2, 3] and len(record.entries) == 3
