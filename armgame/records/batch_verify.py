"""Checking many replays at once: ``armgame verify`` of a score table or of a folder of replays.

Each replay's game is recomputed exactly as ``Replay.verify`` does (its configuration, its
timeline, stopped where it stopped), but replays whose configurations can share a batch are
recomputed together by ``game.batch.replay_many``, which equals the single session game for
game; the rest (an implicit integrator) are played one at a time. Replays are read, checked
and recomputed ``CHUNK`` at a time, so memory stays bounded however many there are.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from itertools import islice
from pathlib import Path

from ..game.batch import files_in, replay_many
from ..game.session import GameResult
from .replay import Replay, same_outcome
from .scores import Check, ScoreEntry, ScoreTable
from .storage import DataFileError

#: Replays read, checked and recomputed together.
CHUNK = 1024
#: Most replay files one ``armgame verify FOLDER`` takes.
MAX_FOLDER_REPLAYS = 100_000


def _chunks(items: Iterable, size: int) -> Iterator[list]:
    it = iter(items)
    while chunk := list(islice(it, size)):
        yield chunk


def verify_replays(replays: Sequence[Replay]) -> list[tuple[bool, GameResult]]:
    """``[replay.verify() for replay in replays]``, recomputed in batches."""
    results = replay_many([r.config for r in replays], [r.timeline for r in replays],
                          [r.result.steps for r in replays])
    return [(same_outcome(got, r.result), got) for r, got in zip(replays, results, strict=True)]


def check_entries(table: ScoreTable, entries: Iterable[ScoreEntry]) -> Iterator[tuple[ScoreEntry, Check]]:
    """``(entry, table.check(entry))`` for each entry, in order, the games recomputed in batches."""
    for chunk in _chunks(entries, CHUNK):
        found = [table.claimed_replay(e) for e in chunk]
        verdicts = iter(verify_replays([f for f in found if isinstance(f, Replay)]))
        for entry, f in zip(chunk, found, strict=True):
            yield entry, f if isinstance(f, Check) else table.reproduced(f, *next(verdicts))


def replay_files(folder: Path) -> list[Path]:
    """Every regular ``*.json`` file directly in ``folder``, sorted; symbolic links are not followed."""
    return files_in(folder, ".json", MAX_FOLDER_REPLAYS, "replay files")


def verify_files(paths: Iterable[Path]) -> Iterator[tuple[Path, Replay | DataFileError, GameResult | None, bool]]:
    """For each file, in order: (path, its replay, the recomputed result, whether it matches).

    A file that is not a valid replay gives (path, the error, None, False) and the others go on.
    """
    for chunk in _chunks(paths, CHUNK):
        loaded: list[Replay | DataFileError] = []
        for path in chunk:
            try:
                loaded.append(Replay.load(path))
            except DataFileError as exc:
                loaded.append(exc)
        verdicts = iter(verify_replays([r for r in loaded if isinstance(r, Replay)]))
        for path, r in zip(chunk, loaded, strict=True):
            if isinstance(r, Replay):
                ok, got = next(verdicts)
                yield path, r, got, ok
            else:
                yield path, r, None, False
