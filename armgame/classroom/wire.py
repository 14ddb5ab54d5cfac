"""What the class and a student's machine both hold to: the join code's form and the largest hand-in.

No imports, so the student's client (``client``, ``memberships``) reads these without loading any of
the server (``roster``, ``intake``, the clerk and what they import: numpy's batch replays, the table).
A rule either side checks, and the other must agree with, belongs here.
"""

from __future__ import annotations

#: The join code's letters: nothing a projector font confuses (no O/0, I/l/1, S/5, Z/2, B/8).
CODE_ALPHABET = "ACDEFGHJKMNPQRTUVWXY"
#: Four letters: short to type from the back row.
CODE_LENGTH = 4
#: The largest hand-in a class reads: a 60 s bot game that acts every control period is about
#: 0.55 MB and a lab run on a preset about 0.5 MB; eight times that, and no more, is read at once.
#: The client keeps a bigger replay rather than send what the class would cut off.
MAX_HANDIN_BYTES = 4 * 1024 * 1024


def normal_code(text: str) -> str:
    """A typed join code as the class compares it: case and surrounding spaces do not matter."""
    return text.strip().upper()
