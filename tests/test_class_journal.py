"""A class's journal damaged while its server was down (issue 54): every acknowledged game is still in the table,
rebuilt from its replay where its line was damaged, or named in the teacher's terminal with the copy of the
journal set aside; never silently gone, never a traceback.

The class is opened in-process (``Clerk``, what ``armgame class serve`` opens first), not served: each altered
journal costs one opening of the table, not a server's start.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from class_server import running_class, tapped_games

from armgame.classroom.intake import Clerk
from armgame.classroom.roster import Roster
from armgame.records.entry import CLAIM_FIELDS, ScoreEntry
from armgame.records.tablefile import JOURNAL_NAME

NAMES = ("Ann B", "Bo", "Cy")
#: What an entry says of its game, all of it from its replay: the fields a damaged line must come back with.
GAME_FIELDS = (*CLAIM_FIELDS, "replay", "replay_sha256", "version", "game_sha256")


@pytest.fixture(scope="module")
def stopped(tmp_path_factory) -> tuple[Path, list[ScoreEntry]]:
    """A class of three with 6 games taken, its server gone without a word (its journal not yet taken into the
    table, as after a kill -9); and the entries acknowledged."""
    folder = tmp_path_factory.mktemp("class") / "class"
    folder.mkdir()
    roster, _ = Roster.open(folder, 10)
    clerk = Clerk(folder, roster, warn=lambda line: None)
    tokens = [clerk.join(name, None)[1] for name in NAMES]
    for i, data in enumerate(tapped_games(6, ["x"])):
        assert clerk.hand_in(tokens[i % 3], data)["ok"]
    assert len((folder / JOURNAL_NAME).read_bytes().splitlines()) == 6
    return folder, list(clerk.entries)


def reopened(folder: Path) -> tuple[list[ScoreEntry], list[str]]:
    said: list[str] = []
    clerk = Clerk(folder, Roster.open(folder, None)[0], warn=said.append)
    return clerk.entries, said


def game(entry: ScoreEntry) -> tuple:
    return tuple(getattr(entry, key) for key in GAME_FIELDS)


def missing(acknowledged: list[ScoreEntry], entries: list[ScoreEntry], said: list[str], folder: Path) -> list[str]:
    """The acknowledged games neither in ``entries`` as they were taken nor named in what the teacher was told
    (a line naming the game's replay or its player, and the copy of the journal set aside, which exists)."""
    have = {game(e) for e in entries}
    told = "\n".join(said)
    copies = list(folder.glob(f"{JOURNAL_NAME}.corrupt-*"))
    return [e.replay for e in acknowledged if game(e) not in have
            and not ((e.replay in told or repr(e.name) in told) and copies and copies[0].name in told)]


def altered(stopped, tmp_path: Path, position: int, mask: int) -> Path:
    source, _ = stopped
    folder = tmp_path / f"at-{position}-{mask}"
    shutil.copytree(source, folder)
    journal = folder / JOURNAL_NAME
    data = bytearray(journal.read_bytes())
    data[position] ^= mask
    journal.write_bytes(bytes(data))
    return folder


def test_a_journal_as_written_reopens_whole_and_says_nothing(stopped, tmp_path):
    folder = altered(stopped, tmp_path, 0, 0)
    entries, said = reopened(folder)
    assert sorted(map(game, entries)) == sorted(map(game, stopped[1])) and said == []


def test_one_byte_in_the_third_line_is_rebuilt_and_said_in_the_teachers_terminal(stopped, tmp_path):
    """The issue's case: one byte of the 3rd line altered; ``armgame class serve`` says so and the game is in."""
    source, acknowledged = stopped
    lines = (source / JOURNAL_NAME).read_bytes().split(b"\n")
    third = lines[2]
    score = len(lines[0]) + len(lines[1]) + 2 + third.index(b'"score": ') + len(b'"score": ')
    folder = altered(stopped, tmp_path, score, 0x01)  # its score 0 reads 1: a valid line, not its replay's game
    said: list[str] = []
    with running_class(folder, lines=said) as opened:
        assert sorted(map(game, opened.clerk.entries)) == sorted(map(game, acknowledged))
    told = "\n".join(said)
    third_game = next(e for e in acknowledged if e.id.encode() in third)
    assert "line 3 was damaged; rebuilt from its replay" in told and third_game.replay in told
    copy = next(folder.glob(f"{JOURNAL_NAME}.corrupt-*"))
    assert copy.name in told and copy.read_bytes()[len(lines[0]) + 1:].startswith(lines[1])


def test_a_line_no_replay_rebuilds_is_named_with_the_copy(stopped, tmp_path):
    """The line's replay gone too: its game is named (player, score, replay), with where the bytes are kept."""
    _, acknowledged = stopped
    folder = altered(stopped, tmp_path, 0, 0)
    journal = folder / JOURNAL_NAME
    lines = journal.read_bytes().split(b"\n")
    lost = next(e for e in acknowledged if e.id.encode() in lines[1])
    (folder / "replays" / lost.replay).unlink()
    lines[1] = lines[1].replace(b'"hits"', b'"hits"}')  # not JSON any more
    journal.write_bytes(b"\n".join(lines))
    entries, said = reopened(folder)
    assert len(entries) == 5
    told = "\n".join(said)
    assert "line 2 was damaged and no replay rebuilds it" in told and f"'{lost.name}'" in told
    assert lost.replay in told and next(folder.glob(f"{JOURNAL_NAME}.corrupt-*")).name in told
    assert missing(acknowledged, entries, said, folder) == []


def scan(stopped, tmp_path, positions, mask: int) -> None:
    _, acknowledged = stopped
    for position in positions:
        folder = altered(stopped, tmp_path, position, mask)
        entries, said = reopened(folder)
        assert missing(acknowledged, entries, said, folder) == [], (position, said)
        assert len(entries) == len(acknowledged), (position, said)
        shutil.rmtree(folder)


def test_every_newline_and_one_byte_in_67_of_the_journal_altered(stopped, tmp_path):
    """The default tier's share, about 60 openings (the slow tier alters every byte)."""
    data = (stopped[0] / JOURNAL_NAME).read_bytes()
    newlines = [i for i, byte in enumerate(data) if byte == ord("\n")]
    scan(stopped, tmp_path, [*newlines, *range(5, len(data), 67)], 0x01)


@pytest.mark.slow
@pytest.mark.parametrize("mask", [0x01, 0x80])
def test_every_byte_of_the_journal_altered(stopped, tmp_path, mask):
    scan(stopped, tmp_path, range(len((stopped[0] / JOURNAL_NAME).read_bytes())), mask)
