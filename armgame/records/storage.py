"""Durable little files: atomic writes and JSON read strictly as data.

Shared by the replay files and the high-score table. A write goes to a temporary file in
the target's own folder (a rename is only atomic within one file system), is flushed and
fsynced, renamed over the target, and then the folder itself is fsynced so that the rename
survives a power cut. A reader therefore sees the old file or the new one, never a mixture.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from pathlib import Path

from ..errors import UserError


class DataFileError(UserError):
    """A file that is not what it claims to be: unreadable, not JSON, or failing its schema."""


def _read_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_UMASK = _read_umask()


def atomic_write_bytes(path: Path, data: bytes) -> None:
    path = Path(path)
    folder = path.parent
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        # mkstemp makes the file private (0600); a shared classroom table wants the usual mode.
        with contextlib.suppress(OSError, AttributeError):
            os.fchmod(fd, 0o666 & ~_UMASK)
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    fsync_folder(folder)


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


def read_limited(path: Path, limit: int, what: str) -> bytes:
    path = Path(path)
    try:
        with open(path, "rb") as f:
            data = f.read(limit + 1)
    except FileNotFoundError:
        raise DataFileError(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise DataFileError(f"{path}: is a folder, not a {what}") from None
    except OSError as exc:
        raise DataFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise DataFileError(f"{path}: larger than {limit // (1024 * 1024)} MiB, too large for a {what}")
    return data


def dump_json(value: object) -> bytes:
    return (json.dumps(value, indent=1, sort_keys=True, allow_nan=False, ensure_ascii=False) + "\n").encode("utf-8")


# ---------------------------------------------------------------- schema checks
# Each raises ValueError naming the field; the callers add the file's name.

def check_int(name: str, value: object, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{name} must be a whole number, got {_show(value)}")
    if not low <= value <= high:
        raise ValueError(f"{name} must be from {low} to {high}, got {_show(value)}")
    return value


def check_float(name: str, value: object, low: float, high: float, low_open: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{name} must be a number, got {_show(value)}")
    value = float(value)
    if not math.isfinite(value) or not (low < value if low_open else low <= value) or value > high:
        interval = f"above {low:g} and at most {high:g}" if low_open else f"from {low:g} to {high:g}"
        raise ValueError(f"{name} must be a finite number {interval}, got {_show(value)}")
    return value


def check_str(name: str, value: object, max_len: int, printable: bool = True) -> str:
    if not isinstance(value, str):
        raise ValueError(f"{name} must be text, got {_show(value)}")
    if len(value) > max_len:
        raise ValueError(f"{name} must be at most {max_len} characters, got {len(value)}")
    if printable and not value.isprintable():
        raise ValueError(f"{name} must not contain control characters, got {_show(value)}")
    return value


def check_keys(name: str, value: object, required: set[str], optional: frozenset[str] = frozenset()) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{name} must be a JSON object, got {_show(value)}")
    missing = required - value.keys()
    if missing:
        raise ValueError(f"{name} lacks {', '.join(sorted(missing))}")
    unknown = value.keys() - required - optional
    if unknown:
        raise ValueError(f"{name} has unknown field(s) {', '.join(sorted(unknown)[:5])}")
    return value


def _show(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
