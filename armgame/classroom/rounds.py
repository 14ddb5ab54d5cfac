"""A round: "everyone play now", a countdown on the projector, and the round's winners at its end.

The teacher starts a round of a few minutes from the teacher's page; the projector counts it down and
shows the round's own standings (each student's best game played during the round), and when the
clock runs out, the round's winners, large, for the room to cheer. The class's overall standings are
untouched: a round is a view of the games, not a table of its own. A rehearsal's round (``armgame class
serve --rehearse``) lasts ``REHEARSAL_ROUND_SECONDS`` whatever minutes the teacher chose, and its winners
come down ``REHEARSAL_WINNERS_SECONDS`` after its end, so the whole round is walked through in under a minute.

A round has one end that everything uses: ``Round.closes``, its clock plus ``GRACE_SECONDS`` (a game
finished as the clock runs out is still on its way), kept to the millisecond. A game counts in it
(``Round.refusal``) only if the class takes it before ``closes``, and the projector says "round over" only
from ``closes`` on (``Round.over``): the clerk decides each game as it enters it and builds the projector's
view on the same thread, so no game can join the winners once they are shown. And a game counts only if it
was played during the round, as far as the class can know: its start ticket (``Tickets``, fetched from
the class as the game begins) is from the round, and at least a game's length before the hand-in. A game
without one (a kept replay, an older client) goes on the board, not in a round.

Kept in the roster (``Roster.round``: its number, start and length), and the games the clerk took into it
in the class's folder (``intake.ROUND_GAMES``), so a server restarted during a round goes on with it. No I/O
here, and no clock of its own (``now`` is given).
"""

from __future__ import annotations

import secrets
import threading
from collections import OrderedDict
from collections.abc import Callable, Collection, Iterable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta

from ..records.standings import one_row_per_player, player_key, shared_rank
from ..valid import INT64_MAX

#: Seconds after a round's clock runs out during which a game still counts (it was finished in time).
GRACE_SECONDS = 10
#: A round's length, in whole minutes, as the teacher's page offers it.
MIN_MINUTES, MAX_MINUTES = 1, 30
#: The winners the projector names at a round's end.
WINNERS = 3
#: Seconds from a round's end until the projector takes its winners down (they show once the grace is over).
WINNERS_SECONDS = 90
#: A rehearsal's round, and its winners' seconds as above: 15 s of winners after the 10 s of grace.
REHEARSAL_ROUND_SECONDS = 30
REHEARSAL_WINNERS_SECONDS = 25
#: Seconds a game's start ticket may come after the game's own clock started: the ticket's request and the
#: hand-in cross the network at different speeds, so a game handed in at once may seem this much short.
START_SLACK_SECONDS = 2.0
#: Start tickets the class keeps for one player (the oldest dropped first), and for the whole class: a ticket is
#: about 200 bytes, so a class's tickets stay under 2 MB whatever its students' machines ask for.
TICKETS_PER_PLAYER = 4
MAX_TICKETS = 8192


@dataclass(frozen=True)
class Round:
    number: int
    start: datetime
    minutes: int
    #: The table's entries entered before the round began (its first game is entry ``after + 1``).
    after: int = 0
    #: A rehearsal's round: its length in seconds, in place of its minutes (0: an ordinary round).
    seconds: int = 0

    @property
    def end(self) -> datetime:
        return self.start + (timedelta(seconds=self.seconds) if self.seconds else timedelta(minutes=self.minutes))

    @property
    def hold(self) -> int:
        """Seconds from the round's end until the projector takes its winners down."""
        return REHEARSAL_WINNERS_SECONDS if self.seconds else WINNERS_SECONDS

    @property
    def closes(self) -> datetime:
        """The round's one end: its clock and the grace after it. A game taken before it may count; from it on the
        projector shows the winners."""
        return self.end + timedelta(seconds=GRACE_SECONDS)

    def over(self, now: datetime) -> bool:
        """The round's results are final: its clock and the grace after it have run out."""
        return now >= self.closes

    def refusal(self, started: datetime | None, played: float, now: datetime) -> str | None:
        """Why a game taken ``now``, whose start ticket the class gave at ``started`` (None: it has none), and
        whose clock runs ``played`` seconds, is not in this round; None if it is."""
        if now < self.start:
            return "it came before the round"
        if self.over(now):
            return f"round {self.number} was over when it came"
        if started is None:
            return ("it has no start ticket from this class (a game kept from before, or an older armgame): the "
                    "round counts games begun during it")
        if started < self.start:
            return f"it began before round {self.number} did"
        if (now - started).total_seconds() + START_SLACK_SECONDS < played:
            return f"it came sooner after its start ticket than a {played:g} s game can be played"
        return None

    def as_dict(self) -> dict[str, object]:
        return {"number": self.number, "start": self.start.isoformat(timespec="milliseconds"), "minutes": self.minutes,
                "after": self.after, **({"seconds": self.seconds} if self.seconds else {})}

    @classmethod
    def from_dict(cls, data: object) -> Round:
        """A round as the roster keeps it; ValueError naming what is wrong."""
        if not isinstance(data, dict) or not {"number", "start", "minutes", "after"} <= set(data) <= \
                {"number", "start", "minutes", "after", "seconds"}:
            raise ValueError("round must be an object of number, start, minutes and after (and a rehearsal's seconds)")
        number, minutes, start, after = data["number"], data["minutes"], data["start"], data["after"]
        seconds = data.get("seconds", 0)
        if isinstance(seconds, bool) or not isinstance(seconds, int) or not 0 <= seconds <= 60 * MAX_MINUTES:
            raise ValueError(f"round's seconds must be a whole number from 0 to {60 * MAX_MINUTES}")
        if isinstance(after, bool) or not isinstance(after, int) or not 0 <= after <= INT64_MAX:
            raise ValueError("round's after must be a whole number of entries")
        if isinstance(number, bool) or not isinstance(number, int) or not 1 <= number <= 10_000:
            raise ValueError("round's number must be a whole number from 1 to 10000")
        if isinstance(minutes, bool) or not isinstance(minutes, int) or not MIN_MINUTES <= minutes <= MAX_MINUTES:
            raise ValueError(f"round's minutes must be a whole number from {MIN_MINUTES} to {MAX_MINUTES}")
        if not isinstance(start, str) or len(start) > 40:
            raise ValueError("round's start must be an ISO date and time")
        when = datetime.fromisoformat(start)
        if when.tzinfo is None:
            raise ValueError("round's start must carry its time zone")
        return cls(number, when, minutes, after, seconds)


def new_round(previous: Round | None, minutes: object, entered: int, now: datetime | None = None,
              rehearsal: bool = False) -> Round:
    """The next round, starting ``now`` after the table's ``entered`` entries; ValueError if ``minutes`` is not a
    round's length. A rehearsal's round lasts ``REHEARSAL_ROUND_SECONDS``, whatever its minutes."""
    if isinstance(minutes, bool) or not isinstance(minutes, int) or not MIN_MINUTES <= minutes <= MAX_MINUTES:
        raise ValueError(f"a round lasts a whole number of minutes from {MIN_MINUTES} to {MAX_MINUTES}")
    start = now or datetime.now(UTC)
    start = start.replace(microsecond=start.microsecond // 1000 * 1000)  # as the roster keeps it
    return Round((previous.number + 1) if previous else 1, start, minutes, entered,
                 REHEARSAL_ROUND_SECONDS if rehearsal else 0)


def round_view(rnd: Round | None, best_first: Sequence, hidden: Iterable[str], now: datetime,
               rows: int, name_of: Callable[[str], str] = lambda name: name,
               counted: Collection[str] = ()) -> dict[str, object] | None:
    """What the projector shows of ``rnd``: its clock (start, end and ``closes``, ISO: the page counts down),
    whether it is over, its standings (each student's best game in it; programs and hidden names never), and
    once over, its winners (taken down ``hold`` seconds after its end). ``best_first``: the class's entries in
    rank order; ``counted``: the ids of the games the clerk took into the round (``Round.refusal``);
    ``name_of``: the name the class shows for a game's (the teacher may have changed it)."""
    if rnd is None:
        return None
    hidden = set(hidden)
    games = [e for e in best_first
             if not e.program and e.id in counted and player_key(name_of(e.name)) not in hidden]
    table = []
    for row in one_row_per_player(games, lambda e: name_of(e.name)):
        table.append({"rank": shared_rank(table, row.best.score), "name": row.name, "score": row.best.score,
                      "games": row.games})
        if len(table) >= rows:
            break
    over = rnd.over(now)
    return {"number": rnd.number, "start": rnd.start.isoformat(timespec="milliseconds"),
            "end": rnd.end.isoformat(timespec="milliseconds"),
            "closes": rnd.closes.isoformat(timespec="milliseconds"), "minutes": rnd.minutes, "hold": rnd.hold,
            "over": over,
            "players": len({player_key(name_of(e.name)) for e in games}), "students": table,
            "winners": [r for r in table if r["rank"] <= WINNERS] if over else []}


class Tickets:
    """The start tickets the class gave: when each student's game could have begun, as the class's own clock
    says. A ticket is a random nonce, given to a joined player (by their token's digest) and taken back once,
    by the hand-in of the game it started; bounded per player and for the class (the oldest dropped first).
    Thread-safe: given on the event loop (stamped as the request arrives), taken on the clerk's thread."""

    def __init__(self, per_player: int = TICKETS_PER_PLAYER, most: int = MAX_TICKETS) -> None:
        self.per_player, self.most = per_player, most
        self._given: OrderedDict[str, tuple[str, datetime]] = OrderedDict()  # nonce -> (holder, when), oldest first
        self._held: dict[str, list[str]] = {}  # holder -> their nonces, oldest first
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._given)

    def give(self, holder: str, now: datetime) -> str:
        nonce = secrets.token_urlsafe(18)
        with self._lock:
            mine = self._held.setdefault(holder, [])
            while len(mine) >= self.per_player:
                self._given.pop(mine.pop(0), None)
            while len(self._given) >= self.most:
                old, (who, _) = self._given.popitem(last=False)
                self._drop(who, old)
            self._given[nonce] = (holder, now)
            mine.append(nonce)
        return nonce

    def take(self, nonce: str | None, holder: str) -> datetime | None:
        """When ``nonce`` was given to ``holder`` (and it is used up), or None: never given, given to another
        player, or dropped since."""
        if not nonce:
            return None
        with self._lock:
            given = self._given.get(nonce)
            if given is None or given[0] != holder:
                return None
            del self._given[nonce]
            self._drop(holder, nonce)
            return given[1]

    def _drop(self, holder: str, nonce: str) -> None:
        mine = self._held.get(holder, [])
        if nonce in mine:
            mine.remove(nonce)
        if not mine:
            self._held.pop(holder, None)
