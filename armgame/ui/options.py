"""The options every windowed command shares (``--size``, ``--fullscreen``, ``--mute``, ``--settings``).

Parsing only: no pygame here, so ``armgame --help`` and headless runs stay light. The values in force
are the command line's, else the settings file's (``armgame.ui.settings``), else a default that fits
the desktop.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..records.storage import user_path
from .settings import Settings, load, parse_size


def _size(text: str) -> tuple[int, int]:
    try:
        return parse_size(text, "--size")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--size ")) from None


def add_window_options(p: argparse.ArgumentParser, sound: bool = True, trail: bool = False) -> None:
    g = p.add_argument_group("window")
    g.add_argument("--size", type=_size, default=None, metavar="WxH",
                   help="window size, e.g. 1280x720 (default: the settings file's, else one that fits the "
                   "desktop; never larger than the desktop)")
    g.add_argument("--fullscreen", action="store_true", help="fill the screen (F11 toggles it in the window)")
    if sound:
        g.add_argument("--mute", action="store_true", help="start with the sounds off (m toggles them)")
    if trail:
        g.add_argument("--trail", action="store_true", help="draw the hand's path over the last second")
    g.add_argument("--settings", metavar="FILE", default=None,
                   help="settings file to use (default: $XDG_CONFIG_HOME/armgame/settings.toml)")


def window_settings(args: argparse.Namespace) -> tuple[Settings, Path]:
    """The settings in force for this window: the file's, with this command line's options over them."""
    settings, path = load(user_path(args.settings, "--settings") if getattr(args, "settings", None) else None)
    if getattr(args, "size", None) is not None:
        settings = settings.with_changes(size=args.size)
    if getattr(args, "mute", False):
        settings = settings.with_changes(mute=True)
    return settings, path
