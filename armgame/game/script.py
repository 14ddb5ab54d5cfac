"""Input scripts for headless play: one event a line, ``TIME KEY ACTION``.

    # reach up and left
    0.50 d down
    1.25 d up

TIME is in seconds of game time (the event takes effect at the physics step nearest to
it), KEY one of the game's keys, ACTION ``down`` or ``up``; ``#`` starts a comment.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import UserError
from ..records.storage import read_limited
from .session import DOWN, UP, InputEvent

MAX_SCRIPT_BYTES = 16 * 1024 * 1024


class ScriptError(UserError):
    pass


def parse_script(text: str, keys: tuple[str, ...], dt: float, source: str = "script") -> list[InputEvent]:
    events: list[InputEvent] = []
    last_time = 0.0
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        where = f"{source}, line {number}"
        fields = line.split()
        if len(fields) != 3:
            raise ScriptError(f"{where}: expected 'TIME KEY ACTION', got {line!r}")
        time_text, key, action = fields
        try:
            time = float(time_text)
        except ValueError:
            raise ScriptError(f"{where}: time {time_text!r} is not a number") from None
        if not math.isfinite(time) or time < 0.0:
            raise ScriptError(f"{where}: time must be a finite number of seconds >= 0, got {time_text!r}")
        if time < last_time:
            raise ScriptError(f"{where}: time {time_text} comes before the previous event's {last_time:g}")
        key = key.lower()
        if key not in keys:
            raise ScriptError(f"{where}: unknown key {fields[1]!r}; keys are {' '.join(keys)}")
        action = action.lower()
        if action not in (DOWN, UP):
            raise ScriptError(f"{where}: action must be 'down' or 'up', got {fields[2]!r}")
        last_time = time
        events.append(InputEvent(round(time / dt), key, action))
    return events


def load_script(path: Path, keys: tuple[str, ...], dt: float) -> list[InputEvent]:
    data = read_limited(Path(path), MAX_SCRIPT_BYTES, "script file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ScriptError(f"{path}: not a text file (UTF-8 expected)") from None
    return parse_script(text, keys, dt, source=str(path))
