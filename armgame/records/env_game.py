"""The replay of a game a Gymnasium env played: its variant and its continuous actions, in a task section.

A Reach env's game is the game of its seed plus what the env adds (``armgame.game.variant.GameVariant``:
a dwell, motor noise drawn each decision, a force field at the hand, the speed guard) and, for the
continuous ids, the muscle levels it commanded (``GameSession.level_events``), which the key timeline does
not hold. Before this section a replay of such a game held only the key timeline, and ``armgame verify``
replayed the plain game: 19 hits recorded, 0 replayed (issue 40). The section, ``"kind": "reach-env"``,
carries all of it, versioned (``"version": 1``); a replay without it is the game itself and verifies as
before. ``armgame.env.record.replay_of`` writes it; the commands that verify replays register its reader
(``register``), records' own readers never need it (the table ranks no replay with a task section).

    {"kind": "reach-env", "version": 1, "env_id": "armgame/ReachHard-v1", "decision_steps": 5,
     "hold_steps": 50, "motor_noise": 0.3, "field": {"kind": "curl", "b": 2.0}, "speed_limit": 68.9,
     "observation_delay": 5, "levels": [[0, 1.0, 0.0, 0.5, 0.0], ...], "stopped": false}

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
SECTION_VERSION = 1
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
        return {"kind": TASK_KIND, "version": SECTION_VERSION, "env_id": self.env_id,
                "decision_steps": v.decision_steps, "hold_steps": v.hold_steps, "motor_noise": v.motor_noise,
                "field": field, "speed_limit": None if math.isinf(v.speed_limit) else v.speed_limit,
                "observation_delay": self.observation_delay,
                "levels": [[e.step, *e.levels] for e in self.levels], "stopped": self.stopped}

    @classmethod
    def from_dict(cls, data: object, config: GameConfig, last_step: int) -> EnvGameTask:
        """Rebuild and check a section; raises ValueError naming the bad field."""
        d = check_keys("task", data, {"kind", "version", "env_id", "decision_steps", "hold_steps", "motor_noise",
                                      "field", "speed_limit", "observation_delay", "levels", "stopped"})
        env_id = section_head(d, TASK_KIND, SECTION_VERSION, "a Reach env's")
        decision_steps = check_int("task.decision_steps", d["decision_steps"], 1, MAX_DECISION_STEPS)
        hold_steps = check_int("task.hold_steps", d["hold_steps"], 0, MAX_HOLD_STEPS)
        noise = check_float("task.motor_noise", d["motor_noise"], 0.0, 1.0)
        field, parameter = _field(d["field"])
        limit = math.inf if d["speed_limit"] is None else check_float("task.speed_limit", d["speed_limit"], 0.0,
                                                                        MAX_SPEED_LIMIT, low_open=True)
        delay = check_int("task.observation_delay", d["observation_delay"], 0, 10**6)
        stopped = check_bool("task.stopped", d["stopped"])
        levels = levels_from_list(d["levels"], last_step)
        try:
            variant = GameVariant(hold_steps, noise, decision_steps, field, parameter, limit)
        except UserError as exc:
            raise ValueError(f"task: {exc}") from None
        return cls(variant, levels, stopped, env_id, delay)

    def session(self, config: GameConfig, timeline: Sequence[InputEvent], steps: int) -> GameSession:
        """The game replayed from its timeline and levels to ``steps`` (and its runaway, if it stopped at one)."""
        return VariantPlay(config, self.variant).play(timeline, self.levels, steps, self.stopped)

    def verify(self, config: GameConfig, timeline: Sequence[InputEvent], result: GameResult,
               max_work: int | None = MAX_VERIFY_WORK) -> tuple[bool, GameResult, GameSession]:
        """Replay and compare. Stops early, as ``Replay.verify`` does, once the game has scored more hits or
        resets than recorded, or spent ``max_work`` (steps, and ``TRY_WORK`` a target posture tried)."""

        def going_on(session: GameSession) -> bool:
            board = session.rules.board
            if board.hits > result.hits or board.resets > result.resets:
                return False
            return max_work is None or session.steps + TRY_WORK * session.rules.tries <= max_work

        session = VariantPlay(config, self.variant).play(timeline, self.levels, result.steps, self.stopped, going_on)
        recomputed = session.result()
        return same_outcome(recomputed, result), recomputed, session


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
