"""What a valid field of a file armgame reads is: the checks every reader of hostile data uses, and the
patterns and bounds they share.

Replays, score tables and their cache, a teacher's record of a table, a class's roster, lab protocols and
the envs' task sections are all read as hostile data: each field is checked as it is read, and one that
fails raises a ``ValueError`` naming it (``config.seed must be from 0 to 9223372036854775807, got -1``);
the caller adds the file's name. A check returns the value it passed, so a reader builds its record from
what the checks return.

Here, below every layer (beside ``errors``, ``limits`` and ``files``; it imports nothing of armgame), so
that each reader finds them in one place and none reaches into another layer's module for them. The ranges
of one kind of record stay beside its dataclass: an arm's in ``physics.params.PARAMETER_RANGES``, a game's
in ``game.rules.GAME_RANGES``. The bounds several records share are here: ``INT64_MAX`` (a seed, and a step
a compiled loop reads as a 64-bit integer), ``COUNT_MAX`` (a score, a count of hits or resets, a place in a
table's order of entry) and the digests' ``HEX64`` and ``HEX32``.
"""

from __future__ import annotations

import math
import re
from datetime import datetime

#: The largest signed 64-bit integer: the largest seed a game, a table or a class takes (the browser's game,
#: ``classroom/static/engine.js``, plays every seed to it), and the largest step a compiled loop reads (a C
#: ``long long``: ``records/_ctimeline.c``).
INT64_MAX = 2**63 - 1
#: The largest score, count of hits or resets, or place in a table's order of entry a file may hold: far
#: past any game's (a replay holds at most ``limits.MAX_HITS`` hits), and exact in a double.
COUNT_MAX = 10**9
#: A SHA-256 as armgame writes it (``hashlib``'s ``hexdigest``): 64 lowercase hexadecimal digits.
HEX64 = re.compile(r"[0-9a-f]{64}")
#: A 128-bit id as armgame writes it (``uuid4().hex``): 32 lowercase hexadecimal digits.
HEX32 = re.compile(r"[0-9a-f]{32}")
#: A word: a scene's, a ruleset's or a version's name (``check_word``).
WORD = re.compile(r"[A-Za-z0-9][A-Za-z0-9 ._+-]*")
#: The longest player's name, in characters (``check_name``).
MAX_NAME = 40


def check_int(name: str, value: object, low: int, high: int) -> int:
    """``value``, a whole number (not a bool) from ``low`` to ``high``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{name} must be a whole number, got {show_value(value)}")
    if not low <= value <= high:
        raise ValueError(f"{name} must be from {low} to {high}, got {show_value(value)}")
    return value


def check_float(name: str, value: object, low: float, high: float, low_open: bool = False) -> float:
    """``value`` as a float: a finite number (not a bool) from ``low`` (above it, if ``low_open``) to ``high``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{name} must be a number, got {show_value(value)}")
    try:
        value = float(value)
    except OverflowError:  # a whole number past any float's (TOML and JSON read them): as far out as inf
        value = math.inf if value > 0 else -math.inf
    if not math.isfinite(value) or not (low < value if low_open else low <= value) or value > high:
        interval = f"above {low:g} and at most {high:g}" if low_open else f"from {low:g} to {high:g}"
        raise ValueError(f"{name} must be a finite number {interval}, got {show_value(value)}")
    return value


def check_str(name: str, value: object, max_len: int, printable: bool = True) -> str:
    """``value``, text of at most ``max_len`` characters, and with ``printable`` no control character."""
    if not isinstance(value, str):
        raise ValueError(f"{name} must be text, got {show_value(value)}")
    if len(value) > max_len:
        raise ValueError(f"{name} must be at most {max_len} characters, got {len(value)}")
    if printable and not value.isprintable():
        raise ValueError(f"{name} must not contain control characters, got {show_value(value)}")
    return value


def check_bool(name: str, value: object) -> bool:
    """``value``, true or false (JSON's, not a number)."""
    if not isinstance(value, bool):
        raise ValueError(f"{name} must be true or false, got {value!r}")
    return value


def check_keys(name: str, value: object, required: set[str], optional: frozenset[str] = frozenset()) -> dict:
    """``value``, a JSON object with every field of ``required``, and no field but those and ``optional``."""
    if not isinstance(value, dict):
        raise ValueError(f"{name} must be a JSON object, got {show_value(value)}")
    missing = required - value.keys()
    if missing:
        raise ValueError(f"{name} lacks {', '.join(sorted(missing))}")
    unknown = value.keys() - required - optional
    if unknown:
        raise ValueError(f"{name} has unknown field(s) {', '.join(sorted(unknown)[:5])}")
    return value


def check_pattern(name: str, value: object, pattern: re.Pattern[str]) -> str:
    """``value``, text of at most 200 characters that ``pattern`` matches whole (``HEX64``: a SHA-256)."""
    value = check_str(name, value, 200)
    if not pattern.fullmatch(value):
        raise ValueError(f"{name} is not a valid {name.replace('_', ' ')}: {value!r}")
    return value


def check_word(name: str, value: object, max_len: int = 40) -> str:
    """``value``, a ``WORD`` of at most ``max_len`` characters."""
    value = check_str(name, value, max_len)
    if not WORD.fullmatch(value):
        raise ValueError(f"{name} must be letters, digits and . _ + - , got {value!r}")
    return value


def check_name(name: object, what: str = "player name") -> str:
    """A player's name: 1 to 40 printable characters, surrounding spaces trimmed. The two joiners (ZWJ, ZWNJ) are
    printable here: Sinhala, Persian and other scripts spell names with them (where a name may hold one is
    ``records.lookalikes.name_problem``'s question, for a class's names)."""
    name = check_str(what, name, 10**6, printable=False).strip()
    if not name:
        raise ValueError(f"{what} is empty")
    if len(name) > MAX_NAME:
        raise ValueError(f"{what} must be at most {MAX_NAME} characters, got {len(name)}")
    if not name.replace("\u200c", "").replace("\u200d", "").isprintable():
        raise ValueError(f"{what} must not contain control characters, got {name!r}")
    return name


def check_date(name: str, value: object) -> str:
    """``value``, an ISO 8601 date and time with its time zone, from 1970 to 9000."""
    value = check_str(name, value, 40)
    try:
        when = datetime.fromisoformat(value)
    except ValueError:
        raise ValueError(f"{name} must be an ISO 8601 date and time, got {value!r}") from None
    if when.tzinfo is None:
        raise ValueError(f"{name} must carry its time zone, got {value!r}")
    if not 1970 <= when.year <= 9000:  # far from datetime's ends, so any time zone conversion works
        raise ValueError(f"{name} must be from 1970 to 9000, got {value!r}")
    return value


def show_value(value: object) -> str:
    """A value as a refusal quotes it: its ``repr``, cut to 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
