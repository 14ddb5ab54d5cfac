"""Reading a file safely, and checking a path the user typed: what every layer may need of files.

The game reads scripts, records reads replays and tables, the lab reads protocols: they all read
through ``read_limited`` here, which lives below every layer (like ``errors`` and ``limits``, it
imports nothing of armgame but ``errors``) so that no layer reaches up to another for it.
``armgame.records.storage`` holds the rest (writing, JSON) and re-exports these; ``armgame.valid``, the
schema checks.

* Reading: the path is opened without blocking (``O_NONBLOCK``, so a FIFO cannot hang the
  reader), then ``fstat`` must show a regular file, and at most ``limit + 1`` bytes are
  read. Inside a folder armgame owns (the score table's), symlinks are not followed.
* Paths given by the user (``user_path``): ``~user`` that names nobody, and a path the file system
  cannot name (a name over its ``NAME_MAX`` bytes, the whole over its ``PATH_MAX``), are one line,
  before anything is read, written or played, not an ``OSError: File name too long`` at some depth.
"""

from __future__ import annotations

import errno
import os
import stat
import tomllib
from pathlib import Path

from .errors import UserError


class DataFileError(UserError):
    """A file that is not what it claims to be: unreadable, not JSON, or failing its schema."""


# POSIX flags, each optional: where the platform lacks one (Windows has none of these) the same
# promise is kept another way, or is moot there (a FIFO or a terminal cannot sit at a file path).
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_NOCTTY = getattr(os, "O_NOCTTY", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_BINARY = getattr(os, "O_BINARY", 0)  # Windows: bytes as they are, no newline translation
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)

#: Where the file system does not say (Windows has no ``pathconf``): the longest name of NTFS, APFS and
#: ext4, and the longest path Windows takes with long paths enabled.
DEFAULT_NAME_MAX = 255
DEFAULT_PATH_MAX = 32767 if os.name == "nt" else 4096
#: Bytes a path the user types must leave below the longest path: for the names armgame makes in it or
#: beside it (``scores.json`` in a folder, ``.NAME.0123456789ab.tmp`` beside a file written atomically).
USER_PATH_ROOM = 64


def show_path(path: object) -> str:
    """A path for a one-line message: control characters escaped, at most 200 characters."""
    text = str(path)
    if not text.isprintable():
        text = repr(text)[1:-1]
    return text if len(text) <= 200 else text[:197] + "..."


def user_data_dir() -> Path:
    """armgame's per-user data folder by each platform's convention (``platformdirs``): the table's,
    the lab's runs and the class client's live in it, so they are found side by side on every platform.
    Here, below every layer, so the student's client finds its folder without loading the table."""
    import platformdirs

    return Path(platformdirs.user_data_dir("armgame", appauthor=False))


def user_path(text: str | os.PathLike[str], what: str = "path") -> Path:
    """A path the user typed, ``~`` expanded; a ``~user`` that names nobody, or a path too long for the
    file system (``check_path_length``), is a ``UserError``."""
    if isinstance(text, str) and not text:
        raise UserError(f"{what} is empty")
    try:
        path = Path(text).expanduser()
    except RuntimeError:  # Path("~nosuchuser/x").expanduser(): "Could not determine home directory"
        raise UserError(f"{what} {str(text)[:80]!r}: no such user's home folder") from None
    check_path_length(path, what, USER_PATH_ROOM)
    return path


def path_limits(path: Path) -> tuple[int, int]:
    """(longest name, longest path) in bytes of the file system ``path`` is (or would be) on: asked of its
    nearest existing folder, since a path not yet made lands on the file system of its nearest ancestor."""
    probe = os.path.abspath(path)
    while not os.path.isdir(probe):  # isdir says False, never raises, for a path too long to ask about
        parent = os.path.dirname(probe)
        if parent == probe:
            break
        probe = parent
    limits = []
    for name, default in (("PC_NAME_MAX", DEFAULT_NAME_MAX), ("PC_PATH_MAX", DEFAULT_PATH_MAX)):
        try:
            limits.append(os.pathconf(probe, name) or default)  # type: ignore[attr-defined]  # no pathconf on Windows
        except (AttributeError, OSError, ValueError):  # no pathconf here, or the file system will not say
            limits.append(default)
    return limits[0], limits[1]


def check_path_length(path: Path, what: str = "path", room: int = 0) -> None:
    """Refuse a path the file system cannot name, in one line naming ``what``: a name in it longer than
    the file system's longest name, or the whole (made absolute, with ``room`` more for the files armgame
    will make in or beside it) longer than its longest path, in the system's units (bytes; UTF-16 units
    on Windows)."""
    name_max, path_max = path_limits(path)
    longest = max(Path(path).parts, key=_size_of, default="")
    size = _size_of(longest)
    if size > name_max:
        raise UserError(f"{what} {show_path(path)}: a name in it is {size:,} {_UNITS} long, more than the file "
                        f"system allows ({name_max})")
    size = _size_of(os.path.abspath(path))
    most = path_max - 1 - room  # PATH_MAX counts the terminating NUL
    if size > most:
        extra = " (with room for the names armgame makes in it or beside it)" if room else ""
        raise UserError(f"{what} {show_path(path)}: the path is {size:,} {_UNITS} long, more than the file system "
                        f"allows{extra}: {most:,}")


#: What the file system counts a name's length in: Windows' (NTFS) in UTF-16 units, POSIX ones in bytes.
_UNITS = "characters" if os.name == "nt" else "bytes"


def _size_of(text: str) -> int:
    """The length of a name or path as the file system counts it (``_UNITS``)."""
    if os.name == "nt":
        return len(text.encode("utf-16-le", "surrogatepass")) // 2
    return len(os.fsencode(text))


def kind_of(mode: int) -> str:
    """What a file of ``mode`` is, for a message: "a folder", "a FIFO", ..."""
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    return "not a regular file"


def open_regular(path: Path, what: str, follow: bool = True) -> int:
    """Open ``path`` for reading without blocking and return the descriptor of a regular file.

    ``O_NONBLOCK`` makes opening a FIFO return at once (no writer needed); ``fstat`` on the
    open descriptor then refuses it, so there is no window between the check and the read. A
    platform without ``O_NONBLOCK`` (Windows, where no FIFO sits at a file path) checks the path
    before opening it.
    ``follow=False`` refuses a symlink (files inside a folder armgame owns): by ``O_NOFOLLOW``, or
    where the platform has none, by ``lstat`` before the open and the same file (device and inode)
    after it, so a symlink swapped in between is refused too.
    """
    path = Path(path)
    flags = os.O_RDONLY | _NONBLOCK | _NOCTTY | _CLOEXEC | _BINARY | (0 if follow else _NOFOLLOW)
    seen = None
    try:
        if (not follow and not _NOFOLLOW) or not _NONBLOCK:
            seen = os.stat(path, follow_symlinks=follow)
            if stat.S_ISLNK(seen.st_mode):
                raise OSError(errno.ELOOP, "is a symbolic link")
            if not stat.S_ISREG(seen.st_mode) and not stat.S_ISDIR(seen.st_mode):
                # No O_NONBLOCK: a FIFO would block the open itself, so it is refused before.
                raise DataFileError(f"{show_path(path)}: is {kind_of(seen.st_mode)}, not a {what}")
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise DataFileError(f"{show_path(path)}: no such {what}") from None
    except IsADirectoryError:
        raise DataFileError(f"{show_path(path)}: is a folder, not a {what}") from None
    except OSError as exc:
        if exc.errno == errno.ELOOP and not follow:
            raise DataFileError(f"{show_path(path)}: is a symbolic link; a {what} here must be a regular file") \
                from None
        raise DataFileError(f"{show_path(path)}: cannot read: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if seen is not None and (st.st_dev, st.st_ino) != (seen.st_dev, seen.st_ino):
            raise DataFileError(f"{show_path(path)}: changed while it was opened (a symbolic link swapped in?)")
        if not stat.S_ISREG(st.st_mode):
            raise DataFileError(f"{show_path(path)}: is {kind_of(st.st_mode)}, not a {what}")
        if _NONBLOCK and os.get_blocking(fd) is False:
            os.set_blocking(fd, True)  # a regular file never blocks; plain reads from here on
    except BaseException:
        os.close(fd)
        raise
    return fd


def read_limited(path: Path, limit: int, what: str, follow: bool = True) -> bytes:
    """At most ``limit`` bytes of the regular file ``path``; anything else is one ``DataFileError``."""
    path = Path(path)
    fd = open_regular(path, what, follow)
    try:
        with os.fdopen(fd, "rb") as f:
            data = f.read(limit + 1)
    except OSError as exc:
        raise DataFileError(f"{show_path(path)}: cannot read: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise DataFileError(f"{show_path(path)}: larger than {_size(limit)}, too large for a {what}")
    return data


def _size(n: int) -> str:
    return f"{n // (1024 * 1024)} MiB" if n >= 1024 * 1024 else f"{n} bytes"


def parse_toml(data: bytes, source: object, not_text: str, error: type[Exception] = UserError) -> dict:
    """A TOML file's bytes as data; ``error`` in one line naming ``source`` on any fault (``not_text``: what the
    file should have been, said when it is not UTF-8 text)."""
    try:
        return tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise error(f"{source}: {not_text}") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{source}: not valid TOML: {exc}") from None
    except RecursionError:  # tomllib recurses into nested arrays and tables
        raise error(f"{source}: not valid TOML: nested too deeply") from None
