"""The class's lab runs on disk: where the clerk keeps each one, and how they are read again at a restart.

A person's first run of a protocol goes to ``lab/`` (the only runs the class curve reads, and what
``armgame analyze --class`` reads afterwards); their later runs and every program's run go to
``lab-more/``, kept for the teacher's CSV. A run's file is named by its player and its identity
(``lab_identity``: its game's and its protocol, whoever's name it carries). Both folders are the class's
own: a link or a file planted in their place is refused, never written through or read.

The clerk (``intake.Clerk``) decides which folder a run goes to and answers the student; this module only
writes and reads the files, on the clerk's thread.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..records.identity import game_digest
from ..records.replay import Replay
from ..records.storage import atomic_write_bytes, read_limited
from ..records.tablefile import name_slug

LAB_DIR, LAB_MORE_DIR = "lab", "lab-more"


@dataclass
class LabRun:
    player: str
    program: bool
    protocol: Any
    rows: list[dict[str, object]]
    path: Path
    #: A person's first run of its protocol (in ``lab/``): the only kind the class curve reads.
    first: bool = True


def lab_identity(replay: Replay) -> str:
    """A lab run's identity: its game's (``records.identity``) and its protocol, whoever's name it carries."""
    return hashlib.sha256((game_digest(replay) + repr(replay.task.as_dict())).encode()).hexdigest()  # type: ignore[union-attr]


def write_run(class_folder: Path, player: str, replay: Replay, identity: str, first: bool) -> Path:
    """``replay``, a lab run under ``player``'s name, kept durably in ``lab/`` if it is the player's ``first`` run
    of its protocol, else in ``lab-more/``; its path. UserError if a folder is not the class's own."""
    folder = class_folder / (LAB_DIR if first else LAB_MORE_DIR)
    real_folder(folder)
    path = folder / f"{name_slug(player)}-{identity[:12]}.json"
    atomic_write_bytes(path, replay.to_bytes(), "lab run")
    return path


def read_runs(class_folder: Path, max_bytes: int) -> tuple[list[LabRun], set[str], list[str]]:
    """The lab runs already in ``class_folder`` (a restart), each re-verified: the runs, every kept run's
    identity (so one sent again is known), and a line per run of ``lab/`` left out of the class curve."""
    from ..lab.analysis import trial_rows

    runs: list[LabRun] = []
    identities: set[str] = set()
    problems = []
    for path in runs_in(class_folder / LAB_DIR):
        try:
            replay = read_run(path, max_bytes)
            if replay.task is None or replay.player is None:
                raise UserError(f"{path}: not a lab run with a player's name")
            if replay.driven != "keyboard":
                raise UserError(f"{path}: a program's run (kept, never in the class curve)")
            ok, _, session = replay.task.verify(replay.config, replay.timeline, replay.result)
            if not ok:
                raise UserError(f"{path}: does not reproduce its trials")
        except UserError as exc:
            problems.append(str(exc))
            continue
        identities.add(lab_identity(replay))
        runs.append(LabRun(replay.player, replay.driven != "keyboard", replay.task.protocol,
                           trial_rows(session), path))
    for path in runs_in(class_folder / LAB_MORE_DIR):
        with contextlib.suppress(UserError):
            replay = read_run(path, max_bytes)
            identities.add(lab_identity(replay))
            if replay.task is None or replay.player is None:
                continue
            rows: list[dict[str, object]] = []
            if replay.driven != "keyboard":  # a program's run: its reaches are in the teacher's CSV
                ok, _, session = replay.task.verify(replay.config, replay.timeline, replay.result)
                if not ok:
                    continue
                rows = trial_rows(session)
            runs.append(LabRun(replay.player, replay.driven != "keyboard", replay.task.protocol,
                               rows, path, first=False))
    return runs, identities, problems


def real_folder(folder: Path) -> None:
    """``folder`` made if missing; refused if anything but a real folder is there (a planted link would
    carry the class's writes out of its folder)."""
    try:
        os.mkdir(folder, 0o700)
    except FileExistsError:
        pass
    except OSError as exc:
        raise UserError(f"cannot make the class's {folder.name}/ folder: {exc.strerror or exc}") from None
    if not stat.S_ISDIR(os.lstat(folder).st_mode):
        raise UserError(f"the class's {folder.name}/ is not a folder (a link or a file was put there): nothing was "
                        f"written")


def runs_in(folder: Path) -> list[Path]:
    """The lab runs kept in ``folder`` (regular files only: a planted link is not followed)."""
    if not folder.is_dir() or folder.is_symlink():
        return []
    return sorted(p for p in folder.glob("*.json") if p.is_file() and not p.is_symlink())


def read_run(path: Path, max_bytes: int) -> Replay:
    return Replay.from_bytes(read_limited(path, max_bytes, "lab run", follow=False), str(path))
