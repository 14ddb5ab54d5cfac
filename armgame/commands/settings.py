"""armgame settings: where the window's settings file is and the values in force."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "settings",
        help="the window's settings file and the values in force",
        description="Print the path of the settings file (key map, mute, palette, window size) and the values "
        "in force: the file's, or the defaults where it is silent. The file is TOML; the game rewrites it when "
        "you change something in the window (m mutes, resizing). Headless runs never read it.",
    )
    p.add_argument("--settings", metavar="FILE", default=None,
                   help="the settings file to read (default: $XDG_CONFIG_HOME/armgame/settings.toml)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..records.storage import user_path
    from ..ui.settings import load

    settings, path = load(user_path(args.settings, "--settings") if args.settings else None)
    print(f"{path}{'' if path.exists() else '  (no file yet: the defaults are in force)'}")
    for line in settings.describe():
        print(f"  {line}")
    return 0
