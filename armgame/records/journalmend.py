"""A damaged journal mended from the replays, before its entries are taken into the table (``ScoreTable.compact``).

Every line of ``scores.journal`` (``tablefile``) was an entry a server acknowledged, and each names its replay,
saved in ``replays/`` before the line was written. A line altered on disk (a bad sector, a byte flipped, an editor)
would otherwise be dropped at the next whole write, with a copy set aside and not a word to the teacher. Here the
replay is the authority: a line that does not read as an entry, or whose entry is not what its replay says, is
rebuilt from the replay its text still names (by file name or by SHA-256: one altered byte leaves one of the two
whole), once the replay re-simulates to its own claims. A line that names no such replay is named in the notice,
with what can still be read of it. The journal's bytes as found are kept beside it
(``scores.journal.corrupt-<UTC time>``) before anything is rewritten, and the notice names that copy.

What no replay records cannot be checked: an entry's id, its place in the order of entry and when it was entered
(a flipped digit there still reads as a valid entry of the same game). Its game, its player and its score are its
replay's, and those are what is checked.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import uuid
from collections.abc import Callable
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

from ..limits import MAX_REPLAY_BYTES, MAX_TABLE_BYTES
from .entry import CLAIM_FIELDS, ScoreEntry
from .identity import game_digests
from .replay import Replay
from .storage import DataFileError, atomic_write_bytes, copy_aside, open_regular, parse_json, read_limited
from .tableformat import entry_line

_FILE = re.compile(rb"[A-Za-z0-9][A-Za-z0-9._-]{0,150}\.json")
_SHA = re.compile(rb"(?<![0-9a-f])[0-9a-f]{64}(?![0-9a-f])")
_FIELD = {name: re.compile(rb'"' + name.encode() + rb'": ?("(?:[^"\\\n]|\\.){0,200}"|-?[0-9]{1,20})')
          for name in ("id", "name", "score", "date", "replay", "entered", "entered_at")}
#: The most lines of one journal rebuilt from their replays (each re-simulated): past it, the rest are named.
MAX_REBUILT = 1000

#: Makes an entry from a replay, its file's name in replays/ and its bytes (``scores._new_entry``).
EntryMaker = Callable[[Replay, str, bytes, "list[str] | None"], ScoreEntry]


def mend_journal(journal: Path, replays: Path, held: set[str], held_ids: set[str], make: EntryMaker) -> list[str]:
    """Under the table's lock: rewrite ``journal`` with every damaged line rebuilt from its replay (or, when none
    rebuilds it, left out if it does not read as an entry, kept as it is if it does); the notices for the teacher
    (none: nothing was wrong, nothing was written). ``held`` and ``held_ids``: the replays' SHA-256 and the ids of
    the table's own entries (a line whose game is in the table already is not entered twice; no id is given twice)."""
    try:
        data = read_limited(journal, MAX_TABLE_BYTES, "table journal", follow=False)
    except (DataFileError, OSError):
        return []  # the whole write that follows refuses it, saying why
    *lines, tail = data.split(b"\n")
    kept: list[bytes] = []
    notes: list[str] = []
    held, ids = set(held), set(held_ids)
    rebuilt = 0
    for number, line in enumerate([*lines, tail] if tail else lines, 1):
        cut = number > len(lines)  # no newline: a write a kill cut off (never acknowledged), or a damaged newline
        entry = _entry(line)
        if entry is not None and _backed(entry, replays):
            kept.append(line)
            held.add(entry.replay_sha256)
            ids.add(entry.id)
            if cut:
                notes.append(f"line {number} had lost its newline: kept")
            continue
        games, already = [], []
        names = _candidates(line, replays)
        readable = _fields(line) if entry is None and len(names) == 1 else {}  # two games' line: whose id is it?
        for name in names:
            found = _rebuild(replays / name, make, readable, entry, ids) if rebuilt < MAX_REBUILT else None
            if found is None:
                continue
            if found.replay_sha256 in held:
                already.append(found)
                continue
            rebuilt += 1
            held.add(found.replay_sha256)
            ids.add(found.id)
            games.append(found)
        kept += [entry_line(e).encode("utf-8") for e in games]
        said = [f"{e.name}'s game, score {e.score} (replays/{e.replay})" for e in games]
        if games:
            notes.append(f"line {number} was damaged; rebuilt from its replay: {'; '.join(said)}")
        elif already:
            notes.append(f"line {number} was damaged; its game is in the table already (replays/{already[0].replay})")
        elif entry is not None:
            kept.append(line)
            held.add(entry.replay_sha256)
            ids.add(entry.id)
            notes.append(f"line {number} was damaged: it is not what its replay says and no replay rebuilds it, so "
                         f"it is kept as it reads ({_what_it_held(line)})")
        elif not cut:
            notes.append(f"line {number} was damaged and no replay rebuilds it; it held {_what_it_held(line)}")
    if not notes:
        return []
    kept_as = _keep_aside(journal)
    atomic_write_bytes(journal, b"".join(line + b"\n" for line in kept), "table journal")
    where = f"its bytes as found are kept as {kept_as}" if kept_as else "no copy of its bytes could be kept"
    return [f"{journal} was damaged ({where}):"] + [f"  {note}" for note in notes]


def _entry(line: bytes) -> ScoreEntry | None:
    try:
        return ScoreEntry.from_dict(parse_json(line))
    except (ValueError, RecursionError, DataFileError):
        return None


def _read(path: Path) -> tuple[bytes, Replay] | None:
    try:
        data = read_limited(path, MAX_REPLAY_BYTES, "replay", follow=False)
        return data, Replay.from_bytes(data, str(path))
    except (DataFileError, OSError, ValueError):
        return None


def _backed(entry: ScoreEntry, replays: Path) -> bool:
    """Whether the entry is what its replay file says: the file it names, with its SHA-256, and every field the
    replay records (the game was re-simulated when it was taken, and its file has not changed since)."""
    found = _read(replays / entry.replay)
    if found is None:
        return False
    data, replay = found
    if hashlib.sha256(data).hexdigest() != entry.replay_sha256 or entry.version != replay.version:
        return False
    if any(getattr(entry, key) != read(replay) for key, read in CLAIM_FIELDS.items()):
        return False
    return entry.game_sha256 is None or entry.game_sha256 in game_digests(replay)


def _candidates(line: bytes, replays: Path) -> list[str]:
    """The replay files a damaged line names: by file name, or by its SHA-256 (whose first 8 digits end the
    file's name, ``TableFile._replay_name``), in the order the line names them."""
    names: list[str] = []
    for found in _FILE.finditer(line):
        name = found.group().decode("ascii")
        if name not in names and (replays / name).is_file():
            names.append(name)
    for found in _SHA.finditer(line):
        digest = found.group().decode("ascii")
        with contextlib.suppress(OSError):
            for path in sorted(replays.glob(f"*-{digest[:8]}.json")):
                with contextlib.suppress(DataFileError):
                    data = read_limited(path, MAX_REPLAY_BYTES, "replay", follow=False)
                    if path.name not in names and hashlib.sha256(data).hexdigest() == digest:
                        names.append(path.name)
    return names


def _rebuild(path: Path, make: EntryMaker, readable: dict[str, object], entry: ScoreEntry | None,
             ids: set[str]) -> ScoreEntry | None:
    """The entry of the replay at ``path``, if it re-simulates to its own claims and is a whole game under a
    player's name: with the id, place and time of entry of the damaged ``entry`` (or those still ``readable`` in
    its line), else a new id (never one in ``ids``) and no place (the next whole write numbers it)."""
    found = _read(path)
    if found is None:
        return None
    data, replay = found
    if replay.player is None or replay.task is not None or not replay.complete:
        return None
    try:
        ok, _ = replay.verify()
    except Exception:  # a replay that blows up or costs too much rebuilds nothing
        return None
    if not ok:
        return None
    made = make(replay, path.name, data, None)
    if entry is not None:
        made = replace(made, id=entry.id, entered=entry.entered, entered_at=entry.entered_at)
    else:
        with contextlib.suppress(ValueError):
            made = ScoreEntry.from_dict({**made.as_dict(), **{k: readable[k] for k in ("id", "entered", "entered_at")
                                                              if k in readable}})
    return made if made.id not in ids else replace(made, id=uuid.uuid4().hex)


def _fields(line: bytes) -> dict[str, object]:
    """The fields of a damaged line still readable one by one."""
    found: dict[str, object] = {}
    for name, pattern in _FIELD.items():
        match = pattern.search(line)
        if match is not None:
            with contextlib.suppress(ValueError, DataFileError):
                found[name] = parse_json(match.group(1))
    return found


def _what_it_held(line: bytes) -> str:
    fields = _fields(line)
    said = [f"{key} {fields[key]!r}" for key in ("name", "score", "date", "replay") if key in fields]
    return ", ".join(said) if said else "nothing readable (its bytes are in the copy)"


def _keep_aside(journal: Path) -> Path | None:
    """A copy of the journal's bytes as found, beside it (the table's own copies are named alike), or None."""
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    try:
        fd = open_regular(journal, "table journal", follow=False)
    except (DataFileError, OSError):
        return None
    try:
        for n in range(1000):
            path = journal.with_name(f"{journal.name}.corrupt-{stamp}{f'-{n}' if n else ''}")
            try:
                copy_aside(fd, path)
            except FileExistsError:
                continue
            except OSError:
                return None
            return path
        return None
    finally:
        os.close(fd)
