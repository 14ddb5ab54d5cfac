"""How counts read in anything armgame prints or draws: "1 hit", "2 hits", "1 entry", "3 entries";
and how a name from a fixed set that is not in it is answered: with the closest valid one.

The one place for each, so that no message says "1 hits" and every mistyped name gets the same
help. Pure Python, the standard library only.
"""

from __future__ import annotations

from collections.abc import Iterable

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


def closest(name: str, choices: Iterable[str]) -> str | None:
    """The valid name ``name`` most likely meant (``difflib``, ignoring case), or None if none is close.

    >>> closest("pley", ("play", "replay", "simulate")), closest("CURL", ("curl", "null")), closest("zz", ("a",))
    ('play', 'curl', None)
    """
    import difflib  # only a refusal needs it: every command line would pay it at start-up otherwise

    by_folded = {c.lower(): c for c in choices}
    found = difflib.get_close_matches(name.lower(), list(by_folded), n=1, cutoff=0.6)
    return by_folded[found[0]] if found else None


def unknown_name(what: str, name: str, choices: Iterable[str], also: str = "") -> str:
    """The one line that refuses ``name`` as a ``what``: the closest valid name first, then them all.

    ``also`` ends the list with what else is accepted.

    >>> unknown_name("bot", "modle", ("model", "naive"))
    "unknown bot 'modle': did you mean model? (choose one of model, naive)"
    >>> unknown_name("lab preset", "spiral", ("null", "curl"), "or give a .toml file")
    "unknown lab preset 'spiral': choose one of null, curl, or give a .toml file"
    """
    choices = list(choices)
    listed = f"choose one of {', '.join(choices)}{', ' + also if also else ''}"
    close = closest(name, choices)
    return f"unknown {what} {name!r}: " + (f"did you mean {close}? ({listed})" if close else listed)
