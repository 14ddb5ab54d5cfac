"""Durable little files: one safe way to read and to write every file armgame touches.

Every reader and writer of the program goes through this module: scripts, replays, the
score table and its cache, settings, ``simulate --out``, ``play --record`` and figures.
What it guarantees, whatever is planted at the path:

* Reading: the path is opened without blocking (``O_NONBLOCK``, so a FIFO cannot hang the
  reader), then ``fstat`` must show a regular file, and at most ``limit + 1`` bytes are
  read. Inside a folder armgame owns (the score table's), symlinks are not followed.
* Writing: the target, if it exists, must be a regular file (or a symlink, which is
  replaced, never written through); a device, FIFO, socket or folder is refused in one line.
  The data goes to a temporary file created exclusively (``O_CREAT | O_EXCL | O_NOFOLLOW``,
  so a planted temporary name or symlink is never written through) in the target's own
  folder (a rename is only atomic within one file system), is flushed and fsynced, renamed
  over the target, and then the folder is fsynced so that the rename survives a power cut.
  A reader therefore sees the old file or the new one, never a mixture.
* A file made for a person (a replay ``--record`` names, the CSVs and figures of ``--out``) is never
  replaced unless asked: the temporary file is *linked* to its name (``link_new``), which fails if
  anything is there, instead of renamed over it. ``fresh_files`` says which targets those are, so the
  writers below the commands (the lab's CSVs, the figures) keep the promise without knowing of it.
* Paths given by the user: ``~user`` that names nobody, or a path too long for the file system, is
  one line, not a traceback.

The reading half (``open_regular``, ``read_limited``, ``user_path``, ``DataFileError``) lives in
``armgame.files``, below every layer, so the game reads its scripts without reaching up to records;
it is re-exported here, where every other reader and writer finds it. What a valid field of a file
read is (the schema checks every reader applies to what ``parse_json`` returns) is ``armgame.valid``'s.
"""

from __future__ import annotations

import contextlib
import contextvars
import json
import math
import os
import secrets
import stat
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any, BinaryIO

from ..files import (
    _CLOEXEC,
    _NOFOLLOW,
    DataFileError,
    check_path_length,
    open_regular,
    read_limited,
    show_path,
    user_path,
)
from ..files import kind_of as _kind

__all__ = ["STRICT_DECODER", "DataFileError", "atomic_write_bytes", "atomic_writer", "check_output_path",
           "check_path_length", "check_writable_folder", "copy_aside", "dump_json", "fresh_files", "fsync_folder",
           "is_taken", "link_new", "open_regular", "parse_json", "read_limited", "save_figure", "show_path",
           "user_path", "write_new"]


def _read_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_UMASK = _read_umask()


def _folder_mode(folder: Path, about: str) -> int | None:
    """The mode of ``folder`` (following links), None if there is nothing there; any other failure to
    look (a path too long for the file system, no permission to search) is one ``DataFileError``
    beginning ``about``. pathlib's ``exists()`` and ``is_dir()`` raise for those instead."""
    try:
        return os.stat(folder).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        raise DataFileError(f"{about}: {exc.strerror or exc}") from None


def check_output_path(path: Path, what: str = "file") -> Path:
    """Refuse, before any work, a target that is not (or cannot become) a regular file.

    An existing symlink is allowed: the atomic rename replaces the link itself, so nothing is
    ever written through it. The folder must exist and be a folder.
    """
    path = Path(path)
    if not path.name or path.name in (".", ".."):
        raise DataFileError(f"{show_path(path)}: not a file name")
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise DataFileError(f"{show_path(path)}: cannot write the {what}: {exc.strerror or exc}") from None
    if st is not None and not (stat.S_ISREG(st.st_mode) or stat.S_ISLNK(st.st_mode)):
        raise DataFileError(f"{show_path(path)}: is {_kind(st.st_mode)}; the {what} is written only to a regular file")
    folder = path.parent
    mode = _folder_mode(folder, f"{show_path(path)}: cannot write the {what}")
    if mode is None or not stat.S_ISDIR(mode):
        raise DataFileError(f"{show_path(path)}: cannot write the {what}: folder {show_path(folder)} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):  # known before a game or a run, not after it
        raise DataFileError(f"{show_path(path)}: cannot write the {what}: folder {show_path(folder)} is not "
                            f"writable by you")
    return path


def check_writable_folder(folder: Path, what: str = "folder", room: int = 0) -> None:
    """Find out before a game that its results could not be saved there (not after it): ``room`` is the
    longest path, in bytes, of what will be made inside (``files.check_path_length``)."""
    folder = Path(folder)
    check_path_length(folder, what, room)
    probe = folder
    about = f"{what} {show_path(folder)}: cannot use it"
    while (mode := _folder_mode(probe, about)) is None:  # the nearest existing ancestor decides whether mkdir works
        if probe.parent == probe:
            break
        probe = probe.parent
    if mode is None or not stat.S_ISDIR(mode):
        raise DataFileError(f"{what} {show_path(folder)}: {show_path(probe)} is not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise DataFileError(f"{what} {show_path(folder)}: {show_path(probe)} cannot be written by you")


def _temporary(folder: Path, name: str, private: bool = False) -> tuple[int, Path]:
    """A new temporary file beside ``name``: readable by all the umask allows, or by its owner only (``private``)."""
    mode = 0o600 if private else 0o666 & ~_UMASK
    for _ in range(100):
        tmp = folder / f".{name}.{secrets.token_hex(6)}.tmp"
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, mode)
        except FileExistsError:
            continue
        return fd, tmp
    raise DataFileError(f"{folder}: cannot create a temporary file")


#: The targets that must not be replaced (``fresh_files``), as ``_key`` spells them: a context variable, so
#: that two commands run in one process (the tests, a thread) never see each other's.
_FRESH: contextvars.ContextVar[frozenset[str]] = contextvars.ContextVar("armgame_fresh_files", default=frozenset())


def _key(path: Path) -> str:
    return os.path.normcase(os.path.abspath(path))


def is_taken(path: Path) -> bool:
    """Something, anything (a dangling symlink too), is at ``path``: a new file may not be made there."""
    try:
        os.lstat(path)
    except FileNotFoundError:
        return False
    except OSError:  # cannot tell (a name too long, no permission): the writer's own check says why
        return False
    return True


@contextlib.contextmanager
def fresh_files(paths: Iterable[Path] = (), folders: Iterable[Path] = ()) -> Iterator[None]:
    """While the block runs, every atomic write to one of ``paths``, or to any file directly in one of
    ``folders`` (a figure added to a command's output later is covered too), makes a new file or fails
    (a ``DataFileError``), whichever function below the command writes it."""
    keys = {_key(Path(p)) for p in paths} | {_key(Path(f)) + os.sep for f in folders}
    token = _FRESH.set(_FRESH.get() | keys)
    try:
        yield
    finally:
        _FRESH.reset(token)


def _is_fresh(path: Path) -> bool:
    fresh = _FRESH.get()
    key = _key(path)
    return key in fresh or (os.path.dirname(key) + os.sep) in fresh


def link_new(tmp: Path, path: Path) -> None:
    """Give the whole file ``tmp`` the name ``path`` only if nothing is there (``FileExistsError`` if
    something is), never replacing it, even if it appeared a moment ago: two writers racing for one name
    cannot both have it. ``tmp`` is gone afterwards.

    A hard link is atomic and refuses an existing name (a symlink too: nothing is written through it).
    Where the file system has no hard links (FAT, some network shares): on Windows a plain rename, which
    never replaces there; elsewhere the name is claimed by an exclusive create and the file renamed onto
    the claim (a crash between leaves an empty file, never a lost one)."""
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise
    except (AttributeError, NotImplementedError, OSError):  # no hard links here: the ways below say why not
        if os.name == "nt":
            os.rename(tmp, path)
            return
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, 0o666 & ~_UMASK)
        os.close(fd)
        os.replace(tmp, path)
        return
    with contextlib.suppress(OSError):
        os.unlink(tmp)


@contextlib.contextmanager
def atomic_writer(path: Path, what: str = "file", replace: bool | None = None,
                  private: bool = False) -> Iterator[BinaryIO]:
    """Yield a binary file whose content replaces ``path`` atomically when the block ends cleanly.

    Rows can be streamed into it (``simulate`` writes as it integrates); on any error the
    temporary file is removed and the target stays as it was. ``replace=False`` makes a new file or
    fails if ``path`` is taken (``link_new``); None: False for the targets of ``fresh_files``, else True.
    ``private``: the file is its owner's to read (a token that proves a name, say).
    """
    path = check_output_path(Path(path), what)
    if replace is None:
        replace = not _is_fresh(path)
    folder = path.parent
    try:
        fd, tmp = _temporary(folder, path.name, private)
    except OSError as exc:
        raise DataFileError(f"{show_path(path)}: cannot write the {what}: {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        check_output_path(path, what)  # the target may have been swapped for a FIFO while we wrote
        if replace:
            os.replace(tmp, path)
        else:
            link_new(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, FileExistsError):
            raise DataFileError(f"{show_path(path)}: already exists (it appeared while the {what} was made): "
                                f"it was not replaced") from None
        if isinstance(exc, OSError):
            raise DataFileError(f"{show_path(path)}: cannot write the {what}: {exc.strerror or exc}") from None
        raise
    fsync_folder(folder)


def atomic_write_bytes(path: Path, data: bytes, what: str = "file", replace: bool | None = None,
                       private: bool = False) -> None:
    with atomic_writer(path, what, replace, private) as f:
        f.write(data)


def _durable_temporary(path: Path, data: bytes, what: str) -> Path:
    """``data`` in a new temporary file beside ``path``, flushed to disk: ready to be given its name. Nothing is
    left behind if writing it fails."""
    try:
        fd, tmp = _temporary(path.parent, path.name)
    except OSError as exc:
        raise DataFileError(f"{show_path(path)}: cannot write the {what}: {exc.strerror or exc}") from None
    with _removed_on_failure(tmp, path, what), os.fdopen(fd, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    return tmp


@contextlib.contextmanager
def _removed_on_failure(tmp: str, path: Path, what: str) -> Iterator[None]:
    """Removes the temporary file ``tmp`` if the block fails; an OS error becomes one line naming ``path``."""
    try:
        yield
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise DataFileError(f"{show_path(path)}: cannot write the {what}: {exc.strerror or exc}") from None
        raise


#: The most numbered names ``write_new`` tries before it gives up: far more than any class makes.
MAX_NUMBERED = 10_000


def write_new(name_of: Callable[[int], Path], first: int, data: bytes, what: str = "file") -> Path:
    """Write ``data`` to a new file ``name_of(n)``, the first ``n`` from ``first`` whose name is free, and
    return it. Each name is claimed atomically (``link_new``): two writers at once get two numbers, and
    no file already there is ever replaced. All the names lie in one folder."""
    first_path = check_output_path(Path(name_of(first)), what)
    folder = first_path.parent
    tmp = _durable_temporary(first_path, data, what)
    with _removed_on_failure(tmp, first_path, what):
        for n in range(first, first + MAX_NUMBERED):
            path = Path(name_of(n))
            if n != first:
                check_output_path(path, what)
            try:
                link_new(tmp, path)
            except FileExistsError:
                continue
            fsync_folder(folder)
            return path
        raise DataFileError(f"{show_path(first_path)}: {MAX_NUMBERED:,} numbered names after it are all taken")


def atomic_write_many(items: list[tuple[Path, bytes]], what: str = "file") -> None:
    """``atomic_write_bytes`` for many files of one folder, as durable, at a fraction of the cost.

    Each file is written to its temporary file; the temporary files are fsynced together (on threads:
    the file system commits them in one journal transaction rather than one each, 0.13 ms a file
    rather than 0.31 for a class's batch of replays here), then renamed; the folder is fsynced once,
    after the last rename. On an error the files not yet renamed are removed and the error is raised:
    the ones renamed are whole."""
    written: list[tuple[int, Path, Path]] = []  # (open file, temporary, target)
    pending: list[tuple[Path, Path]] = []
    try:
        for path, data in items:
            path = check_output_path(Path(path), what)
            fd, tmp = _temporary(path.parent, path.name)
            written.append((fd, tmp, path))
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
        _fsync_together([fd for fd, _, _ in written])
        while written:
            fd, tmp, path = written.pop(0)
            os.close(fd)
            pending.append((tmp, path))
        while pending:
            tmp, path = pending[0]
            check_output_path(path, what)
            os.replace(tmp, path)
            pending.pop(0)
    except BaseException as exc:
        for fd, tmp, _ in written:
            with contextlib.suppress(OSError):
                os.close(fd)
            pending.append((tmp, Path()))
        for tmp, _ in pending:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        if isinstance(exc, OSError):
            raise DataFileError(f"cannot write the {what}: {exc.strerror or exc}") from None
        raise
    for folder in {Path(path).parent for path, _ in items}:
        fsync_folder(folder)


#: Threads that fsync a batch's files at once (``atomic_write_many``); made when first needed.
_SYNCERS: Any = None


def _fsync_together(fds: list[int]) -> None:
    global _SYNCERS
    if len(fds) <= 1:
        for fd in fds:
            os.fsync(fd)
        return
    if _SYNCERS is None:
        from concurrent.futures import ThreadPoolExecutor  # here: only a batch's writer needs it (7 ms to import)

        _SYNCERS = ThreadPoolExecutor(max_workers=8, thread_name_prefix="armgame-fsync")
    for _ in _SYNCERS.map(os.fsync, fds):  # an error raised by any is raised here
        pass


def save_figure(fig: object, path: Path, **options: object) -> Path:
    """A matplotlib figure saved through ``atomic_writer`` (the format from the file's suffix)."""
    path = Path(path)
    with atomic_writer(path, "figure") as f:
        fig.savefig(f, format=path.suffix.lstrip(".").lower() or "png", **options)  # type: ignore[attr-defined]
    return path


def copy_aside(source_fd: int, target: Path) -> None:
    """Copy an open file's bytes to a new file ``target`` (created exclusively), fsynced."""
    fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, 0o666 & ~_UMASK)
    try:
        os.lseek(source_fd, 0, os.SEEK_SET)
        while chunk := os.read(source_fd, 1 << 20):
            view = memoryview(chunk)
            while view:
                view = view[os.write(fd, view):]
        os.fsync(fd)
    except BaseException:
        os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(target)
        raise
    os.close(fd)
    fsync_folder(target.parent)


def fsync_folder(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # some platforms cannot open folders; the rename is still atomic there
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _no_constants(name: str) -> float:
    # Python's json would otherwise accept NaN and Infinity, which are not JSON.
    raise ValueError(f"{name} is not a JSON number")


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):  # 1e999 parses as infinity
        raise ValueError(f"{text[:20]} is out of range")
    return value


#: A decoder that yields plain data only: no NaN/Infinity, no out-of-range floats.
STRICT_DECODER = json.JSONDecoder(parse_constant=_no_constants, parse_float=_finite_float)


def parse_json(text: str | bytes) -> object:
    """Parse JSON text as plain data: no NaN/Infinity, bounded nesting, no code ever run."""
    if isinstance(text, bytes):
        text = text.decode("utf-8")
    try:
        return STRICT_DECODER.decode(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"not valid JSON: {exc}") from None
    except RecursionError:
        raise ValueError("not valid JSON: nested too deeply") from None


def dump_json(value: object) -> bytes:
    return (json.dumps(value, indent=1, sort_keys=True, allow_nan=False, ensure_ascii=False) + "\n").encode("utf-8")
