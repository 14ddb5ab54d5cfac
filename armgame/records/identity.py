"""A game's identity: what it is, not the file it came in, so that one game enters a table once.

Two replays are the same game when they play the same rules with the same seed and the same
input, whatever else differs: the JSON's layout, the date, the player's name, the armgame
version, the muscles' key bindings (``--keys`` only renames them), and events that change
nothing. ``game_digest`` is the SHA-256 of the canonical form:

* the ruleset's digest (``rulesets.config_digest``: the whole configuration but the seed and
  the key bindings), the seed and the number of steps played;
* the input timeline as the session applies it (``GameSession.key_event``): a muscle key named
  by its muscle's index, and only events that change something. A key-down of a key already
  held, a key-up of a key that is up, the release of space or tab (only their press acts) and
  anything at or after the last step are dropped, exactly as the session ignores them.

A classmate who copies a replay under another name, moves its date by a microsecond, or adds
a repeated key-down gets the same digest, and the table refuses the copy.
"""

from __future__ import annotations

import hashlib
import json

from ..game.session import DOWN, RESET_KEY, TOGGLE_ARM_KEY
from .replay import Replay
from .rulesets import config_digest

#: Bumped if the canonical form ever changes (a new digest for every game).
IDENTITY_VERSION = 1


def canonical_timeline(replay: Replay) -> list[tuple[int, str, str]]:
    """The events that change the game, muscle keys named by index (``m0``..``m3``)."""
    index = {m.key: f"m{i}" for i, m in enumerate(replay.config.muscles)}
    held: set[str] = set()
    last = replay.result.steps
    events = []
    for e in replay.timeline:
        if e.step >= last:  # the session ignores input once the game is over
            break
        down = e.action == DOWN
        if e.key in index:
            name = index[e.key]
            if (name in held) == down:
                continue  # a key-down of a held key, or a key-up of a key that is up
            (held.add if down else held.discard)(name)
            events.append((e.step, name, e.action))
        elif e.key in (RESET_KEY, TOGGLE_ARM_KEY) and down:
            events.append((e.step, e.key, e.action))
    return events


def game_digest(replay: Replay) -> str:
    """SHA-256 (hex) of the game's canonical form: equal digests, the same game."""
    form = {"identity": IDENTITY_VERSION, "rules": config_digest(replay.config), "seed": replay.config.seed,
            "steps": replay.result.steps, "timeline": canonical_timeline(replay)}
    return hashlib.sha256(json.dumps(form, separators=(",", ":")).encode()).hexdigest()
