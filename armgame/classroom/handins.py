"""The hand-in pipeline: a batch of hand-ins from their bytes to their answers, run by the clerk on its thread.

``Clerk`` (``intake``) is the class's one writer and the facade the worker calls: its ``check_many`` and ``enter``
are this pipeline's, which holds the clerk's state it writes (the table, the boards, the round's games) through the
clerk. A hand-in passes, in order, cheapest first:

* ``check_many``: each hand-in ``_read`` (its token, its replay parsed once, its work bounded; a lab run is the
  clerk's, ``Clerk.lab_run``), then ``_game`` (the class's game and seed, its identity computed once and looked
  up: a game known already is answered without re-simulating it); a game a batch holds twice is ``AGAIN``;
* ``_verify_games``: the games still to verify re-simulated together (``records.batch_verify``'s lanes, each
  verdict the single session's, bit for bit), a forgery seen before not played again (``_remember``);
* ``enter``: the verified games written to the table together (one write for a burst), taken into the round that
  is on (``_into_round``, kept in ``ROUND_GAMES``), each answered with its rank (``_answer``).
"""

from __future__ import annotations

import bisect
import contextlib
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..game.batch import replay_many
from ..game.session import GameResult
from ..records.batch_verify import batchable
from ..records.identity import game_digests
from ..records.replay import Replay, same_outcome
from ..records.rulesets import class_game_name, config_digest
from ..records.scores import ScoreEntry, replay_work, sort_key
from ..records.standings import player_key, shared_rank
from ..records.storage import DataFileError, atomic_write_bytes, dump_json, parse_json, read_limited
from .bounds import MAX_HANDIN_WORK, MAX_ROUND_GAMES_BYTES, REMEMBERED_FORGERIES
from .errors import RefusedError
from .roster import Player
from .rounds import Round
from .wire import Arrival

CLOSED = "the class is closed to new games: this game is not taken (your replay stays on your machine)"
#: The current round's games, by entry id, as the clerk took them into it (``rounds.Round.refusal``): the round's
#: standings survive a restart. Its number and start say which round; another round's file counts nothing.
ROUND_GAMES = "round.json"


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


class Again:
    """``Clerk.check_many``'s answer for a game that came twice in one batch: check it again after the batch."""


AGAIN = Again()


@dataclass(frozen=True)
class _Pending:
    """A game through every check but its re-simulation (``Clerk.check_many`` verifies them together)."""

    player: Player
    replay: Replay
    digests: tuple[str, ...]


def ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


def handed_in_by(name: str) -> RefusedError:
    """The refusal of a game another player handed in first (whether it came before, or in the same burst)."""
    return RefusedError(409, f"this game was already handed in by {name}: a game counts once, whoever hands it in")


def read_round_games(folder: Path, rnd: Round | None, warn: Callable[[str], None]) -> set[str]:
    """The current round's games as ``ROUND_GAMES`` keeps them (none if it is another round's, or unreadable:
    the teacher is told through ``warn``)."""
    path = folder / ROUND_GAMES
    if rnd is None or not path.exists():
        return set()
    try:
        data = parse_json(read_limited(path, MAX_ROUND_GAMES_BYTES, "round's games", follow=False))
    except (DataFileError, ValueError) as exc:
        warn(f"{path}: {exc}: round {rnd.number} counts only the games from now on")
        return set()
    if not isinstance(data, dict) or data.get("number") != rnd.number or \
            data.get("start") != rnd.as_dict()["start"] or not isinstance(data.get("games"), list):
        return set()
    return {g for g in data["games"] if isinstance(g, str)}


class HandInPipeline:
    """The hand-in pipeline of one class's ``clerk``: called by it alone, on its one thread (not thread-safe)."""

    def __init__(self, clerk: Any) -> None:
        """``clerk``: the ``intake.Clerk`` whose state the pipeline reads and writes (its roster, table, entries,
        boards, version, round), with the lab runs and names that are its own."""
        self.clerk = clerk
        #: Each game in the table by its identity (``game_sha256``): a game handed in again is known at once.
        self.games: dict[str, ScoreEntry] = {e.game_sha256: e for e in clerk.entries if e.game_sha256}
        self._recomputed: OrderedDict[str, GameResult] = OrderedDict()  # forged games' results, by identity

    def check_many(self, hand_ins: Sequence[tuple[str | None, bytes]]
                   ) -> list[Checked | BaseException | Again]:
        """``Clerk.check`` of hand-ins that arrived together, each outcome (the exception it would raise,
        returned) in order: the cheap refusals first, then the games still to verify re-simulated together
        (``records.batch_verify``'s lanes, each verdict the single session's, bit for bit). ``AGAIN``: a game the
        batch holds earlier, to check again once the batch is entered (``Clerk.check`` never returns it)."""
        outcomes: list[Checked | BaseException | _Pending | Again] = []
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
        player = self.clerk.player(token)
        try:
            replay = Replay.from_bytes(data, "the replay")
        except DataFileError as exc:
            raise RefusedError(400, str(exc)) from None
        if self.clerk.roster.closed and replay.task is None:
            raise RefusedError(403, CLOSED)
        work = replay_work(replay)
        if work > MAX_HANDIN_WORK:
            raise RefusedError(413, f"the replay claims {replay.result.hits} hits in {replay.result.steps} steps, more "
                               f"to check ({work:,}) than a class checks for one hand-in ({MAX_HANDIN_WORK:,})")
        if replay.task is not None:
            return Checked(player, replay, answer=self.clerk.lab_run(player, replay))
        return self._game(player, replay)

    def _game(self, player: Player, replay: Replay) -> Checked | _Pending:
        r = replay.result
        if not replay.complete:
            raise RefusedError(400, "the game stopped before its clock ran out: only a whole game is handed in")
        game, seed = self.clerk.game, self.clerk.roster.seed
        if config_digest(replay.config) != game.digest or r.seed != seed:
            raise RefusedError(400, f"this class plays the {game.name} game ({game.config.time_limit:g} s) "
                               f"of seed {seed}; this game is {class_game_name(replay.config)} rules "
                               f"({r.duration:g} s), seed {r.seed} (play it with --join to get the class's game)")
        # An entry keeps the digest of the identity version that entered it: the game is looked up by each.
        # Computed here once and carried to the table's entry (``Checked.digests``).
        digests = game_digests(replay)
        twin = next((self.games[d] for d in digests if d in self.games), None)
        if twin is not None:  # known: answered without re-simulating it
            if player_key(self.clerk.shown_name(twin.name)) == player_key(player.name):
                return Checked(player, replay, digests, answer=self._answer(twin, already=True))
            raise handed_in_by(twin.name)
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
            results = self.clerk.table.add_many([c.replay for c in checked], [c.digests for c in checked], journal=True)
        except (ValueError, UserError) as exc:  # the table could not be written: none was entered
            refusal = RefusedError(503, f"the class's table could not take the game: {exc}")
            return [refusal for _ in checked]
        answers: list[Answer | RefusedError] = []
        fresh = [r for r in results if isinstance(r, ScoreEntry)]
        for entry in fresh:
            bisect.insort(self.clerk.entries, entry, key=sort_key)
            self.clerk.boards[entry.program].add(entry)
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
                self.clerk.version += 1
                self.clerk.arrival = Arrival(self.clerk.version, self.clerk.shown_name(result.name), result.score,
                                             str(answer["note"]), result.program)
                answers.append(answer)
            elif twin is not None and player_key(self.clerk.shown_name(twin.name)) == player_key(c.player.name):
                answers.append(self._answer(twin, already=True))  # the same game twice in one burst
            elif twin is not None:
                answers.append(handed_in_by(twin.name))
            else:
                answers.append(RefusedError(400, f"not entered: {result}"))
        return answers

    def _into_round(self, checked: Sequence[Checked], results: Sequence[object],
                    tickets: Sequence[str | None]) -> list[str]:
        """The games just entered taken into the round that is on (their start tickets used up), kept in
        ``ROUND_GAMES`` before any is answered; for each game, the line its student is told of the round (empty
        when no round is on, or for a program's game, which no round shows)."""
        rnd = self.clerk.current_round()
        now = self.clerk.clock()  # after the table's write: the moment the game is taken, as the projector's end is
        lines, taken = [], []
        for c, result, ticket in zip(checked, results, tickets, strict=True):
            if not isinstance(result, ScoreEntry) or rnd is None or result.program or \
                    now >= rnd.end + timedelta(seconds=rnd.hold):
                lines.append("")
                continue
            started = self.clerk.tickets.take(ticket, c.player.token_sha256)
            why = rnd.refusal(started, self.clerk.game.config.time_limit, now)
            if why is None:
                taken.append(result.id)
                lines.append(f"in round {rnd.number}")
            else:
                lines.append(f"on the board, not in round {rnd.number}: {why}")
        if taken:
            self.clerk.round_games.update(taken)
            try:
                atomic_write_bytes(self.clerk.folder / ROUND_GAMES, dump_json(
                    {"number": rnd.number, "start": rnd.as_dict()["start"], "games": sorted(self.clerk.round_games)}),
                    "round's games")
            except (OSError, DataFileError) as exc:  # the round goes on; only a restart would lose them
                self.clerk.warn(f"the round's games could not be kept ({exc}): a restart would leave them out of it")
        return lines

    def _answer(self, entry: ScoreEntry, already: bool = False) -> Answer:
        """Where ``entry`` leaves its player: their rank among students (or programs), and their best."""
        board = self.clerk.boards[entry.program]
        rank = board.rank(player_key(self.clerk.shown_name(entry.name)))
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
        hidden = self.clerk.roster.is_hidden
        shown = [(i, p) for i, p in enumerate(placed, 1) if not hidden(str(p["name"])) or i == position]
        top = [[p["rank"], p["name"], p["score"]] for _, p in shown]
        # The player's own row, by its index in top: rows of an equal score share the place, so it cannot say.
        yours = next((j for j, (i, _) in enumerate(shown) if i == position), len(top))
        if position > 10:
            top.append([rank, row.name, best.score])
        return {"ok": True, "already": already, "name": entry.name, "score": entry.score, "rank": rank,
                "of": len(board), "best": best.score, "list": "programs" if entry.program else "students",
                "note": note, "top": top, "yours": yours,
                "message": ("already handed in: " if already else "handed in: ") + line}
