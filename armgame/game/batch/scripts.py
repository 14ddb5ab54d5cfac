"""A class's scripts: one game per student's script file, all played in one batch.

Owns ``armgame play --headless --script A B ...`` (or a folder of ``*.txt``): finding the files,
reading and checking every script, and the bounds on one run. Invariant: everything is checked and
bounded before any game runs (how many files, their bytes, their events together; a bad script is
named in one line and nothing is played); files are regular files directly in the folder given,
never a symbolic link followed. Each result is the single session's (``replay_many``).
"""

from __future__ import annotations

import os
import stat
from collections.abc import Sequence
from pathlib import Path

from ...errors import UserError
from ...files import user_path
from ..rules import GameConfig
from ..session import RESET_KEY, TOGGLE_ARM_KEY, GameResult
from .replays import replay_many

#: Bounds on one class run (``armgame play --headless --script A B ...``), checked before any game runs.
MAX_SCRIPTS = 5000
MAX_SCRIPT_EVENTS = 2_000_000
MAX_SCRIPTS_BYTES = 256 * 1024 * 1024


def files_in(folder: Path, suffix: str, limit: int, what: str) -> list[Path]:
    """The regular files ``*suffix`` directly in ``folder``, sorted by name.

    Symbolic links are skipped, never followed (a link could lead out of the folder), as
    are hidden files and subfolders; more than ``limit`` files is refused before any is read.
    """
    try:
        entries = sorted(os.scandir(folder), key=lambda e: e.name)
    except OSError as exc:
        raise UserError(f"{folder}: cannot list the folder: {exc.strerror or exc}") from None
    found = [Path(e.path) for e in entries
             if e.name.endswith(suffix) and not e.name.startswith(".") and e.is_file(follow_symlinks=False)]
    if len(found) > limit:
        raise UserError(f"{folder}: {len(found)} {what}, more than the {limit} one run takes")
    return found


def script_paths(names: Sequence[str | Path]) -> list[Path]:
    """Script files from the command line: files as given, folders as their ``*.txt`` files in sorted order."""
    paths: list[Path] = []
    for name in names:
        path = user_path(name, "--script")  # a name the file system cannot take is one line, not an OSError
        if path.is_dir():
            inside = files_in(path, ".txt", MAX_SCRIPTS, "scripts")
            if not inside:
                raise UserError(f"{path}: no *.txt scripts in this folder")
            paths += inside
        else:
            paths.append(path)
        if len(paths) > MAX_SCRIPTS:
            raise UserError(f"more than {MAX_SCRIPTS} scripts in one run: split the class into several runs")
    total = 0
    for path in paths:
        try:
            info = path.stat()
        except OSError:
            continue  # the reader names what is wrong with it
        if stat.S_ISREG(info.st_mode):
            total += info.st_size
    if total > MAX_SCRIPTS_BYTES:
        raise UserError(f"the scripts add up to {total // (1024 * 1024)} MiB, more than the "
                        f"{MAX_SCRIPTS_BYTES // (1024 * 1024)} MiB one run takes")
    return paths


def play_scripts(config: GameConfig, paths: Sequence[Path]) -> list[GameResult]:
    """Play one game per script (``config`` with each), all in one batch; results in order.

    Every script is read and checked before any game runs, and their events together are
    bounded by ``MAX_SCRIPT_EVENTS``.
    """
    # Here, not at the top: importing the batch (as the vector env does) loads no script reader.
    from ..script import load_script

    keys = (*(m.key for m in config.muscles), RESET_KEY, TOGGLE_ARM_KEY)
    timelines, total = [], 0
    for path in paths:
        if not path.is_file():
            raise UserError(f"{path}: not a script file" if path.exists() else f"{path}: no such script file")
        timeline = load_script(path, keys, config.dt)
        total += len(timeline)
        if total > MAX_SCRIPT_EVENTS:
            raise UserError(f"the scripts hold more than {MAX_SCRIPT_EVENTS} events together (at {path}): "
                            "split the class into several runs")
        timelines.append(timeline)
    return replay_many([config] * len(paths), timelines)
