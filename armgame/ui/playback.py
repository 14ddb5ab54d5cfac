"""The controls every replay and demo shares, in one place: speed steps, real speed, skips, their help.

A game replay, a lab replay, each demo and the autopilot demo take the same keys (- and + for speed, 1
for real time, left and right to skip, p to pause), so a teacher learns them once; their windows call
these rather than keeping copies that drift apart.
"""

from __future__ import annotations

from collections.abc import Sequence

SPEED_UP = ("+", "=", "[+]", "keypad +")
SPEED_DOWN = ("-", "[-]", "keypad -")
REPLAY_SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)
SKIP_SECONDS = 5.0
#: Longest real time one frame may account for (as RealTimeDriver's default): a stall skips ahead.
MAX_FRAME = 0.25
#: The speed and skip keys as help lines say them.
PLAYBACK_HELP = ("-/+ speed", "1 real speed", f"left/right {SKIP_SECONDS:g} s")


def speed_after(name: str, speed: float, speeds: Sequence[float] = REPLAY_SPEEDS) -> float | None:
    """The speed key ``name`` (pygame's key name) sets from ``speed``; None if it is no speed key."""
    if name == "1":
        return 1.0
    if name in SPEED_UP:
        return next((s for s in speeds if s > speed * 1.001), speed)
    if name in SPEED_DOWN:
        return next((s for s in reversed(speeds) if s < speed / 1.001), speed)
    return None


def skip_sign(name: str) -> int:
    """+1 for right (forth), -1 for left (back), 0 for any other key."""
    return 1 if name == "right" else -1 if name == "left" else 0
