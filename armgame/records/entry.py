"""A table entry: what it says about its game, each field checked as it is read, and its orders.

An entry names its player, how the game was driven, its result, its rules (ruleset and config digest),
its game's digest (``identity.game_digest``), its place in the table's order of entry and its replay
file with that file's SHA-256; ``replay_claims`` is what its replay says about the same fields
(``CLAIM_FIELDS``), which ``checking`` compares field for field and the verification cache keeps.
``sort_key`` ranks (best first, ties by the order of entry) and ``entry_order`` is the order of entry itself.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from datetime import datetime

from ..game.rules import MAX_CONFIG_SECONDS
from ..valid import (
    COUNT_MAX,
    HEX32,
    HEX64,
    INT64_MAX,
    check_bool,
    check_date,
    check_float,
    check_int,
    check_keys,
    check_name,
    check_pattern,
    check_str,
    check_word,
)
from .identity import identity_claims
from .replay import DRIVEN, KEYBOARD_DEVICES, Replay
from .rulesets import config_digest, ruleset_name

_REPLAY_FILE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,150}\.json")


@dataclass(frozen=True)
class ScoreEntry:
    id: str
    name: str
    driven: str
    driver: str | None
    score: int
    hits: int
    resets: int
    seed: int
    scene: str
    duration: float
    date: str
    version: str
    replay: str
    replay_sha256: str
    #: The ruleset the game claims (``standard``, or ``custom``) and its config digest; None in
    #: entries carried over from a format 1 table (their replay decides, see ``ScoreTable.ruleset``).
    ruleset: str | None = None
    config_sha256: str | None = None
    #: The game's identity (``identity.game_digest``), its place in the order of entry (1, 2, ...), when the
    #: table took it, and whether it ran its whole clock; None in entries carried over from older tables.
    game_sha256: str | None = None
    entered: int | None = None
    entered_at: str | None = None
    complete: bool | None = None

    def as_dict(self) -> dict[str, object]:
        return {name: getattr(self, name) for name in _ENTRY_FIELDS}  # dataclasses.asdict deep-copies: 10x slower

    @property
    def when(self) -> datetime:
        return datetime.fromisoformat(self.date)

    @property
    def how(self) -> str:
        return f"{self.driven} ({self.driver})" if self.driver else self.driven

    @property
    def program(self) -> bool:
        """Whether the game says a program played it: anything but the keyboard with no driver named, or with
        only the device a person played it on (``KEYBOARD_DEVICES``: the class's browser game)."""
        return self.driven != "keyboard" or (self.driver is not None and self.driver not in KEYBOARD_DEVICES)

    @classmethod
    def from_dict(cls, data: object) -> ScoreEntry:
        """Check every field; raises ValueError naming the first bad one.

        Why it is written out field by field: a 100,000-entry table is read on every ``armgame scores``,
        and generic checks plus the frozen dataclass's ``__init__`` took most of that time. Each field
        first takes a test that only passes values the field's check would pass unchanged (exact
        types, precompiled patterns that bound the length and allow no control character); anything
        else goes through the check itself, in the same order, so the same first error is named.
        """
        if type(data) is dict and _REQUIRED <= data.keys() <= _ALL_FIELDS:  # what check_keys passes
            d = data
        else:
            d = check_keys("entry", data, _REQUIRED, _OPTIONAL)
        get = d.get
        v = d["driven"]
        if v not in DRIVEN:  # DRIVEN holds short printable words, so only its words pass check_str and this
            raise ValueError(f"driven must be one of {', '.join(DRIVEN)}, got {check_str('driven', v, 20)!r}")
        driven = v
        ruleset, digest = get("ruleset"), get("config_sha256")
        v = d["id"]
        id_ = v if type(v) is str and HEX32.fullmatch(v) else check_pattern("id", v, HEX32)
        v = raw_name = d["name"]
        name = v if type(v) is str and _NAME.fullmatch(v) else check_name(v)
        v = d["driver"]
        if v is not None and not (type(v) is str and len(v) <= 200 and v.isprintable()):
            v = check_str("driver", v, 200)
        driver = v
        v = d["score"]
        score = v if type(v) is int and 0 <= v <= COUNT_MAX else check_int("score", v, 0, COUNT_MAX)
        v = d["hits"]
        hits = v if type(v) is int and 0 <= v <= COUNT_MAX else check_int("hits", v, 0, COUNT_MAX)
        v = d["resets"]
        resets = v if type(v) is int and 0 <= v <= COUNT_MAX else check_int("resets", v, 0, COUNT_MAX)
        v = d["seed"]
        seed = v if type(v) is int and 0 <= v <= INT64_MAX else check_int("seed", v, 0, INT64_MAX)
        v = d["scene"]
        scene = v if type(v) is str and _WORD40.fullmatch(v) else check_word("scene", v)
        v = d["duration"]
        duration = (v if type(v) is float and 0.0 < v <= MAX_CONFIG_SECONDS
                    else check_float("duration", v, 0.0, MAX_CONFIG_SECONDS, low_open=True))
        date = check_date("date", d["date"])
        v = d["version"]
        version = v if type(v) is str and _WORD40.fullmatch(v) else check_word("version", v)
        v = d["replay"]
        replay = v if type(v) is str and _REPLAY_FILE.fullmatch(v) else check_pattern("replay", v, _REPLAY_FILE)
        v = d["replay_sha256"]
        replay_sha256 = v if type(v) is str and HEX64.fullmatch(v) else check_pattern("replay_sha256", v, HEX64)
        if ruleset is not None and not (type(ruleset) is str and _WORD40.fullmatch(ruleset)):
            ruleset = check_word("ruleset", ruleset)
        if digest is not None and not (type(digest) is str and HEX64.fullmatch(digest)):
            digest = check_pattern("config_sha256", digest, HEX64)
        v = get("game_sha256")
        if v is not None and not (type(v) is str and HEX64.fullmatch(v)):
            v = check_pattern("game_sha256", v, HEX64)
        game = v
        v = get("entered")
        if v is not None and not (type(v) is int and 1 <= v <= COUNT_MAX):
            v = check_int("entered", v, 1, COUNT_MAX)
        entered = v
        v = get("entered_at")
        entered_at = None if v is None else check_date("entered_at", v)
        v = get("complete")
        complete = None if v is None else check_bool("complete", v)
        if (ruleset is None) != (digest is None):
            raise ValueError("ruleset and config_sha256 come together")
        if score > hits:
            raise ValueError(f"score {score} is more than the hits {hits}")
        if name != raw_name:
            raise ValueError(f"name {raw_name!r} has surrounding spaces")
        # The fields are checked: set them as the frozen dataclass's __init__ would, in one step.
        entry = _new_object(cls)
        entry.__dict__.update(
            id=id_, name=name, driven=driven, driver=driver, score=score, hits=hits, resets=resets, seed=seed,
            scene=scene, duration=duration, date=date, version=version, replay=replay,
            replay_sha256=replay_sha256, ruleset=ruleset, config_sha256=digest, game_sha256=game,
            entered=entered, entered_at=entered_at, complete=complete,
        )
        return entry


_ENTRY_FIELDS = tuple(f.name for f in fields(ScoreEntry))
_OPTIONAL = frozenset({"ruleset", "config_sha256", "game_sha256", "entered", "entered_at", "complete"})
_REQUIRED = set(_ENTRY_FIELDS) - _OPTIONAL
_ALL_FIELDS = frozenset(_ENTRY_FIELDS)
_new_object = object.__new__
#: The values check_word passes unchanged at its default length: a word of 1 to 40 characters.
_WORD40 = re.compile(r"[A-Za-z0-9][A-Za-z0-9 ._+-]{0,39}")
#: The names check_name passes unchanged: 1 to 40 printable characters, none of them surrounding spaces.
#: (Only a guard for the fast path: it lets through fewer names than check_name, never more.)
_NAME = re.compile(r"[!-~](?:[ -~]{0,38}[!-~])?")


def sort_key(entry: ScoreEntry) -> tuple[int, int, datetime, str]:
    """Best first; equal scores by the table's order of entry, the earlier entry first.

    Entries carried over from a table older than format 3 have no place yet (they get one, in
    the order of their dates, at the table's next write): among them the earlier date first.
    """
    return (-entry.score, entry.entered or 0, entry.when, entry.id)


def entry_order(entry: ScoreEntry) -> tuple[int, datetime, str]:
    """The order the table took its entries in: the first of two entries of one game is the one that counts."""
    return (entry.entered or 0, entry.when, entry.id)


#: The fields an entry must say of its replay's game as the replay does (the entry's field of each name), with
#: how the replay says each: ``replay_claims`` reads them, ``checking`` compares an entry's with them, and the
#: verification cache keeps them (with the game's identity, ``identity.IDENTITY_FIELDS``) beside a verdict.
CLAIM_FIELDS: dict[str, Callable[[Replay], object]] = {
    "name": lambda replay: replay.player,
    "driven": lambda replay: replay.driven,
    "driver": lambda replay: replay.driver,
    "score": lambda replay: replay.result.score,
    "hits": lambda replay: replay.result.hits,
    "resets": lambda replay: replay.result.resets,
    "seed": lambda replay: replay.result.seed,
    "scene": lambda replay: replay.result.scene,
    "duration": lambda replay: replay.result.duration,
    "date": lambda replay: replay.date,
    "config_sha256": lambda replay: config_digest(replay.config),
    "ruleset": lambda replay: ruleset_name(replay.config),
    "complete": lambda replay: replay.complete,
}


def replay_claims(replay: Replay, digests: Sequence[str] | None = None) -> dict[str, object]:
    """What an entry must say about its replay's game, field for field (``CLAIM_FIELDS``); and the game's
    identity (``identity.identity_claims``: the digest an entry may hold, by each identity version)."""
    return {name: read(replay) for name, read in CLAIM_FIELDS.items()} | identity_claims(replay, digests)
