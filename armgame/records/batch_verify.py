"""Checking many replays at once: ``armgame verify`` of a score table or of a folder of replays.

Each replay's game is recomputed exactly as ``Replay.verify`` does (its configuration, its
timeline, stopped where it stopped), but replays whose configurations can share a batch are
recomputed together by ``game.batch.replay_many``, which equals the single session game for
game; the rest (an implicit integrator) are played one at a time. Replays are read, checked
and recomputed ``CHUNK`` at a time, so memory stays bounded however many there are.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from functools import lru_cache
from itertools import islice
from pathlib import Path

from ..errors import UserError
from ..game.batch import files_in, replay_many
from ..game.rules import GameConfig
from ..game.session import GameResult
from ..limits import MAX_VERIFY_WORK
from .replay import Replay, VerifyCostError, same_outcome
from .rulesets import ruleset_of
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


def verify_replays(replays: Sequence[Replay], kernel: str | None = None) -> list[tuple[bool, GameResult]]:
    """``[replay.verify() for replay in replays]``, the games of ranked rulesets recomputed in batches
    (a game that does not reproduce is recomputed to its end, where ``verify`` stops once it passes
    its claim: the verdicts are the same).

    Only those: their cost is known (the ruleset's steps) and they share a batch by construction.
    A lab run is compared trial by trial, and a custom game's ``verify`` stops as soon as it scores
    more than it claims (a rigged configuration could hit a target at every step), so both keep
    their own ``verify``. ``kernel`` is ``BatchGameSession``'s (None: compiled where built).
    """
    batched = [i for i, r in enumerate(replays) if batchable(r)]
    # exact: the results are the single session's (numpy's fast kernel replays a game alone where a hit
    # was decided within round-off of a target's edge), so the batch's verdict is final both ways: a
    # planted pile of forgeries costs its batched steps, not one single-session game each.
    results = replay_many([replays[i].config for i in batched], [replays[i].timeline for i in batched],
                          [replays[i].result.steps for i in batched], exact=True, kernel=kernel)
    verdicts: list[tuple[bool, GameResult] | None] = [None] * len(replays)
    for i, got in zip(batched, results, strict=True):
        verdicts[i] = (same_outcome(got, replays[i].result), got)
    return [v if v is not None else r.verify() for r, v in zip(replays, verdicts, strict=True)]


def batchable(replay: Replay) -> bool:
    """Whether ``verify_replays`` recomputes ``replay`` in a batch: a game of a ranked ruleset."""
    return replay.task is None and _ranked(replay.config)


@lru_cache(maxsize=64)
def _ranked(config: GameConfig) -> bool:
    # A class's replays share a few configurations; their digest (a JSON dump and a SHA-256) cost a
    # batch's verification 7% when it was taken for each. Cached here, not in ruleset_of: equal
    # configurations may still differ in their digest (0.0 and -0.0), which decides a table's ranking,
    # but here only which path recomputes the game, and both give the same verdict.
    return ruleset_of(config) is not None


def check_entries(table: ScoreTable, entries: Iterable[ScoreEntry],
                  max_work: int | None = None) -> Iterator[tuple[ScoreEntry, Check]]:
    """``(entry, table.check(entry))`` for each entry, in order, the games recomputed in batches
    (``max_work``: see ``ScoreTable.check_many``)."""
    for chunk in _chunks(entries, CHUNK):
        yield from zip(chunk, table.check_many(chunk, verify_replays, max_work), strict=True)


def replay_files(folder: Path) -> list[Path]:
    """Every regular ``*.json`` file directly in ``folder``, sorted; symbolic links are not followed."""
    return files_in(folder, ".json", MAX_FOLDER_REPLAYS, "replay files")


def verify_files(paths: Iterable[Path], skip: Callable[[Replay], bool] | None = None,
                 max_work: int | None = MAX_VERIFY_WORK
                 ) -> Iterator[tuple[Path, Replay | UserError, GameResult | None, bool]]:
    """For each file, in order: (path, its replay, the recomputed result, whether it matches).

    A file that is not a valid replay, or a game stopped at its verification's budget ``max_work`` (a hit
    storm: ``Replay.verify``'s ``VerifyCostError``), gives (path, the error, None, False) and the others go
    on; a replay that ``skip`` says not to recompute (its cost) gives (path, the replay, None, False).
    """
    for chunk in _chunks(paths, CHUNK):
        loaded: list[Replay | DataFileError] = []
        for path in chunk:
            try:
                loaded.append(Replay.load(path))
            except DataFileError as exc:
                loaded.append(exc)
        wanted = [isinstance(r, Replay) and not (skip is not None and skip(r)) for r in loaded]
        # The ranked games in batches; the others each on its own, a hit storm stopped at its budget.
        batched = iter(verify_replays([r for r, w in zip(loaded, wanted, strict=True)  # type: ignore[misc]
                                       if w and batchable(r)]))  # type: ignore[arg-type]
        for path, r, w in zip(chunk, loaded, wanted, strict=True):
            if not w:
                yield path, r, None, False
                continue
            verdict = next(batched) if batchable(r) else _own_verdict(r, max_work)  # type: ignore[arg-type]
            if isinstance(verdict, VerifyCostError):
                yield path, verdict, None, False
            else:
                ok, got = verdict
                yield path, r, got, ok


def _own_verdict(replay: Replay, max_work: int | None) -> tuple[bool, GameResult] | VerifyCostError:
    """``replay.verify(max_work)``, or why it was not checked (a hit storm stopped at its budget), so the
    other files of a folder are still checked."""
    try:
        return replay.verify(max_work)
    except VerifyCostError as exc:
        return exc
