"""What the vector envs share: Gymnasium's reset masks and the three autoreset modes, kept once, and
``SingleEnvsVectorEnv``, the vector env of single envs where no batch is faster.

``SyncVectorEnv`` is the reference: a native vector env must give what N single envs under it give,
so a mask is checked as it checks one, and ``AutoresetBook`` decides, game by game, when an ended
game starts again (``NEXT_STEP``: on the step after its end, which returns its first observation
and ignores its action; ``SAME_STEP``: in the step that ended it; ``DISABLED``: only when the
caller resets it with a mask).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from gymnasium.error import ResetNeeded
from gymnasium.vector import AutoresetMode, SyncVectorEnv

from .base import EnvArgumentError


def check_reset_mask(mask: Any, n: int, have_games: bool) -> np.ndarray | None:
    """``options["reset_mask"]``: None, or a boolean array of shape (n,) with a true entry."""
    if mask is None:
        return None
    if not isinstance(mask, np.ndarray) or mask.dtype != np.bool_ or mask.shape != (n,):
        raise EnvArgumentError(f"options['reset_mask'] must be a numpy array of {n} booleans, got "
                               f"{type(mask).__name__} {getattr(mask, 'dtype', '')} {getattr(mask, 'shape', '')}")
    if not mask.any():
        raise EnvArgumentError("options['reset_mask'] must mark at least one env to reset")
    if not have_games:
        raise EnvArgumentError("the first reset starts every env: call reset() without a reset_mask first")
    return mask.copy()


class AutoresetBook:
    """Which games ended, and when each starts again, under one of Gymnasium's autoreset modes."""

    def __init__(self, n: int, mode: str | AutoresetMode) -> None:
        try:
            self.mode = mode if isinstance(mode, AutoresetMode) else AutoresetMode(mode)
        except ValueError:
            raise EnvArgumentError(f"autoreset_mode must be one of {', '.join(m.value for m in AutoresetMode)}, "
                                   f"got {mode!r}") from None
        #: Games that ended at the last step and were not reset since.
        self.ended = np.zeros(n, dtype=bool)

    @property
    def restart_now(self) -> np.ndarray:
        """Games the coming step restarts instead of stepping (next-step mode only)."""
        if self.mode is AutoresetMode.NEXT_STEP:
            return self.ended
        return np.zeros_like(self.ended)

    def before_step(self) -> None:
        if self.mode is AutoresetMode.DISABLED and self.ended.any():
            games = ", ".join(map(str, np.flatnonzero(self.ended)[:5]))
            raise ResetNeeded(f"env(s) {games} ended and autoreset is disabled: "
                              "reset them with reset(options={'reset_mask': mask}) before the next step")

    def after_step(self, done: np.ndarray) -> None:
        self.ended = done.copy() if self.mode is not AutoresetMode.SAME_STEP else np.zeros_like(done)

    def reset(self, games: np.ndarray) -> None:
        self.ended &= ~games


class SingleEnvsVectorEnv(SyncVectorEnv):
    """``num_envs`` single envs of one class and arguments as one vector env: Gymnasium's ``SyncVectorEnv``
    (reset masks, the three autoreset modes, ``render()`` a tuple of frames), made from the env's arguments
    so that a vector entry point can return it. The first env checks the arguments (one line for a bad
    one) before the others are made."""

    MAX_ENVS = 4096

    def __init__(self, env_class: Callable[..., Any], num_envs: int = 1, *,
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP, **kwargs: Any) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) \
                or not 1 <= num_envs <= self.MAX_ENVS:
            raise EnvArgumentError(f"num_envs must be a whole number from 1 to {self.MAX_ENVS}, got {num_envs!r}")
        mode = AutoresetBook(1, autoreset_mode).mode  # checked in one line
        first = env_class(**kwargs)
        envs = iter([first] + [env_class(**kwargs) for _ in range(int(num_envs) - 1)])
        super().__init__([lambda: next(envs) for _ in range(int(num_envs))], autoreset_mode=mode)
