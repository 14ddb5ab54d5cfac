"""The schedule of events: what each game's input timeline does to it, and at which step.

Owns the translation of ``InputEvent`` timelines into what the kernels apply between physics
steps: the muscle keys' new goals and rates (``Schedule``, then ``MuscleEvents`` for the compiled
kernel, by game), and the resets and tab presses the session applies through ``key_event``.

Invariant: every event takes effect at exactly the step where the single session applies it
(``TimelineInput`` and ``GameSession.key_event``): events in list order up to the first beyond the
game's stop, each at the later of its step and the game's clock; events at or after the game's
end, repeats of a held key and unknown keys dropped; of several commands to one muscle at one step,
the last, which is what applying them all in order leaves. Key events do not depend on the motion,
so all of this is worked out once, in plain Python, before any physics runs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..session import DOWN, RESET_KEY, TOGGLE_ARM_KEY, InputEvent

if TYPE_CHECKING:
    from .session import BatchGameSession


class Schedule(NamedTuple):
    """A batch's timelines as commands. Both lists are in timeline order, so by game and within a
    game by step: each kernel orders them as it steps."""

    #: The muscle commands: their steps, flat indices ``muscle * n + game`` into the (4, n) goal and
    #: rate arrays, and the new values there.
    steps: np.ndarray
    flat: np.ndarray
    goal: np.ndarray
    rate: np.ndarray
    #: Resets and tab presses as (step, game, key).
    specials: list[tuple[int, int, str]]
    #: The muscle keys held at the end, by game.
    held_at_end: dict[int, list[bool]]


def schedule(batch: BatchGameSession, timelines: Sequence[Sequence[InputEvent]], now: int,
             limit: list[int]) -> Schedule:
    """What each timeline does to ``batch`` and when, from step ``now`` to game i's stop ``limit[i]``."""
    index = {key: m for m, key in enumerate(batch.muscle_keys)}
    rise, decay = batch._rise.tolist(), batch._decay.tolist()
    n, totals = batch.n, batch.total_steps.tolist()
    steps: list[int] = []
    flat: list[int] = []
    goal: list[float] = []
    rate: list[float] = []
    specials: list[tuple[int, int, str]] = []
    held_at_end: dict[int, list[bool]] = {}
    for i, events in enumerate(timelines):
        clock, stop, end = now, limit[i], totals[i]
        held = batch.held[i].tolist()
        last = [(-1, -1)] * len(held)  # per muscle: (step, position in the lists) of its last command
        for e in events:
            if e.step > stop:
                break
            clock = max(clock, e.step)
            if clock >= end:
                continue
            m = index.get(e.key)
            if m is not None:
                down = e.action == DOWN
                if held[m] == down:
                    continue
                held[m] = down
                values = (1.0, rise[m]) if down else (0.0, decay[m])
                if last[m][0] == clock:
                    goal[last[m][1]], rate[last[m][1]] = values
                else:
                    last[m] = (clock, len(steps))
                    steps.append(clock)
                    flat.append(m * n + i)
                    goal.append(values[0])
                    rate.append(values[1])
            elif e.key in (RESET_KEY, TOGGLE_ARM_KEY) and e.action == DOWN:
                specials.append((clock, i, e.key))
        held_at_end[i] = held
    return Schedule(np.array(steps, dtype=np.int64), np.array(flat, dtype=np.intp), np.array(goal), np.array(rate),
                    specials, held_at_end)


@dataclass
class MuscleEvents:
    """Muscle commands by game: game i's are ``cursor[i]:end[i]`` of the flat arrays, by step.

    ``cursor`` advances as the kernel applies them (an event at step s applies before the
    step from s, as ``BatchGameSession.play`` applies it).
    """

    cursor: np.ndarray  # int64 (n,)
    end: np.ndarray  # int64 (n,)
    step: np.ndarray  # int64 (events,)
    muscle: np.ndarray  # int64 (events,), 0-3
    goal: np.ndarray  # float64 (events,)
    rate: np.ndarray  # float64 (events,)

    @classmethod
    def none(cls, n: int) -> MuscleEvents:
        zeros = np.zeros(n, dtype=np.int64)
        return cls(zeros, zeros.copy(), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                   np.zeros(0), np.zeros(0))

    @classmethod
    def by_game(cls, n: int, steps: np.ndarray, flat: np.ndarray, goal: np.ndarray,
                rate: np.ndarray) -> MuscleEvents:
        """From ``schedule``'s muscle commands: by game, within a game by step, flat
        indices ``muscle * n + game``."""
        muscle, game = np.divmod(flat, n)
        end = np.cumsum(np.bincount(game, minlength=n), dtype=np.int64)
        cursor = np.concatenate([[0], end[:-1]]).astype(np.int64)
        return cls(cursor, end, steps.astype(np.int64), muscle.astype(np.int64), goal.astype(float),
                   rate.astype(float))
