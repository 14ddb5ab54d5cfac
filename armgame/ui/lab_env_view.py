"""Frames of a lab run for ``armgame/CenterOut-v0``'s render modes: the lab window's view, as an image or a window.

``armgame.env.center_out`` imports this module on its first frame only, so an env that never renders
never imports pygame; as for the game's envs (``env_view``), the mixer is never started.
"""

from __future__ import annotations

import numpy as np

from ..lab.session import LabSession
from .env_view import EnvView
from .lab_window import LabRenderer


class LabEnvView(EnvView):
    """``EnvView`` drawing with the lab window's ``LabRenderer``: a cursor, home, the target, no arm."""

    def frame(self, session: LabSession) -> np.ndarray | None:  # type: ignore[override]
        if self._renderer is None:
            self._renderer = LabRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
            self._renderer.mode = ""  # an agent takes no keys: no help line
        return super().frame(session)
