"""The game's sounds: optional, and never a reason for the game to stop.

The mixer is started only here, only by a window, and only if it opens: no audio device, no
driver, a missing or damaged file each leave the game silent, never failing. Headless runs never
import this module, so they never start the mixer. The sounds are the WAV files in ``assets/``
(made by ``assets/make_sounds.py``): the checkout's own, or, for an installed wheel, the copy
pyproject.toml's data-files put under ``<prefix>/share/armgame/assets``; where neither is there
the game is simply silent.
"""

from __future__ import annotations

import contextlib
import os
import sys
from pathlib import Path

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
import pygame

from .display import held_stderr

SOUND_NAMES = ("hit", "reset", "tick", "go", "end")
#: Where the sounds may be, in order: beside the package in a checkout (an editable install), then
#: where a wheel's data files land.
ASSET_FOLDERS = (Path(__file__).resolve().parents[2] / "assets", Path(sys.prefix) / "share" / "armgame" / "assets")


def asset_folder(candidates: tuple[Path, ...] = ASSET_FOLDERS) -> Path:
    """The first folder holding the game's sounds (the first candidate if none does: silence)."""
    return next((folder for folder in candidates if (folder / f"{SOUND_NAMES[0]}.wav").is_file()), candidates[0])


class Sounds:
    """Plays the named sounds when the mixer is open and sound is on; otherwise does nothing."""

    def __init__(self, muted: bool = False, folder: Path | None = None) -> None:
        folder = asset_folder() if folder is None else folder
        self.muted = muted
        self.sounds: dict[str, pygame.mixer.Sound] = {}
        self.available = False
        try:
            # A short buffer: a hit's sound must come with the hit, not 100 ms after. ALSA prints its
            # complaints to stderr when there is no sound card: the game is silent, and says nothing.
            pygame.mixer.pre_init(22050, -16, 1, 512)
            with held_stderr():  # what ALSA says is held back, and dropped
                pygame.mixer.init()
        except (pygame.error, NotImplementedError):
            return
        for name in SOUND_NAMES:
            path = folder / f"{name}.wav"
            try:
                if path.is_file():
                    self.sounds[name] = pygame.mixer.Sound(str(path))
            except (pygame.error, OSError):
                continue
        self.available = bool(self.sounds)

    def play(self, name: str) -> None:
        if self.muted:
            return
        sound = self.sounds.get(name)
        if sound is not None:
            with contextlib.suppress(pygame.error):
                sound.play()

    def toggle(self) -> bool:
        self.muted = not self.muted
        return self.muted

    def close(self) -> None:
        if pygame.mixer.get_init():
            pygame.mixer.quit()
