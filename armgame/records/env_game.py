"""The replay of a game a Gymnasium env played: its variant and its continuous actions, in a task section.

A Reach env's game is the game of its seed plus what the env adds (``armgame.game.variant.GameVariant``:
a dwell, motor noise drawn each decision, a force field at the hand, the speed guard) and, for the
continuous ids, the muscle levels it commanded (``GameSession.level_events``), which the key timeline does
not hold. Before this section a replay of such a game held only the key timeline, and ``armgame verify``
replayed the plain game: 19 hits recorded, 0 replayed (issue 40). The section, ``"kind": "reach-env"``,
carries all of it, versioned; a replay without it is the game itself and verifies as before.
``armgame.env.record.replay_of`` writes it; the commands that verify replays register its reader
(``register``), records' own readers never need it (the table ranks no replay with a task section).

    {"kind": "reach-env", "version": 2, "env_id": "armgame/ReachHard-v1", "decision_steps": 5,
     "hold_steps": 50, "motor_noise": 0.3, "field": {"kind": "curl", "b": 2.0}, "speed_limit": 68.9,
     "observation_delay": 5, "levels": [[0, 1.0, 0.0, 0.5, 0.0], ...], "stopped": false,
     "hit_steps": [412, 787, ...]}

``hit_steps`` (version 2, issue 52) is the physics step of every hit, which verification compares one by one: a
count can come out the same under another ruleset (a dwell edited from 50 steps to 1 scores its hits earlier), the
steps of the hits do not. Version 1 carried counts only, so a reader of it could not tell such an edit; this armgame
refuses it in one line. ``benchmarks/env_game_hit_steps.py`` moves a version-1 file one trusts (the repository's
committed games) to version 2: it replays each, keeps only those whose counts match, and writes the steps.

``env_id`` and ``observation_delay`` are what the agent played, for the reader: neither changes the game
(a delay changes only what the agent saw), so verification does not depend on them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import UserError
from ..game.rules import GameConfig
from ..game.session import GameResult, GameSession, InputEvent, LevelEvent
from ..game.variant import FIELD_KINDS, GameVariant, VariantPlay
from ..limits import MAX_EVENTS, MAX_VERIFY_WORK
from ..valid import check_bool, check_float, check_int, check_keys, check_str
from .replay import TRY_WORK, register_task, same_outcome

TASK_KIND = "reach-env"
SECTION_VERSION = 2
#: The version that recorded counts but not the hits' steps: read only by the migration (``legacy=True``).
COUNTS_ONLY_VERSION = 1
#: Bounds on what a section may claim (a reader refuses more before replaying anything).
MAX_HOLD_STEPS = 10_000
MAX_DECISION_STEPS = 1_000
MAX_FIELD = 1_000.0
MAX_SPEED_LIMIT = 1e6


def section_head(d: dict, kind: str, version: int, whose: str) -> str | None:
    """An env's task section's ``kind`` and ``version`` checked against the ones this armgame reads (``whose``
    section, for the message), and its ``env_id`` (None, or the id that played it)."""
    if d["kind"] != kind:
        raise ValueError(f"task.kind must be {kind!r}, got {d['kind']!r}")
    read = check_int("task.version", d["version"], 1, 10**6)
    if read != version:
        raise ValueError(f"task.version {read}: this armgame reads {whose} section of version {version}")
    return None if d["env_id"] is None else check_str("task.env_id", d["env_id"], 100)


@dataclass(frozen=True)
class EnvGameTask:
    """A Reach env's game beyond its key timeline: the variant, the level events, and whether a runaway ended it."""

    variant: GameVariant
    levels: tuple[LevelEvent, ...] = ()
    #: The game ended at a runaway in the decision after its last step (``GameVariant``'s guard).
    stopped: bool = False
    env_id: str | None = None
    observation_delay: int = 0
    #: The physics step of every hit, in order; None only for a version-1 section read by the migration.
    hit_steps: tuple[int, ...] | None = None

    def about(self) -> str:
        """The variant in words, for ``armgame verify``'s line."""
        v = self.variant
        parts = [self.env_id or "a Reach env"]
        if v.hold_steps:
            parts.append(f"dwell {v.hold_steps} steps")
        if v.motor_noise:
            parts.append(f"motor noise {v.motor_noise:g}")
        if v.field is not None:
            parts.append(f"{v.field} field")
        if self.levels:
            parts.append(f"{len(self.levels):,} muscle-level commands")
        if self.stopped:
            parts.append("stopped by a runaway")
        return ", ".join(parts)

    def as_dict(self) -> dict[str, object]:
        v = self.variant
        field: object = None
        if v.field == "curl":
            field = {"kind": "curl", "b": v.field_parameter}
        elif v.field == "viscous":
            field = {"kind": "viscous", "matrix": [list(row) for row in v.field_parameter]}  # type: ignore[union-attr]
        d: dict[str, object] = {
            "kind": TASK_KIND, "version": SECTION_VERSION if self.hit_steps is not None else COUNTS_ONLY_VERSION,
            "env_id": self.env_id, "decision_steps": v.decision_steps, "hold_steps": v.hold_steps,
            "motor_noise": v.motor_noise, "field": field,
            "speed_limit": None if math.isinf(v.speed_limit) else v.speed_limit,
            "observation_delay": self.observation_delay, "levels": [[e.step, *e.levels] for e in self.levels],
            "stopped": self.stopped}
        if self.hit_steps is not None:
            d["hit_steps"] = list(self.hit_steps)
        return d

    @classmethod
    def from_dict(cls, data: object, config: GameConfig, last_step: int, legacy: bool = False) -> EnvGameTask:
        """Rebuild and check a section; raises ValueError naming the bad field. ``legacy``: read a version-1
        section too (its ``hit_steps`` None), as the migration to version 2 does and nothing else."""
        fields = {"kind", "version", "env_id", "decision_steps", "hold_steps", "motor_noise", "field",
                  "speed_limit", "observation_delay", "levels", "stopped"}
        old = isinstance(data, dict) and data.get("version") == COUNTS_ONLY_VERSION and data.get("kind") == TASK_KIND
        if old and not legacy:
            raise ValueError(f"task.version {COUNTS_ONLY_VERSION}: a Reach env's section of version "
                             f"{COUNTS_ONLY_VERSION} records no hit steps, so a ruleset edited to the same count "
                             f"would pass; this armgame reads version {SECTION_VERSION} (record the game again, "
                             f"or move a file you trust with benchmarks/env_game_hit_steps.py)")
        d = check_keys("task", data, fields if old else fields | {"hit_steps"})
        env_id = section_head(d, TASK_KIND, COUNTS_ONLY_VERSION if old else SECTION_VERSION, "a Reach env's")
        decision_steps = check_int("task.decision_steps", d["decision_steps"], 1, MAX_DECISION_STEPS)
        hold_steps = check_int("task.hold_steps", d["hold_steps"], 0, MAX_HOLD_STEPS)
        noise = check_float("task.motor_noise", d["motor_noise"], 0.0, 1.0)
        field, parameter = _field(d["field"])
        limit = math.inf if d["speed_limit"] is None else check_float("task.speed_limit", d["speed_limit"], 0.0,
                                                                        MAX_SPEED_LIMIT, low_open=True)
        delay = check_int("task.observation_delay", d["observation_delay"], 0, 10**6)
        stopped = check_bool("task.stopped", d["stopped"])
        levels = levels_from_list(d["levels"], last_step)
        # A runaway's decision is played past the last step, and the hits it scored on the way count.
        hits = None if old else _hit_steps(d["hit_steps"], last_step + decision_steps * stopped)
        try:
            variant = GameVariant(hold_steps, noise, decision_steps, field, parameter, limit)
        except UserError as exc:
            raise ValueError(f"task: {exc}") from None
        return cls(variant, levels, stopped, env_id, delay, hits)

    def session(self, config: GameConfig, timeline: Sequence[InputEvent], steps: int) -> GameSession:
        """The game replayed from its timeline and levels to ``steps`` (and its runaway, if it stopped at one)."""
        return VariantPlay(config, self.variant).play(timeline, self.levels, steps, self.stopped)

    def verify(self, config: GameConfig, timeline: Sequence[InputEvent], result: GameResult,
               max_work: int | None = MAX_VERIFY_WORK) -> tuple[bool, GameResult, GameSession]:
        """Replay and compare the result and the step of every hit (a version-1 section, read by the migration:
        the result alone). Stops early, as ``Replay.verify`` does, once the game has scored more hits or
        resets than recorded, or spent ``max_work`` (steps, and ``TRY_WORK`` a target posture tried)."""

        def going_on(session: GameSession) -> bool:
            board = session.rules.board
            if board.hits > result.hits or board.resets > result.resets:
                return False
            return max_work is None or session.steps + TRY_WORK * session.rules.tries <= max_work

        session = VariantPlay(config, self.variant).play(timeline, self.levels, result.steps, self.stopped, going_on)
        recomputed = session.result()
        same_hits = self.hit_steps is None or hit_steps(session) == self.hit_steps
        return same_outcome(recomputed, result) and same_hits, recomputed, session

    def hit_difference(self, config: GameConfig, timeline: Sequence[InputEvent], result: GameResult) -> str | None:
        """Where the replayed hits part from the recorded steps, in words (``armgame verify``'s line when the counts
        agree but the steps do not), or None where they do not part."""
        if self.hit_steps is None:
            return None
        replayed = hit_steps(self.session(config, timeline, result.steps))
        for k, (recorded, got) in enumerate(zip(self.hit_steps, replayed, strict=False)):
            if recorded != got:
                return f"hit {k + 1} recorded at step {recorded:,}, replayed at step {got:,}"
        if len(replayed) != len(self.hit_steps):
            return f"{len(self.hit_steps):,} hit steps recorded, {len(replayed):,} hits replayed"
        return None


def hit_steps(session: GameSession) -> tuple[int, ...]:
    """The physics step of each of a game's hits (the rules keep their times: ``t = step * dt`` exactly)."""
    dt = session.config.dt
    return tuple(round(t / dt) for t in session.rules.board.hit_times)


def _hit_steps(data: object, last_step: int) -> tuple[int, ...]:
    if not isinstance(data, list):
        raise ValueError("task.hit_steps must be a list of physics steps")
    if len(data) > last_step:  # at most one hit a step
        raise ValueError(f"task.hit_steps has {len(data):,} steps, more than the game's {last_step:,}")
    steps, previous = [], 0
    for i, item in enumerate(data):
        previous = check_int(f"task.hit_steps[{i}]", item, previous + 1, last_step)
        steps.append(previous)
    return tuple(steps)


def _field(data: object) -> tuple[str | None, object]:
    if data is None:
        return None, None
    d = check_keys("task.field", data, {"kind"}, frozenset({"b", "matrix"}))
    kind = d["kind"]
    if kind not in FIELD_KINDS:
        raise ValueError(f"task.field.kind must be 'curl' or 'viscous', got {kind!r}")
    if kind == "curl":
        d = check_keys("task.field", data, {"kind", "b"})
        return "curl", check_float("task.field.b", d["b"], -MAX_FIELD, MAX_FIELD)
    d = check_keys("task.field", data, {"kind", "matrix"})
    rows = d["matrix"]
    if not (isinstance(rows, list) and len(rows) == 2 and all(isinstance(r, list) and len(r) == 2 for r in rows)):
        raise ValueError("task.field.matrix must be [[b11, b12], [b21, b22]]")
    return "viscous", tuple(tuple(check_float(f"task.field.matrix[{i}][{j}]", v, -MAX_FIELD, MAX_FIELD)
                                  for j, v in enumerate(row)) for i, row in enumerate(rows))


def levels_from_list(data: object, last_step: int) -> tuple[LevelEvent, ...]:
    """A section's ``"levels"``, checked: [step, four levels from 0 to 1], steps in order, within the game."""
    if not isinstance(data, list):
        raise ValueError("task.levels must be a list of [step, level, level, level, level]")
    if len(data) > MAX_EVENTS:
        raise ValueError(f"task.levels has {len(data)} commands, more than {MAX_EVENTS}")
    events, previous = [], 0
    for i, item in enumerate(data):
        where = f"task.levels[{i}]"
        if not isinstance(item, list) or len(item) != 5:
            raise ValueError(f"{where} must be [step, level, level, level, level]")
        step = check_int(f"{where} step", item[0], previous, last_step)
        levels = tuple(check_float(f"{where} level", v, 0.0, 1.0) for v in item[1:])
        events.append(LevelEvent(step, levels))
        previous = step
    return tuple(events)


def read(section: object, config: GameConfig, last_step: int) -> EnvGameTask:
    return EnvGameTask.from_dict(section, config, last_step)


def register() -> None:
    """Let records read replays with a Reach env's section (``armgame verify`` calls it; again costs nothing)."""
    register_task(TASK_KIND, read)
