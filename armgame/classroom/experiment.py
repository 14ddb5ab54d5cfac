"""A classroom experiment (issue 50, item 3): the class split at random into two conditions, two lab protocols.

The teacher names the two at the start (``armgame class serve --lab A --lab-b B``): the split is fixed before the
first student joins, so nobody joins before it and no one's group depends on when the teacher clicked. Each student
is assigned at their first join for the lab, in permuted blocks of two: the 1st and 2nd lab joins get one condition
each in an order drawn from the class's seed and the block's number, the 3rd and 4th likewise, and so on, so the
two groups are never more than one student apart. The draw is ``numpy.random.default_rng([seed, block])``: the same
on every machine and every numpy, and the seed and every assignment are kept in ``class.json`` (``Experiment``), so
a restarted class goes on with the same groups and ``armgame analyze --class`` finds them afterwards. The student is
told nothing: their lab client is handed the protocol to run, never its condition or its group.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..records.standings import player_key
from ..valid import INT64_MAX, check_int, check_keys, check_str

CONDITIONS = ("a", "b")
#: The names the projector gives the two groups (the teacher's protocols are named beside them).
GROUP_NAMES = {"a": "group A", "b": "group B"}


def condition_at(seed: int, i: int) -> str:
    """The condition of the ``i``-th lab join (from 0): each block of two joins gets one of each, in an order drawn
    from ``seed`` and the block's number alone (so a restart, or a class that replays its joins, draws the same)."""
    first = int(np.random.default_rng([seed, i // 2]).integers(2))
    return CONDITIONS[first if i % 2 == 0 else 1 - first]


@dataclass
class Experiment:
    """Two conditions (``a``, ``b``: each a preset's name or a protocol as plain data, as ``Roster.lab``), the seed
    of the split, and each assigned student's ``player_key`` with their condition, in the order of assignment."""

    a: str | dict
    b: str | dict
    seed: int
    assigned: list[tuple[str, str]] = field(default_factory=list)

    def condition_of(self, name: str, renamed: Mapping[str, str] | None = None) -> str | None:
        """``name``'s condition, or None. ``renamed`` (``Roster.renamed``: an old name's key -> the name shown now):
        a student the teacher renamed keeps the condition their first name drew, under either name."""
        keys = {player_key(name)}
        if renamed:
            shown = player_key(renamed.get(player_key(name), name))
            keys |= {shown} | {old for old, now in renamed.items() if player_key(now) == shown}
        return next((c for k, c in self.assigned if k in keys), None)

    def assign(self, name: str, renamed: Mapping[str, str] | None = None) -> tuple[str, bool]:
        """``name``'s condition, and whether it is new (then the caller saves the class's record)."""
        known = self.condition_of(name, renamed)
        if known is not None:
            return known, False
        c = condition_at(self.seed, len(self.assigned))
        self.assigned.append((player_key(name), c))
        return c, True

    def protocol_of(self, condition: str) -> str | dict:
        return self.a if condition == "a" else self.b

    def counts(self) -> dict[str, int]:
        return {c: sum(1 for _, x in self.assigned if x == c) for c in CONDITIONS}

    def as_dict(self) -> dict[str, object]:
        return {"a": self.a, "b": self.b, "seed": self.seed, "assigned": [list(pair) for pair in self.assigned]}

    @classmethod
    def from_dict(cls, d: object, max_players: int) -> Experiment:
        """An experiment read from ``class.json``, checked as hostile; ValueError in one line otherwise (an assignment
        the seed would not have drawn is refused: a hand-edited split is no random one)."""
        from ..lab.protocol_file import protocol_from_dict

        d = check_keys("experiment", d, {"a", "b", "seed", "assigned"})
        conditions = []
        for c in CONDITIONS:
            value = d[c]
            if isinstance(value, dict):
                protocol_from_dict(value, f"experiment {c}")
            else:
                value = check_str(f"experiment {c}", value, 80)
            conditions.append(value)
        seed = check_int("experiment seed", d["seed"], 0, INT64_MAX)
        items = d["assigned"]
        if not isinstance(items, list) or len(items) > max_players:
            raise ValueError(f"experiment assigned must be a list of at most {max_players} pairs")
        assigned: list[tuple[str, str]] = []
        for i, item in enumerate(items):
            if not (isinstance(item, list) and len(item) == 2 and isinstance(item[0], str)
                    and item[1] in CONDITIONS and len(item[0]) <= 200):
                raise ValueError(f"experiment assigned[{i}] must be [a name's key, \"a\" or \"b\"]")
            if item[1] != condition_at(seed, i):
                raise ValueError(f"experiment assigned[{i}] is not the condition its seed draws: the split was changed")
            assigned.append((item[0], item[1]))
        if len({k for k, _ in assigned}) != len(assigned):
            raise ValueError("experiment assigned names one student twice")
        return cls(conditions[0], conditions[1], seed, assigned)
