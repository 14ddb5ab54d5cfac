"""The class's own record: its join code, the seed it ranks, who joined, and what the teacher decided.

Kept in the class's folder beside its table, written only by the server (one writer: the clerk
thread), atomically and fsynced before a join is acknowledged::

    class.json        {"format": "armgame-class", "format_version": 4, "code": "FROG", "seed": 10,
                       "closed": false, "locked": false, "lab": "lesson", a protocol or null,
                       "browser_lab": false,
                       "round": {"number", "start", "minutes", "after"} or null,
                       "renamed": {old name's key: the name shown now},
                       "players": {key: {"name", "token_sha256", "joined", "address"}},
                       "hidden": [key, ...],
                       "experiment": {"a", "b", "seed", "assigned": [[key, "a" or "b"], ...]} or null}
    teacher.secret    the teacher's secret, created once with owner-only permissions

A student's name is theirs: the first client to take it receives a random token, and only the
token's SHA-256 is kept here, so the folder itself never holds what would let someone else hand
in under that name. Names are compared by ``records.standings.player_key`` ("alice" is "Alice"),
and a name is the one player's a reader would take it for (``holder_of``: the same key, one of the
skeletons of ``records.lookalikes``, or a name the teacher changed, which stays the renamed student's);
``intake.Clerk.check_new_name`` refuses a new name that has a holder or that hides part of itself.
The address each name joined from is kept for the teacher (which names came from one machine).
A ``locked`` roster takes no new names; ``lab`` is the protocol the class curve shows, the
teacher's choice (``--lab``), never the one most names happened to run; ``experiment``, a split of the
class into two conditions (``experiment.Experiment``); ``browser_lab``, the teacher's switch that has every
browser at ``/play`` run the class's lab in place of the game. Formats 1 to 3 (before these) are read as they are
(no switch: off) and written back as 4.

The join code is four letters from an alphabet with nothing a projector font confuses (no O/0,
I/l/1, S/5, Z/2, B/8): short to type from the back row, and read case-insensitively.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import hmac
import json
import os
import re
import secrets
import stat
from dataclasses import dataclass, field
from pathlib import Path

from ..limits import DEFAULT_SEED
from ..records.lookalikes import skeletons
from ..records.replay import now_iso
from ..records.standings import legacy_player_key, player_key
from ..records.storage import DataFileError, atomic_write_bytes, dump_json, parse_json, read_limited
from ..valid import HEX64, INT64_MAX, check_date, check_int, check_keys, check_name, check_str
from .bounds import MAX_PLAYERS, MAX_ROSTER_BYTES
from .experiment import Experiment
from .wire import CODE_ALPHABET, CODE_LENGTH, normal_code

ROSTER_NAME = "class.json"
SECRET_NAME = "teacher.secret"
FORMAT = "armgame-class"
FORMAT_VERSION = 4
_SECRET = re.compile(r"[A-Za-z0-9_-]{20,100}")


def new_code() -> str:
    return "".join(secrets.choice(CODE_ALPHABET) for _ in range(CODE_LENGTH))


def token_digest(token: str) -> str:
    return hashlib.sha256(token.encode("utf-8", "surrogatepass")).hexdigest()


@dataclass
class Player:
    name: str
    token_sha256: str
    joined: str
    #: The client address the name joined from ("" in a class from before addresses were kept).
    address: str = ""


@functools.lru_cache(maxsize=2 * MAX_PLAYERS)
def _player_lines(key: str, address: str, joined: str, name: str, token_sha256: str) -> str:
    """One player in the record, as ``dump_json`` writes it at that depth (its fields in sorted order)."""
    def text(value: object) -> str:
        return json.dumps(value, ensure_ascii=False, allow_nan=False)

    return (f'  {text(key)}: {{\n   "address": {text(address)},\n   "joined": {text(joined)},\n'
            f'   "name": {text(name)},\n   "token_sha256": {text(token_sha256)}\n  }}')


@dataclass
class Roster:
    """The class's record, in memory; ``save`` writes it back (the clerk thread is its one writer)."""

    folder: Path
    code: str
    seed: int
    secret: str
    closed: bool = False
    players: dict[str, Player] = field(default_factory=dict)
    hidden: set[str] = field(default_factory=set)
    created: str = field(default_factory=now_iso)
    locked: bool = False
    #: The class curve's protocol: a preset's name, a protocol file's ``as_dict`` (the teacher's own), or None.
    lab: str | dict | None = None
    #: The last round the teacher started (``rounds.Round.as_dict``), or None.
    round: dict | None = None
    #: Names the teacher changed: the old name's ``player_key`` to the name the class shows now.
    renamed: dict[str, str] = field(default_factory=dict)
    #: A classroom experiment: two conditions and who is in which (``experiment.Experiment``), or None.
    experiment: Experiment | None = None
    #: The teacher's switch: every browser at /play runs the class's lab (the game's students too), not the game.
    browser_lab: bool = False

    def __post_init__(self) -> None:
        self.reindex()

    def reindex(self) -> None:
        """The lookups the server's event loop makes while the clerk's thread changes the roster: rebuilt
        whole and swapped in, so a reader on another thread sees the old index or the new, never half. Every
        change through ``add``, ``remove`` and ``changed`` does it; call it after filling ``players`` directly."""
        self.by_token = {p.token_sha256: key for key, p in self.players.items()}
        self.by_skeleton = {s: key for key, p in self.players.items() for s in skeletons(p.name)}
        # A name the teacher changed stays its student's: nobody else joins under it, or one that reads like it,
        # and has their games shown under the new name (``renamed`` maps the old key to it).
        self.by_old_skeleton = {s: now for old, now in self.renamed.items() for s in skeletons(old)}

    def add(self, key: str, player: Player) -> None:
        """``player`` under ``key``, saved; nothing changed if the save fails."""
        self.players[key] = player
        try:
            self.save()
        except BaseException:
            del self.players[key]
            raise
        finally:
            self.reindex()

    def remove(self, key: str) -> Player:
        """The player under ``key`` taken out, saved; nothing changed if the save fails."""
        player = self.players.pop(key)
        try:
            self.save()
        except BaseException:
            self.players[key] = player
            raise
        finally:
            self.reindex()
        return player

    def changed(self, **values: object) -> None:
        """Fields set and saved together; all put back if the save fails (memory never disagrees with disk)."""
        before = {name: getattr(self, name) for name in values}
        before_hidden = set(self.hidden)
        for name, value in values.items():
            setattr(self, name, value)
        try:
            self.save()
        except BaseException:
            for name, value in before.items():
                setattr(self, name, value)
            self.hidden = before_hidden
            raise
        finally:
            self.reindex()

    @property
    def path(self) -> Path:
        return self.folder / ROSTER_NAME

    # ------------------------------------------------------------------ files
    @classmethod
    def open(cls, folder: Path, seed: int | None) -> tuple[Roster, bool]:
        """The class in ``folder`` (going on with it), or a new one there; and whether it is new.

        ``seed``: the seed asked for (None: the class's own, or the default for a new class). A class
        ranks one seed for its whole life: asking another for an existing class is refused.
        """
        path = folder / ROSTER_NAME
        if os.path.lexists(path):
            roster = cls._read(folder)
            if seed is not None and seed != roster.seed:
                raise DataFileError(f"the class in {folder} ranks seed {roster.seed}, not {seed}: go on with it "
                                    f"without --seed, or start a new class in another --folder")
            return roster, False
        roster = cls(folder, new_code(), DEFAULT_SEED if seed is None else seed, _new_secret(folder))
        roster.save()
        return roster, True

    @classmethod
    def _read(cls, folder: Path) -> Roster:
        path = folder / ROSTER_NAME
        data = read_limited(path, MAX_ROSTER_BYTES, "class record", follow=False)
        try:
            d = parse_json(data)
            if not isinstance(d, dict) or d.get("format") != FORMAT:
                raise ValueError(f"not an armgame class record (no \"format\": \"{FORMAT}\")")
            version = check_int("format_version", d.get("format_version"), 1, 10**6)
            if version > FORMAT_VERSION:
                raise ValueError(f"class record format {version} is newer than this armgame reads: update armgame")
            later = ({"locked", "lab", "round", "renamed"} if version >= 2 else set()) | \
                ({"experiment"} if version >= 3 else set()) | ({"browser_lab"} if version >= 4 else set())
            d = check_keys("class record", d, {"format", "format_version", "code", "seed", "closed", "players",
                                               "hidden", "created", *later})
            code = check_str("code", d["code"], CODE_LENGTH)
            if len(code) != CODE_LENGTH or any(c not in CODE_ALPHABET for c in code):
                raise ValueError(f"code must be {CODE_LENGTH} letters of {CODE_ALPHABET}, got {code!r}")
            seed = check_int("seed", d["seed"], 0, INT64_MAX)
            if not isinstance(d["closed"], bool):
                raise ValueError("closed must be true or false")
            if not isinstance(d["players"], dict) or len(d["players"]) > MAX_PLAYERS:
                raise ValueError(f"players must be an object of at most {MAX_PLAYERS} names")
            players = {}
            for key, item in d["players"].items():
                p = check_keys(f"player {key!r}", item, {"name", "token_sha256", "joined",
                                                         *({"address"} if version >= 2 else ())})
                name = check_name(p["name"])
                if key not in (player_key(name), legacy_player_key(name)):
                    raise ValueError(f"player {key!r} is filed under another name's key")
                key = player_key(name)  # a class from before lookalikes counted: filed again under today's key
                if key in players:  # two names that are now one: the machine that joined first (filed first) keeps it
                    continue
                digest = check_str("token_sha256", p["token_sha256"], 64)
                if not HEX64.fullmatch(digest):
                    raise ValueError(f"player {name!r}: token_sha256 is not a SHA-256")
                address = check_str("address", p["address"], 64) if version >= 2 else ""
                players[key] = Player(name, digest, check_date("joined", p["joined"]), address)
            if not isinstance(d["hidden"], list) or not all(isinstance(k, str) for k in d["hidden"]):
                raise ValueError("hidden must be a list of names")
            created = check_date("created", d["created"])
            locked = d.get("locked", False)
            if not isinstance(locked, bool):
                raise ValueError("locked must be true or false")
            lab = d.get("lab")
            if isinstance(lab, dict):
                from ..lab.protocol_file import protocol_from_dict

                protocol_from_dict(lab, "lab")  # a class record's own protocol is checked like any other
            elif lab is not None:
                lab = check_str("lab", lab, 80)
            renamed = d.get("renamed", {})
            if not isinstance(renamed, dict) or len(renamed) > MAX_PLAYERS:
                raise ValueError(f"renamed must be an object of at most {MAX_PLAYERS} names")
            renamed = {check_str("a renamed key", k, 200): check_name(v) for k, v in renamed.items()}
            rnd = d.get("round")
            if rnd is not None:
                from .rounds import Round

                rnd = Round.from_dict(rnd).as_dict()
            experiment = d.get("experiment")
            if experiment is not None:
                experiment = Experiment.from_dict(experiment, MAX_PLAYERS)
            browser_lab = d.get("browser_lab", False)
            if not isinstance(browser_lab, bool):
                raise ValueError("browser_lab must be true or false")
        except ValueError as exc:
            raise DataFileError(f"{path}: {exc}; the class cannot go on from it (nothing was changed)") from None
        hidden = {player_key(k) for k in d["hidden"]}  # player_key of an older key is today's key
        return cls(folder, code, seed, _read_secret(folder), d["closed"], players, hidden, created, locked, lab, rnd,
                   renamed, experiment, browser_lab)

    def save(self) -> None:
        """The record written whole (``dump_json``'s bytes): each player's lines made once and kept, since a
        class saves at every join (``dump_json`` of 1,000 players each time took a class 28 s to join)."""
        head = dump_json({
            "format": FORMAT, "format_version": FORMAT_VERSION, "code": self.code, "seed": self.seed,
            "closed": self.closed, "locked": self.locked, "lab": self.lab, "round": self.round,
            "renamed": dict(sorted(self.renamed.items())),
            "experiment": None if self.experiment is None else self.experiment.as_dict(),
            "browser_lab": self.browser_lab,
            "created": self.created,
            "hidden": sorted(self.hidden),
            "players": {},
        })
        if self.players:
            # The key's own text: a quote inside a string is escaped, so only the key itself reads '"players": {}'.
            lines = ",\n".join(_player_lines(k, p.address, p.joined, p.name, p.token_sha256)
                               for k, p in sorted(self.players.items()))
            head = head.replace(b'"players": {}', b'"players": {\n' + lines.encode() + b"\n }", 1)
        atomic_write_bytes(self.path, head, "class record")

    # ------------------------------------------------------------------ questions
    def code_matches(self, typed: str) -> bool:
        return hmac.compare_digest(normal_code(typed).encode(), self.code.encode())

    def secret_matches(self, typed: str) -> bool:
        return hmac.compare_digest(typed.encode("utf-8", "surrogatepass"), self.secret.encode())

    def player_of(self, token: str) -> Player | None:
        """The player whose token this is (safe from another thread: one lookup in the swapped-in index)."""
        key = self.by_token.get(token_digest(token))
        return None if key is None else self.players.get(key)

    def lookalike_of(self, name: str) -> Player | None:
        """The player already in whose name a reader would take ``name`` for (not the same key's)."""
        key = player_key(name)
        index = self.by_skeleton
        return next((self.players[k] for s in skeletons(name) if (k := index.get(s)) not in (None, key)
                     and k in self.players), None)

    def renamed_from(self, name: str) -> str | None:
        """The name shown now for a student the teacher renamed from ``name``, or from one that reads like it;
        None if ``name`` is no old name."""
        index = self.by_old_skeleton
        return self.renamed.get(player_key(name)) or next((now for s in skeletons(name) if (now := index.get(s))), None)

    def rejoins(self, name: object, token: str | None) -> Player | None:
        """The player ``token`` proves ``name`` is already (a join again, not a new name): its name, or its old
        one the teacher changed; else None. Safe from another thread (the swapped-in indexes), cheap (no
        skeletons): the event loop asks it before a join counts against a machine's new names."""
        player = self.player_of(token) if token else None
        if player is None or not isinstance(name, str):
            return None
        key, own = player_key(name), player_key(player.name)
        return player if key == own or player_key(self.renamed.get(key, "")) == own else None

    def projector_key(self) -> str:
        """The key in the projector's link: it shows the join code; derived from the secret, never the secret."""
        return hmac.new(self.secret.encode(), b"armgame projector", hashlib.sha256).hexdigest()[:20]

    def class_id(self) -> str:
        """What tells this class from another served at the same address (last week's, whose code may differ): a
        browser tags its kept games with it, so a game is never handed in to another class. Derived from the
        secret, never the secret; not a proof of anything, so a stranger may read it."""
        return hmac.new(self.secret.encode(), b"armgame class", hashlib.sha256).hexdigest()[:16]

    def is_hidden(self, name: str) -> bool:
        return player_key(name) in self.hidden


def _new_secret(folder: Path) -> str:
    """The teacher's secret, in a file only its owner may read; kept if one is already there."""
    path = folder / SECRET_NAME
    if os.path.lexists(path):
        return _read_secret(folder)
    secret = secrets.token_urlsafe(18)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags, 0o600)
    except OSError as exc:
        raise DataFileError(f"{path}: cannot write the teacher's secret: {exc.strerror or exc}") from None
    with os.fdopen(fd, "w", encoding="ascii") as f:
        f.write(secret + "\n")
        f.flush()
        os.fsync(f.fileno())
    return secret


def _read_secret(folder: Path) -> str:
    path = folder / SECRET_NAME
    with contextlib.suppress(FileNotFoundError):
        if stat.S_ISLNK(os.lstat(path).st_mode):
            raise DataFileError(f"{path}: is a symbolic link; the teacher's secret must be a regular file")
    secret = read_limited(path, 200, "teacher's secret", follow=False).decode("ascii", "replace").strip()
    if not _SECRET.fullmatch(secret):
        raise DataFileError(f"{path}: not a teacher's secret armgame wrote")
    return secret
