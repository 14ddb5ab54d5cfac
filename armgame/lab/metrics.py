"""Per-reach measures of a centre-out reach, and the trials table that carries them. Pure numpy.

A reach is the hand's sampled path from before the go cue to the end of the trial, *as shown and
scored* (after any visual transform: under a visuomotor rotation the errors are those the player
saw). From it ``reach_metrics`` computes the measures of the adaptation literature:

- **speed**: the hand speed from the sampled positions by central differences (one-sided at the
  record's two ends), ``np.gradient`` with the record's uniform step; error O(dt^2).
- **peak speed** (m/s): the largest sampled speed at or after the go cue.
- **movement onset**: the last time before the peak at which the speed rises through ``threshold``
  (default 5%) of that reach's peak speed; **movement end**: the first time after the peak at which
  it falls through it. Both are interpolated linearly between samples. The end is the end of the
  *primary* movement: a corrective submovement after the speed has dropped below the threshold is
  left out, as is usual, so that path measures describe the planned reach and not the homing in.
  A speed already above the threshold at the first sample puts the onset there; one still above it
  at the last sample puts the end there (a trial cut off mid-movement, for example by a time-out).
- **reaction time** (s): onset minus the go cue (negative for a movement started before the cue).
- **movement time** (s): end minus onset.
- **initial direction error** (deg, signed, + = counter-clockwise): the angle from the target
  direction (home to target centre) to the hand's displacement from where it was at onset to where
  it is a fixed ``direction_delay`` (default 100 ms) after onset (or, with
  ``direction_at="peak_acceleration"``, at the peak of the tangential acceleration between onset
  and peak speed), in (-180, 180]. It measures the feedforward plan, before visual feedback can
  correct it. The displacement starts at the hand's onset position, not at the home centre: the hand
  rests anywhere inside the home circle, and a resting offset of a few millimetres would otherwise
  read as tens of degrees over the first centimetre of movement.
- **maximum perpendicular error** (m, signed, + = left of the line, the counter-clockwise side):
  the hand's signed distance from the straight line through the home position and the target
  centre, largest in magnitude between onset and end.
- **path-length ratio**: the path's length from onset to end over the straight distance between
  its two ends: 1 for any straight movement. (For a reach that stops on the target this is the
  start-target distance; dividing by the chord rather than by the nominal distance keeps a reach
  that stops short from passing for a straighter one.)

A reach with no movement (peak speed below ``min_peak_speed``, default 0.01 m/s) has NaN for every
measure but its peak speed; a record with fewer than two samples after the go cue, a non-finite
position or times that do not increase has NaN for all of them. ``reach_metrics`` never raises on
a trial's content; it raises ``ValueError`` only for a malformed ``Reach`` (a programming error).

On an error-clamp (channel) trial ``channel_measures`` reads the force the arm pressed into the
channel (sampled with the path, from the go cue to the trial's end, signed along the left normal
of the home-to-target line):

- **peak channel force** (N): the sampled force largest in magnitude, with its sign;
- **channel force at peak speed** (N): the force at the sample of the hand's peak speed;
- **adaptation index**: the least-squares slope, through the origin, of the channel force on the
  force that would exactly cancel the field ``F = B v`` at the hand's velocity on that trial (its
  component across the line, ``-n . B v``): 0 when nothing was learned, 1 when the field is
  fully compensated (Smith, Ghazizadeh & Shadmehr 2006). NaN with no field to measure against.

The trials table (``TRIAL_COLUMNS``) is CSV: one row per reach, NaN written as an empty field.
"""

from __future__ import annotations

import csv
import io
import math
import os
import stat
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from ..errors import UserError
from ..records.storage import DataFileError, atomic_write_bytes
from ..valid import show_value

NAN = float("nan")


@dataclass(frozen=True)
class Reach:
    """One trial's hand path and what it was aimed at.

    ``t`` (n,) s, increasing with a uniform step; ``hand`` (n, 2) m, the hand as shown and scored;
    ``start`` the home position (m); ``target`` the target centre (m); ``go_time`` the go cue (s, on
    the clock of ``t``); ``hit`` whether the trial ended by reaching and holding the target.
    """

    t: np.ndarray
    hand: np.ndarray
    start: tuple[float, float]
    target: tuple[float, float]
    go_time: float
    hit: bool


@dataclass(frozen=True)
class ReachMetrics:
    """The measures of one reach (definitions in the module docstring); NaN where undefined."""

    reaction_time_s: float
    movement_time_s: float
    peak_speed_m_per_s: float
    initial_direction_error_deg: float
    max_perpendicular_error_m: float
    path_length_ratio: float

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


UNDEFINED = ReachMetrics(NAN, NAN, NAN, NAN, NAN, NAN)


@dataclass(frozen=True)
class ChannelMeasures:
    """What an error-clamp trial measures (module docstring); NaN where undefined."""

    channel_force_peak_n: float
    channel_force_at_peak_speed_n: float
    adaptation_index: float

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


NO_CHANNEL = ChannelMeasures(NAN, NAN, NAN)


def channel_measures(force: np.ndarray, velocity: np.ndarray, normal: tuple[float, float],
                     field: tuple[tuple[float, float], tuple[float, float]] | None) -> ChannelMeasures:
    """The channel trial's measures from the force pressed into the channel ``force`` (n,) N, the hand's
    velocity ``velocity`` (n, 2) m/s at the same samples, the line's unit left ``normal`` and the field
    ``F = B v`` (N s/m) the adaptation index is measured against (None: no index).

    >>> v = np.array([[0.0, 0.0], [0.3, 0.0], [0.5, 0.0], [0.2, 0.0]])
    >>> B = ((0.0, 2.0), (-2.0, 0.0))               # curl b = 2: F = (2 vy, -2 vx)
    >>> ideal = 2.0 * v[:, 0]                       # cancelling it along n = (0, 1): -n . B v = 2 vx
    >>> channel_measures(0.5 * ideal, v, (0.0, 1.0), B).adaptation_index
    0.5
    """
    f = np.asarray(force, dtype=np.float64)
    v = np.asarray(velocity, dtype=np.float64)
    if f.ndim != 1 or v.shape != (f.size, 2):
        raise ValueError(f"channel_measures wants force (n,) and velocity (n, 2), got {f.shape} and {v.shape}")
    if f.size == 0 or not (np.isfinite(f).all() and np.isfinite(v).all()):
        return NO_CHANNEL
    peak = float(f[np.argmax(np.abs(f))])
    at_speed = float(f[np.argmax(np.hypot(v[:, 0], v[:, 1]))])
    index = NAN
    if field is not None:
        b = np.asarray(field, dtype=np.float64)
        n = np.asarray(normal, dtype=np.float64)
        ideal = -(v @ b.T) @ n
        power = float(ideal @ ideal)
        if power > 1e-12:
            index = float(ideal @ f) / power
    return ChannelMeasures(peak, at_speed, index)

DIRECTION_AT = ("delay", "peak_acceleration")


def reach_metrics(reach: Reach, *, threshold: float = 0.05, direction_at: str = "delay",
                  direction_delay: float = 0.1, min_peak_speed: float = 0.01) -> ReachMetrics:
    """The reach's measures.

    ``threshold``: onset and end, as a fraction of the reach's peak speed (0 < threshold < 1).
    ``direction_at``: ``"delay"`` (the displacement ``direction_delay`` s after onset, clipped to the
    record's end) or ``"peak_acceleration"``. ``min_peak_speed`` (m/s): below it the hand did not
    move.

    >>> T, D = 0.5, 0.1
    >>> t = np.arange(0.0, 1.0 + 1e-9, 0.001)
    >>> s = np.clip((t - 0.3) / T, 0.0, 1.0)
    >>> x = D * (10 * s**3 - 15 * s**4 + 6 * s**5)
    >>> m = reach_metrics(Reach(t, np.stack([x, 0 * x], axis=1), (0.0, 0.0), (D, 0.0), 0.2, True))
    >>> round(m.peak_speed_m_per_s / (D / T), 4), round(m.path_length_ratio, 6), m.max_perpendicular_error_m
    (1.875, 1.0, 0.0)
    """
    if not 0.0 < threshold < 1.0:
        raise ValueError(f"threshold must be between 0 and 1, got {threshold!r}")
    if direction_at not in DIRECTION_AT:
        raise ValueError(f"direction_at must be one of {', '.join(DIRECTION_AT)}, got {direction_at!r}")
    if not direction_delay > 0.0:
        raise ValueError(f"direction_delay must be positive, got {direction_delay!r}")
    if not min_peak_speed >= 0.0:
        raise ValueError(f"min_peak_speed must be zero or more, got {min_peak_speed!r}")
    t = np.asarray(reach.t, dtype=np.float64)
    hand = np.asarray(reach.hand, dtype=np.float64)
    if t.ndim != 1 or hand.shape != (t.size, 2):
        raise ValueError(f"Reach wants t of shape (n,) and hand of shape (n, 2), got {t.shape} and {hand.shape}")
    start = np.asarray(reach.start, dtype=np.float64)
    target = np.asarray(reach.target, dtype=np.float64)
    if start.shape != (2,) or target.shape != (2,):
        raise ValueError("Reach wants start and target as (x, y) pairs")

    go = float(reach.go_time)
    finite = (np.isfinite(t).all() and np.isfinite(hand).all() and np.isfinite(start).all()
              and np.isfinite(target).all() and math.isfinite(go))
    if not finite or t.size < 2 or np.any(np.diff(t) <= 0.0):
        return UNDEFINED
    after_go = np.flatnonzero(t >= go)
    if after_go.size < 2:
        return UNDEFINED

    step = (t[-1] - t[0]) / (t.size - 1)  # the step is uniform: one spacing keeps a still hand at exactly 0
    speed = np.hypot(*np.gradient(hand, step, axis=0).T)
    peak = int(after_go[np.argmax(speed[after_go])])
    peak_speed_m_per_s = float(speed[peak])
    if not peak_speed_m_per_s >= min_peak_speed or peak_speed_m_per_s == 0.0:
        return ReachMetrics(NAN, NAN, peak_speed_m_per_s, NAN, NAN, NAN)
    level = threshold * peak_speed_m_per_s

    below = np.flatnonzero(speed[:peak] < level)
    if below.size:  # the speed rises through the level between samples i and i + 1
        i = int(below[-1])
        t_on = t[i] + (level - speed[i]) / (speed[i + 1] - speed[i]) * (t[i + 1] - t[i])
    else:
        t_on = t[0]
    below = np.flatnonzero(speed[peak + 1:] < level)
    if below.size:  # the speed falls through the level between samples j - 1 and j
        j = peak + 1 + int(below[0])
        t_end = t[j - 1] + (speed[j - 1] - level) / (speed[j - 1] - speed[j]) * (t[j] - t[j - 1])
    else:
        t_end = t[-1]

    def at(time: float) -> np.ndarray:
        return np.array([np.interp(time, t, hand[:, 0]), np.interp(time, t, hand[:, 1])])

    p_on, p_end = at(t_on), at(t_end)
    inside = (t > t_on) & (t < t_end)
    path = np.vstack([p_on, hand[inside], p_end])
    length = float(np.sum(np.hypot(*np.diff(path, axis=0).T)))
    chord = float(np.hypot(*(p_end - p_on)))
    ratio = length / chord if chord > 0.0 else NAN

    if direction_at == "delay":
        p_dir = at(min(t_on + direction_delay, t[-1]))
    else:
        accel = np.gradient(speed, step)
        first = int(np.searchsorted(t, t_on))
        k = first + int(np.argmax(accel[first:peak + 1])) if first <= peak else peak
        p_dir = hand[k]
    moved = p_dir - p_on

    aim = target - start
    distance = float(np.hypot(*aim))
    if distance > 0.0:
        unit = aim / distance
        side = unit[0] * (path[:, 1] - start[1]) - unit[1] * (path[:, 0] - start[0])
        deviation = float(side[np.argmax(np.abs(side))])
        if np.any(moved != 0.0):
            cross = unit[0] * moved[1] - unit[1] * moved[0]
            dot = unit[0] * moved[0] + unit[1] * moved[1]
            direction = math.degrees(math.atan2(cross, dot))
            direction = 180.0 if direction == -180.0 else direction
        else:
            direction = NAN
    else:  # the target sits on the home position: no direction to err from
        deviation = direction = NAN

    return ReachMetrics(
        reaction_time_s=float(t_on - go),
        movement_time_s=float(t_end - t_on),
        peak_speed_m_per_s=peak_speed_m_per_s,
        initial_direction_error_deg=float(direction),
        max_perpendicular_error_m=deviation,
        path_length_ratio=ratio,
    )


# ------------------------------------------------------------------------------- the trials table

#: The error-clamp columns, empty on other trials; a table without them (written before they existed)
#: still reads, with them empty.
CHANNEL_COLUMNS: tuple[str, ...] = tuple(f.name for f in fields(ChannelMeasures))
#: 1 when space ("hand home") sent the hand home during the reach: the row measures the path before the jump
#: only, and the class curve leaves the trial out (an abandoned reach is not one of the experiment's). A table
#: written before the column existed still reads, with it 0.
HAND_SENT_HOME = "hand_sent_home"
#: Issue 41's columns: what the player saw of the hand (``feedback``: full, endpoint or none), the trial's
#: ``disturbance`` in units of the run's first perturbation (+1 it, -1 its opposite, 0 none, a catch or a channel
#: trial; empty when a run's perturbations share no unit), and a channel trial's index against the reference field
#: held at the hand and at the joints (``armgame.lab.designs``). A table without them still reads (``feedback`` as
#: full, the rest empty).
DESIGN_COLUMNS: tuple[str, ...] = ("feedback", "disturbance", "adaptation_index_hand", "adaptation_index_joint")
#: The arm's posture at home for the trial (its block's, in degrees): a run whose blocks move home (``frames``)
#: reads by posture without the protocol at hand. A table written before them reads with them empty.
POSTURE_COLUMNS: tuple[str, ...] = ("home_shoulder_deg", "home_elbow_deg")
TRIAL_COLUMNS: tuple[str, ...] = ("block", "trial", "target_deg", "perturbation", "reaction_time_s",
                                  "movement_time_s", "peak_speed_m_per_s", "initial_direction_error_deg",
                                  "max_perpendicular_error_m", "path_length_ratio", "hit", *CHANNEL_COLUMNS,
                                  HAND_SENT_HOME, *DESIGN_COLUMNS, *POSTURE_COLUMNS)
#: Columns a table may lack (written before they existed), and what each then reads as.
LATER_COLUMNS: dict[str, object] = {**dict.fromkeys(CHANNEL_COLUMNS, NAN), HAND_SENT_HOME: False,
                                    **dict.fromkeys(DESIGN_COLUMNS, NAN), "feedback": "full",
                                    **dict.fromkeys(POSTURE_COLUMNS, NAN)}
_FLAGS = ("hit", HAND_SENT_HOME)
METRIC_COLUMNS: tuple[str, ...] = tuple(f.name for f in fields(ReachMetrics))
_TEXT_COLUMNS = ("block", "perturbation", "feedback")
#: Whose run a row is, in a table of several runs (``armgame analyze A.json B.json --out all.csv``).
LABEL_COLUMNS: tuple[str, ...] = ("player", "replay")
_NONNEGATIVE = ("movement_time_s", "peak_speed_m_per_s", "path_length_ratio")
#: Columns named before every column named its unit: a table written then reads under the new names.
RENAMED_COLUMNS = {"reaction_time": "reaction_time_s", "movement_time": "movement_time_s",
                   "peak_speed": "peak_speed_m_per_s"}
MAX_TRIALS_BYTES = 16 * 1024 * 1024
MAX_TEXT = 64
MAX_TRIAL = 1_000_000


class TrialsFileError(DataFileError):
    """A trials table that cannot be read: the message names the file, the line and the column."""


def write_trials_csv(path: Path, rows: Iterable[Mapping[str, object]], labels: Sequence[str] = ()) -> None:
    """Write one row per reach, the columns of ``TRIAL_COLUMNS``, atomically.

    ``labels``: text columns written first (``analyze``'s ``player`` and ``replay``, so that rows of
    several runs in one table stay attributable); each row then has them too, as text.

    Numbers are written exactly (the shortest text that reads back to the same float); an
    undefined measure (NaN) is an empty field; ``hit`` and ``hand_sent_home`` are 1 or 0. Only a regular file is
    written:
    an existing folder, device or symbolic link at ``path`` is refused (``UserError``). A row with a
    missing or unknown column, or a value of the wrong kind, is a ``ValueError`` (a caller's bug).
    """
    path = Path(path)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow([*labels, *TRIAL_COLUMNS])
    expected = {*labels, *TRIAL_COLUMNS}
    for n, row in enumerate(rows, start=1):
        keys = set(row)
        if keys != expected:
            missing, unknown = expected - keys, keys - expected
            what = f"lacks {', '.join(sorted(missing))}" if missing else f"has unknown {', '.join(sorted(unknown))}"
            raise ValueError(f"trial row {n} {what}")
        writer.writerow([*(_label(name, row[name], n) for name in labels),
                         *(_format(name, row[name], n) for name in TRIAL_COLUMNS)])
    _write_text(path, out.getvalue())


def read_trials_csv(path: Path) -> list[dict[str, object]]:
    """Read a trials table written by ``write_trials_csv`` (or a spreadsheet), trusting nothing.

    The file must be a regular file of at most 16 MiB, UTF-8 (a leading byte-order mark is allowed),
    with a header naming exactly the columns of ``TRIAL_COLUMNS`` (in any order; the ``LATER_COLUMNS``
    may be absent, as in tables written before they existed: the ``CHANNEL_COLUMNS`` and the
    ``DESIGN_COLUMNS`` read as NaN, ``feedback`` as full, ``hand_sent_home`` as False;
    ``LABEL_COLUMNS``, which ``analyze`` writes first, are allowed and not returned; the old names of
    ``RENAMED_COLUMNS``, before each column named its unit, read as the new ones). Each row is
    checked: ``block`` and ``perturbation`` printable text of at most 64 characters, ``trial`` a
    whole number from 0 to 1,000,000, ``target_deg`` a finite number, each measure a finite number
    or empty (read as NaN; times may be negative, speed, movement time and ratio may not), ``hit``
    and ``hand_sent_home`` one of 1, 0, true, false. The first problem raises ``TrialsFileError`` (a
    ``UserError``) in one line naming the file, the line and the column. Rows come back in file order, typed, keyed in
    ``TRIAL_COLUMNS`` order.
    """
    path = Path(path)
    data = _read_regular(path, MAX_TRIALS_BYTES)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise TrialsFileError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    rows: list[dict[str, object]] = []
    try:
        header = next(reader, None)
        if header is None:
            raise TrialsFileError(f"{path}: empty, expected a header naming {', '.join(TRIAL_COLUMNS)}")
        header = [RENAMED_COLUMNS.get(name.strip(), name.strip()) for name in header]
        if len(set(header)) != len(header):
            raise TrialsFileError(f"{path}: line 1: a column is named twice")
        missing = [name for name in TRIAL_COLUMNS if name not in header and name not in LATER_COLUMNS]
        unknown = [name for name in header if name not in TRIAL_COLUMNS and name not in LABEL_COLUMNS]
        if missing or unknown:
            what = (f"lacks column(s) {', '.join(missing)}" if missing
                    else f"has unknown column(s) {show_value(unknown)}")
            raise TrialsFileError(f"{path}: line 1: {what}")
        for fields_ in reader:
            line = reader.line_num
            if not fields_:
                continue
            if len(fields_) != len(header):
                raise TrialsFileError(f"{path}: line {line}: {len(fields_)} fields, expected {len(header)}")
            values = dict(zip(header, fields_, strict=True))
            row: dict[str, object] = {}
            for name in TRIAL_COLUMNS:
                if name not in values:  # a column the table was written before
                    row[name] = LATER_COLUMNS[name]
                    continue
                try:
                    row[name] = _parse(name, values[name])
                except ValueError as exc:
                    raise TrialsFileError(f"{path}: line {line}, column {name}: {exc}") from None
            rows.append(row)
    except csv.Error as exc:
        raise TrialsFileError(f"{path}: line {reader.line_num}: not CSV: {exc}") from None
    return rows


def class_columns(metric: str) -> tuple[str, ...]:
    """A class curve's columns: the mean and s.e.m. name the measure and its unit (``mean_<metric>``, in the
    measure's SI unit, as in ``trials.csv``), so the file says what it holds."""
    return ("trial", "block", "perturbation", f"mean_{metric}", f"sem_{metric}", "n")


def write_class_csv(path: Path, curve: Iterable[Mapping[str, object]], metric: str) -> None:
    """Write a class curve (``figures.class_curve`` of ``metric``): one row per trial, ``class_columns(metric)``,
    atomically.

    The mean and s.e.m. are in the measure's own (SI) unit, as ``trials.csv`` has it; NaN (no data, or
    fewer than two students) is an empty field. Same file rules as ``write_trials_csv``.
    """
    if metric not in METRIC_COLUMNS:
        raise ValueError(f"no such measure {metric!r}")
    path = Path(path)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(class_columns(metric))
    fields_ = {"trial", "block", "perturbation", "mean", "sem", "n"}
    for n, row in enumerate(curve, start=1):
        if set(row) != fields_:
            raise ValueError(f"class curve row {n} must have exactly the fields {', '.join(sorted(fields_))}")
        writer.writerow([_format("trial", row["trial"], n), _format("block", row["block"], n),
                         _format("perturbation", row["perturbation"], n), _format("mean", row["mean"], n),
                         _format("sem", row["sem"], n), _format("trial", row["n"], n)])
    _write_text(path, out.getvalue())


def _write_text(path: Path, text: str) -> None:
    check_regular_target(path)
    try:
        atomic_write_bytes(path, text.encode("utf-8"))
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None


def _label(name: str, value: object, n: int) -> str:
    """A label column's text, printable (anything else shown as '?'); text a spreadsheet would run as a
    formula is quoted ('=...), since a player's name is whatever the player typed."""
    if not isinstance(value, str):
        raise ValueError(f"trial row {n}, {name}: must be text, got {value!r}")
    value = "".join(c if c.isprintable() else "?" for c in value)
    return "'" + value if value[:1] in ("=", "+", "-", "@") else value


def _format(name: str, value: object, n: int) -> str:
    where = f"trial row {n}, {name}"
    if name in _TEXT_COLUMNS:
        if not isinstance(value, str) or not value or len(value) > MAX_TEXT or not value.isprintable():
            raise ValueError(f"{where}: must be printable text of 1 to {MAX_TEXT} characters, got {value!r}")
        return value
    if name == "trial":
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) \
                or not 0 <= value <= MAX_TRIAL:
            raise ValueError(f"{where}: must be a whole number from 0 to {MAX_TRIAL}, got {value!r}")
        return str(int(value))
    if name in _FLAGS:
        if not isinstance(value, (bool, np.bool_)):
            raise ValueError(f"{where}: must be True or False, got {value!r}")
        return "1" if value else "0"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{where}: must be a number, got {value!r}")
    number = float(value)
    if math.isnan(number) and name != "target_deg":
        return ""
    if not math.isfinite(number):
        raise ValueError(f"{where}: must be finite, got {number!r}")
    return repr(number)


def _parse(name: str, text: str) -> object:
    text = text.strip()
    if name in _TEXT_COLUMNS:
        if not text or len(text) > MAX_TEXT or not text.isprintable():
            raise ValueError(f"must be printable text of 1 to {MAX_TEXT} characters, got {show_value(text)}")
        return text
    if name == "trial":
        if not text.isascii() or not text.isdigit() or len(text) > 7 or int(text) > MAX_TRIAL:
            raise ValueError(f"must be a whole number from 0 to {MAX_TRIAL}, got {show_value(text)}")
        return int(text)
    if name in _FLAGS:
        flag = text.lower()
        if flag not in ("1", "0", "true", "false"):
            raise ValueError(f"must be 1, 0, true or false, got {show_value(text)}")
        return flag in ("1", "true")
    if text == "" and name != "target_deg":
        return NAN
    try:
        number = float(text) if len(text) <= 40 else NAN
    except ValueError:
        number = NAN
    if not math.isfinite(number):  # also refuses the words nan and inf, and 1e999
        empty = "" if name == "target_deg" else " or empty"
        raise ValueError(f"must be a finite number{empty}, got {show_value(text)}")
    if name in _NONNEGATIVE and number < 0.0:
        raise ValueError(f"must not be negative, got {show_value(text)}")
    return number


def check_regular_target(path: Path) -> None:
    """Refuse to write ``path`` unless it is absent (in an existing folder) or a regular file (``UserError``).

    A symbolic link is refused too: the atomic rename would replace the link, not write where it points,
    which surprises whoever made it.
    """
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        if not path.parent.is_dir():
            raise UserError(f"cannot write {path}: no folder {path.parent}") from None
        return
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(info.st_mode):
        raise UserError(f"cannot write {path}: it exists and is not a regular file")


def _read_regular(path: Path, limit: int) -> bytes:
    """The file's bytes, refusing anything but a regular file (a FIFO would block, /dev/zero never end)."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise TrialsFileError(f"{path}: no such trials table") from None
    except OSError as exc:
        raise TrialsFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise TrialsFileError(f"{path}: not a regular file")
        with os.fdopen(fd, "rb", closefd=False) as f:
            data = f.read(limit + 1)
    except OSError as exc:
        raise TrialsFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    if len(data) > limit:
        raise TrialsFileError(f"{path}: larger than {limit // (1024 * 1024)} MiB, too large for a trials table")
    return data
