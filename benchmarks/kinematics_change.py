"""What the rules' own hand (armgame 0.4, ``armgame.game.rules.hand_position``) changed: games' outcomes.

    python benchmarks/kinematics_change.py                       # 2,000 students, 1,000 random scripts, 300 bots
    python benchmarks/kinematics_change.py --students 200 --scripts 100 --bots 30
    python benchmarks/kinematics_change.py --json

Until 0.3 the rules found the hand with the C library's ``math.cos`` and ``math.sin``, tested a hit with
``(hx - tx) ** 2 + (hy - ty) ** 2`` (the C library's ``pow``) and kept a new target clear of the hand with
``math.dist``; 0.4 uses the arm's own sine (``physics.trig``), ``dx * dx + dy * dy`` and squared distances,
so that the browser's engine (``classroom/static/engine.js``) finds the same bits. ``OldRules`` and
``old_session`` below are 0.3.0's code, copied verbatim (its Python loop, which its compiled loop
equalled bit for bit). Every game is played under 0.3's kinematics: the students' scripts of
``class_speed.py`` (seed 10 for the first 2,000 as in a class, the game's own number after), random
scripts of taps, holds, chords and resets at random seeds up to 2^63 - 1, and the model and naive
bots alternately (seeds 0 on, their keys chosen under 0.3's hand as they were then); each recorded
timeline is replayed under 0.4's, as ``Replay.verify`` would replay a 0.3 replay now. Printed: how many
games have the same result (score, hits, resets, steps), the same hit times and the same final state,
bit for bit, and the last target's position to the bit. Exit status 1 if any result differs.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from class_speed import student_timeline

from armgame.errors import UserError
from armgame.game.bots import Autopilot, make_bot
from armgame.game.rules import MAX_TRIES, GameConfig, GameRules, Target
from armgame.game.session import GameSession, InputEvent

CLASS_SEED = 10


class OldTarget(Target):
    def contains(self, x: float, y: float) -> bool:  # 0.3.0's
        return (x - self.x) ** 2 + (y - self.y) ** 2 <= self.radius * self.radius


class OldRules(GameRules):
    """0.3.0's GameRules: the C library's hand, ``math.dist``."""

    def _hand(self, q1: float, q2: float) -> tuple[float, float]:
        p = self.config.arm
        return (p.l1 * math.cos(q1) + p.l2 * math.cos(q1 + q2), p.l1 * math.sin(q1) + p.l2 * math.sin(q1 + q2))

    def _draw_target(self, hand: tuple[float, float]) -> Target:
        c = self.config
        xmin, xmax, ymin, ymax = c.view
        r = c.target_radius
        best, best_distance = None, -1.0
        for tries in range(1, MAX_TRIES + 1):
            q1 = math.radians(self._rng.uniform(*c.target_shoulder_range))
            q2 = math.radians(self._rng.uniform(*c.target_elbow_range))
            x, y = self._hand(q1, q2)
            if not (xmin + r <= x <= xmax - r and ymin + r <= y <= ymax - r):
                continue
            distance = math.dist((x, y), hand)
            if distance > 3.0 * r:
                self.tries += tries
                return OldTarget(x, y, r)
            if distance > best_distance:
                best, best_distance = OldTarget(x, y, r), distance
        self.tries += MAX_TRIES
        if best is None:
            raise UserError("no target fits on screen with these settings (target radius or ranges too large)")
        return best


class OldSession(GameSession):
    """0.3.0's GameSession: its Python loop's hand and hit test."""

    def _advance(self, n: int) -> int:
        n = min(n, self.total_steps - self.steps)
        if n <= 0:
            return 0
        step = self._physics_step
        dt = self.config.dt
        arm = self.config.arm
        l1, l2 = arm.l1, arm.l2
        cos, sin = math.cos, math.sin
        rules = self.rules
        target = rules.target
        tx, ty, rr = target.x, target.y, target.radius * target.radius
        muscles = self.muscles
        a0, a1, a2, a3 = muscles.activation
        g0, g1, g2, g3 = muscles.goal
        r0, r1, r2, r3 = muscles.rate
        (s0, e0), (s1, e1), (s2, e2), (s3, e3) = muscles.moments
        q1, q2, w1, w2 = self.state
        previous = self.state
        start = self.steps
        for k in range(n):
            t1 = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3
            t2 = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3
            a0 += (g0 - a0) * r0
            a1 += (g1 - a1) * r1
            a2 += (g2 - a2) * r2
            a3 += (g3 - a3) * r3
            previous = (q1, q2, w1, w2)
            q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
            s12 = q1 + q2
            hx = l1 * cos(q1) + l2 * cos(s12)
            hy = l1 * sin(q1) + l2 * sin(s12)
            if (hx - tx) ** 2 + (hy - ty) ** 2 <= rr:
                rules.hand_moved(hx, hy, (start + k + 1) * dt)
                target = rules.target
                tx, ty, rr = target.x, target.y, target.radius * target.radius
        muscles.activation = [a0, a1, a2, a3]
        self.steps = start + n
        self.state = (q1, q2, w1, w2)
        self.previous_state = previous
        return n


def old_session(config: GameConfig) -> GameSession:
    return OldSession(config, compiled=False, rules=OldRules(config))


def random_script(rng: random.Random, total_steps: int) -> list[InputEvent]:
    """Taps, long holds, chords, repeats, resets and tab at random steps, step 0 and the last included."""
    events = []
    for _ in range(rng.randint(0, 60)):
        step = rng.choice((0, total_steps - 1, total_steps, rng.randrange(total_steps)))
        key = rng.choice("dfjkdfjk") if rng.random() < 0.9 else rng.choice(("space", "tab", "x"))
        events.append(InputEvent(step, key, rng.choice(("down", "down", "up"))))
        if rng.random() < 0.5 and key in "dfjk":  # a tap or a hold, released later
            events.append(InputEvent(min(total_steps, step + rng.choice((1, 5, 40, 400))), key, "up"))
    return sorted(events, key=lambda e: e.step)


def games(students: int, scripts: int, bots: int):
    for i in range(students):
        config = GameConfig(seed=CLASS_SEED if i < 2000 else i)
        yield "student", i, config, student_timeline(random.Random(i), config.dt, 60.0)
    for i in range(scripts):
        rng = random.Random(10_000 + i)
        seed = rng.choice((rng.randrange(1000), rng.randrange(2**63), 2**63 - 1 - rng.randrange(1000)))
        config = GameConfig(seed=seed, time_limit=rng.choice((10.0, 30.0, 60.0)),
                            target_radius=rng.choice((0.05, 0.05, 0.1, 0.2)))
        yield "script", i, config, random_script(rng, config.total_steps)
    for i in range(bots):
        yield "bot", i, GameConfig(seed=i), None


def outcomes(students: int, scripts: int, bots: int) -> dict[str, object]:
    count = same = same_all = same_target = hits = 0
    differ = []
    for kind, i, config, timeline in games(students, scripts, bots):
        old = old_session(config)
        if timeline is None:
            Autopilot(old, make_bot(("model", "naive")[i % 2])).play()
            timeline = list(old.timeline)
            then = old.result()
        else:
            then = old.play(timeline)
        new = GameSession(config)
        now = new.play(timeline)
        count += 1
        hits += then.hits
        if then == now:
            same += 1
            same_all += old.rules.board.hit_times == new.rules.board.hit_times and old.state == new.state
            a, b = old.rules.target, new.rules.target
            same_target += (a.x, a.y, a.radius) == (b.x, b.y, b.radius)
        else:
            differ.append(f"{kind} {i}: {then} then, {now} now")
    return {"games": count, "hits": hits, "same_result": same, "same_hit_times_and_state": same_all,
            "same_final_target_bits": same_target,
            "differ": differ[:10]}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=2000, help="students' scripts (default 2000)")
    parser.add_argument("--scripts", type=int, default=1000, help="random scripts (default 1000)")
    parser.add_argument("--bots", type=int, default=300, help="bots' games (default 300)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    if not all(0 <= n <= 100_000 for n in (args.students, args.scripts, args.bots)):
        parser.error("each count must be from 0 to 100000")
    start = time.perf_counter()
    report = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
                         f"Python {platform.python_version()}",
              "outcomes": outcomes(args.students, args.scripts, args.bots)}
    report["seconds"] = round(time.perf_counter() - start, 1)
    found = report["outcomes"]
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print(f"{report['machine']}; {report['seconds']} s")
        print(f"{found['same_result']:,} of {found['games']:,} games ({found['hits']:,} hits) played with 0.3's "
              f"kinematics have the same result with 0.4's; {found['same_hit_times_and_state']:,} the same "
              f"hit times and final state, bit for bit; {found['same_final_target_bits']:,} the same last target "
              f"to the bit (the two sines differ by an ulp or so)")
        for line in found["differ"]:
            print("  differs:", line)
    return 0 if found["same_result"] == found["games"] else 1


if __name__ == "__main__":
    sys.exit(main())
