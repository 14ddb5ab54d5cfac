"""Any game an env played, as a replay ``armgame verify`` recomputes: ``replay_of(env)``.

A game of ``armgame/Reach-v0`` or ``Reach-v1`` with keys is the game itself, and its replay is the
game's (``Replay.from_session``), which the high-score table can read. Every other Reach game (a
continuous id's muscle levels; the suite's dwell, noise, delay, field or target size) gets the
``"reach-env"`` task section (``armgame.records.env_game``): the variant's rules and physics, the
levels commanded, the id, whether a runaway stopped it, and the step of every hit. ``armgame verify`` replays
it with all of that and compares the score, hits, resets, steps and each hit's step.

A CenterOut episode (v0, v1, CenterOutHold, keys or levels) is a lab run from its start to the episode's
end: its replay carries ``"centre-out-env"`` (``CenterOutEnvTask``): the lab's own section (the
protocol, every trial, the hand paths' digest), the go cue's rule (``hold_at_home``) and the levels.
Its reader is here, above the lab, so verifying one needs Gymnasium (``armgame verify`` says so in one
line where it is missing); an episode that continued a run (``continue_run=True``) replays the run
from its first trial.

>>> import gymnasium as gym
>>> import armgame.env
>>> from armgame.env.policies import BotPolicy
>>> env = gym.make("armgame/ReachHoldContinuous-v1", time_limit=3.0)
>>> policy = BotPolicy("model", env)
>>> obs, info = env.reset(seed=10)
>>> done = False
>>> while not done:
...     obs, reward, terminated, truncated, info = env.step(policy(obs))
...     done = terminated or truncated
>>> replay = replay_of(env, driver="model bot")
>>> replay.task.as_dict()["kind"], replay.verify()[0], replay.result.hits == info["hits"]
('reach-env', True, True)
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import UserError
from ..game.rules import GameConfig
from ..game.session import GameResult, InputEvent, LevelEvent
from ..game.variant import play_inputs
from ..lab.record import LabTask, paths_digest, trial_fields
from ..lab.session import LabSession
from ..records.env_game import EnvGameTask, hit_steps, levels_from_list, register, section_head
from ..records.replay import Replay, now_iso, register_task, same_outcome
from ..valid import check_bool, check_keys
from .errors import EnvArgumentError

CENTRE_OUT_KIND = "centre-out-env"
CENTRE_OUT_VERSION = 1


class NotRecordableError(UserError):
    """This env's game cannot be written as a replay (no game yet, or more commands than a replay holds)."""


def replay_of(env: Any, driver: str = "program", player: str | None = None, driven: str = "script") -> Replay:
    """The replay of the game ``env`` (a Reach env, v0 or v1, any of the suite's Reach ids) is playing or played.

    ``driver``: what played it (``"ppo"``, ``"model bot"``); ``driven``: ``"script"`` or ``"bot"``. A plain
    key game's replay is the game's own; any other carries the ``"reach-env"`` section. Registers the
    section's reader, so the replay verifies in this process as it does in ``armgame verify``."""
    base = env.unwrapped
    family = getattr(base, "family", None)
    if family not in ("Reach", "CenterOut"):
        raise EnvArgumentError("replay_of records armgame's envs (the Reach and CenterOut ids)")
    session = base.session
    if session is None:
        raise NotRecordableError("the env has no game yet: reset() it and play before recording")
    if session.level_events_overflow:
        raise NotRecordableError(f"this game commanded its muscles more often than a replay holds "
                                 f"({len(session.level_events):,} commands)")
    spec = getattr(env, "spec", None) or getattr(base, "spec", None)
    env_id = None if spec is None else spec.id
    if family == "CenterOut":
        register_centre_out()
        task = CenterOutEnvTask(LabTask.of(session), session.hold_at_home, tuple(session.level_events), env_id)
        return Replay(session.config, tuple(session.timeline), session.result(), driven, driver, player, now_iso(),
                      task=task)
    settings = base.settings
    version = settings.version
    variant = base.game_variant if version else None
    stopped = getattr(base, "_stopped", None) is not None
    levels = tuple(session.level_events)
    register()  # the section's reader, for verify() here
    if not levels and not stopped and (variant is None or variant.plain):
        return Replay.from_session(session, driven, driver, player)
    from ..game.variant import GameVariant

    task = EnvGameTask(variant or GameVariant(decision_steps=settings.decision_steps), levels, stopped, env_id,
                       base.variant.observation_delay if version else 0, hit_steps(session))
    return Replay(session.config, tuple(session.timeline), session.result(), driven, driver, player, now_iso(),
                  task=task)


@dataclass(frozen=True)
class CenterOutEnvTask:
    """A CenterOut env's episode as a replay's task section: the lab's section, the go cue's rule and the levels."""

    lab: LabTask
    hold_at_home: bool = True
    levels: tuple[LevelEvent, ...] = ()
    env_id: str | None = None

    @property
    def protocol(self) -> Any:
        return self.lab.protocol

    @property
    def trials(self) -> tuple:
        return self.lab.trials

    def about(self) -> str:
        """The episode in words, for ``armgame verify``'s line."""
        rule = "go cue after a hold at home" if self.hold_at_home else "go cue after the delay"
        levels = f", {len(self.levels):,} muscle-level commands" if self.levels else ""
        return (f"{self.env_id or 'a CenterOut env'}, {self.lab.protocol.name}, {rule}, "
                f"{len(self.lab.trials)} trials{levels}")

    def as_dict(self) -> dict[str, object]:
        return {"kind": CENTRE_OUT_KIND, "version": CENTRE_OUT_VERSION, "env_id": self.env_id,
                "hold_at_home": self.hold_at_home, "levels": [[e.step, *e.levels] for e in self.levels],
                "lab": self.lab.as_dict()}

    @classmethod
    def from_dict(cls, data: object, config: GameConfig, last_step: int) -> CenterOutEnvTask:
        """Rebuild and check a section; raises ValueError naming the bad field."""
        d = check_keys("task", data, {"kind", "version", "env_id", "hold_at_home", "levels", "lab"})
        env_id = section_head(d, CENTRE_OUT_KIND, CENTRE_OUT_VERSION, "a CenterOut env's")
        hold_at_home = check_bool("task.hold_at_home", d["hold_at_home"])
        lab = LabTask.from_dict(d["lab"], config, last_step)
        return cls(lab, hold_at_home, levels_from_list(d["levels"], last_step), env_id)

    def new_session(self, config: GameConfig) -> LabSession:
        return LabSession(config, self.lab.protocol, hold_at_home=self.hold_at_home)

    def session(self, config: GameConfig, timeline: Sequence[InputEvent], steps: int) -> LabSession:
        """The episode's run replayed from its timeline and levels to ``steps``."""
        return play_inputs(self.new_session(config), timeline, self.levels, steps)  # type: ignore[return-value]

    def verify(self, config: GameConfig, timeline: Sequence[InputEvent],
               result: GameResult) -> tuple[bool, GameResult, LabSession]:
        """Replay and compare the result, every trial, the hand paths' digest and (a protocol with mixed blocks) each
        trial's perturbation, as ``LabTask.verify`` compares a lab run's."""
        session = self.session(config, timeline, result.steps)
        recomputed = session.result()
        same_trials = tuple(tuple(t) for t in session.trial_records()) == self.lab.trials
        same_paths = paths_digest(session) == self.lab.paths_sha256
        same_fields = self.lab.fields is None or trial_fields(session) == self.lab.fields
        return same_outcome(recomputed, result) and same_trials and same_paths and same_fields, recomputed, session


def register_centre_out() -> None:
    """Let records read a CenterOut env's section (``armgame verify`` does, through ``commands.read_env_games``)."""
    # The commands' reader may be registered first: it reads the same class, imported lazily.
    with contextlib.suppress(ValueError):
        register_task(CENTRE_OUT_KIND, CenterOutEnvTask.from_dict)
