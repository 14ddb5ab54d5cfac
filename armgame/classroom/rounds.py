"""A round: "everyone play now", a countdown on the projector, and the round's winners at its end.

The teacher starts a round of a few minutes from the teacher's page; the projector counts it down and
shows the round's own standings (each student's best game handed in during the round), and when the
clock runs out, the round's winners, large, for the room to cheer. A game counts for the round if it
is entered after the round's start (by the table's own order of entry, exact where a clock's second
is not) and by its end plus ``GRACE_SECONDS`` (a game finished as the clock runs out is still on its
way). The class's overall standings are untouched: a round is a view
of the games, not a table of its own. A rehearsal's round (``armgame class serve --rehearse``) lasts
``REHEARSAL_ROUND_SECONDS`` whatever minutes the teacher chose, and its winners come down
``REHEARSAL_WINNERS_SECONDS`` after its end, so the whole round is walked through in under a minute.

Kept in the roster (``Roster.round``: its number, start and length), so a server restarted during a
round goes on with it. Pure: no I/O, no clock of its own (``now`` is given).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
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

    def counts(self, entered: int | None, entered_at: str | None) -> bool:
        """Whether a game entered as the table's ``entered``-th, at ``entered_at`` (ISO, with its zone), counts."""
        if not entered_at or entered is None or entered <= self.after:
            return False
        return datetime.fromisoformat(entered_at) <= self.end + timedelta(seconds=GRACE_SECONDS)

    def over(self, now: datetime) -> bool:
        """The round's results are final: its clock and the grace after it have run out."""
        return now > self.end + timedelta(seconds=GRACE_SECONDS)

    def as_dict(self) -> dict[str, object]:
        return {"number": self.number, "start": self.start.isoformat(timespec="seconds"), "minutes": self.minutes,
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
    start = (now or datetime.now(UTC)).replace(microsecond=0)
    return Round((previous.number + 1) if previous else 1, start, minutes, entered,
                 REHEARSAL_ROUND_SECONDS if rehearsal else 0)


def round_view(rnd: Round | None, best_first: Sequence, hidden: Iterable[str], now: datetime,
               rows: int, name_of: Callable[[str], str] = lambda name: name) -> dict[str, object] | None:
    """What the projector shows of ``rnd``: its clock (start and end, ISO: the page counts down), whether it is
    over, its standings (each student's best game handed in during it; programs and hidden names never), and
    once over, its winners (taken down ``hold`` seconds after its end). ``best_first``: the class's entries in
    rank order; ``name_of``: the name the class shows for a game's (the teacher may have changed it)."""
    if rnd is None:
        return None
    hidden = set(hidden)
    games = [e for e in best_first
             if not e.program and rnd.counts(e.entered, e.entered_at) and player_key(name_of(e.name)) not in hidden]
    table = []
    for row in one_row_per_player(games, lambda e: name_of(e.name)):
        table.append({"rank": shared_rank(table, row.best.score), "name": row.name, "score": row.best.score,
                      "games": row.games})
        if len(table) >= rows:
            break
    over = rnd.over(now)
    return {"number": rnd.number, "start": rnd.start.isoformat(timespec="seconds"),
            "end": rnd.end.isoformat(timespec="seconds"), "minutes": rnd.minutes, "hold": rnd.hold, "over": over,
            "players": len({player_key(name_of(e.name)) for e in games}), "students": table,
            "winners": [r for r in table if r["rank"] <= WINNERS] if over else []}
