"""What both native vector envs share: Gymnasium's reset masks and the three autoreset modes, kept once.

``SyncVectorEnv`` is the reference: a native vector env must give what N single envs under it give,
so a mask is checked as it checks one, and ``AutoresetBook`` decides, game by game, when an ended
game starts again (``NEXT_STEP``: on the step after its end, which returns its first observation
and ignores its action; ``SAME_STEP``: in the step that ended it; ``DISABLED``: only when the
caller resets it with a mask).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.error import ResetNeeded
from gymnasium.vector import AutoresetMode

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
