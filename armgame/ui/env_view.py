"""Frames of a game for Gymnasium's render modes (``armgame.env``): an image array or a window.

The env imports this module on its first frame, so an env that never renders never imports
pygame. Only the display (for "human") and the font are started: never the mixer, which an
agent training by the thousand has no use for.
"""

from __future__ import annotations

import numpy as np
import pygame

from ..game.session import GameSession
from .render import GameRenderer

CAPTION = "armgame (Gymnasium)"


class EnvView:
    """Draws a session with the game's own ``GameRenderer``: off screen, or in a window paced to ``fps``."""

    def __init__(self, mode: str, size: tuple[int, int], fps: float) -> None:
        if mode not in ("rgb_array", "human"):
            raise ValueError(f"unknown render mode {mode!r}")
        self.mode = mode
        self.size = size
        self.fps = fps
        pygame.font.init()
        self._renderer: GameRenderer | None = None
        self._surface: pygame.Surface | None = None
        self._clock: pygame.time.Clock | None = None

    def frame(self, session: GameSession) -> np.ndarray | None:
        """Draws the session now: an (height, width, 3) uint8 array for "rgb_array", None for "human"."""
        if self._renderer is None:
            self._renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
        if self._surface is None:
            if self.mode == "human":
                pygame.display.init()
                pygame.display.set_caption(CAPTION)
                self._surface = pygame.display.set_mode(self.size)
                self._clock = pygame.time.Clock()
            else:
                self._surface = pygame.Surface(self.size)
        self._renderer.draw(self._surface, session)
        if self.mode == "rgb_array":
            return np.transpose(pygame.surfarray.array3d(self._surface), (1, 0, 2))
        pygame.event.pump()  # keeps the window responsive to the desktop; the env takes no keys
        pygame.display.flip()
        assert self._clock is not None
        self._clock.tick(self.fps)
        return None

    def close(self) -> None:
        if self.mode == "human" and self._surface is not None:
            pygame.display.quit()
        self._surface = None
