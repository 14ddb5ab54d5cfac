"""Rulesets: the named games that rank, each identified by the digest of its configuration.

A replay carries its whole ``GameConfig``, so without rulesets a replay would define its own
rules: a bigger target, a lighter arm or a longer clock would rank beside fair games. A
ruleset fixes everything but the seed: arm, muscles, targets, radius, start posture, view,
clock, integrator and step. Its identity is the SHA-256 of its canonical configuration
(``canonical_config``: the replay's ``config`` object with the seed removed and the muscles'
key bindings removed, as compact JSON with sorted keys and floats by ``repr``, which
round-trips exactly). An entry ranks only if its replay's configuration has the digest of a
ranked ruleset; everything else is a custom game, kept and listed apart, never ranked.

Key bindings are left out because ``--keys`` only says which key drives which muscle: the
timeline names muscles by their key, and the physics and the targets are the same.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
from dataclasses import dataclass

from ..game.rules import GameConfig
from .replay import config_to_dict

#: The label of any configuration that is not a named ruleset.
CUSTOM = "custom"


def canonical_config(config: GameConfig) -> bytes:
    data = config_to_dict(config)
    del data["seed"]
    data["muscles"] = [{k: v for k, v in m.items() if k != "key"} for m in data["muscles"]]  # type: ignore[attr-defined]
    return json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False).encode("utf-8")


#: ``config_digest`` of the configurations seen last, by the object (kept, so its id is not reused): a class's
#: hand-in asks for its replay's six times (its ruleset, its two identities, its entry). By the object, not by
#: equality: two equal configurations may still differ in their JSON (0.0 and -0.0 are equal).
_DIGESTS: dict[int, tuple[GameConfig, str]] = {}
_DIGESTS_KEPT = 64


def config_digest(config: GameConfig) -> str:
    """SHA-256 (hex) of the canonical configuration: equal digests, equal games but for the seed."""
    known = _DIGESTS.get(id(config))
    if known is not None and known[0] is config:
        return known[1]
    digest = hashlib.sha256(canonical_config(config)).hexdigest()
    if len(_DIGESTS) >= _DIGESTS_KEPT:
        with contextlib.suppress(KeyError, StopIteration, RuntimeError):  # another thread's change: kept or not
            del _DIGESTS[next(iter(_DIGESTS))]
    _DIGESTS[id(config)] = (config, digest)
    return digest


@dataclass(frozen=True)
class Ruleset:
    name: str
    config: GameConfig
    description: str

    @property
    def digest(self) -> str:
        return config_digest(self.config)

    @property
    def steps(self) -> int:
        """What verifying one game of this ruleset costs, in physics steps."""
        return self.config.total_steps


#: The rulesets that rank. ``standard`` is today's default game (``GameConfig()``), the seed aside.
RULESETS: dict[str, Ruleset] = {
    r.name: r for r in (
        Ruleset("standard", GameConfig(), "the default game: 60 s, the game arm, 5 cm targets"),
    )
}
_BY_DIGEST = {r.digest: r for r in RULESETS.values()}


#: The rehearsal's clock, in seconds: a teacher walks the whole lesson in five minutes (docs/teaching.md).
REHEARSAL_SECONDS = 15.0
#: The game of a rehearsal class (``armgame class serve --rehearse``): the standard game on a 15 s clock. A class
#: verifies it as it verifies the standard game, but it never ranks in a high-score table (it is not in
#: ``RULESETS``): there it is a custom game, kept apart from the 60 s games it could never be compared with.
REHEARSAL = Ruleset("rehearsal", GameConfig(time_limit=REHEARSAL_SECONDS),
                    "the rehearsal's game: the standard game, 15 s")
#: The games a live class plays, by name: a class takes its own and refuses the other.
CLASS_GAMES: dict[str, Ruleset] = {r.name: r for r in (RULESETS["standard"], REHEARSAL)}
_CLASS_BY_DIGEST = {r.digest: r for r in CLASS_GAMES.values()}


def class_game_name(config: GameConfig) -> str:
    """The class game ``config`` plays, whatever its seed and key bindings ("standard", "rehearsal"), or "custom"."""
    found = _CLASS_BY_DIGEST.get(config_digest(config))
    return found.name if found else CUSTOM


def ruleset_of(config: GameConfig) -> Ruleset | None:
    """The ranked ruleset ``config`` plays (whatever its seed and key bindings), or None for a custom game."""
    return _BY_DIGEST.get(config_digest(config))


def ruleset_by_digest(digest: str) -> Ruleset | None:
    """The ranked ruleset whose configuration has ``digest`` (computed once, not per entry)."""
    return _BY_DIGEST.get(digest)


def ruleset_name(config: GameConfig) -> str:
    found = ruleset_of(config)
    return found.name if found else CUSTOM

