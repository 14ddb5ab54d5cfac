"""The task section of a lab replay: the protocol a run played and the trials it produced.

A lab run is recorded as any game is (``armgame.records.replay``: its ``GameConfig``, input
timeline and result), plus this section, which this module reads and writes itself: records, a
lower layer, knows no lab, and reads the section through the reader this module registers with it
when imported (``register_task``). Verifying replays the timeline on a fresh
``LabSession`` of the same protocol and compares the result, every trial (target, go-cue
step, end step, hit) and a SHA-256 of every trial's hand path (its floats' bytes): a timeline
changed by one key one step is caught even when it ends the same trials at the same steps, so a
replay that verifies is, bit for bit, the data ``armgame analyze`` measures.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import UserError
from ..game.bots import MotorNoise
from ..game.rules import GameConfig
from ..game.session import GameResult, InputEvent
from ..records.replay import register_task, same_outcome
from ..valid import HEX64, INT64_MAX, check_int, check_keys, check_str
from .protocol import Protocol
from .protocol_file import protocol_as_dict, protocol_from_dict
from .session import LAB_SCENE, SINES, LabSession

TASK_KIND = "centre-out"

Trial = tuple[int, int, int, bool]


@dataclass(frozen=True)
class LabTask:
    protocol: Protocol
    #: Each finished trial as (target, go_step, end_step, hit).
    trials: tuple[Trial, ...]
    #: SHA-256 (hex) of the shown hand's path of every trial, in order.
    paths_sha256: str
    #: The bot's motor noise, if it had any: what it was, for the reader (the keys carry its effect, so
    #: verifying replays the timeline and draws nothing).
    motor_noise: MotorNoise | None = None

    @classmethod
    def of(cls, session: LabSession, motor_noise: MotorNoise | None = None) -> LabTask:
        return cls(session.protocol, tuple((t, g, e, h) for t, g, e, h in session.trial_records()),  # type: ignore[misc]
                   paths_digest(session), motor_noise, trial_fields(session), session.sine)

    #: A protocol with mixed blocks (issue 41): each finished trial's perturbation as it ran (``Perturbation.label``),
    #: for the reader and checked by verify; None otherwise (and absent from the file).
    fields: tuple[str, ...] | None = None
    #: Which sine the run's hand took (``session.SINES``): written only when it is the arm's own (the browser's lab
    #: runs), so a replay without the key is one of the C library's, as every run recorded before.
    sine: str = "library"

    def as_dict(self) -> dict[str, object]:
        noise = {} if self.motor_noise is None else {"motor_noise": self.motor_noise.as_dict()}
        fields = {} if self.fields is None else {"fields": list(self.fields)}
        sine = {} if self.sine == "library" else {"sine": self.sine}
        return {"kind": TASK_KIND, "protocol": protocol_as_dict(self.protocol),
                "trials": [list(t) for t in self.trials], "paths_sha256": self.paths_sha256, **noise, **fields,
                **sine}

    @classmethod
    def from_dict(cls, data: object, config: GameConfig, last_step: int) -> LabTask:
        """Rebuild and check a task section; raises ValueError naming the bad field."""
        d = check_keys("task", data, {"kind", "protocol", "trials", "paths_sha256"},
                       frozenset({"motor_noise", "fields", "sine"}))
        kind = check_str("task.kind", d["kind"], 40)
        if kind != TASK_KIND:
            raise ValueError(f"task.kind must be {TASK_KIND!r}, got {kind!r}")
        if config.scene != LAB_SCENE:
            raise ValueError(f"a replay with a task must have scene {LAB_SCENE!r}, got {config.scene!r}")
        try:
            protocol = protocol_from_dict(d["protocol"], "task.protocol", recorded=True)
        except ValueError as exc:
            raise ValueError(f"task.protocol: {exc}") from None
        trials_data = d["trials"]
        if not isinstance(trials_data, list) or len(trials_data) > protocol.trials:
            raise ValueError(f"task.trials must be a list of at most {protocol.trials} trials")
        trials = []
        for i, item in enumerate(trials_data):
            where = f"task.trials[{i}]"
            if not isinstance(item, list) or len(item) != 4 or not isinstance(item[3], bool):
                raise ValueError(f"{where} must be [target, go_step, end_step, hit]")
            target = check_int(f"{where} target", item[0], 0, protocol.targets - 1)
            go = check_int(f"{where} go_step", item[1], 0, last_step)
            end = check_int(f"{where} end_step", item[2], go, last_step)
            trials.append((target, go, end, item[3]))
        digest = check_str("task.paths_sha256", d["paths_sha256"], 64)
        if not HEX64.fullmatch(digest):
            raise ValueError("task.paths_sha256 must be 64 hexadecimal digits")
        fields = None
        if "fields" in d:
            if not isinstance(d["fields"], list) or len(d["fields"]) != len(trials):
                raise ValueError("task.fields must be a list of one perturbation per trial")
            fields = tuple(check_str(f"task.fields[{i}]", v, 120) for i, v in enumerate(d["fields"]))
        sine = check_str("task.sine", d["sine"], 20) if "sine" in d else "library"
        if sine not in SINES:
            raise ValueError(f"task.sine must be one of {', '.join(SINES)}, got {sine!r}")
        return cls(protocol, tuple(trials), digest, _motor_noise(d["motor_noise"]) if "motor_noise" in d else None,
                   fields, sine)

    def new_session(self, config: GameConfig) -> LabSession:
        """A fresh session of this task, at its start (for a window to replay the timeline into)."""
        return LabSession(config, self.protocol, sine=self.sine)

    def session(self, config: GameConfig, timeline: Sequence[InputEvent], steps: int) -> LabSession:
        """The run re-simulated from its timeline: the session, with every trial's hand path."""
        session = self.new_session(config)
        session.play(timeline, steps)
        return session

    def verify(self, config: GameConfig, timeline: Sequence[InputEvent],
               result: GameResult) -> tuple[bool, GameResult, LabSession]:
        session = self.session(config, timeline, result.steps)
        recomputed = session.result()
        same_trials = tuple(tuple(t) for t in session.trial_records()) == self.trials
        same_paths = paths_digest(session) == self.paths_sha256
        same_fields = self.fields is None or trial_fields(session) == self.fields
        return same_outcome(recomputed, result) and same_trials and same_paths and same_fields, recomputed, session


def _motor_noise(data: object) -> MotorNoise:
    d = check_keys("task.motor_noise", data, {"level", "correlation_time_s", "seed"})
    level, time, seed = d["level"], d["correlation_time_s"], d["seed"]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (level, time)):
        raise ValueError("task.motor_noise: level and correlation_time_s must be numbers")
    try:
        return MotorNoise(float(level), check_int("task.motor_noise.seed", seed, 0, INT64_MAX), float(time))
    except UserError as exc:
        raise ValueError(f"task.motor_noise: {exc}") from None


def motor_noise_words(noise: MotorNoise | None) -> str:
    """A run's motor noise in words, as the lab's and analyze's output state it."""
    if noise is None:
        return "no motor noise"
    return (f"motor noise {noise.level:g} (the s.d. of the command as a fraction of it, correlated over "
            f"{1000 * noise.correlation_time:g} ms, seed {noise.seed})")


def trial_fields(session: LabSession) -> tuple[str, ...] | None:
    """Each finished trial's perturbation as it ran, for a protocol with mixed blocks; None for any other."""
    if not any(b.mix for b in session.protocol.blocks):
        return None
    return tuple("channel" if o.plan.channel else o.plan.active.label() for o in session.outcomes)


def paths_digest(session: LabSession) -> str:
    h = hashlib.sha256()
    for o in session.outcomes:
        h.update(np.asarray(o.xs, dtype="<f8").tobytes())
        h.update(np.asarray(o.ys, dtype="<f8").tobytes())
    return h.hexdigest()


def register() -> None:
    """Let records read replays with a centre-out task section (done on import; again costs nothing)."""
    register_task(TASK_KIND, LabTask.from_dict)


register()
