"""Draw the README's and the docs' screenshots off screen, as the windows draw them.

    python docs/make_screenshots.py            # writes docs/img/*.png (run it again when the look changes)
    python docs/make_screenshots.py --out DIR  # somewhere else (the tests do, into a temporary folder)

Each picture is a real frame of a real run: the game's model bot playing seed 10, the lab's adapting
bot in the curl field (mid-reach, and the window's last screen with its learning curve), a live class's
standings as ``armgame class show`` draws them (from standings made up here: no class is served), drawn by the
windows' own renderers onto an off-screen surface (SDL's dummy
video driver: no display needed), then scaled down to a small PNG for the README.
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
from armgame.lab.protocol import preset
from armgame.lab.session import LabSession, lab_config
from armgame.ui.lab_window import LabRenderer
from armgame.ui.render import GameRenderer, Hud

HERE = Path(__file__).resolve().parent
#: Drawn at a projector's size, saved at half of it: small files, text still legible on GitHub.
DRAW_SIZE, SAVE_SIZE = (1280, 720), (800, 450)
#: The class's standings are drawn and saved at a projector's size: they are read from the back row.
CLASS_SIZE = (1024, 768)


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
    hud = Hud(mode="PLAY", help=("d f j k muscles", "space reset (-1)", "tab hide arm", "p pause", "Esc quit"),
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
    """The lab window's last screen: the lesson's learning curve, by the adapting bot (a volunteer's run,
    kept with --record volunteers/v1.json, looks the same)."""
    from armgame.commands.lab import kept_lines
    from armgame.lab.analysis import figure_metric, learning_curve, trial_rows
    from armgame.ui.lab_panels import draw_end

    protocol = preset("lesson")
    session = LabSession(lab_config(protocol, 10), protocol)
    Autopilot(session, make_lab_bot("adaptive")).play()
    renderer = LabRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
    surface = pygame.Surface(DRAW_SIZE)
    curve = learning_curve(trial_rows(session), figure_metric(protocol))
    folder = Path.home() / ".local/share/armgame/lab/2026-11-25_104500_lesson"  # shown as ~/ on any machine
    kept = kept_lines([Path.home() / "class/volunteers/v1.json", folder / "trials.csv",
                       folder / "learning.png", folder / "paths.png"])
    draw_end(renderer, surface, f"lesson: {len(session.outcomes)} trials, {session.result().hits} hits", curve,
             kept, ("r run again", "Esc quit"))
    return _save(surface, out / "lab_end.png")


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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE / "img", help="folder for the PNGs (default docs/img)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    pygame.display.init()
    pygame.font.init()
    try:
        for draw in (game_frame, lab_frame, lab_end_frame, class_frame):
            print(f"wrote {draw(args.out)}")
    finally:
        pygame.quit()
    return 0


if __name__ == "__main__":
    sys.exit(main())
