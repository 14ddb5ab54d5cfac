"""The class's one writer, the ``Clerk``: a join, one hand-in from arrival to answer, the teacher's changes.

The server runs every change (a join, a hand-in, the teacher's hide and close) through the clerk on
a single worker thread (``worker.ClerkThread``), so the table, the roster and the lab folder never
see two writers, and a hand-in is answered only once it is durably on disk (the table's own atomic,
fsynced write). Everything a request carries is checked here before it costs anything: the replay
is parsed with the replay reader's schema, its work bounded before it is re-simulated, its player
taken from the token (never from the file), its game identified by its content
(``records.identity``), so the same game from two machines is one game.

The clerk keeps the class's state and answers each hand-in (its rank, from ``board``); what the
pages show (the standings, the class curve, the teacher's roster and CSVs) is built from that state
by ``views``, on the same thread.

The class's folder::

    class.json, teacher.secret   the roster (``roster``)
    scores.json, replays/        an ordinary armgame table: ``armgame scores --scores DIR`` reads it
    lab/                         each student's first lab run of each protocol (``analyze --class``)
    lab-more/                    their later runs, kept, not in the class curve (``labruns``)
    round.json                   the current round's games (``ROUND_GAMES``: which games it took)
"""

from __future__ import annotations

import bisect
import contextlib
import os
import secrets
import stat
import sys
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..game.batch import replay_many
from ..game.session import GameResult
from ..records.batch_verify import batchable
from ..records.identity import game_digests
from ..records.lookalikes import name_problem
from ..records.replay import Replay, now_iso, same_outcome
from ..records.rulesets import CLASS_GAMES, Ruleset, class_game_name, config_digest
from ..records.scores import ScoreEntry, ScoreTable, replay_work, sort_key
from ..records.standings import player_key, shared_rank
from ..records.storage import DataFileError, atomic_write_bytes, dump_json, parse_json, read_limited
from ..valid import check_name
from .board import Board
from .bounds import MAX_HANDIN_BYTES, MAX_HANDIN_WORK, MAX_PLAYERS, MAX_ROUND_GAMES_BYTES, REMEMBERED_FORGERIES
from .errors import RefusedError
from .labruns import LAB_DIR, LAB_MORE_DIR, LabRun, lab_identity, read_runs, write_run
from .roster import Player, Roster, token_digest
from .rounds import Round, Tickets, new_round

NOT_JOINED = ("this machine has not joined the class under that name: join first "
              "(armgame play --join HOST:PORT --code CODE --name NAME)")
CLOSED = "the class is closed to new games: this game is not taken (your replay stays on your machine)"
#: A new name refused by a closed class (a join for a game: the lab's volunteers still join, ``Clerk.join``).
CLOSED_TO_PLAYERS = "the class is closed to new games, so it takes no new players (the teacher can open it again)"
#: The current round's games, by entry id, as the clerk took them into it (``rounds.Round.refusal``): the round's
#: standings survive a restart. Its number and start say which round; another round's file counts nothing.
ROUND_GAMES = "round.json"


@dataclass(frozen=True)
class Arrival:
    """A game just entered, as the projector announces it."""

    seq: int
    name: str
    score: int
    note: str
    program: bool


#: What the student's machine is told of a hand-in taken: a JSON object (``ok``, ``already``, ``message``; for a
#: game, its rank and the top of its list).
Answer = dict[str, object]


@dataclass(frozen=True)
class Checked:
    """A hand-in through every check, nothing of it entered yet: a game verified for ``enter`` (its player,
    its replay under their name, its identity: ``identity.game_digests``, the current version's first), or,
    when ``answer`` is set, a hand-in answered already (the player's own game handed in before; a lab run,
    kept at once), which ``enter`` never sees."""

    player: Player
    replay: Replay
    digests: tuple[str, ...] = ()
    answer: Answer | None = None


class _Again:
    """``Clerk.check_many``'s answer for a game that came twice in one batch: check it again after the batch."""


AGAIN = _Again()


@dataclass(frozen=True)
class _Pending:
    """A game through every check but its re-simulation (``Clerk.check_many`` verifies them together)."""

    player: Player
    replay: Replay
    digests: tuple[str, ...]


def ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


class Clerk:
    """The class's state and its one writer. Not thread-safe by design: call it from one thread."""

    def __init__(self, folder: Path, roster: Roster, rehearsal: bool = False, records: Path | None = None,
                 warn: Callable[[str], None] | None = None) -> None:
        """``rehearsal``: the class plays the rehearsal's 15 s game and short rounds (``serve --rehearse``);
        ``records``: where the table's record is kept (``records.teacher``; None: the teacher's own records);
        ``warn``: the teacher's terminal, told of anything wrong with the table's files (a damaged journal line,
        rebuilt from its replay or named; None: standard error)."""
        self.folder = Path(folder)
        self.roster = roster
        self.rehearsal = rehearsal
        #: The one game this class takes: a game of other rules is refused, whatever its score.
        self.game: Ruleset = CLASS_GAMES["rehearsal" if rehearsal else "standard"]
        self.table = ScoreTable(self.folder, warn=warn, records=records)
        self._warn = warn or (lambda message: print(f"armgame class: {message}", file=sys.stderr))
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
        with contextlib.suppress(DataFileError):  # a journal a killed server left, mended and taken into the table
            self.table.compact(mend=True)
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
        #: The class's one clock for rounds: start tickets, a game's entry into a round and the round's end.
        self.clock: Callable[[], datetime] = lambda: datetime.now(UTC)
        self.tickets = Tickets()
        self.round_games: set[str] = self._read_round_games()

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
    def join(self, name: object, token: str | None, address: str = "",
             lab: bool = False) -> tuple[Player, str | None]:
        """The player ``name`` for this client: (player, a new token) for a new name, (player, None)
        when ``token`` proves the name is already theirs. RefusedError if another client holds the name
        or one a reader would take it for, if the name hides part of itself, or if the roster is locked.

        ``lab``: the join says it is for the lab (``armgame lab --join``). A closed class is closed to new
        games, and the teacher's lab is not one: its volunteers join a closed class (their games stay refused,
        ``_read``). A locked list is the teacher's "nobody new", and refuses them like any new name."""
        player = self.roster.rejoins(name, token)
        if player is not None:  # the name, or its old one the teacher changed, is this machine's already
            if lab:
                self.assign(player.name)
            return player, None
        name = self.check_new_name(name)
        key = player_key(name)
        if self.roster.closed and not lab:
            raise RefusedError(403, CLOSED_TO_PLAYERS)
        if self.roster.locked:
            raise RefusedError(403, "the class takes no new names now (the teacher locked the list): ask the teacher")
        if len(self.roster.players) >= MAX_PLAYERS:
            raise RefusedError(403, f"the class has {MAX_PLAYERS} players, as many as it takes")
        new_token = secrets.token_urlsafe(24)
        player = Player(name, token_digest(new_token), now_iso(), address[:64])
        self.roster.add(key, player)
        self.version += 1
        if lab:
            self.assign(player.name)
        return player, new_token

    def check_new_name(self, name: object, owner: Player | None = None, what: str = "player name") -> str:
        """The one check of a name a player takes: a machine's new name (``join``), or the one the teacher gives a
        student (``rename``, ``owner`` the student). The name, trimmed; RefusedError if it is no name
        (``valid.check_name``), hides part of itself (``records.lookalikes.name_problem``), or is another
        player's: taken, read like theirs, or a name of theirs the teacher changed (``Roster``'s questions)."""
        try:
            name = check_name(name, what)
        except ValueError as exc:
            raise RefusedError(400, str(exc)) from None
        taken = self.roster.players.get(player_key(name))
        if taken is not None and taken is not owner:
            raise RefusedError(409, f"the name {taken.name} is taken in this class by another machine: choose another "
                               f"name (or join from the machine that took it)")
        if name.strip().upper() == "NAME":
            raise RefusedError(400, "type your own name in place of NAME (in quotes if it has a space: "
                                    "--name \"Ann B\")")
        problem = name_problem(name)
        if problem is not None:
            raise RefusedError(400, f"that name cannot be shown as it is typed ({problem}): type it with plain "
                               f"letters")
        alike = self.roster.lookalike_of(name)
        if alike is not None and alike is not owner:
            raise RefusedError(409, f"that name reads like {alike.name}, who is in this class already: choose a name "
                               f"nobody could mistake for a classmate's: add the first letter of your surname "
                               f"(\"{name} K\", say)")
        now = self.roster.renamed_from(name)
        if now is not None and (owner is None or player_key(now) != player_key(owner.name)):
            raise RefusedError(409, f"that name is {now}'s, whom the teacher renamed: choose another name")
        return name

    def assign(self, name: str) -> str | dict | None:
        """In a classroom experiment, ``name``'s protocol (a preset's name or a protocol as data): their condition's,
        assigned at their first join for the lab and kept in the class's record before the join is answered;
        None in a class of one protocol."""
        experiment = self.roster.experiment
        if experiment is None:
            return None
        before = list(experiment.assigned)
        condition, new = experiment.assign(name, self.roster.renamed)
        if new:
            try:
                self.roster.save()
            except BaseException:
                experiment.assigned = before  # memory never disagrees with disk
                raise
            self.lab_version += 1
        return experiment.protocol_of(condition)

    def lab_protocol(self, name: str | None) -> Any:
        """The protocol a student's lab runs (a ``Protocol``): for ``name`` in a classroom experiment, their
        condition's (``assign``: theirs from their first lab request on, a join's or a browser's plan's, kept in the
        class's record); else, and without a name, the teacher's choice, the lesson's until one is chosen."""
        from ..lab.analysis import curve_protocol
        from ..lab.presets import preset

        choice = None if name is None else self.assign(name)
        return curve_protocol(choice) if choice is not None else self.curve_protocol() or preset("lesson")

    def player(self, token: str | None) -> Player:
        player = self.roster.player_of(token) if token else None
        if player is None:
            raise RefusedError(401, NOT_JOINED)
        return player

    def start_ticket(self, token: str | None) -> str:
        """A start ticket for the game ``token``'s player begins now (``rounds.Tickets``): what the class knows of
        when it was played. Thread-safe (the event loop gives them, stamped as the request comes)."""
        return self.tickets.give(self.player(token).token_sha256, self.clock())

    # ------------------------------------------------------------------ handing in
    def hand_in(self, token: str | None, data: bytes) -> Answer:
        """Check, verify and enter one replay; the answer the student's machine shows. Raises RefusedError."""
        found = self.check(token, data)
        if found.answer is not None:
            return found.answer
        answer = self.enter([found])[0]
        if isinstance(answer, RefusedError):
            raise answer
        return answer

    def check(self, token: str | None, data: bytes) -> Checked:
        """A hand-in checked and verified, ready to ``enter``, or answered already (``Checked.answer``: a game
        handed in before by the same player; a lab run, which is kept here at once). Raises RefusedError;
        writes nothing but a lab run."""
        found = self.check_many([(token, data)])[0]
        if isinstance(found, BaseException):
            raise found
        assert not isinstance(found, _Again), "one hand-in cannot come twice"
        return found

    def check_many(self, hand_ins: Sequence[tuple[str | None, bytes]]
                   ) -> list[Checked | BaseException | _Again]:
        """``check`` of hand-ins that arrived together, each outcome (the exception ``check`` would raise,
        returned) in order: the cheap refusals first, then the games still to verify re-simulated together
        (``records.batch_verify``'s lanes, each verdict the single session's, bit for bit). ``AGAIN``: a game the
        batch holds earlier, to check again once the batch is entered (``check`` never returns it)."""
        outcomes: list[Checked | BaseException | _Pending | _Again] = []
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
        judged: dict[int, Checked | BaseException] = {}
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

    def _read(self, token: str | None, data: bytes) -> Checked | _Pending:
        """One hand-in up to its verification: the token first (it costs nothing), then the replay read once
        (a closed class refuses a game, and takes a lab run: the lab is not a new game), its work bounded, its
        rules and seed, its identity computed once and looked up; a lab run is kept here (its own
        verification). Raises RefusedError."""
        player = self.player(token)
        try:
            replay = Replay.from_bytes(data, "the replay")
        except DataFileError as exc:
            raise RefusedError(400, str(exc)) from None
        if self.roster.closed and replay.task is None:
            raise RefusedError(403, CLOSED)
        work = replay_work(replay)
        if work > MAX_HANDIN_WORK:
            raise RefusedError(413, f"the replay claims {replay.result.hits} hits in {replay.result.steps} steps, more "
                               f"to check ({work:,}) than a class checks for one hand-in ({MAX_HANDIN_WORK:,})")
        if replay.task is not None:
            return Checked(player, replay, answer=self._lab_run(player, replay))
        return self._game(player, replay)

    def _game(self, player: Player, replay: Replay) -> Checked | _Pending:
        r = replay.result
        if not replay.complete:
            raise RefusedError(400, "the game stopped before its clock ran out: only a whole game is handed in")
        if config_digest(replay.config) != self.game.digest or r.seed != self.roster.seed:
            raise RefusedError(400, f"this class plays the {self.game.name} game ({self.game.config.time_limit:g} s) "
                               f"of seed {self.roster.seed}; this game is {class_game_name(replay.config)} rules "
                               f"({r.duration:g} s), seed {r.seed} (play it with --join to get the class's game)")
        # An entry keeps the digest of the identity version that entered it: the game is looked up by each.
        # Computed here once and carried to the table's entry (``Checked.digests``).
        digests = game_digests(replay)
        twin = next((self.games[d] for d in digests if d in self.games), None)
        if twin is not None:  # known: answered without re-simulating it
            if player_key(self.shown_name(twin.name)) == player_key(player.name):
                return Checked(player, replay, digests, answer=self._answer(twin, already=True))
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

    def enter(self, checked: Sequence[Checked], tickets: Sequence[str | None] | None = None
              ) -> list[Answer | RefusedError]:
        """Enter checked games together (one table write for all: a burst of a class costs one write, not
        thirty); each game's answer, or why it was not entered. Durable on disk before this returns.
        ``tickets``: each game's start ticket (``start_ticket``), for the round: a game is in it if the round
        takes it at the moment it is entered (``rounds.Round.refusal``)."""
        try:
            results = self.table.add_many([c.replay for c in checked], [c.digests for c in checked], journal=True)
        except (ValueError, UserError) as exc:  # the table could not be written: none was entered
            refusal = RefusedError(503, f"the class's table could not take the game: {exc}")
            return [refusal for _ in checked]
        answers: list[Answer | RefusedError] = []
        fresh = [r for r in results if isinstance(r, ScoreEntry)]
        for entry in fresh:
            bisect.insort(self.entries, entry, key=sort_key)
            self.boards[entry.program].add(entry)
        for c, result in zip(checked, results, strict=True):
            if isinstance(result, ScoreEntry):
                self.games[c.digests[0]] = result
        rounds = self._into_round(checked, results, tickets or [None] * len(checked))
        for c, result, in_round in zip(checked, results, rounds, strict=True):
            twin = next((self.games[d] for d in c.digests if d in self.games), None)
            if isinstance(result, ScoreEntry):
                answer = self._answer(result)
                if in_round:
                    answer["round"] = in_round
                    answer["message"] = f"{answer['message']}; {in_round}"
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

    def _into_round(self, checked: Sequence[Checked], results: Sequence[object],
                    tickets: Sequence[str | None]) -> list[str]:
        """The games just entered taken into the round that is on (their start tickets used up), kept in
        ``ROUND_GAMES`` before any is answered; for each game, the line its student is told of the round (empty
        when no round is on, or for a program's game, which no round shows)."""
        rnd = self.current_round()
        now = self.clock()  # after the table's write: the moment the game is taken, as the projector's end is
        lines, taken = [], []
        for c, result, ticket in zip(checked, results, tickets, strict=True):
            if not isinstance(result, ScoreEntry) or rnd is None or result.program or \
                    now >= rnd.end + timedelta(seconds=rnd.hold):
                lines.append("")
                continue
            started = self.tickets.take(ticket, c.player.token_sha256)
            why = rnd.refusal(started, self.game.config.time_limit, now)
            if why is None:
                taken.append(result.id)
                lines.append(f"in round {rnd.number}")
            else:
                lines.append(f"on the board, not in round {rnd.number}: {why}")
        if taken:
            self.round_games.update(taken)
            try:
                atomic_write_bytes(self.folder / ROUND_GAMES, dump_json(
                    {"number": rnd.number, "start": rnd.as_dict()["start"], "games": sorted(self.round_games)}),
                    "round's games")
            except (OSError, DataFileError) as exc:  # the round goes on; only a restart would lose them
                self._warn(f"the round's games could not be kept ({exc}): a restart would leave them out of it")
        return lines

    def _read_round_games(self) -> set[str]:
        """The current round's games as ``ROUND_GAMES`` keeps them (none if it is another round's, or unreadable:
        the teacher is told)."""
        rnd = self.current_round()
        path = self.folder / ROUND_GAMES
        if rnd is None or not path.exists():
            return set()
        try:
            data = parse_json(read_limited(path, MAX_ROUND_GAMES_BYTES, "round's games", follow=False))
        except (DataFileError, ValueError) as exc:
            self._warn(f"{path}: {exc}: round {rnd.number} counts only the games from now on")
            return set()
        if not isinstance(data, dict) or data.get("number") != rnd.number or \
                data.get("start") != rnd.as_dict()["start"] or not isinstance(data.get("games"), list):
            return set()
        return {g for g in data["games"] if isinstance(g, str)}

    def _answer(self, entry: ScoreEntry, already: bool = False) -> Answer:
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
        shown = [(i, p) for i, p in enumerate(placed, 1) if not self.roster.is_hidden(str(p["name"])) or i == position]
        top = [[p["rank"], p["name"], p["score"]] for _, p in shown]
        # The player's own row, by its index in top: rows of an equal score share the place, so it cannot say.
        yours = next((j for j, (i, _) in enumerate(shown) if i == position), len(top))
        if position > 10:
            top.append([rank, row.name, best.score])
        return {"ok": True, "already": already, "name": entry.name, "score": entry.score, "rank": rank,
                "of": len(board), "best": best.score, "list": "programs" if entry.program else "students",
                "note": note, "top": top, "yours": yours,
                "message": ("already handed in: " if already else "handed in: ") + line}

    def _build_boards(self) -> None:
        self.boards = {programs: Board((e for e in self.entries if e.program == programs), self.roster.renamed)
                       for programs in (False, True)}

    def shown_name(self, name: str) -> str:
        """The name the class shows for a game entered under ``name`` (the teacher may have changed it)."""
        return self.roster.renamed.get(player_key(name), name)

    # ------------------------------------------------------------------ the lab
    def _lab_run(self, player: Player, replay: Replay) -> Answer:
        from ..lab.analysis import trial_rows

        game = lab_identity(replay)
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
        path = write_run(self.folder, player.name, replay, game, first)
        self.lab_digests.add(game)
        self.lab_runs.append(LabRun(player.name, not person, protocol, trial_rows(session) if first or not person
                                    else [], path, first))
        self.version += 1
        self.lab_version += 1
        if not person:
            counted = "a program's run: kept apart, never in the class curve"
        elif first and self.curve_protocol_of(player.name) == protocol:
            counted = "in the class curve"
        elif first:
            counted = "kept (the class curve shows the protocol the teacher chose)"
        else:
            counted = "kept (your first run of this protocol is the one in the curve)"
        return {"ok": True, "already": False, "message": f"lab run handed in: {counted}"}

    def load_lab(self) -> list[str]:
        """Re-verify the lab runs already in the folder (at a restart); returns a line per run left out."""
        runs, identities, problems = read_runs(self.folder, MAX_HANDIN_BYTES)
        self.lab_runs += runs
        self.lab_digests |= identities
        if self.lab_runs:
            self.version += 1
            self.lab_version += 1
        return problems

    def curve_protocol_of(self, name: str) -> Any:
        """The protocol whose run of ``name``'s is in the class's curve: their condition's in an experiment (a student
        never assigned: neither), else the teacher's choice."""
        from ..lab.analysis import curve_protocol

        experiment = self.roster.experiment
        if experiment is None:
            return self.curve_protocol()
        condition = experiment.condition_of(name, self.roster.renamed)
        return None if condition is None else curve_protocol(experiment.protocol_of(condition))

    def curve_protocol(self) -> Any:
        """The protocol the teacher chose for the class curve (``Roster.lab``), or None."""
        from ..lab.analysis import curve_protocol

        return curve_protocol(self.roster.lab)

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
        player = self.roster.players[player_key(name)]
        new = self.check_new_name(to, player, "the new name")
        old_key, new_key = player_key(name), player_key(new)
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
        return ("the class is closed to new games (the lab's volunteers still join, and their runs count)" if closed
                else "the class takes games again")

    def browser_lab(self, on: bool) -> str:
        """The teacher's switch: every browser at /play runs the class's lab (a game under way is finished first),
        or plays the game again. The lab's protocol is the class curve's (``choose_lab``)."""
        self.roster.changed(browser_lab=bool(on))
        self.version += 1
        if on:
            return (f"every browser runs the lab ({self.lab_protocol_name()}) once its game is over; their runs enter "
                    f"the class curve")
        return "the browsers play the game again"

    def lab_protocol_name(self) -> str:
        """The protocol a browser's lab runs, by name: the teacher's, or the lesson's until one is chosen."""
        lab = self.roster.lab
        return str(lab.get("name", "the class's own")) if isinstance(lab, dict) else (lab or "lesson")

    def lock(self, locked: bool) -> str:
        """No new names (the students already in play on), the lab's volunteers' neither; or new names again."""
        self.roster.changed(locked=bool(locked))
        self.version += 1
        return ("the class takes no new names, not even the lab's volunteers'" if locked
                else "the class takes new names again")

    def choose_lab(self, protocol: object) -> str:
        """The protocol the class curve shows (the teacher's choice; None: none until chosen)."""
        from ..lab.presets import PRESETS

        if protocol is not None and (not isinstance(protocol, str) or protocol not in PRESETS):
            raise RefusedError(400, f"the class curve shows one of the presets: {', '.join(sorted(PRESETS))}")
        if self.roster.experiment is not None:  # the groups' protocols are the experiment: changing one ends it
            raise RefusedError(409, "this class is an experiment of two conditions, fixed when it began: its curves "
                                    "are the two groups'")
        self.roster.changed(lab=protocol)
        self.version += 1
        self.lab_version += 1
        return f"the class curve shows {protocol}" if protocol else "the class curve shows no protocol"

    # ------------------------------------------------------------------ rounds
    def current_round(self) -> Round | None:
        return None if self.roster.round is None else Round.from_dict(self.roster.round)

    def start_round(self, minutes: object) -> str:
        """A new round of ``minutes``, from now (the last one ends here if it was still on)."""
        try:
            rnd = new_round(self.current_round(), minutes, max((e.entered or 0 for e in self.entries), default=0),
                            self.clock(), rehearsal=self.rehearsal)
        except ValueError as exc:
            raise RefusedError(400, str(exc)) from None
        self.roster.changed(round=rnd.as_dict())
        self.round_games = set()  # the file's games are the last round's: this one's own replace them
        self.version += 1
        self.round_over = False
        length = f"{rnd.seconds} s (a rehearsal's round)" if rnd.seconds else f"{rnd.minutes} min"
        return f"round {rnd.number}: {length}, from now"

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
        if rnd is None or self.round_over or not rnd.over(now or self.clock()):
            return False
        self.round_over = True
        self.version += 1
        return True


