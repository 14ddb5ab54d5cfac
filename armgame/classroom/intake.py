"""The class's one writer, the ``Clerk``: a join, one hand-in from arrival to answer, the teacher's changes.

The server runs every change (a join, a hand-in, the teacher's hide and close) through the clerk on
a single worker thread (``worker.ClerkThread``), so the table, the roster and the lab folder never
see two writers, and a hand-in is answered only once it is durably on disk (the table's own atomic,
fsynced write). A hand-in goes through the hand-in pipeline (``handins``), which the clerk calls: everything
it carries is checked before it costs anything, its replay parsed with the replay reader's schema, its work
bounded before it is re-simulated, its player taken from the token (never from the file), its game identified
by its content (``records.identity``), so the same game from two machines is one game.

The clerk keeps the class's state and answers each hand-in (its rank, from ``board``); what the
pages show (the standings, the class curve, the teacher's roster and CSVs) is built from that state
by ``views``, on the same thread.

The class's folder::

    class.json, teacher.secret   the roster (``roster``)
    scores.json, replays/        an ordinary armgame table: ``armgame scores --scores DIR`` reads it
    lab/                         each student's first lab run of each protocol (``analyze --class``)
    lab-more/                    their later runs, kept, not in the class curve (``labruns``)
    round.json                   the current round's games (``handins.ROUND_GAMES``: which games it took)
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
import sys
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ..records.lookalikes import name_problem
from ..records.replay import Replay, now_iso
from ..records.rulesets import CLASS_GAMES, Ruleset
from ..records.scores import ScoreEntry, ScoreTable
from ..records.standings import player_key
from ..records.storage import DataFileError
from ..valid import check_name
from .board import Board
from .bounds import MAX_HANDIN_BYTES, MAX_PLAYERS
from .errors import RefusedError
from .handins import AGAIN, Again, Answer, Checked, HandInPipeline, read_round_games
from .labruns import LAB_DIR, LAB_MORE_DIR, LabRun, lab_identity, read_runs, write_run
from .roster import Player, Roster, token_digest
from .rounds import Round, Tickets, new_round
from .wire import Arrival

NOT_JOINED = ("this machine has not joined the class under that name: join first "
              "(armgame play --join HOST:PORT --code CODE --name NAME)")
#: A new name refused by a closed class (a join for a game: the lab's volunteers still join, ``Clerk.join``).
CLOSED_TO_PLAYERS = "the class is closed to new games, so it takes no new players (the teacher can open it again)"


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
        self.warn = warn or (lambda message: print(f"armgame class: {message}", file=sys.stderr))
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
        self.lab_runs: list[LabRun] = []
        self.lab_digests: set[str] = set()
        self.arrival: Arrival | None = None
        self.round_over = False  # the current round's winners have been shown
        self.version = 0  # bumped at every change the projector should see
        self.lab_version = 0  # and at every change of the class curve (a lab run, a name hidden)
        #: The class's one clock for rounds: start tickets, a game's entry into a round and the round's end.
        self.clock: Callable[[], datetime] = lambda: datetime.now(UTC)
        self.tickets = Tickets()
        self.round_games: set[str] = read_round_games(self.folder, self.current_round(), self.warn)
        #: The hand-in pipeline (``handins``): ``check_many`` and ``enter`` are its.
        self.handins = HandInPipeline(self)

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
        assert found is not AGAIN, "one hand-in cannot come twice"
        return found

    def check_many(self, hand_ins: Sequence[tuple[str | None, bytes]]) -> list[Checked | BaseException | Again]:
        """``check`` of hand-ins that arrived together (``HandInPipeline.check_many``)."""
        return self.handins.check_many(hand_ins)

    def enter(self, checked: Sequence[Checked], tickets: Sequence[str | None] | None = None
              ) -> list[Answer | RefusedError]:
        """Enter checked games together, each one's answer (``HandInPipeline.enter``). Durable on disk before this
        returns."""
        return self.handins.enter(checked, tickets)

    def _build_boards(self) -> None:
        self.boards = {programs: Board((e for e in self.entries if e.program == programs), self.roster.renamed)
                       for programs in (False, True)}

    def shown_name(self, name: str) -> str:
        """The name the class shows for a game entered under ``name`` (the teacher may have changed it)."""
        return self.roster.renamed.get(player_key(name), name)

    # ------------------------------------------------------------------ the lab
    def lab_run(self, player: Player, replay: Replay) -> Answer:
        """A lab run handed in (``HandInPipeline._read``): verified, kept, and where it counts."""
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


