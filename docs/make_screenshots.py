"""Draw the README's and the docs' screenshots off screen, as the windows draw them.

    python docs/make_screenshots.py            # writes docs/img/*.png (run it again when the look changes)
    python docs/make_screenshots.py --out DIR  # somewhere else (the tests do, into a temporary folder)

Each picture is a real frame of a real run: the game's model bot playing seed 10, the lab's adapting
bot in the curl field (mid-reach, and the window's last screen with its learning curve), a live class's
standings as ``armgame class show`` draws them (from standings made up here: no class is served), the
menu (as it opens, and its Settings page after choosing a bright room's looks), the planning and
interaction demos and the autopilot race, drawn by the windows' own renderers onto an off-screen surface
(SDL's dummy video driver: no display needed); the game and the lab scaled down to a small PNG for the
README, the rest kept at a projector's 1024 x 768.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import pygame

from armgame.game.bots import Autopilot, make_bot
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.lab.bots import make_lab_bot
from armgame.lab.presets import preset
from armgame.lab.session import LabSession, lab_config
from armgame.ui.lab_window import LabRenderer
from armgame.ui.render import GameRenderer, Hud

HERE = Path(__file__).resolve().parent
#: Drawn at a projector's size, saved at half of it: small files, text still legible on GitHub.
DRAW_SIZE, SAVE_SIZE = (1280, 720), (800, 450)
#: The class's standings, the menu and the demos are drawn and saved at a projector's size, whole: they
#: are read from the back row (text 19 px or more).
CLASS_SIZE = PROJECTOR = (1024, 768)


def _save(surface: pygame.Surface, path: Path) -> Path:
    pygame.image.save(pygame.transform.smoothscale(surface, SAVE_SIZE), str(path))
    return path


def game_frame(out: Path) -> Path:
    """The game as a player sees it a few seconds in: arm, target, clock, score, muscle bars, the trail."""
    session = GameSession(GameConfig(seed=10))
    pilot = Autopilot(session, make_bot("model"))
    trail: list[tuple[float, float]] = []
    while session.time < 7.3:
        pilot.advance(1)
        if session.steps % 5 == 0:
            trail = [*trail[-49:], session.hand()]
    renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
    surface = pygame.Surface(DRAW_SIZE)
    hud = Hud(help=("d f j k muscles", "space reset (-1)", "tab hide arm", "p pause", "Esc quit"),
              trail=trail)
    renderer.draw(surface, session, hud=hud)
    return _save(surface, out / "game.png")


def lab_frame(out: Path) -> Path:
    """The lab's centre-out task in the curl field: home, the eight targets, the cursor mid-reach."""
    protocol = preset("curl")
    session = LabSession(lab_config(protocol, 10), protocol)
    pilot = Autopilot(session, make_lab_bot("adaptive"))
    def mid_reach() -> bool:  # the 18th trial (the second of the exposure), 0.5 s after its go cue
        return (session.trial_index >= 17 and session.phase == "reach"
                and (session.steps - session.phase_start_step) * session.config.dt > 0.5)

    while not (mid_reach() or session.over):
        pilot.advance(1)
    renderer = LabRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
    surface = pygame.Surface(DRAW_SIZE)
    renderer.draw(surface, session)
    return _save(surface, out / "lab.png")


def lab_end_frame(out: Path) -> Path:
    """The lab window's last screen at a projector's 1024 x 768, as a volunteer of the guide's lesson sees it
    (``armgame lab lesson --join ...``): the learning curve (the adapting bot's run standing in), where each
    file was kept, the run handed in to the class, r run again or Esc quit."""
    from armgame.commands.lab import kept_lines
    from armgame.lab.analysis import figure_metric, learning_curve, trial_rows
    from armgame.ui.lab_panels import draw_end

    protocol = preset("lesson")
    session = LabSession(lab_config(protocol, 10), protocol)
    Autopilot(session, make_lab_bot("adaptive")).play()
    renderer = LabRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
    surface = pygame.Surface(PROJECTOR)
    curve = learning_curve(trial_rows(session), figure_metric(protocol))
    folder = Path.home() / ".local/share/armgame/lab/2026-11-25_104500_lesson"  # shown as ~/ on any machine
    kept = kept_lines([folder / "replay.json", folder / "trials.csv", folder / "learning.png", folder / "paths.png"])
    draw_end(renderer, surface, f"lesson: {len(session.outcomes)} trials, {session.result().hits} hits", curve,
             [*kept, "Lab run handed in: in the class curve"], ("r run again", "Esc quit"))
    path = out / "lab_end.png"
    pygame.image.save(surface, str(path))
    return path


def game_end_frame(out: Path) -> Path:
    """The game's end screen at a projector's 1024 x 768 for a student in the live class who also keeps
    each game (``armgame play --join ... --record``): handed in, ranked, and the file it was saved as."""
    from armgame.commands.play import _screen_line
    from armgame.ui.render import Standing

    session = GameSession(GameConfig(seed=10))
    Autopilot(session, make_bot("model")).play()
    renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
    top = ((1, "Ife", 58), (2, "Chloé", 55), (3, "Ann B", session.result().score), (4, "Nour", 45), (5, "Amira", 42))
    note = _screen_line("handed in: 3rd of 24 in the class (your best so far)")
    standing = Standing(3, 24, top, "the class", note=note,
                        saved="Saved as ann-b-game3.json", mine=2)
    surface = pygame.Surface(PROJECTOR)
    renderer.draw(surface, session, hud=Hud(ended=True, standing=standing,
                                            end_hint="Enter plays again    Esc quits"))
    path = out / "game_end.png"
    pygame.image.save(surface, str(path))
    return path


def class_frame(out: Path) -> Path:
    """`armgame class show`: a class of 24 halfway through a lesson, a new personal best just in (the
    standings as the class's /api/standings answers them; saved at a projector's 1024 x 768)."""
    import json

    from armgame.ui.class_window import ClassWindow, parse_standings

    names = ["Priya", "Yusuf", "Zoë", "Tom", "Ольга", "Kai", "Lena", "محمد", "Noah", "Uma", "Ann", "Bo", "שירה",
             "Mateo", "Aiko", "Jonas", "Fatima", "Leo", "Sara", "Ravi", "Emma", "Finn", "Nia", "Omar"]
    students = [{"rank": i + 1, "name": name, "score": 52 - 2 * i + (i % 3), "hits": 52 - 2 * i + (i % 3),
                 "games": 1 + (7 * i) % 5, "driver": None} for i, name in enumerate(names)]
    programs = [{"rank": i + 1, "name": name, "score": score, "hits": score, "games": 1, "driver": driver}
                for i, (name, score, driver) in enumerate((("Dee's bot", 61, "bot (model)"),
                                                          ("naive", 38, "bot (naive)"),
                                                          ("Kai's script", 31, "script")))]
    answer = {"version": 40, "seed": 10, "closed": False, "joined": 27, "games": 61, "students": students,
              "people": {"students": 24, "lab_only": 0, "programs": 3},
              "programs": programs, "join": "armgame play --join 192.168.1.20:8765 --code HAPF",
              "arrival": {"seq": 61, "name": "Yusuf", "score": 51, "note": "new personal best", "program": False}}
    window = ClassWindow("192.168.1.20:8765", None)
    window.update(parse_standings(json.dumps({**answer, "arrival": {**answer["arrival"], "seq": 60}}).encode()), None)
    window.update(parse_standings(json.dumps(answer).encode()), None)  # arrived after the window opened: news
    surface = pygame.Surface(CLASS_SIZE)
    window.draw(surface)
    # Not class_*.png: those are the class's web pages, drawn by a browser (docs/make_class_screenshots.py).
    path = out / "show_class.png"
    pygame.image.save(surface, str(path))
    return path


def _draw_menu(build, out: Path, name: str, palette: str = "okabe-ito", text_scale: float = 1.0,
               status: str = "") -> Path:
    from armgame.ui.menu import MenuWindow

    menu = MenuWindow(build, palette=palette, text_scale=text_scale)
    menu.status = status
    menu.screen = pygame.Surface(PROJECTOR)
    menu.draw()
    path = out / name
    pygame.image.save(menu.screen, str(path))
    return path


def menu_frame(out: Path) -> Path:
    """`armgame` alone: the menu's first page at a projector's 1024 x 768, as it first opens."""
    from armgame.commands.menu import main_page

    return _draw_menu(lambda: main_page(lambda argv: 0), out, "menu.png")


def menu_settings_frame(out: Path) -> Path:
    """The menu's Settings page just after a teacher chose high-contrast and text size 1.5 there: the
    menu is redrawn with them at once (a settings file of its own in a temporary folder)."""
    import tempfile

    from armgame.commands.menu import settings_page

    with tempfile.TemporaryDirectory() as folder:
        saved = os.environ.get("XDG_CONFIG_HOME")
        os.environ["XDG_CONFIG_HOME"] = folder
        try:
            for item in (0, 0, 1, 1):  # text size 1x -> 1.25x -> 1.5x; okabe-ito -> classic -> high-contrast
                settings_page().items[item].act()

            def shown():  # the file's path is this script's temporary one: the page shows the usual one
                page = settings_page()
                page.lines = tuple("~/.config/armgame/settings.toml" if line.endswith("settings.toml") else line
                                   for line in page.lines)
                return page

            return _draw_menu(shown, out, "menu_settings.png", "high-contrast", 1.5,
                              "saved to ~/.config/armgame/settings.toml")
        finally:
            if saved is None:
                del os.environ["XDG_CONFIG_HOME"]
            else:
                os.environ["XDG_CONFIG_HOME"] = saved


def _demo(name: str, out: Path, seconds: float, palette: str = "okabe-ito", text_scale: float = 1.0) -> Path:
    from armgame.demos.catalog import make_run
    from armgame.ui.demo_window import DemoWindow

    now = [0.0]
    window = DemoWindow(name, make_run(name), clock=lambda: now[0], size=PROJECTOR, palette=palette,
                        text_scale=text_scale)
    window.open()
    pygame.display.set_mode(PROJECTOR)
    window.handle(pygame.event.Event(pygame.VIDEORESIZE, w=PROJECTOR[0], h=PROJECTOR[1], size=PROJECTOR))
    while window.run.t < seconds:
        now[0] += 1 / 60
        window.frame()
    path = out / f"demo_{name}.png"
    pygame.image.save(pygame.display.get_surface(), str(path))
    window.close()
    return path


def planning_frame(out: Path) -> Path:
    """`armgame demo planning` at 1024 x 768 mid-reach: both plans, the speed plot, the legend."""
    return _demo("planning", out, 0.7)


def interaction_frame(out: Path) -> Path:
    """`armgame demo interaction` at 1024 x 768 with a bright room's settings (high-contrast, 1.5)."""
    return _demo("interaction", out, 0.15, "high-contrast", 1.5)  # 0.15 s into the reach out


def autopilot_frame(out: Path) -> Path:
    """`armgame demo autopilot` at a 4:3 projector's 1024 x 768, 15 s into the race."""
    from armgame.ui.autopilot_window import AutopilotWindow

    pygame.display.init()
    screen = pygame.display.set_mode(PROJECTOR)
    window = AutopilotWindow(10, 60.0, screen, clock=lambda: 0.0)
    window.skip(15.0)
    window.frame(0.0)
    path = out / "demo_autopilot.png"
    pygame.image.save(pygame.display.get_surface(), str(path))
    pygame.display.quit()
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE / "img", help="folder for the PNGs (default docs/img)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    pygame.display.init()
    pygame.font.init()
    try:
        for draw in (game_frame, game_end_frame, lab_frame, lab_end_frame, class_frame, menu_frame, menu_settings_frame,
                     planning_frame, interaction_frame, autopilot_frame):
            print(f"wrote {draw(args.out)}")
            pygame.display.init()  # a demo window closes the display it opened
            pygame.font.init()
    finally:
        pygame.quit()
    return 0


if __name__ == "__main__":
    sys.exit(main())
