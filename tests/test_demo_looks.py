"""Issue 27: the demo windows and the autopilot follow the settings' palette and text size, read from
the back row of a 1024 x 768 projector (text 19 px or more, none cut), lay out for 4:3 as well as 16:9
and for a tall window (text 2.5% of its height or more), and draw what never moves once per size.
SDL's dummy driver; no display."""

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pygame
import pytest

from armgame.demos.catalog import make_run
from armgame.ui.autopilot_window import AutopilotWindow
from armgame.ui.demo_window import DemoWindow
from armgame.ui.render import PALETTES, min_text

PROJECTOR, WIDE, TALL = (1024, 768), (1920, 1080), (768, 1024)


@pytest.fixture
def display():
    pygame.display.init()
    pygame.font.init()
    yield
    pygame.display.quit()


@pytest.fixture(scope="module")
def planning_run():
    return make_run("planning")


def resize(window, size):
    pygame.display.set_mode(size)
    window.handle(pygame.event.Event(pygame.VIDEORESIZE, w=size[0], h=size[1], size=size))


def demo(name, size, run=None, **looks):
    now = [0.0]
    window = DemoWindow(name, run or make_run(name), clock=lambda: now[0], size=size, **looks)
    window.open()
    resize(window, size)
    for _ in range(3):
        now[0] += 0.2
        window.frame()
    return window, now


def assert_readable(size, boxes, smallest, what):
    """Inside the window, no two overlapping, none cut with an ellipsis, none under ``smallest`` px."""
    window = pygame.Rect((0, 0), size)
    texts = [(name, rect) for name, rect in boxes if not name.startswith("bar") and name != "progress"]
    for i, (name, rect) in enumerate(boxes):
        assert window.contains(rect), f"{what} at {size}: {name!r} {rect} is cut by the window"
        for other, r in boxes[i + 1:]:
            assert not rect.colliderect(r), f"{what} at {size}: {name!r} {rect} overlaps {other!r} {r}"
    for name, rect in texts:
        assert not name.endswith("..."), f"{what} at {size}: {name!r} is cut short"
        assert rect.height >= smallest, f"{what} at {size}: {name!r} is {rect.height} px high"


@pytest.mark.parametrize("name", ["interaction", "chaos", "planning"])
def test_a_demo_takes_the_palette_and_the_text_size(display, name, planning_run):
    run = planning_run if name == "planning" else None
    plain, _ = demo(name, PROJECTOR, run)
    heights = {text: rect.height for text, rect in plain.text_boxes()}
    large, _ = demo(name, PROJECTOR, run, palette="high-contrast", text_scale=1.5)
    # The scene's background, before it is scaled to the window (which greys white a little).
    assert plain._static.get_at((2, 400))[:3] == PALETTES["okabe-ito"].scene
    assert large._static.get_at((2, 400))[:3] == PALETTES["high-contrast"].scene != PALETTES["okabe-ito"].scene
    help_line = next(rect.height for text, rect in large.text_boxes() if text.startswith("p pause"))
    assert help_line >= 1.4 * heights[next(t for t in heights if t.startswith("p pause"))]
    assert_readable(PROJECTOR, large.text_boxes(), round(1.5 * min_text(PROJECTOR)) - 2, name)
    assert not large.room.colliderect(pygame.Rect(0, 0, 1, 1))  # the arm still has its room


@pytest.mark.parametrize("size", [TALL, (720, 1280)])
def test_a_tall_window_keeps_its_text_at_a_fortieth_of_its_height(display, size, planning_run):
    for name in ("passive", "interaction", "planning"):
        window, _ = demo(name, size, planning_run if name == "planning" else None)
        assert_readable(size, window.text_boxes(), 0.025 * size[1] - 1, name)


def test_what_never_moves_is_drawn_once_per_size(display):
    window, now = demo("interaction", PROJECTOR)
    built = window.static_builds
    for _ in range(30):
        now[0] += 1 / 60
        window.frame()
    assert window.static_builds == built == 1
    resize(window, WIDE)
    for _ in range(30):
        now[0] += 1 / 60
        window.frame()
    assert window.static_builds == 2
    # What the layer holds is drawn every frame: the bars' labels and the help line are among the texts.
    texts = [text for text, _ in window.text_boxes()]
    assert "TOTAL" in texts and texts[-1].endswith("Esc quit") and any(t.startswith("t = ") for t in texts)


@pytest.mark.parametrize("size", [PROJECTOR, WIDE, (1280, 720)])
@pytest.mark.parametrize("scale", [1.0, 1.5])
def test_the_autopilot_reads_from_the_back_row_at_4_3_and_16_9(display, size, scale):
    pygame.display.set_mode(size)
    window = AutopilotWindow(10, 60.0, pygame.display.get_surface(), clock=lambda: 0.0, palette="high-contrast",
                             text_scale=scale)
    window.frame(0.2)
    boxes = window.all_boxes(size)
    assert_readable(size, boxes, round(scale * min_text(size)) - 1, "autopilot")
    modes = sorted(name for name, _ in boxes if name.startswith("mode: "))
    assert modes == ["mode: AUTOPILOT: model", "mode: AUTOPILOT: naive"]  # whole, never "AUTOPILOT: mo..."


def test_the_autopilot_draws_its_caption_once_per_size(display):
    pygame.display.set_mode(PROJECTOR)
    window = AutopilotWindow(10, 60.0, pygame.display.get_surface(), clock=lambda: 0.0)
    for _ in range(20):
        window.frame(1 / 60)
    assert window.static_builds == 1
    caption = window.layout(PROJECTOR)[0][0].rect
    screen = pygame.display.get_surface()
    ink = window.palette.ink
    assert any(screen.get_at((x, caption.centery))[:3] == ink for x in range(caption.left, caption.right))
    pygame.display.set_mode(WIDE)
    for _ in range(5):
        window.frame(1 / 60)
    assert window.static_builds == 2
    window.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_p))
    window.frame(0.0)  # paused: the help line says "p resume", so the layer is drawn again
    assert window.static_builds == 3 and window.layout(WIDE)[2][-1].text.startswith("p resume")


def test_the_autopilot_and_demo_windows_open_in_the_desktops_shape(display, monkeypatch):
    from armgame.ui import autopilot_window, demo_window
    from armgame.ui import display as display_module

    monkeypatch.setattr(display_module, "desktop_size", lambda: (1024, 768))
    sizes = []
    real = pygame.display.set_mode

    def set_mode(size=(0, 0), *args, **kwargs):
        sizes.append(tuple(size))
        return real(size, *args, **kwargs)

    monkeypatch.setattr(pygame.display, "set_mode", set_mode)
    autopilot_window.run_window(10, 60.0, max_frames=1)
    demo_window.run_window("chaos", make_run("chaos"), clock=lambda: 0.0, max_frames=1, frame_rate=None)
    # The whole of a 4:3 desktop less its title and task bars, not a 16:9 strip (1024 x 576) in it.
    assert sizes[0] == (1024, 704)
    assert next(s for s in sizes[1:] if s != (0, 0)) == (1024, 704)


def test_the_demo_command_passes_the_settings_to_the_window(tmp_path, monkeypatch):
    from armgame import cli

    seen = {}
    monkeypatch.setattr("armgame.ui.demo_window.run_window", lambda name, run, **kwargs: seen.update(kwargs))
    settings = tmp_path / "settings.toml"
    settings.write_text('palette = "high-contrast"\ntext_scale = 1.5\n', encoding="utf-8")
    assert cli.main(["demo", "chaos", "--settings", str(settings)]) == 0
    assert seen["palette"] == "high-contrast" and seen["text_scale"] == 1.5
