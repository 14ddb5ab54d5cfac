"""Made for a projector, and an arm that shows its muscles: the rules a back-row student needs, checked on the
layouts and on drawn frames at 1024 x 768 (SDL's dummy driver; no display)."""

import math
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"

import pygame
import pytest

from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.ui.body import area, draw_arm, muscle_ends, muscle_outline
from armgame.ui.render import MIN_LINE, PALETTES, GameRenderer, Hud, contrast_ratio, min_text, text_heights
from armgame.ui.settings import Settings, SettingsError, from_toml

PROJECTOR = (1024, 768)


@pytest.fixture(scope="module")
def fonts():
    pygame.display.init()
    pygame.font.init()
    yield
    pygame.display.quit()


def renderer(palette="okabe-ito", text_scale=1.0):
    session = GameSession(GameConfig())
    return session, GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles), palette,
                                 text_scale)


def test_the_smallest_text_is_a_fortieth_of_the_window_height(fonts):
    assert min_text(PROJECTOR) == 19 and text_heights(PROJECTOR)[2] >= 19
    session, r = renderer()
    hud = Hud(mode="PLAY", help=("d/f shoulder", "j/k elbow", "p pause", "Esc quit"))
    lay = r.layout(PROJECTOR, session, hud)
    assert min(lab.height for lab in lay.labels) >= 19
    assert min(lab.rect.height for lab in lay.labels) >= 19
    # text_scale (a large room): every text larger, and the layout still fits without overlaps.
    session, big = renderer(text_scale=1.5)
    lay = big.layout(PROJECTOR, session, hud)
    assert min(lab.height for lab in lay.labels) >= round(1.5 * 19) - 1
    boxes = lay.boxes()
    for i, (name, a) in enumerate(boxes):
        assert pygame.Rect((0, 0), PROJECTOR).contains(a), name
        assert not any(a.colliderect(b) for _, b in boxes[i + 1:]), name


@pytest.mark.parametrize("palette", sorted(PALETTES))
def test_lines_a_student_must_see_are_three_to_one_on_their_background(palette):
    p = PALETTES[palette]
    for line in (p.trail, p.edge, p.link, p.target, p.hand):
        for background in (p.scene, p.workspace):
            assert contrast_ratio(line, background) >= 3.0, (palette, line, background)
    assert contrast_ratio(p.link, p.skin) >= 3.0  # the body's outline on its fill


def test_trails_and_outlines_are_three_pixels_or_more(fonts):
    session, r = renderer()
    screen = pygame.Surface(PROJECTOR)
    trail = [(0.1 * math.cos(t / 10), 0.5 + 0.1 * math.sin(t / 10)) for t in range(30)]
    lay = r.draw(screen, session, hud=Hud(trail=trail))
    p = r.palette
    # Across the trail's path, at least MIN_LINE pixels of its colour.
    x, y = lay.view.to_screen(*trail[15])
    column = [tuple(screen.get_at((x, yy)))[:3] for yy in range(y - 10, y + 11)]
    assert column.count(p.trail) >= MIN_LINE
    assert MIN_LINE == 3


def test_a_muscle_swells_with_its_activation_and_sits_where_it_acts():
    q1, q2, l1, l2 = math.radians(45), math.radians(90), 0.3, 0.33
    for i in range(4):
        rest, full = (area(muscle_outline(i, q1, q2, l1, l2, a)) for a in (0.0, 1.0))
        assert full > 1.8 * rest > 0
    # Each muscle's pull turns its joint the way its key does: pectoralis and biceps anticlockwise
    # (the torque of the pull on the insertion about the joint), posterior deltoid and triceps clockwise.
    elbow = (l1 * math.cos(q1), l1 * math.sin(q1))
    for i, (joint, sign) in enumerate((((0, 0), 1), ((0, 0), -1), (elbow, 1), (elbow, -1))):
        origin, insertion = muscle_ends(i, q1, q2, l1, l2)
        rx, ry = insertion[0] - joint[0], insertion[1] - joint[1]
        fx, fy = origin[0] - insertion[0], origin[1] - insertion[1]
        assert sign * (rx * fy - ry * fx) > 0, i


def test_the_drawn_muscle_grows_and_brightens_in_its_keys_colour(fonts):
    p = PALETTES["okabe-ito"]
    counts = []
    for a in (0.0, 1.0):
        screen = pygame.Surface((600, 600))
        screen.fill(p.scene)
        draw_arm(screen, (450.0, 450.0), 600.0, math.radians(45), math.radians(90), 0.3, 0.33, [0.0, 0.0, a, 0.0], p)
        counts.append(sum(1 for x in range(0, 600, 2) for y in range(0, 600, 2)
                          if tuple(screen.get_at((x, y)))[:3] == p.muscles[2]))
    assert counts[0] == 0 and counts[1] > 100  # the biceps in j's full colour only when active


def test_the_game_draws_the_same_frames_incrementally_as_whole(fonts):
    """The window redraws only what the last frame covered: the frame must be the one a whole redraw gives."""
    screen = pygame.display.set_mode(PROJECTOR)
    session, r = renderer()
    _, whole = renderer()
    session.key_event("d", "down")
    for _ in range(5):
        session.advance(40)
        r.draw(screen, session, hud=Hud(help=("p pause",)))
    reference = pygame.Surface(PROJECTOR)
    whole.draw(reference, session, hud=Hud(help=("p pause",)))
    assert pygame.image.tobytes(screen, "RGB") == pygame.image.tobytes(reference.convert(screen), "RGB")
    screen.fill((0, 0, 0))  # what a change of mode (F11) leaves: the next frame is drawn whole
    session.advance(40)
    r.draw(screen, session, hud=Hud(help=("p pause",)))
    whole.draw(reference, session, hud=Hud(help=("p pause",)))
    assert pygame.image.tobytes(screen, "RGB") == pygame.image.tobytes(reference.convert(screen), "RGB")


def test_text_scale_and_the_high_contrast_palette_are_settings():
    s = from_toml(b'palette = "high-contrast"\ntext_scale = 1.5\n', "s.toml")
    assert s.palette == "high-contrast" and s.text_scale == 1.5
    assert from_toml(s.to_toml().encode(), "again") == s
    assert Settings().text_scale == 1.0
    for bad in ("text_scale = 9", "text_scale = \"big\"", "text_scale = true", "text_scale = nan"):
        with pytest.raises(SettingsError, match=r"text_scale must be a number from 0\.75 to 2\.5"):
            from_toml(bad.encode(), "s.toml")


def test_the_end_screens_long_lines_wrap_whole_inside_the_panel(fonts):
    from armgame.ui.render import Standing

    note = ("Not handed in yet: the class at 192.168.1.20:8765 did not answer (busy, or stopped for a moment); your "
            "game is kept and will be handed in the next time you join")
    session, r = renderer("high-contrast")
    session.play([])
    hud = Hud(mode="PLAY", ended=True, standing=Standing(None, 0, (), note=note))
    for size in (PROJECTOR, (800, 600)):
        lay = r.layout(size, session, hud)
        lines = sorted((lab for lab in lay.labels if lab.role == "end"), key=lambda lab: lab.rect.top)
        shown = " ".join(lab.text for lab in lines)
        assert note in shown and "..." not in shown, size
        assert all(lay.panels[0].contains(lab.rect) for lab in lines), size
