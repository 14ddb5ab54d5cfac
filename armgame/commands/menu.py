"""``armgame`` with no command: the menu window (``armgame.ui.menu``), or the commands where no window can open.

Each entry runs the command a user would type (``armgame play``, ``armgame lab curl``, ...) through
``armgame.cli.main`` in this process, so options, settings, errors and what is printed are exactly
the command's own; its window closes back to the menu. Where there is no display (a terminal over
ssh, a CI job), or pygame is missing, the commands are printed instead and the exit status is 0:
``armgame`` alone is how a newcomer asks what there is.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

#: How many replays "Replays and scores" lists (newest first), and how many files it looks at to find them.
RECENT_REPLAYS = 9
MAX_SCANNED = 5000
LAB_PRESETS = {
    "null": "nothing changed: reaches as they are (a baseline)",
    "curl": "a curl force field pushes the hand sideways",
    "rotation": "the cursor turned 30 degrees from the hand",
    "mirror": "the cursor mirrored left to right",
    "jointspace": "the cursor driven by the joint angles, not the hand",
    "lesson": "the class's two minutes: the curl field, 24 reaches",
}


def commands_table(parser: argparse.ArgumentParser) -> str:
    """Every command and what it does, one a line (what ``armgame`` prints where no window opens)."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {action.dest: action.help or "" for action in sub._choices_actions}
    width = max(len(name) for name in helps)
    lines = ["armgame: no display here for the menu; the commands (armgame COMMAND --help lists the options):"]
    lines += [f"  armgame {name:<{width}}  {text}" for name, text in helps.items()]
    return "\n".join(lines)


def no_display_in_environment() -> bool:
    """No X11 or Wayland session to open a window in, told without loading SDL (Linux and BSDs only:
    elsewhere SDL is asked, through ``armgame.ui.display.init_display``)."""
    if not sys.platform.startswith(("linux", "freebsd", "openbsd", "netbsd")):
        return False
    return not any(os.environ.get(name) for name in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"))


def run(parser: argparse.ArgumentParser, launch: Callable[[Sequence[str]], int]) -> int:
    """The menu until it is quit; ``launch`` runs one command line (``armgame.cli.main``)."""
    from ..errors import NoDisplayError

    if no_display_in_environment():
        print(commands_table(parser))
        return 0
    try:
        import pygame

        from ..ui.display import init_display
        from ..ui.menu import run_menu

        init_display()
    except (ImportError, NoDisplayError):
        print(commands_table(parser))
        return 0
    pygame.display.quit()  # the menu opens its own window, and reopens it after each entry
    from ..ui.options import window_settings

    settings, _ = window_settings(argparse.Namespace())
    run_menu(lambda: main_page(launch), palette=settings.palette, size=settings.size,
             text_scale=settings.text_scale, looks=lambda: looks(settings.palette, settings.text_scale))
    return 0


def looks(palette: str, text_scale: float) -> tuple[str, float]:
    """The settings file's palette and text scale, read again after a change on a page (the Settings
    page's, or a window's); ``palette`` and ``text_scale`` while the file cannot be used (the page says why)."""
    from ..ui.settings import SettingsError, load

    try:
        settings, _ = load()
    except SettingsError:
        return palette, text_scale
    return settings.palette, settings.text_scale


def _start(launch: Callable[[Sequence[str]], int], *argv: str) -> Callable[[], str | None]:
    """``launch(argv)`` from the menu; what the menu says after it: nothing, or the command's own last line of
    error (the whole reason, as the terminal has it: a student in the menu may have no terminal in view)."""
    def start() -> str | None:
        said = _LastLine(sys.stderr)
        with contextlib.redirect_stderr(said):
            code = launch(list(argv))
        if code == 0:
            return None
        return said.last or f"armgame {' '.join(argv)} stopped (status {code})"

    return start


class _LastLine(io.TextIOBase):
    """A stream that passes everything on to ``out`` and keeps the last non-empty line written, without the
    ``armgame COMMAND:`` that starts a command's error."""

    def __init__(self, out) -> None:
        self.out, self.last, self._partial = out, "", ""

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        self.out.write(text)
        lines = (self._partial + text).split("\n")
        self._partial = lines.pop()
        for line in lines:
            if line.strip():
                self.last = re.sub(r"^armgame( [a-z]+)*: (error: )?", "", line.strip())
        return len(text)

    def flush(self) -> None:
        self.out.flush()


def main_page(launch: Callable[[Sequence[str]], int]):
    from ..ui.menu import Item, Page

    typed: dict[str, str] = {}  # the class page's values, while the menu is open (kept nowhere else)

    return Page("armgame", [
        Item("Play", "the game: hit the targets with d f j k, one minute", start=_start(launch, "play")),
        Item("Join a class", "play in the live class the projector shows: its games go to the class",
             page=lambda: class_page(launch, typed)),
        Item("Lab", "reach in a force field or a changed display, and adapt",
             page=lambda: lab_page(launch)),
        Item("Demos", "the arm's dynamics, one idea at a time", page=lambda: demos_page(launch)),
        Item("Replays and scores", "the high-score table and the games recorded", page=lambda: replays_page(launch)),
        Item("Settings", "text size, colours, sound, where the settings file is", page=settings_page),
        Item("Quit", "close armgame", quit=True),
    ])


def class_page(launch: Callable[[Sequence[str]], int], typed: dict[str, str] | None = None):
    """Join a live class: its address, code and the student's name, typed once and checked as the
    command line checks them; the first time, the class this machine joined last (the client's own
    memberships file, the one place they are kept). ``typed`` holds them while the page is open."""
    import shlex

    from ..classroom import client
    from ..errors import UserError
    from ..ui.menu import Field, Item, Page
    from ..valid import MAX_NAME, check_name

    typed = {} if typed is None else typed
    if not typed:
        last = client.last_class()
        typed.update(zip(("address", "code", "name"), last or ("", "", ""), strict=True))
    checks: dict[str, Callable[[str], str]] = {
        "address": lambda text: client.ClassAddress.parse(text, "the class's address").label,
        "code": lambda text: client.check_code(text, "the code"),
        "name": lambda text: check_name(text, "your name"),
    }

    def field(key: str, limit: int) -> Field:
        return Field(typed[key], checks[key], lambda value: typed.__setitem__(key, value), limit)

    def missing(*keys: str) -> str | None:
        """The first value not set or not taken by its check (a remembered one may be stale), in its words."""
        for key in keys:
            if not typed[key]:
                return {"address": "type the class's address first (HOST:PORT, as the projector shows it)",
                        "code": "type the class's code first (its four letters, as the projector shows them)",
                        "name": "type your name first"}[key]
            try:
                checks[key](typed[key])
            except (ValueError, UserError) as exc:
                return str(exc)
        return None

    join = ["play", "--join", typed["address"], "--code", typed["code"], "--name", typed["name"]]
    ready = all(typed.values())
    return Page("Join a class", [
        Item("Class address", "HOST:PORT, as the projector shows it", field=field("address", 260)),
        Item("Code", "the class's four letters, as the projector shows them", field=field("code", 16)),
        Item("Your name", f"as the class's table shows it: 1 to {MAX_NAME} characters", field=field("name", MAX_NAME)),
        Item("Join and play", "armgame " + shlex.join(join) if ready else "the three above first",
             start=lambda: _start(launch, *join)(), ready=lambda: missing("address", "code", "name")),
        Item("Show the class's standings", "the projector's table, here: armgame class show "
             + (typed["address"] or "HOST:PORT"), start=lambda: _start(launch, "class", "show", typed["address"])(),
             ready=lambda: missing("address")),
    ], lines=("Every game you finish is handed in to the class by itself.",))


def lab_page(launch: Callable[[Sequence[str]], int]):
    from ..ui.menu import Item, Page

    return Page("Lab", [Item(name, detail, start=_start(launch, "lab", name)) for name, detail in LAB_PRESETS.items()],
                lines=("Centre-out reaches: baseline, exposure, washout. The window says what to do.",))


def demos_page(launch: Callable[[Sequence[str]], int]):
    from ..demos import DEMO_NAMES
    from ..demos.catalog import get_info
    from ..ui.menu import Item, Page

    items = [Item(name, get_info(name).title.removeprefix("armgame demo: "), start=_start(launch, "demo", name))
             for name in DEMO_NAMES]
    items.append(Item("autopilot", "two bots play the game: one knows the interaction torques",
                      start=_start(launch, "demo", "autopilot")))
    return Page("Demos", items)


def recent_replays(folder: Path, limit: int = RECENT_REPLAYS) -> list[Path]:
    """The newest regular ``*.json`` files in ``folder`` (no symlink followed), at most MAX_SCANNED looked at."""
    found: list[tuple[float, Path]] = []
    try:
        with os.scandir(folder) as entries:
            for n, entry in enumerate(entries):
                if n >= MAX_SCANNED:
                    break
                if entry.name.endswith(".json") and entry.is_file(follow_symlinks=False):
                    found.append((entry.stat(follow_symlinks=False).st_mtime, Path(entry.path)))
    except OSError:
        return []
    return [path for _, path in sorted(found, reverse=True)[:limit]]


def replays_page(launch: Callable[[Sequence[str]], int]):
    """The ranked table's top five (as recorded: ``armgame scores`` checks them) and the newest replays."""
    from ..records.replay import Replay
    from ..records.scores import ScoreTable, default_scores_dir
    from ..records.standings import places
    from ..records.storage import DataFileError
    from ..ui.menu import Item, Page
    from . import read_lab_replays

    read_lab_replays()
    warnings: list[str] = []
    lines: list[str] = []
    try:
        table = ScoreTable(default_scores_dir(), warn=warnings.append)
        entries = table.entries()
        lines.append(f"The ranked table ({table.path}):" if entries else f"No ranked scores yet in {table.path}")
        top = entries[:5]
        lines += [f"{i}. {e.name}   {e.score}" for i, e in zip(places(e.score for e in top), top, strict=True)]
        folder = table.replays
    except (DataFileError, OSError) as exc:
        lines.append(f"the table cannot be read: {exc}")
        folder = None
    lines += warnings[:1]
    items = []
    for path in recent_replays(folder) if folder is not None else []:
        try:
            replay = Replay.load(path, follow=False)
        except (DataFileError, OSError, ValueError) as exc:
            items.append(Item(path.name, f"cannot be read: {exc}"))
            continue
        when = replay.date[:16].replace("T", " ") if replay.date else "date unknown"
        items.append(Item(f"watch {replay.player or 'no name'}: score {replay.result.score}",
                          f"{when}, seed {replay.config.seed}, {replay.result.duration:g} s",
                          start=_start(launch, "replay", str(path))))
    if not items:
        lines.append("No replays yet: play a game, and its replay is kept here.")
    return Page("Replays and scores", items, lines=lines)


#: The Settings page's text sizes, smallest first: Enter takes the next larger, after the largest the smallest.
TEXT_SCALES = (0.75, 1.0, 1.25, 1.5, 2.0, 2.5)
#: What each palette is for, as the Settings page says it.
PALETTE_USES = {"okabe-ito": "colour-blind safe (the default)", "classic": "the 2012 game's colours",
                "high-contrast": "black on white, for a bright room"}


def next_text_scale(scale: float) -> float:
    """The next larger of TEXT_SCALES (a value typed into the file between two goes to the larger)."""
    return next((s for s in TEXT_SCALES if s > scale + 1e-9), TEXT_SCALES[0])


def settings_page():
    """Text size, colours and sound, each changed by Enter, saved to the settings file at once; the
    menu redraws itself with the new text size and colours (``looks``), so the choice is seen as made."""
    from ..ui.menu import Item, Page
    from ..ui.settings import PALETTES, SettingsError, load, save

    try:
        settings, path = load()
    except SettingsError as exc:
        return Page("Settings", [], lines=(f"the settings file cannot be used: {exc}",))

    def change(**changes: object) -> Callable[[], str | None]:
        def act() -> str | None:
            try:
                current, _ = load(path)
                save(current.with_changes(**changes), path)
            except SettingsError as exc:
                return f"not saved: {exc}"
            return f"saved to {path}"

        return act

    following = PALETTES[(PALETTES.index(settings.palette) + 1) % len(PALETTES)] \
        if settings.palette in PALETTES else PALETTES[0]
    larger = next_text_scale(settings.text_scale)
    return Page("Settings", [
        Item(f"Text size: {settings.text_scale:g}x",
             f"Enter: {larger:g}x" + (" (1.5x reads from the back of a classroom)" if larger == 1.5 else
                                      " (the smallest)" if larger < settings.text_scale else ""),
             act=change(text_scale=larger)),
        Item(f"Colours: {settings.palette}", f"Enter: {following}, {PALETTE_USES.get(following, '')}",
             act=change(palette=following)),
        Item(f"Sound: {'off' if settings.mute else 'on'}", "Enter: unmute" if settings.mute else "Enter: mute",
             act=change(mute=not settings.mute)),
    ], lines=("Every armgame window uses these, kept in", str(path),
              *(line for line in settings.describe() if line.startswith("keys"))))
