"""The files a command writes for a person (``--record``, ``--out``): none is ever replaced unless asked.

One policy for every command, so that a teacher's rehearsal cannot wipe a volunteer's run:

* A file named outright (``--record ann.json``, ``--out curve.csv``, ``--out DIR``'s own names) that
  exists already is refused, in one line naming it and ``--force``, before the game or the run starts, so
  no minute of play is lost; ``--force`` replaces it. The write itself makes a new file or fails
  (``storage.fresh_files``): a file that appears during the run is not replaced either.
* A name armgame makes (``--record FOLDER``, or ``--record`` alone for the current folder) is numbered:
  ``ann-b-game3.json``, the player's name and the first number past the highest there, claimed
  atomically (``storage.write_new``), so it never needs ``--force`` and two games finishing at once get
  two numbers. A window's later games with ``--record FILE`` are numbered the same way beside it
  (``FILE-2.json`` and on).
* Whatever is written, the line printed (and the window's end screen) names it.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from ..errors import UserError


def add_force_option(p: argparse.ArgumentParser, what: str = "the files it writes") -> None:
    p.add_argument("--force", action="store_true",
                   help=f"replace {what} if they exist (without it, an existing file is never replaced: the "
                   "command stops before it starts)")


def refusal(path: Path, what: str = "file") -> str:
    """The one line for a file that would be replaced."""
    from ..records.storage import show_path

    return f"{show_path(path)} already exists: armgame never replaces a {what} (add --force to replace it, " \
        f"or give another name)"


def refuse_existing(paths: Iterable[Path], force: bool, what: str = "file") -> None:
    """Before any work: a target that is there already is one ``UserError`` unless ``force``."""
    from ..records.storage import check_output_path, is_taken

    if force:
        return
    for path in paths:
        if is_taken(path):
            check_output_path(path, what)  # a device or a FIFO is refused for what it is, first
            raise UserError(refusal(path, what))


@contextlib.contextmanager
def fresh_outputs(paths: Iterable[Path], force: bool, what: str = "file",
                  folder: Path | None = None) -> Iterator[None]:
    """Refuse now any of ``paths`` that exists (unless ``force``); while the block runs, writes to them (and
    to any file directly in ``folder``) make new files only, whoever below the command writes them."""
    from ..records.storage import fresh_files

    paths = list(paths)
    refuse_existing(paths, force, what)
    if force:
        yield
        return
    with fresh_files(paths, [] if folder is None else [folder]):
        yield


def is_folder_target(text: str) -> bool:
    """``--record`` names a folder: one that exists, or a path ending in a separator."""
    from ..records.storage import user_path

    return text.endswith(("/", os.sep)) or user_path(text, "--record").is_dir()


def slug(name: str | None) -> str:
    """A player's name as the start of a file name: "Ann B" is "ann-b" (``tablefile.name_slug``)."""
    from ..records.tablefile import name_slug

    return name_slug(name or "").lower()


@dataclass
class RecordTarget:
    """Where ``--record`` keeps replays: a file (the first one; a window's later games numbered beside
    it), or a folder, where each is ``NAME-KINDn.json`` (``ann-b-game3.json``, ``ann-b-lab1.json``)."""

    path: Path
    folder: bool
    force: bool = False
    kind: str = "game"
    #: Replays kept so far in this command (a window plays several games).
    kept: int = 0

    @classmethod
    def parse(cls, text: str, force: bool, kind: str = "game") -> RecordTarget:
        """Check ``--record`` before the game: a folder that exists and can be written, or a file that
        can be written and is not there already (unless ``force``)."""
        from ..records.storage import check_output_path, check_writable_folder, user_path

        path = user_path(text, "--record")
        if is_folder_target(text):
            if not path.is_dir():
                raise UserError(f"--record {text}: no such folder")
            check_writable_folder(path, "--record")
            return cls(path, True, force, kind)
        check_output_path(path, "replay")
        refuse_existing([path], force, "replay")
        return cls(path, False, force, kind)

    def save(self, replay) -> Path:
        """Write one replay, never over another (``--force`` aside: the file named outright); the path."""
        from ..limits import MAX_REPLAY_BYTES
        from ..records.storage import DataFileError, atomic_write_bytes, write_new

        data, player = replay.to_bytes(), replay.player
        if len(data) > MAX_REPLAY_BYTES:  # cannot happen within MAX_EVENTS; the writer's half of the limit
            raise DataFileError(f"the replay would be {len(data)} bytes, more than a replay may be")
        self.kept += 1
        if self.folder:
            stem = f"{slug(player)}-{self.kind}"
            return write_new(lambda n: self.path / f"{stem}{n}.json", self._next_number(stem), data, "replay")
        if self.kept == 1:
            atomic_write_bytes(self.path, data, "replay", replace=self.force)
            return self.path
        stem, suffix = self.path.stem, self.path.suffix or ".json"
        name_of = lambda n: self.path.with_name(f"{stem}-{n}{suffix}")  # noqa: E731
        if self.force:
            atomic_write_bytes(name_of(self.kept), data, "replay", replace=True)
            return name_of(self.kept)
        return write_new(name_of, self.kept, data, "replay")

    def _next_number(self, stem: str) -> int:
        """One past the highest number of ``stem`` in the folder: the newest game has the highest."""
        pattern = re.compile(re.escape(stem) + r"([1-9][0-9]{0,8})\.json")
        highest = 0
        try:
            with os.scandir(self.path) as entries:
                for entry in entries:
                    match = pattern.fullmatch(entry.name)
                    if match:
                        highest = max(highest, int(match.group(1)))
        except OSError:  # the write itself says what is wrong with the folder
            pass
        return highest + 1
