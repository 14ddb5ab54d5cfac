"""Any game a Reach env played, as a replay ``armgame verify`` recomputes: ``replay_of(env)``.

A game of ``armgame/Reach-v0`` or ``Reach-v1`` with keys is the game itself, and its replay is the
game's (``Replay.from_session``), which the high-score table can read. Every other Reach game (a
continuous id's muscle levels; the suite's dwell, noise, delay, field or target size) gets the
``"reach-env"`` task section (``armgame.records.env_game``): the variant's rules and physics, the
levels commanded, the id, and whether a runaway stopped it. ``armgame verify`` replays it with all of
that and compares the score, hits, resets and steps.

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

from typing import Any

from ..errors import UserError
from ..records.env_game import EnvGameTask, register
from ..records.replay import Replay, now_iso
from .errors import EnvArgumentError


class NotRecordableError(UserError):
    """This env's game cannot be written as a replay (no game yet, or more commands than a replay holds)."""


def replay_of(env: Any, driver: str = "program", player: str | None = None, driven: str = "script") -> Replay:
    """The replay of the game ``env`` (a Reach env, v0 or v1, any of the suite's Reach ids) is playing or played.

    ``driver``: what played it (``"ppo"``, ``"model bot"``); ``driven``: ``"script"`` or ``"bot"``. A plain
    key game's replay is the game's own; any other carries the ``"reach-env"`` section. Registers the
    section's reader, so the replay verifies in this process as it does in ``armgame verify``."""
    base = env.unwrapped
    if getattr(base, "family", None) != "Reach":
        raise EnvArgumentError("replay_of records armgame's Reach envs (Reach-v0, Reach-v1 and the suite's Reach ids); "
                               "a CenterOut episode is a lab run: not recorded here yet")
    session = base.session
    if session is None:
        raise NotRecordableError("the env has no game yet: reset() it and play before recording")
    if session.level_events_overflow:
        raise NotRecordableError(f"this game commanded its muscles more often than a replay holds "
                                 f"({len(session.level_events):,} commands)")
    settings = base.settings
    version = settings.version
    variant = base.game_variant if version else None
    stopped = getattr(base, "_stopped", None) is not None
    levels = tuple(session.level_events)
    register()  # the section's reader, for verify() here
    if not levels and not stopped and (variant is None or variant.plain):
        return Replay.from_session(session, driven, driver, player)
    from ..game.variant import GameVariant

    spec = getattr(env, "spec", None) or getattr(base, "spec", None)
    task = EnvGameTask(variant or GameVariant(decision_steps=settings.decision_steps), levels, stopped,
                       None if spec is None else spec.id,
                       base.variant.observation_delay if version else 0)
    return Replay(session.config, tuple(session.timeline), session.result(), driven, driver, player, now_iso(),
                  task=task)
