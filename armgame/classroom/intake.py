"""One hand-in, from arrival to answer, and the class's standings built from what was entered.

The ``Clerk`` is the class's one writer: the server runs every change (a join, a hand-in, the
teacher's hide and close) through it on a single worker thread, so the table, the roster and the
lab folder never see two writers, and a hand-in is answered only once it is durably on disk (the
table's own atomic, fsynced write). Everything a request carries is checked here before it costs
anything: the replay is parsed with the replay reader's schema, its work bounded before it is
re-simulated, its player taken from the token (never from the file), its game identified by its
content (``records.identity``), so the same game from two machines is one game.

The class's folder::

    class.json, teacher.secret   the roster (``roster``)
    scores.json, replays/        an ordinary armgame table: ``armgame scores --scores DIR`` reads it
    lab/                         each student's first lab run of each protocol (``analyze --class``)
    lab-more/                    their later runs, kept, not in the class curve
"""

from __future__ import annotations

import bisect
import contextlib
import csv
import hashlib
import hmac
import io
import math
import os
import secrets
import stat
from collections import OrderedDict
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..game.batch import replay_many
from ..game.session import GameResult
from ..records.batch_verify import batchable
from ..records.identity import game_digest, game_digests
from ..records.lookalikes import name_problem
from ..records.replay import Replay, now_iso, same_outcome
from ..records.rulesets import RULESETS, ruleset_name
from ..records.scores import ScoreEntry, ScoreTable, replay_work, sort_key
from ..records.standings import PlayerRow, player_key, shared_rank
from ..records.storage import DataFileError, atomic_write_bytes, read_limited
from ..records.tablefile import name_slug
from ..valid import check_name
from .roster import MAX_PLAYERS, Player, Roster, token_digest
from .rounds import Round, new_round, round_view

#: The largest hand-in a class reads: a 60 s bot game that acts every control period is about
#: 0.55 MB and a lab run on a preset about 0.5 MB; eight times that, and no more, is read at once.
MAX_HANDIN_BYTES = 4 * 1024 * 1024
#: The most re-simulation one hand-in may ask for, in physics steps (``records.scores.replay_work``).
#: A standard game costs 15,000 steps and its hits and events; a lab run, its protocol's steps.
#: A game claiming more (a "hit storm") is refused before anything is replayed.
MAX_HANDIN_WORK = 1_500_000
#: Rows of each list the standings carry: the projector shows the top, the CSV has everything.
STANDINGS_ROWS = 60
LAB_DIR, LAB_MORE_DIR = "lab", "lab-more"
NOT_JOINED = ("this machine has not joined the class under that name: join first "
              "(armgame play --join HOST:PORT --code CODE --name NAME)")
CLOSED = "the class is closed: no more games are taken (your replay stays on your machine)"
#: Forged games whose re-simulated result is kept (by identity), so one sent again is not played again:
#: a result is about 200 bytes.
REMEMBERED_FORGERIES = 4096


class RefusedError(Exception):
    """A request the class turns down: an HTTP status and one line saying why (sent as it is)."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.message = message


@dataclass(frozen=True)
class Arrival:
    """A game just entered, as the projector announces it."""

    seq: int
    name: str
    score: int
    note: str
    program: bool


@dataclass(frozen=True)
class Checked:
    """A game checked and verified, not yet entered: its player, its replay under their name, its identity
    (``identity.game_digests``: the current version's first)."""

    player: Player
    replay: Replay
    digests: tuple[str, ...]


class _Again:
    """``Clerk.check_many``'s answer for a game that came twice in one batch: check it again after the batch."""


AGAIN = _Again()


@dataclass(frozen=True)
class _Pending:
    """A game through every check but its re-simulation (``Clerk.check_many`` verifies them together)."""

    player: Player
    replay: Replay
    digests: tuple[str, ...]


@dataclass
class LabRun:
    player: str
    program: bool
    protocol: Any
    rows: list[dict[str, object]]
    path: Path
    #: A person's first run of its protocol (in ``lab/``): the only kind the class curve reads.
    first: bool = True


def ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


class _Board:
    """One list's rows, one a player, best first (``standings.one_row_per_player`` of the list), kept up to
    date as entries arrive: a player's rank is a binary search, not a pass over every entry."""

    def __init__(self, best_first: Iterable[ScoreEntry] = (), renamed: dict[str, str] | None = None) -> None:
        self._rows: dict[str, PlayerRow] = {}
        self._order: list[tuple[tuple, str]] = []  # (sort_key of the row's best, its player's key), sorted
        #: Names the teacher changed (``Roster.renamed``: the old name's key to the name now shown): a renamed
        #: student's games from before and after are one row, under the new name.
        self.renamed = renamed or {}
        for entry in best_first:
            self.add(entry)

    def __len__(self) -> int:
        return len(self._order)

    def add(self, entry: ScoreEntry) -> None:
        name = self.renamed.get(player_key(entry.name), entry.name)
        key = player_key(name)
        row = self._rows.get(key)
        if row is None:
            self._rows[key] = PlayerRow(name, entry, 1)
            bisect.insort(self._order, (sort_key(entry), key))
        elif sort_key(entry) < sort_key(row.best):  # a new best: the row moves, under the best game's name
            del self._order[bisect.bisect_left(self._order, (sort_key(row.best), key))]
            self._rows[key] = PlayerRow(name, entry, row.games + 1)
            bisect.insort(self._order, (sort_key(entry), key))
        else:
            self._rows[key] = PlayerRow(row.name, row.best, row.games + 1)

    def rank(self, key: str) -> int:
        """The 1-based place of the player whose ``player_key`` is ``key`` (who has a row)."""
        return bisect.bisect_left(self._order, (sort_key(self._rows[key].best), key)) + 1

    def row(self, rank: int) -> PlayerRow:
        return self._rows[self._order[rank - 1][1]]

    def each(self) -> Iterator[PlayerRow]:
        """The rows best first, one at a time: the projector's standings stop at their 60th."""
        for _, key in self._order:
            yield self._rows[key]

    def rows(self, first: int | None = None) -> list[PlayerRow]:
        """The rows best first (the ``first`` ones only, if given)."""
        return [self._rows[key] for _, key in self._order[:first]]


class Clerk:
    """The class's state and its one writer. Not thread-safe by design: call it from one thread."""

    def __init__(self, folder: Path, roster: Roster) -> None:
        self.folder = Path(folder)
        self.roster = roster
        self.table = ScoreTable(self.folder, warn=lambda message: None)
        self.table.lock_mode = 0o600  # only the server writes a class's table: nobody else may open its lock
        with contextlib.suppress(OSError):
            if stat.S_ISREG(os.lstat(self.table.lock_path).st_mode):
                os.chmod(self.table.lock_path, 0o600)  # a class from before this armgame
        if not self.table.path.exists():
            self.table.new(roster.seed)
        elif self.table.seed != roster.seed:
            raise DataFileError(f"{self.table.path} ranks seed {self.table.seed}, the class seed {roster.seed}: "
                                f"this folder's table is not the class's (nothing was changed)")
        self._sweep()
        with contextlib.suppress(DataFileError):  # a journal a killed server left, taken into the table (or read)
            self.table.compact()
        self.entries: list[ScoreEntry] = self.table.all_entries()
        # The two lists' rows, one a player, kept as games are entered: an answer's rank and the standings
        # cost a lookup, not a pass over the whole table (which grew with every hand-in).
        self._build_boards()
        self.games: dict[str, ScoreEntry] = {e.game_sha256: e for e in self.entries if e.game_sha256}
        self.lab_runs: list[LabRun] = []
        self.lab_digests: set[str] = set()
        self.arrival: Arrival | None = None
        self.round_over = False  # the current round's winners have been shown
        self.version = 0  # bumped at every change the projector should see
        self.lab_version = 0  # and at every change of the class curve (a lab run, a name hidden)
        self._recomputed: OrderedDict[str, GameResult] = OrderedDict()  # forged games' results, by identity

    def _sweep(self) -> None:
        """Temporary files a server killed mid-write left (never renamed: nothing refers to them). Only
        this class's server writes its folders, and it is not writing yet."""
        for folder in (self.table.replays, self.folder / LAB_DIR, self.folder / LAB_MORE_DIR):
            if folder.is_dir() and not folder.is_symlink():
                for stale in folder.glob(".*.tmp"):
                    with contextlib.suppress(OSError):
                        if stat.S_ISREG(os.lstat(stale).st_mode):
                            stale.unlink()

    # ------------------------------------------------------------------ joining
    def join(self, name: object, token: str | None, address: str = "") -> tuple[Player, str | None]:
        """The player ``name`` for this client: (player, a new token) for a new name, (player, None)
        when ``token`` proves the name is already theirs. RefusedError if another client holds the name
        or one a reader would take it for, if the name hides part of itself, or if the roster is locked."""
        try:
            name = check_name(name)
        except ValueError as exc:
            raise RefusedError(400, str(exc)) from None
        key = player_key(name)
        player = self.roster.players.get(key)
        if player is not None:
            if token is not None and hmac.compare_digest(token_digest(token), player.token_sha256):
                return player, None
            raise RefusedError(409, f"the name {player.name} is taken in this class by another machine: choose another "
                               f"name (or join from the machine that took it)")
        if name.strip().upper() == "NAME":
            raise RefusedError(400, "type your own name in place of NAME (in quotes if it has a space: "
                                    "--name \"Ann B\")")
        problem = name_problem(name)
        if problem is not None:
            raise RefusedError(400, f"that name cannot be shown as it is typed ({problem}): type it with plain "
                               f"letters")
        alike = self.roster.lookalike_of(name)
        if alike is not None:
            raise RefusedError(409, f"that name reads like {alike.name}, who is in this class already: choose a name "
                               f"nobody could mistake for a classmate's")
        if self.roster.closed:
            raise RefusedError(403, "the class is closed to new players")
        if self.roster.locked:
            raise RefusedError(403, "the class takes no new names now (the teacher locked the list): ask the teacher")
        if len(self.roster.players) >= MAX_PLAYERS:
            raise RefusedError(403, f"the class has {MAX_PLAYERS} players, as many as it takes")
        new_token = secrets.token_urlsafe(24)
        player = Player(name, token_digest(new_token), now_iso(), address[:64])
        self.roster.add(key, player)
        self.version += 1
        return player, new_token

    def player(self, token: str | None) -> Player:
        player = self.roster.player_of(token) if token else None
        if player is None:
            raise RefusedError(401, NOT_JOINED)
        return player

    # ------------------------------------------------------------------ handing in
    def hand_in(self, token: str | None, data: bytes) -> dict[str, object]:
        """Check, verify and enter one replay; the answer the student's machine shows. Raises RefusedError."""
        found = self.check(token, data)
        if isinstance(found, dict):
            return found
        answer = self.enter([found])[0]
        if isinstance(answer, RefusedError):
            raise answer
        return answer

    def check(self, token: str | None, data: bytes) -> dict[str, object] | Checked:
        """A hand-in checked and verified, ready to ``enter``; or the answer already (a game handed in
        before by the same player; a lab run, which is kept here at once). Raises RefusedError; writes
        nothing but a lab run."""
        found = self.check_many([(token, data)])[0]
        if isinstance(found, BaseException):
            raise found
        assert not isinstance(found, _Again), "one hand-in cannot come twice"
        return found

    def check_many(self, hand_ins: Sequence[tuple[str | None, bytes]]
                   ) -> list[dict[str, object] | Checked | BaseException | _Again]:
        """``check`` of hand-ins that arrived together, each outcome (the exception ``check`` would raise,
        returned) in order: the cheap refusals first, then the games still to verify re-simulated together
        (``records.batch_verify``'s lanes, each verdict the single session's, bit for bit). ``AGAIN``: a game the
        batch holds earlier, to check again once the batch is entered (``check`` never returns it)."""
        outcomes: list[dict[str, object] | Checked | BaseException | _Pending | _Again] = []
        for token, data in hand_ins:
            try:
                outcomes.append(self._read(token, data))
            except Exception as exc:  # one hand-in's failure is its own answer, never the batch's
                outcomes.append(exc)
        # A game a batch holds twice (whatever each claims) is answered as one after the other: the later one
        # once the first is entered or refused, as if it had come in the next batch (``AGAIN``).
        seen: set[str] = set()
        for i, p in enumerate(outcomes):
            if isinstance(p, _Pending):
                if seen.intersection(p.digests):
                    outcomes[i] = AGAIN
                seen.update(p.digests)
        pending = [p for p in outcomes if isinstance(p, _Pending)]
        verdicts = self._verify_games([(p.replay, p.digests[0]) for p in pending])
        judged: dict[int, dict[str, object] | Checked | BaseException] = {}
        for p, verdict in zip(pending, verdicts, strict=True):
            if isinstance(verdict, BaseException):
                judged[id(p)] = verdict
                continue
            ok, recomputed = verdict
            r = p.replay.result
            judged[id(p)] = Checked(p.player, p.replay.with_player(p.player.name), p.digests) if ok else \
                RefusedError(422, f"the replay does not reproduce its score (recorded {r.score}, it replays to "
                                  f"{recomputed.score}): not entered")
        return [judged[id(o)] if isinstance(o, _Pending) else o for o in outcomes]

    def _read(self, token: str | None, data: bytes) -> dict[str, object] | _Pending:
        """One hand-in up to its verification: the checks that cost nothing first (the token, a closed
        class), then the replay read once, its work bounded, its rules and seed, its identity computed once
        and looked up; a lab run is kept here (its own verification). Raises RefusedError."""
        player = self.player(token)
        if self.roster.closed:
            raise RefusedError(403, CLOSED)
        try:
            replay = Replay.from_bytes(data, "the replay")
        except DataFileError as exc:
            raise RefusedError(400, str(exc)) from None
        work = replay_work(replay)
        if work > MAX_HANDIN_WORK:
            raise RefusedError(413, f"the replay claims {replay.result.hits} hits in {replay.result.steps} steps, more "
                               f"to check ({work:,}) than a class checks for one hand-in ({MAX_HANDIN_WORK:,})")
        if replay.task is not None:
            return self._lab_run(player, replay)
        return self._game(player, replay)

    def _game(self, player: Player, replay: Replay) -> dict[str, object] | _Pending:
        r = replay.result
        if not replay.complete:
            raise RefusedError(400, "the game stopped before its clock ran out: only a whole game is handed in")
        rules = ruleset_name(replay.config)
        if rules not in RULESETS or r.seed != self.roster.seed:
            raise RefusedError(400, f"this class plays the standard game of seed {self.roster.seed}; this game is "
                               f"{rules} rules, seed {r.seed} (play it with --join to get the class's game)")
        # An entry keeps the digest of the identity version that entered it: the game is looked up by each.
        # Computed here once and carried to the table's entry (``Checked.digests``).
        digests = game_digests(replay)
        twin = next((self.games[d] for d in digests if d in self.games), None)
        if twin is not None:  # known: answered without re-simulating it
            if player_key(self.shown_name(twin.name)) == player_key(player.name):
                return self._answer(twin, already=True)
            raise RefusedError(409, f"this game was already handed in by {twin.name}: a game counts once, whoever "
                               f"hands it in")
        return _Pending(player, replay, digests)

    def _verify_games(self, games: Sequence[tuple[Replay, str]]) -> list[tuple[bool, GameResult] | BaseException]:
        """``replay.verify()`` of each game, or the exception it raised: the games together in the batch's
        lanes where they can share them, the rest (and any game whose batch failed) one at a time.

        The batch plays every game to its end; ``verify`` stops once the game has scored more hits or resets
        than claimed, and its refusal names the score there. A game the batch finds past its claim is
        therefore verified again alone (rare: a forgery that hides hits or resets), so every verdict and
        every message is the single session's. A forged game seen before is not played again: its result
        is remembered by its identity (``_recomputed``, bounded)."""
        replays = [replay for replay, _ in games]
        results: list[GameResult | None] = [None] * len(replays)
        todo: list[int] = []
        for i, (replay, digest) in enumerate(games):
            known = self._recomputed.get(digest)
            if known is not None:
                results[i] = known
            elif batchable(replay):
                todo.append(i)
        if todo:
            with contextlib.suppress(Exception):  # e.g. one game's blow-up stopped the batch: each alone below
                got = replay_many([replays[i].config for i in todo], [replays[i].timeline for i in todo],
                                  [replays[i].result.steps for i in todo], exact=True)
                for i, result in zip(todo, got, strict=True):
                    results[i] = result
        verdicts: list[tuple[bool, GameResult] | BaseException] = []
        for (replay, digest), result in zip(games, results, strict=True):
            claimed = result is not None and same_outcome(result, replay.result)
            if result is None or (not claimed and (result.hits > replay.result.hits
                                                   or result.resets > replay.result.resets)):
                try:
                    verdicts.append(replay.verify())
                except Exception as exc:  # the single session's exception is this game's answer
                    verdicts.append(exc)
                continue
            if not claimed:
                self._remember(digest, result)
            verdicts.append((claimed, result))
        return verdicts

    def _remember(self, digest: str, result: GameResult) -> None:
        self._recomputed[digest] = result
        self._recomputed.move_to_end(digest)
        while len(self._recomputed) > REMEMBERED_FORGERIES:
            self._recomputed.popitem(last=False)

    def enter(self, checked: Sequence[Checked]) -> list[dict[str, object] | RefusedError]:
        """Enter checked games together (one table write for all: a burst of a class costs one write, not
        thirty); each game's answer, or why it was not entered. Durable on disk before this returns."""
        try:
            results = self.table.add_many([c.replay for c in checked], [c.digests for c in checked], journal=True)
        except (ValueError, UserError) as exc:  # the table could not be written: none was entered
            refusal = RefusedError(503, f"the class's table could not take the game: {exc}")
            return [refusal for _ in checked]
        answers: list[dict[str, object] | RefusedError] = []
        fresh = [r for r in results if isinstance(r, ScoreEntry)]
        for entry in fresh:
            bisect.insort(self.entries, entry, key=sort_key)
            self.boards[entry.program].add(entry)
        for c, result in zip(checked, results, strict=True):
            if isinstance(result, ScoreEntry):
                self.games[c.digests[0]] = result
        for c, result in zip(checked, results, strict=True):
            twin = next((self.games[d] for d in c.digests if d in self.games), None)
            if isinstance(result, ScoreEntry):
                answer = self._answer(result)
                self.version += 1
                self.arrival = Arrival(self.version, self.shown_name(result.name), result.score, str(answer["note"]),
                                       result.program)
                answers.append(answer)
            elif twin is not None and player_key(self.shown_name(twin.name)) == player_key(c.player.name):
                answers.append(self._answer(twin, already=True))  # the same game twice in one burst
            elif twin is not None:
                answers.append(RefusedError(409, f"this game was already handed in by {twin.name}: a game counts "
                                                 f"once, whoever hands it in"))
            else:
                answers.append(RefusedError(400, f"not entered: {result}"))
        return answers

    def _answer(self, entry: ScoreEntry, already: bool = False) -> dict[str, object]:
        """Where ``entry`` leaves its player: their rank among students (or programs), and their best."""
        board = self.boards[entry.program]
        rank = board.rank(player_key(self.shown_name(entry.name)))
        row = board.row(rank)
        best = row.best
        position = rank  # the row's position; its place is shared with every row of an equal score above it
        while rank > 1 and board.row(rank - 1).best.score == best.score:
            rank -= 1
        where = "in the class" if not entry.program else "among the programs"
        if best.id == entry.id:
            note = "first game" if row.games == 1 else "new personal best"
            line = f"{ordinal(rank)} of {len(board)} {where} (your best so far)"
        else:
            note = f"best {best.score}"
            line = f"score {entry.score}; your best, {best.score}, is {ordinal(rank)} of {len(board)} {where}"
        placed: list[dict[str, object]] = []
        for r in board.rows(10):
            placed.append({"rank": shared_rank(placed, r.best.score), "score": r.best.score, "name": r.name})
        top = [[p["rank"], p["name"], p["score"]] for i, p in enumerate(placed, 1)
               if not self.roster.is_hidden(str(p["name"])) or i == position]
        if position > 10:
            top.append([rank, row.name, best.score])
        return {"ok": True, "already": already, "name": entry.name, "score": entry.score, "rank": rank,
                "of": len(board), "best": best.score, "list": "programs" if entry.program else "students",
                "note": note, "top": top, "message": ("already handed in: " if already else "handed in: ") + line}

    def _build_boards(self) -> None:
        self.boards = {programs: _Board((e for e in self.entries if e.program == programs), self.roster.renamed)
                       for programs in (False, True)}

    def shown_name(self, name: str) -> str:
        """The name the class shows for a game entered under ``name`` (the teacher may have changed it)."""
        return self.roster.renamed.get(player_key(name), name)

    def _rows(self, programs: bool) -> Iterator[PlayerRow]:
        return self.boards[programs].each()

    # ------------------------------------------------------------------ the lab
    def _lab_run(self, player: Player, replay: Replay) -> dict[str, object]:
        from ..lab.analysis import trial_rows

        game = _lab_identity(replay)
        if game in self.lab_digests:  # known before its replay (the costly part) is run again
            return {"ok": True, "already": True, "message": "already handed in: this lab run is in the class"}
        replay = replay.with_player(player.name)
        ok, _, session = replay.task.verify(replay.config, replay.timeline, replay.result)  # type: ignore[union-attr]
        if not ok:
            raise RefusedError(422, "the lab run does not reproduce its trials: not taken")
        protocol = replay.task.protocol  # type: ignore[union-attr]
        person = replay.driven == "keyboard"
        # A person's first run of a protocol is the one in the curve; a program's run never takes that place.
        first = person and not any(run.protocol == protocol and not run.program and
                                   player_key(run.player) == player_key(player.name) for run in self.lab_runs)
        folder = self.folder / (LAB_DIR if first else LAB_MORE_DIR)
        _real_folder(folder)
        path = folder / f"{name_slug(player.name)}-{game[:12]}.json"
        atomic_write_bytes(path, replay.to_bytes(), "lab run")
        self.lab_digests.add(game)
        self.lab_runs.append(LabRun(player.name, not person, protocol, trial_rows(session) if first or not person
                                    else [], path, first))
        self.version += 1
        self.lab_version += 1
        if not person:
            counted = "a program's run: kept apart, never in the class curve"
        elif first and self._curve_protocol() == protocol:
            counted = "in the class curve"
        elif first:
            counted = "kept (the class curve shows the protocol the teacher chose)"
        else:
            counted = "kept (your first run of this protocol is the one in the curve)"
        return {"ok": True, "already": False, "message": f"lab run handed in: {counted}"}

    def load_lab(self) -> list[str]:
        """Re-verify the lab runs already in the folder (at a restart); returns a line per run left out."""
        from ..lab.analysis import trial_rows

        problems = []
        for path in _runs_in(self.folder / LAB_DIR):
            try:
                replay = _read_run(path)
                if replay.task is None or replay.player is None:
                    raise UserError(f"{path}: not a lab run with a player's name")
                if replay.driven != "keyboard":
                    raise UserError(f"{path}: a program's run (kept, never in the class curve)")
                ok, _, session = replay.task.verify(replay.config, replay.timeline, replay.result)
                if not ok:
                    raise UserError(f"{path}: does not reproduce its trials")
            except UserError as exc:
                problems.append(str(exc))
                continue
            self.lab_digests.add(_lab_identity(replay))
            self.lab_runs.append(LabRun(replay.player, replay.driven != "keyboard", replay.task.protocol,
                                        trial_rows(session), path))
        for path in _runs_in(self.folder / LAB_MORE_DIR):
            with contextlib.suppress(UserError):
                replay = _read_run(path)
                self.lab_digests.add(_lab_identity(replay))
                if replay.task is None or replay.player is None:
                    continue
                rows: list[dict[str, object]] = []
                if replay.driven != "keyboard":  # a program's run: its reaches are in the teacher's CSV
                    ok, _, session = replay.task.verify(replay.config, replay.timeline, replay.result)
                    if not ok:
                        continue
                    rows = trial_rows(session)
                self.lab_runs.append(LabRun(replay.player, replay.driven != "keyboard", replay.task.protocol, rows,
                                            path, first=False))
        if self.lab_runs:
            self.version += 1
            self.lab_version += 1
        return problems

    def _curve_protocol(self) -> Any:
        """The protocol the teacher chose for the class curve (``Roster.lab``), or None."""
        from ..lab.analysis import curve_protocol

        return curve_protocol(self.roster.lab)

    def class_curve(self) -> Any:
        """``lab.analysis.class_curve_of`` the teacher's protocol over the class's runs (in SI units): hidden
        names left out, programs' runs counted apart."""
        from ..lab.analysis import ClassRun, class_curve_of

        runs = [run for run in self.lab_runs if run.program or (run.first and not self.roster.is_hidden(run.player))]
        return class_curve_of([ClassRun(run.player, run.program, run.protocol, run.rows) for run in runs],
                              self._curve_protocol())

    def lab_curve(self) -> dict[str, object]:
        """The class curve of the protocol the teacher chose: each person's first run of it (programs' runs
        and hidden names never in it; the programs counted apart). Built by ``lab.analysis.class_curve_of``,
        as ``armgame analyze --class`` builds it from the folder afterwards."""
        from ..lab.analysis import display_unit

        protocol = self._curve_protocol()
        curve = self.class_curve()
        if not curve.students:
            return {"protocol": None if protocol is None else protocol.name, "students": 0, "programs": curve.programs,
                    "metric": None, "trials": []}
        scale, unit = display_unit(curve.metric)  # type: ignore[arg-type]
        trials = [{"trial": int(row["trial"]), "block": str(row["block"]), "perturbation": str(row["perturbation"]),
                   "mean": _finite(row["mean"], scale), "sem": _finite(row["sem"], scale), "n": int(row["n"])}
                  for row in curve.trials]
        return {"protocol": protocol.name, "students": curve.students, "programs": curve.programs,
                "metric": curve.metric, "unit": unit, "trials": trials}

    # ------------------------------------------------------------------ the teacher
    def hide(self, name: object, hidden: bool) -> str:
        if not isinstance(name, str) or player_key(name) not in {player_key(e.name) for e in self.entries} | \
                set(self.roster.players):
            raise RefusedError(404, "no such name in this class")
        key = player_key(name)
        self.roster.changed(hidden=self.roster.hidden | {key} if hidden else self.roster.hidden - {key})
        self.version += 1
        self.lab_version += 1
        return f"{name} is {'hidden from' if hidden else 'shown on'} the projector"

    def release(self, name: object) -> str:
        """The teacher lets another machine take a joined name (a student moved to another laptop): the old
        machine's token no longer hands anything in; the next machine to join under the name gets it, and the
        games already handed in stay the student's."""
        if not isinstance(name, str):
            raise RefusedError(400, "name must be a string")
        key = player_key(name)
        if key not in self.roster.players:
            raise RefusedError(404, "no machine has joined under that name")
        player = self.roster.remove(key)
        self.version += 1
        return (f"{player.name} is free: the next machine to join under it takes it (the old one can no longer "
                f"hand in); their games stay theirs")

    def rename(self, name: object, to: object) -> str:
        """The teacher changes a student's name (a typo, a nickname): the machine that joined under it keeps it
        under the new one, the games handed in before and after are one row under the new name, and the table's
        file keeps each game as it was entered (the CSV shows both). Refused like a join: a new name that hides
        part of itself, or that a reader would take for another student's."""
        if not isinstance(name, str) or player_key(name) not in self.roster.players:
            raise RefusedError(404, "no machine has joined under that name")
        try:
            new = check_name(to, "the new name")
        except ValueError as exc:
            raise RefusedError(400, str(exc)) from None
        old_key, new_key = player_key(name), player_key(new)
        player = self.roster.players[old_key]
        problem = name_problem(new)
        if problem is not None:
            raise RefusedError(400, f"that name cannot be shown as it is typed ({problem})")
        taken = self.roster.players.get(new_key) or self.roster.lookalike_of(new)
        if new_key != old_key and taken is not None and taken is not player:
            raise RefusedError(409, f"that name is taken or reads like {taken.name}: choose another")
        players = {k: p for k, p in self.roster.players.items() if k != old_key}
        players[new_key] = Player(new, player.token_sha256, player.joined, player.address)
        renamed = {k: (new if player_key(v) == old_key else v) for k, v in self.roster.renamed.items()}
        renamed[old_key] = new
        renamed.pop(new_key, None)
        hidden = (self.roster.hidden - {old_key}) | ({new_key} if old_key in self.roster.hidden else set())
        self.roster.changed(players=players, renamed=renamed, hidden=hidden)
        self._build_boards()
        self.version += 1
        self.lab_version += 1
        return f"{player.name} is shown as {new} (the same machine, the same games)"

    def remove(self, names: object) -> str:
        """Names taken off the class at once (a flood of names from one machine): each one's machine can no
        longer hand in, the names are hidden from the projector, and their games stay in the table (the
        teacher's CSV keeps them). One save for all; nothing changed if it fails."""
        if not isinstance(names, list) or not names or len(names) > MAX_PLAYERS or \
                not all(isinstance(n, str) for n in names):
            raise RefusedError(400, "names must be a list of names")
        keys = {player_key(n) for n in names}
        known = keys & (set(self.roster.players) | {player_key(e.name) for e in self.entries})
        if not known:
            raise RefusedError(404, "none of those names is in this class")
        players = {k: p for k, p in self.roster.players.items() if k not in known}
        self.roster.changed(players=players, hidden=self.roster.hidden | known)
        self.version += 1
        self.lab_version += 1
        names = f"{len(known)} name{'s' if len(known) != 1 else ''}"
        return f"{names} removed: hidden, and their machines can no longer hand in"

    def close(self, closed: bool) -> str:
        self.roster.changed(closed=bool(closed))
        self.version += 1
        return "the class is closed to new games" if closed else "the class takes games again"

    def lock(self, locked: bool) -> str:
        """No new names (the students already in play on); or new names again."""
        self.roster.changed(locked=bool(locked))
        self.version += 1
        return "the class takes no new names" if locked else "the class takes new names again"

    def choose_lab(self, protocol: object) -> str:
        """The protocol the class curve shows (the teacher's choice; None: none until chosen)."""
        from ..lab.presets import PRESETS

        if protocol is not None and (not isinstance(protocol, str) or protocol not in PRESETS):
            raise RefusedError(400, f"the class curve shows one of the presets: {', '.join(sorted(PRESETS))}")
        self.roster.changed(lab=protocol)
        self.version += 1
        self.lab_version += 1
        return f"the class curve shows {protocol}" if protocol else "the class curve shows no protocol"

    # ------------------------------------------------------------------ what the page shows
    def standings(self, teacher: bool = False) -> dict[str, object]:
        """The class as the projector shows it (hidden names left out), or as the teacher sees it."""

        def rows(programs: bool) -> list[dict[str, object]]:
            out = []
            for row in self._rows(programs):
                hidden = self.roster.is_hidden(row.name)
                if hidden and not teacher:
                    continue
                e = row.best
                out.append({"rank": shared_rank(out, e.score), "name": row.name, "score": e.score, "hits": e.hits,
                            "games": row.games, "driver": e.how if programs else None,
                            **({"hidden": hidden} if teacher else {})})
                if len(out) >= STANDINGS_ROWS and not teacher:
                    break
            return out

        arrival = self.arrival
        shown = arrival is not None and not self.roster.is_hidden(arrival.name)
        return {"version": self.version, "seed": self.roster.seed, "closed": self.roster.closed,
                "joined": len(self.roster.players), "games": len(self.entries),
                "round": None if teacher else self.round_view(),
                "students": rows(False), "programs": rows(True),
                "arrival": None if not shown else {"seq": arrival.seq, "name": arrival.name,  # type: ignore[union-attr]
                                                   "score": arrival.score, "note": arrival.note,  # type: ignore[union-attr]
                                                   "program": arrival.program}}  # type: ignore[union-attr]

    # ------------------------------------------------------------------ rounds
    def current_round(self) -> Round | None:
        return None if self.roster.round is None else Round.from_dict(self.roster.round)

    def start_round(self, minutes: object) -> str:
        """A new round of ``minutes``, from now (the last one ends here if it was still on)."""
        try:
            rnd = new_round(self.current_round(), minutes, max((e.entered or 0 for e in self.entries), default=0))
        except ValueError as exc:
            raise RefusedError(400, str(exc)) from None
        self.roster.changed(round=rnd.as_dict())
        self.version += 1
        self.round_over = False
        return f"round {rnd.number}: {rnd.minutes} min, from now"

    def stop_round(self) -> str:
        rnd = self.current_round()
        if rnd is None:
            raise RefusedError(404, "no round has been started")
        self.roster.changed(round=None)
        self.version += 1
        return f"round {rnd.number} is off the projector"

    def round_ended(self, now: datetime | None = None) -> bool:
        """Whether the round's results just became final (its clock and grace run out): the projector is told
        once, and shows its winners."""
        rnd = self.current_round()
        if rnd is None or self.round_over or not rnd.over(now or datetime.now(UTC)):
            return False
        self.round_over = True
        self.version += 1
        return True

    def round_view(self, now: datetime | None = None) -> dict[str, object] | None:
        return round_view(self.current_round(), self.entries, self.roster.hidden, now or datetime.now(UTC),
                          STANDINGS_ROWS, name_of=self.shown_name)

    def roster_view(self) -> dict[str, object]:
        """For the teacher's page: every joined name with the machine (address) it joined from and its games
        (0: joined, not played yet), grouped by address, most names first; whether the list is locked, and the
        class curve's protocol."""
        from ..lab.presets import PRESETS

        played: dict[str, int] = {}
        for entry in self.entries:
            key = player_key(self.shown_name(entry.name))
            played[key] = played.get(key, 0) + 1
        machines: dict[str, list[dict[str, object]]] = {}
        for key, p in self.roster.players.items():
            machines.setdefault(p.address or "unknown", []).append(
                {"name": p.name, "joined": p.joined, "games": played.get(key, 0),
                 "hidden": key in self.roster.hidden})
        groups = [{"address": address, "names": sorted(names, key=lambda n: str(n["joined"]))}
                  for address, names in machines.items()]
        groups.sort(key=lambda g: (-len(g["names"]), g["address"]))  # type: ignore[arg-type]
        lab = self.roster.lab
        return {"machines": groups, "joined": len(self.roster.players),
                "waiting": sum(1 for k in self.roster.players if not played.get(k)),
                "locked": self.roster.locked, "closed": self.roster.closed,
                "lab": lab.get("name") if isinstance(lab, dict) else lab, "presets": list(PRESETS)}

    def games_csv(self) -> str:
        """Every game entered, in order; ``entered_local`` is the teacher's clock (what a teacher compares with
        the lesson), ``entered_at`` the same moment in UTC as the table keeps it."""
        columns = ("entered", "name", "list", "driven", "driver", "score", "hits", "resets", "seed", "entered_local",
                   "entered_at", "hidden", "replay")
        ordered = sorted(self.entries, key=lambda e: e.entered or 0)
        return _csv(columns, ([e.entered, e.name, "programs" if e.program else "students", e.driven, e.driver or "",
                               e.score, e.hits, e.resets, e.seed, local_time(e.entered_at), e.entered_at or "",
                               self.roster.is_hidden(e.name), e.replay] for e in ordered))

    def lab_csv(self) -> str:
        from ..lab.metrics import TRIAL_COLUMNS

        columns = ("player", "program", "protocol", "replay", *TRIAL_COLUMNS)
        return _csv(columns, ([run.player, run.program, run.protocol.name, run.path.name,
                               *(row[c] for c in TRIAL_COLUMNS)] for run in self.lab_runs for row in run.rows
                              if run.first or run.program))


def _real_folder(folder: Path) -> None:
    """``folder`` made if missing; refused if anything but a real folder is there (a planted link would
    carry the class's writes out of its folder)."""
    try:
        os.mkdir(folder, 0o700)
    except FileExistsError:
        pass
    except OSError as exc:
        raise UserError(f"cannot make the class's {folder.name}/ folder: {exc.strerror or exc}") from None
    if not stat.S_ISDIR(os.lstat(folder).st_mode):
        raise UserError(f"the class's {folder.name}/ is not a folder (a link or a file was put there): nothing was "
                        f"written")


def _runs_in(folder: Path) -> list[Path]:
    """The lab runs kept in ``folder`` (regular files only: a planted link is not followed)."""
    if not folder.is_dir() or folder.is_symlink():
        return []
    return sorted(p for p in folder.glob("*.json") if p.is_file() and not p.is_symlink())


def _read_run(path: Path) -> Replay:
    return Replay.from_bytes(read_limited(path, MAX_HANDIN_BYTES, "lab run", follow=False), str(path))


def _lab_identity(replay: Replay) -> str:
    """A lab run's identity: its game's (``records.identity``) and its protocol, whoever's name it carries."""
    return hashlib.sha256((game_digest(replay) + repr(replay.task.as_dict())).encode()).hexdigest()  # type: ignore[union-attr]


def _finite(value: object, scale: float) -> float | None:
    value = float(value)  # type: ignore[arg-type]
    return round(value * scale, 6) if math.isfinite(value) else None


_FORMULA = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value: object) -> str:
    """A cell a spreadsheet shows as text: a leading = + - @ would make it a formula (OWASP's advice:
    prefix a quote). Numbers are written as they are, so they stay numbers."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int | float) and not isinstance(value, bool):
        return "" if isinstance(value, float) and not math.isfinite(value) else repr(value)
    text = str(value)
    return "'" + text if text.startswith(_FORMULA) else text


def local_time(utc: str | None) -> str:
    """An ISO time with its zone as this machine's local time, to the second (the teacher's clock)."""
    if not utc:
        return ""
    try:
        return datetime.fromisoformat(utc).astimezone().strftime("%Y-%m-%d %H:%M:%S")
    except (ValueError, OverflowError, OSError):
        return ""


def _csv(columns: Sequence[str], rows) -> str:
    """The CSV text, with a byte-order mark first: the one sign a spreadsheet (Excel) reads to take the file as
    UTF-8, so an accented name is not garbled."""
    out = io.StringIO()
    out.write("\ufeff")
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([csv_cell(v) for v in row])
    return out.getvalue()
