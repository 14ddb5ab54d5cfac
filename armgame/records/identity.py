"""A game's identity: what it is, not the file it came in, so that one game enters a table once.

Two replays are one game when the physics and the score cannot tell them apart. ``game_digest``
is the SHA-256 of the canonical form of what the game's session did:

* the ruleset's digest (``rulesets.config_digest``: the whole configuration but the seed and
  the key bindings), the seed and the number of steps played;
* what each physics step applied (``applied_input``): the set of muscles held, by muscle index,
  as runs over the steps (the step each run starts at and its set), and the resets, as the
  number at each step that has any.

That form is what ``GameSession`` reads, not the events that produced it, so whatever changes
nothing drops out by construction: the muscles' goals are set by ``key_event`` alone and read
only by the next physics step, so a repeated key-down, a key-up of a key that is up, the order
of a step's events and a key pressed and released within one step leave the same set held
after the step's events; tab flips only whether the window draws the arm (``GameRules.toggle_arm``:
neither the physics nor the score reads it); events the session ignores (the end of the clock)
apply nothing. Each space press at a step resets the arm and counts a reset, so two at one step
are two resets: the count is in the form. The key bindings (``--keys``), the JSON's layout, the
date, the player's name and the armgame version are not.

One caveat, on the safe side: a reset pressed at the very step a lab run's last trial ends is
kept in the form though the lab ignores it (the run is over; a replay does not say so without
replaying). Identity is never coarser than the session, only there finer.

This module is the one owner of "is this the same game as an earlier one, and which counts":
``FirstEntries`` answers it for ``armgame scores``, ``armgame verify DIR`` and ``armgame analyze
--class`` alike. A classmate who copies a replay under another name, moves its date by a
microsecond, or adds a tab press or a tap within one step gets the same digest, and the copy
does not count twice.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Generic, TypeVar

from .._native import load
from ..game.session import DOWN, RESET_KEY, TOGGLE_ARM_KEY, UP
from ..valid import INT64_MAX
from .replay import Replay
from .rulesets import config_digest

#: Bumped whenever the canonical form changes (a new digest for every game). 2: what each step applies,
#: not the events (1). Tables keep the digests older versions wrote: ``names_its_game`` still knows them.
IDENTITY_VERSION = 2

T = TypeVar("T")


@dataclass(frozen=True)
class AppliedInput:
    """What a game's input did, step by step (see the module docstring).

    ``held``: ``(step, mask)`` at each step from which the muscles held change (bit ``i``: muscle ``i``
    held), starting from none held; only steps the game ran. ``resets``: ``(step, count)`` at each step
    with resets.
    """

    held: tuple[tuple[int, int], ...]
    resets: tuple[tuple[int, int], ...]


def applied_input(replay: Replay) -> AppliedInput:
    """What each step of the replay's game applies, as its session applies it (``TimelineInput`` feeding
    ``GameSession.key_event``): the events of a step, then the step."""
    index = {m.key: i for i, m in enumerate(replay.config.muscles)}
    steps = replay.result.steps
    # The session takes input until its clock ends (``over``); a game stopped early took it up to its stop,
    # where a reset still counts but a muscle held runs no step.
    end = replay.config.total_steps
    held = mask = 0
    runs: list[tuple[int, int]] = []
    resets: dict[int, int] = {}
    timeline = replay.timeline
    # Each event with the next one's step (None after the last): whether it is its step's last. The loop runs
    # once an event (15,000 in a bot's game), so what it reads is read once, into locals.
    following: list[int | None] = [*(e.step for e in timeline[1:]), None] if timeline else []
    stop = min(end, steps + 1)  # the session is over, or the game stopped before it
    for e, after in zip(timeline, following, strict=True):
        step = e.step
        if step >= stop:
            break
        key = e.key
        m = index.get(key)
        if m is not None:
            held = held | 1 << m if e.action == DOWN else held & ~(1 << m)
        elif key == RESET_KEY and e.action == DOWN:
            resets[step] = resets.get(step, 0) + 1
        if held != mask and after != step and step < steps:
            runs.append((step, held))  # the step's last event: the set its physics step reads
            mask = held
    return AppliedInput(tuple(runs), tuple(sorted(resets.items())))


def _both_forms(replay: Replay) -> tuple[AppliedInput, list[tuple[int, str, str]]]:
    """``applied_input(replay)`` and version 1's events (``_form_v1``'s ``"timeline"``) in one pass, for a game
    that ran to its end (where the two stop at the same event: ``applied_input``'s stop is the end, and
    ``_form_v1``'s the steps played). The same values as the two, in half their time (a bot's game: 15,000
    events). A step's set is taken when the next event's step differs (``applied_input``'s look-ahead: the step's
    last event); while both run, the muscles held are the same, as each event changes them alike."""
    steps = replay.result.steps
    assert steps == replay.config.total_steps, "a game that ran to its end"
    index = {m.key: i for i, m in enumerate(replay.config.muscles)}
    names = [f"m{i}" for i in range(len(index))]
    held = mask = 0
    runs: list[tuple[int, int]] = []
    resets: dict[int, int] = {}
    events: list[tuple[int, str, str]] = []
    add = events.append
    pending: int | None = None  # the step of the event before: its step's last once the step changes
    for e in replay.timeline:
        step = e.step
        if step != pending:
            if pending is not None and held != mask and pending < steps:
                runs.append((pending, held))
                mask = held
            pending = step
        if step >= steps:
            pending = None  # taken above, as the event before's look-ahead would
            break
        key = e.key
        m = index.get(key)
        if m is not None:
            action = e.action
            down = action == DOWN
            bit = 1 << m
            if bool(held & bit) != down:
                add((step, names[m], action))
            held = held | bit if down else held & ~bit
        elif key == RESET_KEY:
            action = e.action
            if action == DOWN:
                resets[step] = resets.get(step, 0) + 1
                add((step, key, action))
        elif key == TOGGLE_ARM_KEY:
            action = e.action
            if action == DOWN:
                add((step, key, action))
    if pending is not None and held != mask and pending < steps:
        runs.append((pending, held))
    return AppliedInput(tuple(runs), tuple(sorted(resets.items()))), events


def _form(replay: Replay, applied: AppliedInput | None = None) -> dict[str, object]:
    applied = applied_input(replay) if applied is None else applied
    return {"identity": IDENTITY_VERSION, "rules": config_digest(replay.config), "seed": replay.config.seed,
            "steps": replay.result.steps, "held": applied.held, "resets": applied.resets}


def _form_v1(replay: Replay, events: list[tuple[int, str, str]] | None = None) -> dict[str, object]:
    """Version 1's form (events, those that change nothing dropped), kept only to recognise the digests
    tables took before version 2: exactly as it was computed then (``events``: its timeline, by ``_both_forms``)."""
    if events is not None:
        return {"identity": 1, "rules": config_digest(replay.config), "seed": replay.config.seed,
                "steps": replay.result.steps, "timeline": events}
    index = {m.key: f"m{i}" for i, m in enumerate(replay.config.muscles)}
    held: set[str] = set()
    last = replay.result.steps
    events = []
    add, discard = held.add, held.discard
    for e in replay.timeline:
        step = e.step
        if step >= last:
            break
        action = e.action
        down = action == DOWN
        name = index.get(e.key)
        if name is not None:
            if (name in held) == down:
                continue
            (add if down else discard)(name)
            events.append((step, name, action))
        elif e.key in (RESET_KEY, TOGGLE_ARM_KEY) and down:
            events.append((step, e.key, action))
    return {"identity": 1, "rules": config_digest(replay.config), "seed": replay.config.seed,
            "steps": replay.result.steps, "timeline": events}


#: ``_ctimeline.c``: ``_both_forms`` in C, giving the forms' JSON text, where built (``armgame._native``).
_CTIMELINE = load("armgame.records._ctimeline", 1)


def _native_digests(replay: Replay) -> tuple[str, str] | None:
    """``game_digests`` of a game that ran to its end from ``_both_forms``'s C twin, or None where it cannot take
    the game (its opening comment): the same text as ``_digest`` of the two forms, so the same digests."""
    steps = replay.result.steps
    if _CTIMELINE is None or not 0 <= steps <= INT64_MAX or type(replay.timeline) is not tuple:
        return None
    texts = _CTIMELINE.forms_text(replay.timeline, tuple(m.key for m in replay.config.muscles), steps, RESET_KEY,
                                  TOGGLE_ARM_KEY, DOWN, UP)
    if texts is None:
        return None
    held, resets, events = texts

    # The forms' dict up to their lists, as json.dumps writes it, without its "}"; only the version differs.
    rest = json.dumps({"rules": config_digest(replay.config), "seed": replay.config.seed, "steps": steps},
                      separators=(",", ":"))[1:-1]
    current = f'{{"identity":{IDENTITY_VERSION},{rest},"held":{held},"resets":{resets}}}'
    first = f'{{"identity":1,{rest},"timeline":{events}}}'
    return (hashlib.sha256(current.encode()).hexdigest(), hashlib.sha256(first.encode()).hexdigest())


def _digest(form: dict[str, object]) -> str:
    # check_circular=False: the same text without the encoder's note of every list it enters (a form is built here,
    # with no cycle), a fifth of the time of a bot's 15,000 events.
    return hashlib.sha256(json.dumps(form, separators=(",", ":"), check_circular=False).encode()).hexdigest()


def game_digest(replay: Replay) -> str:
    """SHA-256 (hex) of the game's canonical form: equal digests, the same game."""
    native = _native_digests(replay) if replay.result.steps == replay.config.total_steps else None
    return native[0] if native is not None else _digest(_form(replay))


def game_digests(replay: Replay) -> tuple[str, ...]:
    """The game's digest by every identity version this armgame knows, the current one first: a table
    entered before a bump holds the older one."""
    if replay.result.steps != replay.config.total_steps:  # stopped early: the two forms stop apart
        return game_digest(replay), _digest(_form_v1(replay))
    native = _native_digests(replay)
    if native is not None:
        return native
    applied, events = _both_forms(replay)
    return _digest(_form(replay, applied)), _digest(_form_v1(replay, events))


#: The fields of ``identity_claims``, in its order.
IDENTITY_FIELDS = ("identity", "game_sha256", "earlier_game_sha256")


def identity_claims(replay: Replay, digests: Sequence[str] | None = None) -> dict[str, object]:
    """What a replay says about its game's identity, for an entry's claims (``entry.replay_claims``)
    and the verification cache: the version, the current digest and the older versions' digests.
    ``digests``: ``game_digests(replay)`` if the caller has them already (a class's server does)."""
    current, *earlier = game_digests(replay) if digests is None else digests
    return dict(zip(IDENTITY_FIELDS, (IDENTITY_VERSION, current, earlier), strict=True))


def current_claims(claims: Mapping[str, object]) -> bool:
    """Whether ``identity_claims`` were made by this identity version (a cache may hold older ones)."""
    return claims.get("identity") == IDENTITY_VERSION


def names_its_game(stored: str, claims: Mapping[str, object]) -> bool:
    """Whether a digest an entry stored is its replay's game: the current digest, or the one the version
    that entered it computed (``identity_claims``). A digest of another game is neither."""
    return stored == claims["game_sha256"] or stored in claims["earlier_game_sha256"]  # type: ignore[operator]


class FirstEntries(Generic[T]):
    """Which of several entries of one game counts, and which are its copies.

    Fed items in the order that decides (the table's order of entry; two entries of one game that check
    out score alike, so best first is that order among them), each with its replay file's SHA-256, its
    game's digest (``game_digest``) and whether it checks out, it names of each item the earlier item it
    copies. The rules, the same for ``armgame scores``, ``verify DIR`` and ``analyze --class``:

    * the first item of a game that checks out counts; a later item of that game is its copy;
    * one replay file is one game (the same bytes play the same game), so a later item of a file already
      counted is a copy before any check: ``counted_file`` lets a caller flag it unread;
    * an item that does not check out takes no place (its check says what is wrong with it), so a forged
      entry planted earlier, naming an honest replay file or carrying an honest game's digest, never
      pushes the honest entry out.
    """

    def __init__(self) -> None:
        self._files: dict[str, T] = {}
        self._games: dict[str, T] = {}

    def counted_file(self, file_sha256: str) -> T | None:
        """The item that counts for this replay file so far, if any: a later item of it is a copy."""
        return self._files.get(file_sha256)

    def counted(self, game: str) -> T | None:
        """The item that counts for ``game`` so far, if any (to skip checking a copy at all)."""
        return self._games.get(game)

    def copy_of(self, item: T, file_sha256: str | None, game: str | None, ok: bool) -> T | None:
        """The earlier item ``item`` copies (same replay file or same game), or None. An ``item`` that
        checks out (``ok``) and copies none counts from now on, for its file and its game."""
        if not ok:
            return None
        first = self._files.get(file_sha256) if file_sha256 is not None else None
        if first is None and game is not None:
            first = self._games.get(game)
        if first is not None and first is not item:
            return first
        if file_sha256 is not None:
            self._files[file_sha256] = item
        if game is not None:
            self._games[game] = item
        return None
