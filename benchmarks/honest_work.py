"""The work ``armgame scores`` counts for honest games, and what that work really costs: the measurements
behind ``MAX_CHECK_WORK`` (``armgame.records.listing``) and ``HIT_WORK``/``EVENT_WORK``
(``armgame.records.checking``).

    python benchmarks/honest_work.py              # every bot on seeds 0 to 41, fast keyboard players
    python benchmarks/honest_work.py --seeds 10

Part 1, the honest games of the standard 60 s game: every shipped bot (``armgame.game.bots.BOT_NAMES``)
on each seed, and scripted keyboard players pressing keys as fast as a person can (20 key presses a
second, one key at a time; and all four keys at 20 presses a second each, which no person does): for
each, its steps, hits, input events and ``replay_work``, and the largest against the budget.

Part 2, what the units cost on this machine, in the game's own loop (compiled where built): a physics
step with no input; an input event (a key change between steps: ``key_event`` and a call of the loop);
one try of a target draw (``GameRules._draw_target``: up to 1,000 tries a hit, under any rules), and a
whole draw under the standard rules, with the number of tries it took over 20,000 draws from random
hands. Best of 3 runs each; report ratios, the absolute times vary with the machine.
"""

from __future__ import annotations

import argparse
import math
import random
import time

from armgame.game.bots import BOT_NAMES, play_bot
from armgame.game.rules import GameConfig, GameRules
from armgame.game.session import GameSession, InputEvent
from armgame.records.listing import MAX_CHECK_WORK
from armgame.records.replay import Replay
from armgame.records.scores import EVENT_WORK, HIT_WORK, RANKED_HIT_WORK, replay_work

KEYS = "dfjk"


def keyboard(presses_per_second: float, keys: str, seed: int, together: bool = False) -> Replay:
    """A standard game whose player presses ``presses_per_second`` keys a second, each held half the
    period: one key at a time, taking ``keys`` in turn, or (``together``) each of ``keys`` at that rate,
    their presses staggered."""
    session = GameSession(GameConfig(seed=seed))
    dt, total = session.config.dt, session.total_steps
    events = []
    if together:
        period = round(1 / presses_per_second / dt)
        for i, key in enumerate(keys):
            for start in range(i * period // len(keys), total, period):
                events += [InputEvent(start, key, "down"), InputEvent(start + period // 2, key, "up")]
    else:
        period = round(1 / presses_per_second / dt)
        for n, start in enumerate(range(0, total, period)):
            key = keys[n % len(keys)]
            events += [InputEvent(start, key, "down"), InputEvent(start + period // 2, key, "up")]
    session.play(sorted(events, key=lambda e: e.step))
    return Replay.from_session(session, "keyboard", None, "fast")


def best_of(run, repeats: int = 5) -> float:
    """The least CPU time of ``repeats`` runs (CPU time: the other jobs of a shared machine count less)."""
    times = []
    for _ in range(repeats):
        start = time.process_time()
        run()
        times.append(time.process_time() - start)
    return min(times)


def costs() -> None:
    config = GameConfig(seed=10)
    step = best_of(lambda: GameSession(config).play([])) / config.total_steps
    n = config.total_steps
    events = [InputEvent(i, "d", "down" if i % 2 == 0 else "up") for i in range(n)]
    event = (best_of(lambda: GameSession(config).play(events)) - step * n) / n
    storm = GameRules(GameConfig(seed=10, target_radius=0.5))  # every try lands on the hand: all 1,000 are made
    draw_all = best_of(lambda: [storm._draw_target((0.3, 0.4)) for _ in range(200)]) / 200
    rules = GameRules(config)
    uniform, tries = rules._rng.uniform, [0]

    def counted(a: float, b: float) -> float:
        tries[0] += 1
        return uniform(a, b)

    rules._rng.uniform = counted  # type: ignore[method-assign]
    hands = random.Random(1)
    counts = []
    start = time.process_time()
    for _ in range(20_000):
        tries[0] = 0
        hand = rules._hand(math.radians(hands.uniform(15, 90)), math.radians(hands.uniform(45, 90)))
        rules._draw_target(hand)
        counts.append(tries[0] // 2)
    standard = (time.process_time() - start) / 20_000
    print(f"a physics step: {step * 1e6:.3f} us")
    print(f"an input event: {event * 1e6:.3f} us = {event / step:.1f} steps (EVENT_WORK = {EVENT_WORK})")
    print(f"a target draw of 1,000 tries (any rules' worst): {draw_all * 1e3:.3f} ms = {draw_all / step:,.0f} steps "
          f"(HIT_WORK = {HIT_WORK:,})")
    print(f"a target draw under the standard rules: {standard * 1e6:.2f} us = {standard / step:.0f} steps, "
          f"{sum(counts) / len(counts):.2f} tries on average, at most {max(counts)} in 20,000 draws "
          f"(RANKED_HIT_WORK = {RANKED_HIT_WORK})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=42, help="seeds 0 to N-1 for each bot (default: 42)")
    args = parser.parse_args()
    games: list[tuple[str, Replay]] = []
    for bot in BOT_NAMES:
        for seed in range(args.seeds):
            session = play_bot(GameConfig(seed=seed), bot)
            games.append((f"bot {bot}, seed {seed}", Replay.from_session(session, "bot", bot)))
    games.append(("keyboard, 20 presses/s of one key", keyboard(20, "d", 10)))
    games.append(("keyboard, 20 presses/s, the four keys in turn", keyboard(20, KEYS, 10)))
    games.append(("keyboard, each of the four keys 20 presses/s", keyboard(20, KEYS, 10, together=True)))
    print(f"{'game':48} {'hits':>5} {'events':>7} {'work':>9}")
    worst: dict[str, tuple[int, str]] = {}
    for name, replay in games:
        work = replay_work(replay)
        kind = name.split(",")[0]
        if work > worst.get(kind, (0, ""))[0]:
            worst[kind] = (work, name)
        if not name.startswith("bot") or args.seeds <= 3:
            print(f"{name:48} {replay.result.hits:5} {len(replay.timeline):7} {work:9,}")
    for kind, (work, name) in worst.items():
        print(f"largest of {kind}: {work:,} ({name})")
    largest = max(work for work, _ in worst.values())
    print(f"largest honest work: {largest:,}; MAX_CHECK_WORK {MAX_CHECK_WORK:,} is "
          f"{MAX_CHECK_WORK / largest:.2f} times it")
    costs()


if __name__ == "__main__":
    main()
