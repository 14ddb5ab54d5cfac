"""What every armgame env shares: a session driven by key or muscle-level actions, drawn by ``armgame.ui``.

The Reach envs (the game) and the CenterOut envs (the lab's task) differ in their session, spaces and
reward; how an action reaches the session (the same key events a player's keys make, or muscle
levels) and how frames are made (pygame imported on the first frame only) are written once here.
Above it, each family's versions share a base of their own (``reach.ReachBaseEnv``,
``center_out.CenterOutBaseEnv``) and are siblings over it: no version subclasses another.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from ..game.session import DOWN, RESET_KEY, UP, GameSession
from .errors import EnvArgumentError
from .features import muscle_levels

__all__ = ["EnvArgumentError", "SessionEnv"]  # EnvArgumentError's old home: env.errors holds it

class SessionEnv(gym.Env):
    """A Gymnasium env over one armgame session (``self.session``, None before ``reset``).

    Subclasses set ``family`` (the id's stem, e.g. ``"Reach"``), ``continuous``, ``render_mode``,
    ``render_size`` and ``_view = None``, and give ``_new_view`` (which imports pygame).
    """

    # Gymnasium's own annotation; each env gives itself the render_fps of its decision step.
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 50}  # noqa: RUF012
    family = "armgame"
    version = 0
    continuous = False
    session: GameSession | None = None

    @property
    def env_name(self) -> str:
        """The registered id's name, for messages: "Reach-v0", "CenterOutContinuous-v0", ..."""
        return f"{self.family}{'Continuous' if self.continuous else ''}-v{self.version}"

    def _check_render_mode(self, render_mode: str | None) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise EnvArgumentError(f"render_mode must be one of {self.metadata['render_modes']} or None, "
                                   f"got {render_mode!r}")

    # ---------------------------------------------------------------- an episode's edges
    def _first_view(self) -> tuple[np.ndarray, dict]:
        """What ``reset`` returns once the episode has begun: its first frame drawn in ``"human"`` mode, then its
        first observation and info (each version's ``_observation`` and ``_info``)."""
        if self.render_mode == "human":
            self.render()
        return self._observation(), self._info()  # type: ignore[attr-defined]

    def _session_begun(self) -> GameSession:
        """The session ``step`` acts on; Gymnasium's ResetNeeded before the first ``reset``."""
        session = self.session
        if session is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        return session

    # ---------------------------------------------------------------- actions
    def _press_keys(self, action: Any, n: int) -> None:
        """Hold the four muscle keys as the action says (a fifth entry presses the reset key)."""
        pressed = np.asarray(action).tolist()
        if not isinstance(pressed, list) or len(pressed) != n or not all(p in (0, 1) for p in pressed):
            raise ValueError(f"a {self.env_name} action is {n} zeros or ones (keys held), got {action!r}")
        session = self.session
        assert session is not None
        held, keys = session.held, session.muscles.keys
        for i in range(4):
            down = pressed[i] == 1
            if down != held[i]:
                session.key_event(keys[i], DOWN if down else UP)
        if n == 5 and pressed[4] == 1:
            session.key_event(RESET_KEY, DOWN)

    def _set_levels(self, action: Any, n: int) -> None:
        """Drive the four muscles toward the action's levels (a fifth entry >= 0.5 presses reset).

        v1's actions are centred: ``a`` in [-1, 1] is the level ``(a + 1) / 2``."""
        levels = np.asarray(action, dtype=np.float64)
        if levels.shape != (n,) or not np.isfinite(levels).all():
            span = "[-1, 1]" if self.version else "[0, 1]"
            raise ValueError(f"a {self.env_name} action is {n} finite numbers in {span}, got {action!r}")
        levels = muscle_levels(levels, centred=self.version > 0)
        session = self.session
        assert session is not None
        session.set_muscle_levels(levels[:4].tolist())
        if n == 5 and levels[4] >= 0.5:
            session.key_event(RESET_KEY, DOWN)

    # ---------------------------------------------------------------- frames
    def _new_view(self) -> Any:
        raise NotImplementedError

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gym.logger.warn("render() needs a render_mode: make the env with render_mode='rgb_array' or 'human'")
            return None
        if self.session is None:
            raise gym.error.ResetNeeded("call reset() before render()")
        if self._view is None:
            self._view = self._new_view()
        return self._view.frame(self.session)

    def close(self) -> None:
        if self._view is not None:
            self._view.close()
            self._view = None
