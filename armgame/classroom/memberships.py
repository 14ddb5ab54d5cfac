"""The classes a student's machine joined, and every name it joined each under: ``memberships.json``.

Format 2 (written since 0.5)::

    {"format": 2,
     "classes": {"FROG": {"address": "192.168.1.20:8765", "seed": 10, "duration": 60.0, "at": 1764400000.5,
                          "names": [{"name": "Kofi A", "token": "...", "at": 1764400000.5}, ...]}}}

A name's token is what proves to the class that the name is this machine's, and the class gives it once:
a token lost is a name lost (the teacher can let the machine take it again). So every name a machine
joined a class under keeps its token, most recent first: a student who joins their bot as "Kofi's robot"
is still "Kofi A" on the next join. Bounded (``bounds``): ``MAX_MEMBERSHIP_NAMES`` names a class and
``MAX_MEMBERSHIP_CLASSES`` classes, the ones joined longest ago dropped first.

Format 1 (before 0.5) kept one name a class, ``{CODE: {"name", "token", "seed", "address", "at"}}``; it is
read as format 2 with that one name, and written as format 2 at the next join.

The file is read as hostile (it is only ever the user's own, but a damaged or planted file must not cost
more than its bound or send a token into a request's header unchecked): at most ``MAX_MEMBERSHIPS_BYTES``, a
regular file (never a symlink), every field checked. One that fails is one ``DataFileError`` line naming it, and
nothing is written over it. It is written atomically and private (0600): the tokens are the user's alone.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from ..files import DataFileError, read_limited, show_path
from ..limits import MAX_GAME_SECONDS
from ..records.standings import player_key
from ..records.storage import atomic_write_bytes, parse_json
from ..valid import INT64_MAX, check_float, check_int, check_keys, check_name, check_pattern, check_str
from .bounds import MAX_MEMBERSHIP_CLASSES, MAX_MEMBERSHIP_NAMES, MAX_MEMBERSHIPS_BYTES
from .wire import CODE_ALPHABET, CODE_LENGTH

FORMAT = 2
#: A token as a class writes it (``secrets.token_urlsafe``), at most as long as a class takes one.
TOKEN = re.compile(r"[A-Za-z0-9_-]{1,200}")
_WHAT = "class memberships file"
_LATEST = 1e12  # seconds since 1970: far past any clock's "at"


@dataclass(frozen=True)
class Name:
    """A name this machine joined a class under, the token that proves it, and when it last joined."""

    name: str
    token: str
    at: float


@dataclass(frozen=True)
class Joined:
    """A class this machine joined: where it was last, its seed, when, its names (most recent first), and its
    game's clock (a rehearsal's games are 15 s; a file written before it was kept: 60 s)."""

    address: str
    seed: int
    at: float
    names: tuple[Name, ...]
    duration: float = 60.0

    def name(self, typed: str | None) -> Name | None:
        """The name this machine joined under that ``typed`` is (as the class tells names apart); None: the
        most recent one."""
        if typed is None:
            return self.names[0]
        key = player_key(typed)
        return next((n for n in self.names if player_key(n.name) == key), None)


def read(path: Path) -> dict[str, Joined]:
    """The classes ``path`` holds, by code (none if there is no file). DataFileError: a file that is not
    one, in one line naming it and what to do."""
    try:
        path.lstat()
    except FileNotFoundError:
        return {}
    except OSError:
        pass  # read_limited says what is wrong, in its line
    data = read_limited(path, MAX_MEMBERSHIPS_BYTES, _WHAT, follow=False)
    try:
        return _checked(parse_json(data))
    except (ValueError, UnicodeDecodeError) as exc:
        raise DataFileError(f"{show_path(path)}: not a {_WHAT} armgame can read ({exc}): move it aside and join "
                            f"again (the teacher can let this machine take back a name it held)") from None


def _checked(data: object) -> dict[str, Joined]:
    if not isinstance(data, dict):
        raise ValueError("it is not a JSON object")
    if "format" not in data:  # format 1: {CODE: {name, token, seed, address, at}}, one name a class
        data = {"format": FORMAT, "classes": {code: _from_format_1(code, v) for code, v in data.items()}}
    check_keys("the file", data, {"format", "classes"})
    version = check_int("format", data["format"], 1, 10**6)
    if version != FORMAT:
        raise ValueError(f"format {version} is a newer armgame's (this one reads {FORMAT})")
    classes = data["classes"]
    if not isinstance(classes, dict):
        raise ValueError("classes must be a JSON object")
    out = {}
    for code, value in classes.items():
        if len(code) != CODE_LENGTH or any(c not in CODE_ALPHABET for c in code):
            raise ValueError(f"{code[:20]!r} is not a class code")
        c = check_keys(f"class {code}", value, {"address", "seed", "at", "names"}, frozenset({"duration"}))
        names = c["names"]
        if not isinstance(names, list) or not names:
            raise ValueError(f"class {code}: names must be a list of at least one name")
        kept: dict[str, Name] = {}
        for item in names[:10 * MAX_MEMBERSHIP_NAMES]:  # a planted list costs no more than its bound
            n = check_keys(f"class {code}: a name", item, {"name", "token", "at"})
            name = Name(check_name(n["name"], f"class {code}: a name"),
                        check_pattern("token", n["token"], TOKEN), check_float("at", n["at"], 0, _LATEST))
            kept.setdefault(player_key(name.name), name)
        out[code] = Joined(check_str(f"class {code}: address", c["address"], 300),
                           check_int(f"class {code}: seed", c["seed"], 0, INT64_MAX),
                           check_float(f"class {code}: at", c["at"], 0, _LATEST),
                           _newest(kept.values(), MAX_MEMBERSHIP_NAMES),
                           check_float(f"class {code}: duration", c.get("duration", 60.0), 0.0, MAX_GAME_SECONDS,
                                       low_open=True))
    return dict(_newest_classes(out))


def _from_format_1(code: object, value: object) -> dict[str, object]:
    """A format 1 class (one name) as format 2's."""
    v = check_keys(f"class {str(code)[:20]!r}", value, {"name", "token", "seed", "address"}, frozenset({"at"}))
    try:
        at = float(check_str("at", v.get("at", "0"), 40))
        seed = int(check_str("seed", v["seed"], 40))
    except ValueError:
        raise ValueError(f"class {str(code)[:20]!r}: its seed and time must be numbers") from None
    return {"address": v["address"], "seed": seed, "at": at,
            "names": [{"name": v["name"], "token": v["token"], "at": at}]}


def _newest(names, cap: int) -> tuple[Name, ...]:
    return tuple(sorted(names, key=lambda n: -n.at)[:cap])


def _newest_classes(classes: Mapping[str, Joined]) -> list[tuple[str, Joined]]:
    return sorted(classes.items(), key=lambda kv: -kv[1].at)[:MAX_MEMBERSHIP_CLASSES]


def joined(classes: Mapping[str, Joined], code: str, address: str, seed: int, name: str, token: str,
           now: float, duration: float = 60.0) -> dict[str, Joined]:
    """``classes`` with this machine's join of ``code`` under ``name`` (its token) kept as the most recent:
    the class's other names stay, the oldest past the caps go."""
    before = classes.get(code)
    others = () if before is None else tuple(n for n in before.names if player_key(n.name) != player_key(name))
    names = (Name(name, token, now), *others)[:MAX_MEMBERSHIP_NAMES]
    return dict(_newest_classes({**classes, code: Joined(address, seed, now, names, duration)}))


def write(path: Path, classes: Mapping[str, Joined]) -> None:
    """``classes`` into ``path``, atomically, readable by the user alone (the tokens prove the names)."""
    data = {"format": FORMAT, "classes": {
        code: {"address": j.address, "seed": j.seed, "duration": j.duration, "at": j.at,
               "names": [{"name": n.name, "token": n.token, "at": n.at} for n in j.names]}
        for code, j in classes.items()}}
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, json.dumps(data, indent=1, ensure_ascii=False).encode(), _WHAT, private=True)
