"""How counts read in anything armgame prints or draws: "1 hit", "2 hits", "1 entry", "3 entries".

The one place for it, so that no message says "1 hits". Pure Python, imports nothing.
"""

from __future__ import annotations

_SIBILANT_ENDINGS = ("s", "x", "z", "ch", "sh")


def plural_of(noun: str) -> str:
    """The regular English plural of ``noun``.

    >>> [plural_of(w) for w in ("hit", "entry", "reset", "key", "box", "match")]
    ['hits', 'entries', 'resets', 'keys', 'boxes', 'matches']
    """
    if noun.endswith("y") and len(noun) > 1 and noun[-2] not in "aeiou":
        return noun[:-1] + "ies"
    if noun.endswith(_SIBILANT_ENDINGS):
        return noun + "es"
    return noun + "s"


def plural(count: int, noun: str, plural_form: str | None = None) -> str:
    """``count`` and ``noun``, the noun in the plural unless the count is exactly one.

    ``plural_form`` gives an irregular plural. Only the last word of ``noun`` changes, so
    "valid entry" works.

    >>> plural(1, "hit"), plural(0, "hit"), plural(2, "valid entry"), plural(1, "entry")
    ('1 hit', '0 hits', '2 valid entries', '1 entry')
    >>> plural(3, "thread"), plural(1, "thread"), plural(2, "child", "children")
    ('3 threads', '1 thread', '2 children')
    """
    if count == 1:
        return f"{count} {noun}"
    if plural_form is None:
        head, _, last = noun.rpartition(" ")
        plural_form = f"{head} {plural_of(last)}" if head else plural_of(last)
    return f"{count} {plural_form}"
