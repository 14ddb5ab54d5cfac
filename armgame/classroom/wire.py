"""What the class and a student's machine both hold to: the join code's form, the busy class's line and the arrival
the projector announces.

No imports but the standard library's, so the student's client (``client``, ``memberships``) and ``class show``'s
window read these without loading any of the server (``roster``, ``intake``, the clerk and what they import:
numpy's batch replays, the table). A rule either side checks, and the other must agree with, belongs here; a bound
both sides hold to (the largest hand-in) is in ``bounds`` with the class's others, which imports nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

#: The join code's letters: nothing a projector font confuses (no O/0, I/l/1, S/5, Z/2, B/8).
CODE_ALPHABET = "ACDEFGHJKMNPQRTUVWXY"
#: Four letters: short to type from the back row.
CODE_LENGTH = 4
#: What a student is told when the class cannot take their game yet: the class's 503, and the client's own line for
#: a 503 without one (the server's connection limit). The client hands the game in again.
BUSY = "the class is busy: your game is kept and will be handed in in a moment"


def normal_code(text: str) -> str:
    """A typed join code as the class compares it: case and surrounding spaces do not matter."""
    return text.strip().upper()


@dataclass(frozen=True)
class Arrival:
    """A game just entered, as the projector announces it: the clerk makes it (``handins``), the standings carry it
    (``views``) and ``class show``'s window reads it back (``ui.class_window.parse_standings``)."""

    seq: int
    name: str
    score: int
    note: str
    program: bool

    @property
    def news(self) -> str:
        """What the projector says of it for a few seconds."""
        return f"{self.name}: {self.score}, {self.note}" if self.note else f"{self.name}: {self.score}"
