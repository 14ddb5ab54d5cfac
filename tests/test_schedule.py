"""The batch's schedule of events (numpy over all events at once) against the loop it replaced, event by event.

``reference_schedule`` is ``armgame.game.batch.schedule`` as it was until 0.3: the single session's rules
written as a loop over each game's events. Every output must be equal, on timelines a hostile script could
hold: steps out of order, negative or past the stop and the end, repeated keys, several changes of one key
at one step, unknown keys, key-ups of reset and tab, a stop before the batch's step.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from armgame.game.batch import BatchGameSession
from armgame.game.batch.schedule import Schedule, schedule
from armgame.game.rules import GameConfig
from armgame.game.session import DOWN, RESET_KEY, TOGGLE_ARM_KEY, InputEvent

KEYS = ("d", "f", "j", "k", RESET_KEY, TOGGLE_ARM_KEY, "x")


def scheduled(batch: BatchGameSession, timelines, now: int, limit: list[int]) -> Schedule:
    """``schedule`` of the batch's timelines, handed what the batch hands it."""
    return schedule(batch.kernel_inputs, batch._held, batch.total_steps, timelines, now, limit)


def reference_schedule(batch: BatchGameSession, timelines, now: int, limit: list[int]) -> Schedule:
    index = {key: m for m, key in enumerate(batch.muscle_keys)}
    rise, decay = batch._rise.tolist(), batch._decay.tolist()
    n, totals = batch.n, batch.total_steps.tolist()
    steps, flat, goal, rate, specials = [], [], [], [], []
    held_at_end = batch._held.copy()
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
        held_at_end[:, i] = held
    return Schedule(np.array(steps, dtype=np.int64), np.array(flat, dtype=np.intp), np.array(goal, dtype=float),
                    np.array(rate, dtype=float), specials, held_at_end)


def assert_same(got: Schedule, want: Schedule) -> None:
    for name in ("steps", "flat", "goal", "rate", "held_at_end"):
        a, b = getattr(got, name), getattr(want, name)
        assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b), name
    assert got.specials == want.specials
    assert all(type(c) is int and type(g) is int for c, g, _ in got.specials)


events = st.builds(InputEvent, st.integers(-5, 80), st.sampled_from(KEYS), st.sampled_from(["down", "up", "held"]))


@settings(max_examples=150, deadline=None)
@given(timelines=st.lists(st.lists(events, max_size=30), min_size=1, max_size=5),
       now=st.integers(0, 20), data=st.data())
def test_the_schedule_is_the_loop_it_replaced(timelines, now, data):
    n = len(timelines)
    seconds = data.draw(st.lists(st.sampled_from([0.1, 0.2, 0.3]), min_size=n, max_size=n))
    batch = BatchGameSession([GameConfig(seed=i, time_limit=t) for i, t in enumerate(seconds)], kernel="numpy")
    batch._held[...] = np.array(data.draw(st.lists(st.booleans(), min_size=4 * n, max_size=4 * n))).reshape(4, n)
    limit = [min(int(t), data.draw(st.integers(-3, 90))) for t in batch.total_steps]
    assert_same(scheduled(batch, timelines, now, limit), reference_schedule(batch, timelines, now, limit))


def test_a_class_of_scripts_and_steps_no_game_reaches():
    """Long timelines as a class's are, and steps beyond int64 (past every stop: dropped)."""
    rng = np.random.default_rng(4)
    timelines = []
    for _ in range(40):
        steps = np.sort(rng.integers(0, 15_500, 300))
        timelines.append([InputEvent(int(s), KEYS[int(k)], ("down", "up")[int(a)])
                          for s, k, a in zip(steps, rng.integers(0, 7, 300), rng.integers(0, 2, 300), strict=True)])
    timelines[3].append(InputEvent(2**70, "d", "down"))
    timelines[5].insert(0, InputEvent(-(2**70), "f", "down"))
    batch = BatchGameSession([GameConfig(seed=i) for i in range(40)], kernel="numpy")
    limit = [int(t) for t in batch.total_steps]
    limit[7] = 9_000
    got, want = scheduled(batch, timelines, 0, limit), reference_schedule(batch, timelines, 0, limit)
    assert_same(got, want)
    assert len(got.steps) > 3_000 and len(got.specials) > 1_000
