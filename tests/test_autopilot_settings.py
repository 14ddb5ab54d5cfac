"""The autopilot demo's window takes the settings' palette and text scale, as every other window does."""

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pygame
import pytest

from armgame import cli
from armgame.ui.autopilot_window import AutopilotWindow
from armgame.ui.display import open_window
from armgame.ui.render import PALETTES


@pytest.fixture
def window_size():
    size = (1024, 768)
    open_window(size)
    yield size
    pygame.display.quit()


def test_the_palette_and_text_scale_reach_both_games_and_the_captions(window_size):
    plain = AutopilotWindow(10, 60.0, pygame.display.get_surface(), clock=lambda: 0.0)
    large = AutopilotWindow(10, 60.0, pygame.display.get_surface(), clock=lambda: 0.0, palette="high-contrast",
                            text_scale=1.5)
    assert large.palette is PALETTES["high-contrast"]
    assert all(g.renderer.palette is PALETTES["high-contrast"] and g.renderer.text_scale == 1.5 for g in large.games)
    heights = [{lab.role: lab.rect.height for lab in w.layout(window_size)[0] + w.layout(window_size)[2]}
               for w in (plain, large)]
    assert heights[1]["caption"] >= 1.4 * heights[0]["caption"] and heights[1]["help"] >= 1.4 * heights[0]["help"]
    large.frame(0.1)
    assert large.screen.get_at((1, 1))[:3] == PALETTES["high-contrast"].window


def test_the_demo_command_passes_the_settings_file_to_the_window(tmp_path, monkeypatch):
    seen = {}
    monkeypatch.setattr("armgame.ui.autopilot_window.run_window", lambda seed, **kwargs: seen.update(kwargs))
    settings = tmp_path / "settings.toml"
    settings.write_text('palette = "high-contrast"\ntext_scale = 1.5\n', encoding="utf-8")
    assert cli.main(["demo", "autopilot", "--settings", str(settings), "--size", "800x600"]) == 0
    assert seen == {"size": (800, 600), "fullscreen": False, "palette": "high-contrast", "text_scale": 1.5}
