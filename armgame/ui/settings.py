"""The window's settings that persist between games: key map, mute, palette, text scale, window size.

A small TOML file in the user's config folder (``$XDG_CONFIG_HOME/armgame/settings.toml``, normally
``~/.config/armgame/settings.toml``; ``%APPDATA%\\armgame`` on Windows, ``~/Library/Application
Support/armgame`` on macOS), or the file ``--settings``
names. It is read with ``tomllib`` through the storage module's size-limited reader, only when it is a
regular file (never a symlink, a FIFO or a device), and every value is checked: a bad file is refused in
one line naming the key. The window rewrites it atomically when the player changes something there
(``m`` mutes). Headless runs never read it: a script's keys and a replay's result must not depend on
who runs them.

No pygame here: ``armgame settings`` and the tests use it without SDL.
"""

from __future__ import annotations

import os
import stat
import sys
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import UserError
from ..files import parse_toml

FILE_NAME = "settings.toml"
#: A settings file is a few lines; anything larger is not one.
MAX_BYTES = 64 * 1024
PALETTES = ("okabe-ito", "classic", "high-contrast")
#: ``text_scale``: every text this many times its usual size (1.5 for the back of a large room).
MIN_TEXT_SCALE, MAX_TEXT_SCALE = 0.75, 2.5
MIN_SIDE, MAX_SIDE = 320, 10000
DEFAULT_KEYS = "dfjk"
#: Keys the windows use for themselves: a muscle cannot take them.
RESERVED_KEYS = frozenset({"space", "tab", "escape", "p", "f11"})


class SettingsError(UserError):
    """A settings file that cannot be used, named with the key at fault."""


@dataclass(frozen=True)
class Settings:
    keys: str = DEFAULT_KEYS
    mute: bool = False
    palette: str = PALETTES[0]
    text_scale: float = 1.0
    #: Window size in pixels; None: a default that fits the desktop.
    size: tuple[int, int] | None = None

    def with_changes(self, **changes: object) -> Settings:
        return replace(self, **changes)  # type: ignore[arg-type]

    def to_toml(self) -> str:
        """The file's text. Values go through ``tomli_w``, which escapes quotes, backslashes and the
        rest, so whatever ``from_toml`` accepted is written back as TOML it accepts again."""
        import tomli_w

        values: dict[str, object] = {"keys": self.keys, "mute": self.mute, "palette": self.palette,
                                     "text_scale": self.text_scale}
        if self.size is not None:
            values["size"] = f"{self.size[0]}x{self.size[1]}"
        return ("# armgame window settings: `armgame settings` shows them; the game rewrites this file when\n"
                "# you change something in the window (m mutes).\n" + tomli_w.dumps(values))

    def describe(self) -> list[str]:
        size = f"{self.size[0]}x{self.size[1]}" if self.size else "fit the desktop (default)"
        return [f"keys = {self.keys}", f"mute = {str(self.mute).lower()}", f"palette = {self.palette}",
                f"text_scale = {self.text_scale:g}", f"size = {size}"]


def default_path() -> Path:
    """The platform's per-user config folder: ``platformdirs``' on Windows (``%APPDATA%``) and macOS
    (``~/Library/Application Support``); elsewhere the XDG rule, which ignores a relative path."""
    if sys.platform in ("win32", "darwin"):
        import platformdirs

        base = Path(platformdirs.user_config_dir(appauthor=False, roaming=True))
    else:
        xdg = os.environ.get("XDG_CONFIG_HOME", "")
        # The XDG spec: a relative path in $XDG_CONFIG_HOME is invalid and must be ignored.
        base = Path(xdg) if xdg and os.path.isabs(xdg) else Path.home() / ".config"
    return base / "armgame" / FILE_NAME


def parse_size(text: str, what: str = "size") -> tuple[int, int]:
    """``"1280x720"`` -> (1280, 720), each side from 320 to 10000 px."""
    try:
        w, h = (int(v) for v in text.strip().lower().split("x"))
    except ValueError:
        raise ValueError(f"{what} must be WIDTHxHEIGHT in pixels, e.g. 1280x720, got {text[:40]!r}") from None
    if not (MIN_SIDE <= w <= MAX_SIDE and MIN_SIDE <= h <= MAX_SIDE):
        raise ValueError(f"{what} must be {MIN_SIDE} to {MAX_SIDE} px a side, got {text[:40]!r}")
    return w, h


def check_muscle_keys(text: object, what: str = "keys") -> str:
    """Four different muscle keys as ``--keys`` takes them (``"dfjk"`` or ``"a,s,d,f"``)."""
    if not isinstance(text, str) or len(text) > 80:
        raise ValueError(f"{what} must be text such as \"dfjk\", got {str(text)[:40]!r}")
    names = [k.strip().lower() for k in (text.split(",") if "," in text else list(text))]
    if len(names) != 4 or any(not n or not n.isprintable() for n in names):
        raise ValueError(f"{what} needs 4 keys, one per muscle, got {text!r}")
    if len(set(names)) != 4:
        raise ValueError(f"{what} must name 4 different keys, got {text!r}")
    taken = RESERVED_KEYS & set(names)
    if taken:
        raise ValueError(f"{what} cannot use {', '.join(sorted(taken))}: the window needs it")
    return text


def from_toml(data: bytes, source: str) -> Settings:
    table = parse_toml(data, source, "not UTF-8 text", SettingsError)
    unknown = sorted(set(table) - {"keys", "mute", "palette", "text_scale", "size"})
    if unknown:
        raise SettingsError(f"{source}: unknown key {unknown[0]!r} (known: keys, mute, palette, text_scale, size)")
    settings = Settings()
    try:
        if "keys" in table:
            settings = settings.with_changes(keys=check_muscle_keys(table["keys"]))
        if "mute" in table:
            if not isinstance(table["mute"], bool):
                raise ValueError(f"mute must be true or false, got {table['mute']!r}"[:120])
            settings = settings.with_changes(mute=table["mute"])
        if "palette" in table:
            if table["palette"] not in PALETTES:
                raise ValueError(f"palette must be {', '.join(PALETTES[:-1])} or {PALETTES[-1]}, "
                                 f"got {str(table['palette'])[:40]!r}")
            settings = settings.with_changes(palette=table["palette"])
        if "text_scale" in table:
            scale = table["text_scale"]
            if isinstance(scale, bool) or not isinstance(scale, int | float) or \
                    not MIN_TEXT_SCALE <= scale <= MAX_TEXT_SCALE:
                raise ValueError(f"text_scale must be a number from {MIN_TEXT_SCALE:g} to {MAX_TEXT_SCALE:g}, "
                                 f"got {str(scale)[:40]!r}")
            settings = settings.with_changes(text_scale=float(scale))
        if "size" in table:
            if not isinstance(table["size"], str):
                raise ValueError(f"size must be text such as \"1280x720\", got {str(table['size'])[:40]!r}")
            settings = settings.with_changes(size=parse_size(table["size"]))
    except ValueError as exc:
        raise SettingsError(f"{source}: {exc}") from None
    return settings


def _regular_or_missing(path: Path) -> bool:
    """True for a regular file, False when there is none; anything else is refused.

    Checked without following a symlink, so a link planted in the config folder cannot point the game
    at another file, and a FIFO or a device can never block or flood the read.
    """
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return False
    except OSError as exc:
        raise SettingsError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if stat.S_ISLNK(st.st_mode):
        raise SettingsError(f"{path}: is a symbolic link; settings are read from a regular file only")
    if not stat.S_ISREG(st.st_mode):
        raise SettingsError(f"{path}: not a regular file")
    if st.st_size > MAX_BYTES:
        raise SettingsError(f"{path}: {st.st_size} bytes, too large for a settings file (at most {MAX_BYTES})")
    return True


def load(path: Path | None = None) -> tuple[Settings, Path]:
    """The settings in force and the file they come from (defaults when the file does not exist)."""
    from ..records.storage import read_limited

    path = default_path() if path is None else Path(path).expanduser()
    if not _regular_or_missing(path):
        return Settings(), path
    try:
        data = read_limited(path, MAX_BYTES, "settings file")
    except UserError as exc:
        raise SettingsError(str(exc)) from None
    return from_toml(data, str(path)), path


def save(settings: Settings, path: Path) -> None:
    """Write atomically (a temporary file renamed over the old one), creating the config folder."""
    from ..records.storage import atomic_write_bytes

    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _regular_or_missing(path)  # refuses to replace a symlink, a FIFO or a device
        atomic_write_bytes(path, settings.to_toml().encode("utf-8"))
    except OSError as exc:
        raise SettingsError(f"cannot write {path}: {exc.strerror or exc}") from None
