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
from itertools import chain, repeat
from operator import attrgetter, eq
from typing import NamedTuple

import numpy as np

from ..session import DOWN, RESET_KEY, TOGGLE_ARM_KEY, InputEvent, compiled_kernel
from .kernel_inputs import KernelInputs


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
    #: The muscle keys held at the end, (4, n) as the batch keeps them.
    held_at_end: np.ndarray


#: Event codes beyond the muscles' 0-3; -1: a key the game ignores.
_RESET, _TOGGLE = 4, 5

#: Larger than any step a game has (24 h at any dt the configuration allows), smaller than int64's end.
_FAR = 2**62


#: ``_ckernel``'s ``event_columns`` (``_cevents.c``), where built: this pass in C, its result read in place.
_C_EVENT_COLUMNS = getattr(compiled_kernel(), "event_columns", None)


def _event_columns(timelines: Sequence[Sequence[InputEvent]], codes: dict[str, int]) -> tuple[np.ndarray, ...]:
    """Every event of every timeline as columns (step, code, down), in order: the only per-event Python (in C
    where built: a bot's 15,000 events in 0.3 ms rather than 3)."""
    if _C_EVENT_COLUMNS is not None:
        columns = _C_EVENT_COLUMNS(timelines, codes, DOWN)
        if columns is not None:
            steps, code, down = columns
            return (np.frombuffer(steps, dtype=np.int64), np.frombuffer(code, dtype=np.int64),
                    np.frombuffer(down, dtype=bool))
    events = list(chain.from_iterable(timelines))
    count = len(events)
    steps_list = list(map(attrgetter("step"), events))
    try:
        steps = np.fromiter(steps_list, dtype=np.int64, count=count)
    except OverflowError:  # a step no game reaches, either way: past every stop, or before every clock
        steps = np.fromiter((min(max(s, -1), _FAR) for s in steps_list), dtype=np.int64, count=count)
    code = np.fromiter(map(codes.get, map(attrgetter("key"), events), repeat(-1)), dtype=np.int64, count=count)
    down = np.fromiter(map(eq, map(attrgetter("action"), events), repeat(DOWN)), dtype=bool, count=count)
    return steps, code, down


def schedule(inputs: KernelInputs, held: np.ndarray, total_steps: np.ndarray,
             timelines: Sequence[Sequence[InputEvent]], now: int, limit: list[int]) -> Schedule:
    """What each timeline does to a batch and when, from step ``now`` to game i's stop ``limit[i]``.

    The batch: its muscles (``inputs``), the keys each game holds now (``held``, (4, n), muscle by
    muscle as the batch keeps them) and each game's end (``total_steps``).

    The single session's rules (``TimelineInput``, ``GameSession.key_event``), in numpy over all the
    events at once rather than in a loop per event (0.23 s of a class's 1,000 games before):

    * a game's events stop at its first event past its stop;
    * an event takes effect at its game's clock, the latest step so far (and at least ``now``), and
      none at or after the game's end;
    * a muscle key's event changes something only if it differs from the key's state before it, which
      is the previous event's of that key (each event leaves the key as it says) or the batch's;
    * of one muscle's changes at one step the last wins, in the first's place; a reset or tab counts
      when pressed.
    """
    n = held.shape[1]
    codes = {RESET_KEY: _RESET, TOGGLE_ARM_KEY: _TOGGLE} | {key: m for m, key in enumerate(inputs.muscle_keys)}
    counts = np.fromiter(map(len, timelines), dtype=np.int64, count=n)
    steps, code, down = _event_columns(timelines, codes)
    game = np.repeat(np.arange(n, dtype=np.int64), counts)
    stop = np.asarray(limit, dtype=np.int64)
    end = total_steps.astype(np.int64)
    # Past a game's stop: its first such event and all after it (a running count within the game).
    past = np.cumsum(steps > stop[game])
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    before = np.concatenate([[0], past])[starts]
    kept = past == before[game]
    # The clock: a running maximum within each game, each game lifted above the last one's values.
    top = np.maximum(stop, now - 1) + 1  # an event past its stop is dropped whatever its value
    clipped = np.clip(steps, now, top[game])
    lift = game * (int(top.max(initial=now)) - now + 1)
    clock = np.maximum.accumulate(clipped + lift) - lift
    kept &= clock < end[game]
    # Resets and tab, when pressed, in timeline order.
    special = np.flatnonzero(kept & (code >= _RESET) & down)
    names = {_RESET: RESET_KEY, _TOGGLE: TOGGLE_ARM_KEY}
    specials = [(c, g, names[k]) for c, g, k in zip(clock[special].tolist(), game[special].tolist(),
                                                  code[special].tolist(), strict=True)]
    # Muscle events by key (game * 4 + muscle), each key's in timeline order.
    index = np.flatnonzero(kept & (code >= 0) & (code < _RESET))
    key = game[index] * 4 + code[index]
    order = np.argsort(key, kind="stable")
    index, key = index[order], key[order]
    now_down = down[index]
    first = np.ones(len(index), dtype=bool)
    first[1:] = key[1:] != key[:-1]
    held = held.T.reshape(-1)  # by game * 4 + muscle
    was_down = np.empty_like(now_down)
    was_down[1:] = now_down[:-1]
    was_down[first] = held[key[first]]
    last = np.ones(len(index), dtype=bool)
    last[:-1] = key[:-1] != key[1:]
    held_at_end = held.copy()
    held_at_end[key[last]] = now_down[last]
    change = now_down != was_down
    index, key, now_down = index[change], key[change], now_down[change]
    # One command per key and step: the first change's place, the last change's value.
    run_clock = clock[index]
    new_run = np.ones(len(index), dtype=bool)
    new_run[1:] = (key[1:] != key[:-1]) | (run_clock[1:] != run_clock[:-1])
    starts_of_runs = np.flatnonzero(new_run)
    ends_of_runs = np.concatenate([starts_of_runs[1:], [len(index)]]) - 1
    place = np.argsort(index[starts_of_runs], kind="stable")
    run_start, run_end = starts_of_runs[place], ends_of_runs[place]
    muscle, games = key[run_start] % 4, key[run_start] // 4
    pressed = now_down[run_end]
    return Schedule(run_clock[run_start], (muscle * n + games).astype(np.intp), pressed.astype(np.float64),
                    np.where(pressed, inputs.rise[muscle], inputs.decay[muscle]), specials,
                    held_at_end.reshape(n, 4).T.copy())


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
