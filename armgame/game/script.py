"""Input scripts for headless play: one event a line, ``TIME KEY ACTION``.

    # reach up and left
    0.50 d down
    1.25 d up

TIME is in seconds of game time (the event takes effect at the physics step nearest to
it), KEY one of the game's keys, ACTION ``down`` or ``up``; ``#`` starts a comment. A UTF-8
byte-order mark at the start is allowed. Events after the game's end are dropped; a script
is refused if it has more events than a replay may hold (``armgame.limits``).
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import UserError
from ..files import read_limited
from ..limits import MAX_EVENTS, MAX_GAME_SECONDS, MAX_SCRIPT_BYTES
from .session import DOWN, UP, InputEvent


class ScriptError(UserError):
    pass


def parse_script(text: str, keys: tuple[str, ...], dt: float, source: str = "script",
                 last_step: int | None = None) -> list[InputEvent]:
    """The events of a script, in order; those after ``last_step`` (the game's end) are dropped."""
    text = text.removeprefix("\ufeff")
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
        if not math.isfinite(time) or not 0.0 <= time <= MAX_GAME_SECONDS:
            raise ScriptError(f"{where}: time must be from 0 to {MAX_GAME_SECONDS:g} s (the longest game), "
                              f"got {time_text[:40]!r}")
        if time < last_time:
            raise ScriptError(f"{where}: time {time_text} comes before the previous event's {last_time:g}")
        key = key.lower()
        if key not in keys:
            raise ScriptError(f"{where}: unknown key {fields[1]!r}; keys are {' '.join(keys)}")
        action = action.lower()
        if action not in (DOWN, UP):
            raise ScriptError(f"{where}: action must be 'down' or 'up', got {fields[2]!r}")
        last_time = time
        step = round(time / dt)
        if last_step is not None and step > last_step:
            continue
        if len(events) >= MAX_EVENTS:
            raise ScriptError(f"{where}: more than {MAX_EVENTS} events, the most a replay holds")
        events.append(InputEvent(step, key, action))
    return events


def load_script(path: Path, keys: tuple[str, ...], dt: float, last_step: int | None = None) -> list[InputEvent]:
    data = read_limited(Path(path), MAX_SCRIPT_BYTES, "script file")
    source = repr(str(path)) if not str(path).isprintable() else str(path)
    if len(source) > 200:
        source = source[:197] + "..."
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ScriptError(f"{source}: not a text file (UTF-8 expected)") from None
    return parse_script(text, keys, dt, source=source, last_step=last_step)
