"""Checking entries against their replays: each game recomputed (or its cached verdict used), and
compared with what its entry claims.

An entry names its replay file and that file's SHA-256, so a score typed into the table, a replay
edited, or replays swapped between entries all show up when its game is recomputed. What recomputing
costs is counted before it runs (``replay_work``): a checker that will not spend that much leaves the
game ``NOT CHECKED`` (``armgame scores``'s budget; ``armgame verify`` checks everything unless told
``--max-work``). Verdicts, failures too, are kept in the per-user ``VerificationCache``.
"""

from __future__ import annotations

import hashlib
import os
import stat
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..game.rules import MAX_TRIES
from ..game.session import GameResult
from ..limits import MAX_REPLAY_BYTES
from ..words import plural
from .cache import VerificationCache, file_signature
from .entry import CLAIM_FIELDS, ScoreEntry, replay_claims
from .identity import names_its_game
from .replay import EVENT_WORK, TRY_WORK, Replay, VerifyCostError
from .rulesets import ruleset_of
from .storage import DataFileError, open_regular

#: The label of a game whose replay costs more than its checker would spend (``check_many``'s ``max_work``).
NOT_CHECKED = "NOT CHECKED"


@dataclass(frozen=True)
class Check:
    """What recomputing an entry's game says: ``ok``, or a short label and why not.

    ``ruleset`` is the ruleset the replay plays (``custom`` if none), when the replay could be read.
    """

    ok: bool
    label: str
    detail: str = ""
    ruleset: str | None = None
    #: The game's digest (``identity.game_digest``), when the replay could be read.
    game: str | None = None


class TableChecks:
    """``check`` and ``check_many`` of a table's entries; ``ScoreTable`` is one (its ``replays`` folder and
    its ``cache``)."""

    replays: Path
    cache: VerificationCache | None

    def replay_path(self, entry: ScoreEntry) -> Path:
        return self.replays / entry.replay

    def _replay_file(self, entry: ScoreEntry) -> Path:
        mode = os.lstat(self.replays).st_mode if self.replays.exists() or self.replays.is_symlink() else None
        if mode is not None and not stat.S_ISDIR(mode):
            raise DataFileError(f"{self.replays}: is not a folder (a symbolic link is not followed)")
        return self.replay_path(entry)

    def check(self, entry: ScoreEntry) -> Check:
        """Whether the entry's replay is the one it names and reproduces its game. Never raises."""
        return self.check_many([entry])[0]

    def check_many(self, entries: Sequence[ScoreEntry],
                   recompute: Callable[[Sequence[Replay]], list[tuple[bool, GameResult]]] | None = None,
                   max_work: int | None = None) -> list[Check]:
        """``check`` for each entry; the games not in the cache are recomputed together.

        ``recompute`` maps replays to ``replay.verify()`` of each (``records.batch_verify`` passes
        the batched one); if it fails, the games are recomputed one at a time, so one entry's
        failure still marks only that entry. ``max_work``: a replay whose ``replay_work`` is more
        is not recomputed (``NOT CHECKED``; remembered, so that it is not read again, until a check with a
        larger ``max_work`` or none, as ``armgame verify``'s, recomputes it).
        """
        found: list[Check | tuple[str, dict | Replay, list[int]]] = []
        for entry in entries:
            try:
                found.append(self._claim(entry, max_work))
            except Exception as exc:  # one entry's failure never takes the table down
                found.append(_bad(exc))
        pending: dict[str, tuple[Replay, list[int]]] = {}
        for i, f in enumerate(found):
            if not isinstance(f, Check) and isinstance(f[1], Replay):
                work = replay_work(f[1])
                if max_work is not None and work > max_work:
                    skipped = {"claims": replay_claims(f[1]), "ok": False, "label": NOT_CHECKED, "file": f[2],
                               "work": work, "detail": not_checked_detail(f[1], work)}
                    if self.cache is not None:  # remembered, so the next listing does not even read it
                        self.cache.put(f[0], skipped)
                    found[i] = (f[0], skipped, f[2])
                else:
                    pending[f[0]] = (f[1], f[2])
        verdicts = _recompute([replay for replay, _ in pending.values()], recompute)
        judged: dict[str, dict] = {}
        for (digest, (replay, signature)), verdict in zip(pending.items(), verdicts, strict=True):
            judged[digest] = {"claims": replay_claims(replay), **verdict, "file": signature}
            if self.cache is not None:
                self.cache.put(digest, judged[digest])
        checks = []
        for entry, f in zip(entries, found, strict=True):
            if isinstance(f, Check):
                checks.append(f)
                continue
            digest, item, _ = f
            try:
                checks.append(self._judge(entry, judged[digest] if isinstance(item, Replay) else item))
            except Exception as exc:
                checks.append(_bad(exc))
        return checks

    def _claim(self, entry: ScoreEntry, max_work: int | None = None) -> Check | tuple[str, dict | Replay, list[int]]:
        """A failed ``Check``; or the replay's digest with its cached verdict, or the replay still to
        recompute, and the replay file's signature. A replay file whose signature a cached verdict
        recorded is not read at all (``cache.file_signature``)."""
        try:
            path = self._replay_file(entry)
            fd = open_regular(path, "replay file", follow=False)
        except DataFileError as exc:
            missing = not self.replay_path(entry).exists() and not self.replay_path(entry).is_symlink()
            return Check(False, "REPLAY MISSING" if missing else "REPLAY UNREADABLE", str(exc))
        with os.fdopen(fd, "rb") as f:
            signature = file_signature(os.fstat(f.fileno()))
            if self.cache is not None and self.cache.digest_of(signature) == entry.replay_sha256:
                cached = _usable(self.cache.get(entry.replay_sha256), max_work)
                if cached is not None:
                    return entry.replay_sha256, cached, signature
            try:
                data = f.read(MAX_REPLAY_BYTES + 1)
            except OSError as exc:
                return Check(False, "REPLAY UNREADABLE", f"{path}: cannot read: {exc.strerror or exc}")
        if len(data) > MAX_REPLAY_BYTES:
            return Check(False, "REPLAY UNREADABLE", f"{path}: larger than a replay may be")
        digest = hashlib.sha256(data).hexdigest()
        if digest != entry.replay_sha256:
            return Check(False, "REPLAY CHANGED", f"{path.name} is not the replay this entry was saved with")
        cached = _usable(self.cache.get(digest), max_work) if self.cache else None
        if cached is not None:
            if self.cache is not None and cached.get("file") != signature:
                self.cache.put(digest, {**cached, "file": signature})  # known unchanged without reading, next time
            return digest, cached, signature
        try:
            replay = Replay.from_bytes(data, str(path))
        except DataFileError as exc:
            cached = {"claims": None, "ok": False, "label": "BAD REPLAY", "detail": str(exc), "file": signature}
            if self.cache:
                self.cache.put(digest, cached)
            return digest, cached, signature
        if replay.task is not None:
            return Check(False, "NOT A GAME", f"{path.name} is a lab run, which is never ranked")
        return digest, replay, signature

    @staticmethod
    def _judge(entry: ScoreEntry, cached: dict) -> Check:
        """The verdict on an entry whose replay's claims and recomputed verdict are ``cached``."""
        claims = cached["claims"]
        if claims is None:
            return Check(False, cached["label"], cached["detail"])
        # The claims the entry's own fields must equal; its game's digest is compared by ``names_its_game`` below.
        wanted = {key: value for key, value in claims.items() if key in CLAIM_FIELDS}
        if entry.config_sha256 is None:  # a format 1 entry makes no claim about its rules
            wanted.pop("config_sha256")
            wanted.pop("ruleset")
        if entry.complete is None:  # entries from older tables make no such claim
            wanted.pop("complete")
        for key, value in wanted.items():
            if getattr(entry, key) != value:
                return Check(False, "NOT ITS REPLAY", f"the entry says {key} {getattr(entry, key)!r}, its replay "
                             f"{value!r}", claims["ruleset"], claims["game_sha256"])
        # The digest by the identity version that entered it (older tables: none stored).
        if entry.game_sha256 is not None and not names_its_game(entry.game_sha256, claims):
            return Check(False, "NOT ITS REPLAY", f"the entry says game_sha256 {entry.game_sha256!r}, its replay "
                         f"{claims['game_sha256']!r}", claims["ruleset"], claims["game_sha256"])
        if not claims["complete"]:
            return Check(False, "NOT A WHOLE GAME", "the game stopped before its clock ran out", claims["ruleset"],
                         claims["game_sha256"])
        return Check(cached["ok"], cached["label"], cached["detail"], claims["ruleset"], claims["game_sha256"])


# Work is counted in ``records.replay``'s units (``TRY_WORK``, ``EVENT_WORK``: physics steps of the game's
# compiled loop), the ones ``Replay.verify`` counts as it runs.
#: What recomputing one hit can cost under any rules: drawing the next target tries up to ``MAX_TRIES`` (1,000)
#: postures (``GameRules._draw_target``), ``TRY_WORK`` each: 6,000.
HIT_WORK = MAX_TRIES * TRY_WORK
#: What one hit costs under a ranked ruleset, whose target ranges keep a drawn target clear of the hand:
#: 1.36 tries on average and at most 9 in 20,000 draws from random hands, a draw measured at 14 steps.
RANKED_HIT_WORK = 100


def replay_work(replay: Replay) -> int:
    """The most work recomputing ``replay`` can take, in physics steps, known before running it: its
    steps, its claimed hits (verification stops as soon as the game passes its claim), each a target draw
    (``RANKED_HIT_WORK`` under a ranked ruleset, else ``HIT_WORK``), and its events."""
    hit = RANKED_HIT_WORK if ruleset_of(replay.config) is not None else HIT_WORK
    return replay.result.steps + hit * replay.result.hits + EVENT_WORK * len(replay.timeline)


def not_checked_detail(replay: Replay, work: int) -> str:
    """Why a replay was left unchecked: what it claims, and the work that makes (``replay_work``)."""
    r = replay.result
    return (f"its replay claims {plural(r.steps, 'step')}, {plural(r.hits, 'hit')} and "
            f"{plural(len(replay.timeline), 'event')}: {work:,} steps of work, more than this check spends on one "
            f"game (armgame verify checks it)")


def _usable(cached: dict | None, max_work: int | None) -> dict | None:
    """A cached verdict, unless it is a game left unchecked for its cost that this caller would check."""
    if cached is not None and cached["label"] == NOT_CHECKED and (max_work is None or cached["work"] <= max_work):
        return None
    return cached


def _bad(exc: Exception) -> Check:
    reason = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
    return Check(False, "BAD REPLAY", reason)


def _recompute(replays: list[Replay],
               recompute: Callable[[Sequence[Replay]], list[tuple[bool, GameResult]]] | None) -> list[dict]:
    if replays and recompute is not None:
        try:
            return [_judged(replay, *outcome) for replay, outcome in zip(replays, recompute(replays), strict=True)]
        except Exception:  # e.g. one game's blow-up stopped the batch: find it one game at a time
            pass
    return [_verdict(replay) for replay in replays]


def _verdict(replay: Replay) -> dict[str, object]:
    try:
        ok, recomputed = replay.verify()
    except VerifyCostError as exc:  # a hit storm, stopped at its verification's budget: unchecked, not bad
        return {"ok": False, "label": NOT_CHECKED, "detail": str(exc), "work": replay_work(replay)}
    except Exception as exc:  # a blow-up (NonFiniteState) or anything else the game raises
        return {"ok": False, "label": "BAD REPLAY", "detail": str(exc) or type(exc).__name__}
    return _judged(replay, ok, recomputed)


def _judged(replay: Replay, ok: bool, recomputed: GameResult) -> dict[str, object]:
    if ok:
        return {"ok": True, "label": "ok", "detail": ""}
    r = replay.result
    return {"ok": False, "label": "NOT REPRODUCED",
            "detail": f"recorded score {r.score}, the replay gives {recomputed.score} "
                      f"({plural(recomputed.hits, 'hit')}, {plural(recomputed.resets, 'reset')})"}
