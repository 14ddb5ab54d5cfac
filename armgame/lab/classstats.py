"""The class's statistics (issue 50): what a class of students reads off its own runs, with intervals across students.

Pure: no files, no clock; numpy and scipy only. Its input is what ``analysis.class_curve_of`` chose (each person's
first run of the teacher's protocol, programs apart) as ``(name, trial rows)`` pairs, so the projector's ``/lab``
(``classroom.views``) and ``armgame analyze --class`` (``commands.analyze``) compute the same numbers by one code.

Every interval is across students, never across trials: the mean of one number per student, and
``mean ± t(0.975, n-1) · s / sqrt(n)`` (Student's t: a class is 5 to 40, too few for 1.96). Below ``MIN_INTERVAL``
students there is no interval (the page shows the students' own curves instead). Each per-student number is
taken on the measure the learning curve plots (``analysis.figure_metric``), on the ordinary trials of a block only
(catch, channel and no-cursor probes left out), a reach sent home with space never counted:

* early and late exposure error: the mean of the first and of the last ``EDGE_TRIALS`` ordinary trials of the
  protocol's first perturbed block;
* after-effect: the first ``AFTER_TRIALS`` ordinary trial(s) of the first unperturbed block after it (washout) less
  the mean of the last ``EDGE_TRIALS`` of the unperturbed block before it (late baseline);
* learning: late less early exposure error, a paired difference per student;
* generalization (a block that trains one direction and probes others): per probed direction, by its angle from
  the trained one, the mean probe measure (the channel trials' adaptation index, or a no-cursor probe's error)
  less that direction's baseline probes (``analysis.baseline_for``);
* two groups (a classroom experiment): the difference of the groups' means of any of these, with Welch's interval
  (unequal variances, Welch-Satterthwaite degrees of freedom).

The fitted rates (``student_fit``) are the two-rate learner ``armgame analyze RUN --fit two-rate`` fits: costly
(tens of milliseconds a run), so the CSV and ``analyze`` compute them, never the projector's recompute.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.special import stdtrit  # scipy.stats.t.ppf's own quantile (to the bit), without scipy.stats' 0.5 s import

#: k, the trials averaged at each end of a block: early and late exposure, late baseline. Three: enough to
#: average a person's reach-to-reach scatter, few enough that "early" is still before most of the learning (the
#: lesson's exposure is 16 reaches).
EDGE_TRIALS = 3
#: The washout trials the after-effect is read on: the first one only, since a person unlearns within a few.
AFTER_TRIALS = 1
#: Students needed for an interval: with fewer, t(0.975, n-1) is 12.7 (n = 2) and the interval says nothing.
MIN_INTERVAL = 3
#: The interval's coverage.
LEVEL = 0.95

Rows = Sequence[Mapping[str, object]]


@dataclass(frozen=True)
class Estimate:
    """A mean across ``n`` values with its 95 % interval (``low``, ``high``; NaN below ``MIN_INTERVAL``)."""

    mean: float
    low: float
    high: float
    n: int

    def as_dict(self, scale: float = 1.0) -> dict[str, object]:
        return {"mean": _json(self.mean * scale), "low": _json(self.low * scale), "high": _json(self.high * scale),
                "n": self.n}


def estimate(values: Sequence[float]) -> Estimate:
    """The mean of the finite ``values`` and its t interval (``mean ± t(0.975, n-1) s / sqrt(n)``)."""
    data = np.asarray([v for v in values if math.isfinite(v)], dtype=np.float64)
    n = int(data.size)
    if n == 0:
        return Estimate(math.nan, math.nan, math.nan, 0)
    mean = float(data.mean())
    if n < MIN_INTERVAL:
        return Estimate(mean, math.nan, math.nan, n)
    half = float(stdtrit(n - 1, 0.5 + LEVEL / 2)) * float(data.std(ddof=1)) / math.sqrt(n)
    return Estimate(mean, mean - half, mean + half, n)


@dataclass(frozen=True)
class Difference:
    """Group A's mean less group B's, with Welch's 95 % interval (NaN when either group is below
    ``MIN_INTERVAL``) and its degrees of freedom."""

    a: Estimate
    b: Estimate
    difference: float
    low: float
    high: float
    df: float

    def as_dict(self, scale: float = 1.0) -> dict[str, object]:
        return {"a": self.a.as_dict(scale), "b": self.b.as_dict(scale), "difference": _json(self.difference * scale),
                "low": _json(self.low * scale), "high": _json(self.high * scale), "df": _json(self.df)}


def welch(a: Sequence[float], b: Sequence[float]) -> Difference:
    """mean(a) - mean(b) over the finite values, with Welch's interval: ``± t(0.975, df) sqrt(s_a²/n_a + s_b²/n_b)``,
    df by Welch-Satterthwaite."""
    ea, eb = estimate(a), estimate(b)
    x = np.asarray([v for v in a if math.isfinite(v)], dtype=np.float64)
    y = np.asarray([v for v in b if math.isfinite(v)], dtype=np.float64)
    difference = ea.mean - eb.mean if x.size and y.size else math.nan
    if x.size < MIN_INTERVAL or y.size < MIN_INTERVAL:
        return Difference(ea, eb, difference, math.nan, math.nan, math.nan)
    va, vb = float(x.var(ddof=1)) / x.size, float(y.var(ddof=1)) / y.size
    se = math.sqrt(va + vb)
    if se == 0.0:
        return Difference(ea, eb, difference, difference, difference, math.inf)
    df = (va + vb) ** 2 / (va ** 2 / (x.size - 1) + vb ** 2 / (y.size - 1))
    half = float(stdtrit(df, 0.5 + LEVEL / 2)) * se
    return Difference(ea, eb, difference, difference - half, difference + half, df)


# ------------------------------------------------------------------ one student
@dataclass(frozen=True)
class LessonBlocks:
    """Where a protocol's lesson is: the block indices of the late baseline, the exposure and the washout (None:
    the protocol has no such block)."""

    baseline: int | None
    exposure: int | None
    washout: int | None


def lesson_blocks(protocol) -> LessonBlocks:
    """The first perturbed block (not all channel trials), the unperturbed block just before it and the first
    unperturbed one after it."""
    blocks = protocol.blocks
    exposure = next((i for i, b in enumerate(blocks) if not b.perturbation.is_null and not b.channel_block), None)
    if exposure is None:
        return LessonBlocks(None, None, None)
    baseline = next((i for i in range(exposure - 1, -1, -1) if blocks[i].perturbation.is_null
                     and not blocks[i].channel_block), None)
    washout = next((i for i in range(exposure + 1, len(blocks)) if blocks[i].perturbation.is_null
                    and not blocks[i].channel_block), None)
    return LessonBlocks(baseline, exposure, washout)


def block_of_trials(protocol) -> list[int]:
    """Each trial number's block (index 0 for trial 1): blocks may share a name, their places cannot."""
    return [b for b, block in enumerate(protocol.blocks) for _ in range(block.trials)]


def is_probe(protocol, row: Mapping[str, object], block: int) -> bool:
    """Whether a row is a probe of its block (a channel or catch trial, or one with other feedback), not one of
    its ordinary trials."""
    b = protocol.blocks[block]
    return row["perturbation"] == "channel" or row["perturbation"] != b.perturbation.kind \
        or row.get("feedback", b.feedback) != b.feedback


def value_of(row: Mapping[str, object], metric: str) -> float:
    """A row's ``metric``, NaN for a reach sent home with space (as ``figures.class_curve`` counts it)."""
    return math.nan if row.get("hand_sent_home") else float(row[metric])  # type: ignore[arg-type]


def ordinary_values(protocol, rows: Rows, metric: str) -> dict[int, list[float]]:
    """Each block's ordinary trials' finite ``metric``, in trial order."""
    where = block_of_trials(protocol)
    out: dict[int, list[float]] = {}
    for row in rows:
        t = int(row["trial"]) - 1  # type: ignore[arg-type]
        if not 0 <= t < len(where) or is_probe(protocol, row, where[t]):
            continue
        v = value_of(row, metric)
        if math.isfinite(v):
            out.setdefault(where[t], []).append(v)
    return out


@dataclass(frozen=True)
class StudentMeasures:
    """One student's numbers, in the measure's SI unit (NaN: the run has no such trials)."""

    player: str
    early: float
    late: float
    late_baseline: float
    after_effect: float
    #: Generalization: (block name, angle from the trained direction) -> the probe measure less its baseline.
    probes: dict[tuple[str, float], float] = field(default_factory=dict)

    @property
    def learning(self) -> float:
        """Late less early exposure error."""
        return self.late - self.early


def _mean(values: Sequence[float]) -> float:
    return float(np.mean(values)) if len(values) else math.nan


def student_measures(protocol, player: str, rows: Rows, metric: str) -> StudentMeasures:
    """One student's early and late exposure error, late baseline and after-effect, and probes by direction."""
    places = lesson_blocks(protocol)
    values = ordinary_values(protocol, rows, metric)
    exposure = values.get(places.exposure, []) if places.exposure is not None else []
    baseline = values.get(places.baseline, []) if places.baseline is not None else []
    washout = values.get(places.washout, []) if places.washout is not None else []
    early, late = _mean(exposure[:EDGE_TRIALS]), _mean(exposure[-EDGE_TRIALS:])
    late_baseline = _mean(baseline[-EDGE_TRIALS:])
    after = _mean(washout[:AFTER_TRIALS]) - late_baseline if washout else math.nan
    return StudentMeasures(player, early, late, late_baseline, after, probes_by_direction(protocol, rows, metric))


def generalization_blocks(protocol) -> list[int]:
    """The blocks that train one direction and probe others (``presets.generalization``,
    ``rotation-generalization``)."""
    return [b for b, block in enumerate(protocol.blocks) if block.directions is not None
            and len(block.directions) == 1 and block.probes > 0 and block.probe_directions is not None]


def probe_value(row: Mapping[str, object], metric: str) -> float:
    """A probe's measure: a channel trial's adaptation index, a no-cursor (or catch) probe's ``metric``."""
    if row.get("hand_sent_home"):
        return math.nan
    return float(row["adaptation_index" if row["perturbation"] == "channel" else metric])  # type: ignore[arg-type]


def probes_by_direction(protocol, rows: Rows, metric: str) -> dict[tuple[str, float], float]:
    """Per generalization block and probed direction (its angle from the trained one, + anticlockwise): the mean
    probe measure less that direction's baseline (the mean of the probes of the same kind to it before the first
    perturbed block, or the nearest probed direction's: ``analysis.baseline_for``). Empty for other designs."""
    from .analysis import baseline_for, signed_angle

    chosen = generalization_blocks(protocol)
    if not chosen:
        return {}
    where = block_of_trials(protocol)
    first = lesson_blocks(protocol).exposure
    first = len(protocol.blocks) if first is None else first
    base: dict[tuple[bool, float], list[float]] = {}
    per: dict[tuple[int, bool, float], list[float]] = {}
    for row in rows:
        t = int(row["trial"]) - 1  # type: ignore[arg-type]
        if not 0 <= t < len(where) or not is_probe(protocol, row, where[t]):
            continue
        v = probe_value(row, metric)
        if not math.isfinite(v):
            continue
        kind, deg = row["perturbation"] == "channel", float(row["target_deg"]) % 360.0  # type: ignore[arg-type]
        if where[t] < first:
            base.setdefault((kind, deg), []).append(v)
        elif where[t] in chosen:
            per.setdefault((where[t], kind, deg), []).append(v)
    out: dict[tuple[str, float], float] = {}
    for (b, kind, deg), vs in per.items():
        offsets = {d: float(np.mean(v)) for (k, d), v in base.items() if k == kind}
        offset = baseline_for(offsets, deg)[0] if offsets else 0.0
        trained = protocol.target_angles_deg()[protocol.blocks[b].directions[0]] % 360.0
        out[(protocol.blocks[b].name, signed_angle(deg - trained))] = float(np.mean(vs)) - offset
    return out


# ------------------------------------------------------------------ the class
@dataclass(frozen=True)
class ClassStats:
    """The class's statistics: the curve with its interval per trial, each student's numbers, the answer, and the
    generalization by direction. ``own``: the students' own curves (trial, value) when too few for an interval."""

    metric: str
    curve: tuple[dict[str, object], ...]  # trial, block, perturbation, mean, low, high, n
    students: tuple[StudentMeasures, ...]
    early: Estimate
    late: Estimate
    learning: Estimate
    after_effect: Estimate
    generalization: tuple[dict[str, object], ...]  # block, angle_deg, mean, low, high, n
    own: tuple[tuple[str, tuple[tuple[int, float], ...]], ...]

    @property
    def n(self) -> int:
        return len(self.students)

    def as_dict(self, scale: float = 1.0, probe_scale: float = 1.0) -> dict[str, object]:
        """JSON-ready, each measure times ``scale`` (the page's unit), probes times ``probe_scale``."""
        return {
            "k": EDGE_TRIALS, "after_trials": AFTER_TRIALS, "min_interval": MIN_INTERVAL,
            "curve": [{**{k: row[k] for k in ("trial", "block", "perturbation", "n")},
                       **{k: _json(float(row[k]) * scale) for k in ("mean", "low", "high")}} for row in self.curve],
            "early": self.early.as_dict(scale), "late": self.late.as_dict(scale),
            "learning": self.learning.as_dict(scale), "after_effect": self.after_effect.as_dict(scale),
            "generalization": [{"block": g["block"], "angle_deg": g["angle_deg"],
                                **g["estimate"].as_dict(probe_scale)} for g in self.generalization],  # type: ignore[attr-defined]
            "own": [{"player": name, "points": [[t, _json(v * scale)] for t, v in points]}
                    for name, points in self.own],
        }


def curve_with_intervals(students: Sequence[Rows], metric: str) -> list[dict[str, object]]:
    """Per trial number: the mean across students, its t interval (NaN below ``MIN_INTERVAL``) and n, on top of
    ``figures.class_curve`` (the curve the class's page always drew: its means, its n, its block labels)."""
    from .figures import class_curve

    curve = class_curve(students, metric)
    n = np.array([row["n"] for row in curve], dtype=np.float64)
    sem = np.array([row["sem"] for row in curve], dtype=np.float64)
    wide = n >= MIN_INTERVAL
    half = np.full(len(curve), math.nan)
    if wide.any():
        half[wide] = stdtrit(n[wide] - 1, 0.5 + LEVEL / 2) * sem[wide]
    return [{"trial": row["trial"], "block": row["block"], "perturbation": row["perturbation"], "mean": row["mean"],
             "low": row["mean"] - h, "high": row["mean"] + h, "n": row["n"]}
            for row, h in zip(curve, half, strict=True)]


def class_stats(protocol, students: Sequence[tuple[str, Rows]], metric: str | None = None) -> ClassStats:
    """The class's statistics of ``students`` (name, trial rows), runs of ``protocol`` (``analysis.class_curve_of``'s
    members), in ``metric`` (default: the curve's, ``analysis.figure_metric``)."""
    from .analysis import figure_metric

    metric = metric or figure_metric(protocol)
    measures = tuple(student_measures(protocol, name, rows, metric) for name, rows in students)
    curve = curve_with_intervals([rows for _, rows in students], metric) if students else []
    directions: dict[tuple[str, float], list[float]] = {}
    for m in measures:
        for key, v in m.probes.items():
            directions.setdefault(key, []).append(v)
    general = tuple({"block": block, "angle_deg": angle, "estimate": estimate(v)}
                    for (block, angle), v in sorted(directions.items(), key=lambda item: item[0][1]))
    own = ()
    if len(students) < MIN_INTERVAL:
        own = tuple((name, tuple((int(r["trial"]), value_of(r, metric)) for r in rows))  # type: ignore[arg-type]
                    for name, rows in students)
    return ClassStats(metric, tuple(curve), measures, estimate([m.early for m in measures]),
                      estimate([m.late for m in measures]), estimate([m.learning for m in measures]),
                      estimate([m.after_effect for m in measures]), general, own)


# ------------------------------------------------------------------ fits and the table, one row per student
FIT_NAMES = ("A_f", "A_s", "B_f", "B_s")


def student_fit(rows: Rows, metric: str) -> dict[str, float]:
    """The two-rate learner's rates (``A_f, A_s, B_f, B_s``) fitted to one run's ``metric`` as ``armgame analyze
    RUN --fit two-rate`` fits them (the rows' ``disturbance`` is its schedule); empty when the run cannot be
    fitted (too few trials, no disturbance) or the fit does not converge to finite rates."""
    from .fit import fit_learner

    disturbance = [float(r.get("disturbance", math.nan)) for r in rows]  # type: ignore[arg-type]
    clamped = [r["perturbation"] == "channel" for r in rows]
    observed = [float(r[metric]) for r in rows]  # type: ignore[arg-type]
    if not disturbance or not all(math.isfinite(d) for d in disturbance):
        return {}
    try:
        fit = fit_learner("two-rate", disturbance, clamped, observed, "error")
    except (ValueError, ArithmeticError, np.linalg.LinAlgError):
        return {}
    from .fit import SYMBOLS

    rates = {SYMBOLS[name]: float(fit.values[name]) for name in fit.names}
    return rates if all(math.isfinite(v) for v in rates.values()) else {}


STUDENT_COLUMNS = ("name", "early", "late", "learning", "late_baseline", "after_effect", *FIT_NAMES)


def student_table(protocol, students: Sequence[tuple[str, Rows]], metric: str | None = None,
                  fits: Sequence[Mapping[str, float]] | None = None) -> list[dict[str, object]]:
    """One row per student (``STUDENT_COLUMNS``; measures in SI units, NaN where undefined): the teacher's CSV
    and ``armgame analyze --class --students``. ``fits``: each student's ``student_fit`` if already made."""
    from .analysis import figure_metric

    metric = metric or figure_metric(protocol)
    out = []
    for i, (name, rows) in enumerate(students):
        m = student_measures(protocol, name, rows, metric)
        rates = fits[i] if fits is not None else student_fit(rows, metric)
        out.append({"name": name, "early": m.early, "late": m.late, "learning": m.learning,
                    "late_baseline": m.late_baseline, "after_effect": m.after_effect,
                    **{k: rates.get(k, math.nan) for k in FIT_NAMES}})
    return out


def _json(v: float) -> float | None:
    return round(float(v), 6) if math.isfinite(v) else None


def estimate_words(e: Estimate, scale: float = 1.0, unit: str = "") -> str:
    """"+1.13 cm (95 % CI 0.90 to 1.37, n = 24)", or without an interval "(n = 2, too few for an interval)"."""
    per = f" {unit}" if unit else ""
    if e.n == 0:
        return "none measured"
    if not math.isfinite(e.low):
        return f"{e.mean * scale:+.2f}{per} (n = {e.n}, too few for an interval)"
    return f"{e.mean * scale:+.2f}{per} (95 % CI {e.low * scale:+.2f} to {e.high * scale:+.2f}, n = {e.n})"


def answer_line(s: ClassStats, scale: float = 1.0, unit: str = "") -> str:
    """The class's answer to the lesson's question in one line, as the projector shows it and ``armgame analyze
    --class`` prints it: the after-effect and late against early exposure error, each across students."""
    return (f"after-effect: {estimate_words(s.after_effect, scale, unit)}; late - early exposure error: "
            f"{estimate_words(s.learning, scale, unit)}")


# ------------------------------------------------------------------ two conditions (a classroom experiment)
@dataclass(frozen=True)
class Groups:
    """A classroom experiment's two groups: each group's class curve (``analysis.ClassCurve``) and statistics, in
    one measure, and group A's after-effect less group B's with Welch's interval (None when the two protocols are
    measured differently: a force field's against a rotation's)."""

    curves: tuple[object, object]
    stats: tuple[ClassStats | None, ClassStats | None]
    metric: str
    difference: Difference | None


def two_groups(runs: Sequence[object], protocols: tuple[object, object], condition_of,
               people_only: bool = True) -> Groups:
    """The two groups of ``runs`` (``analysis.ClassRun``): a run is group A's if its player's condition
    (``condition_of(name)``: "a", "b" or None) is "a" and it runs A's protocol, likewise B's; each group's curve is
    ``analysis.class_curve_of`` (each person's first run, programs apart), as the live class's ``/lab`` shows it
    and ``armgame analyze --class`` rebuilds it from the class's folder."""
    from .analysis import class_curve_of, figure_metric

    metric = figure_metric(protocols[0])
    same = figure_metric(protocols[1]) == metric
    curves, out = [], []
    for c, protocol in zip(("a", "b"), protocols, strict=True):
        mine = [r for r in runs if getattr(r, "program", False) or condition_of(getattr(r, "player", None) or "") == c]
        curve = class_curve_of(mine, protocol, metric if same or c == "a" else None, people_only=people_only)
        curves.append(curve)
        out.append(class_stats(protocol, [(mine[i].player or f"run {i + 1}", mine[i].rows) for i in curve.members],
                               curve.metric) if curve.students else None)
    difference = None
    if same:
        difference = welch([m.after_effect for m in out[0].students] if out[0] else [],
                           [m.after_effect for m in out[1].students] if out[1] else [])
    return Groups((curves[0], curves[1]), (out[0], out[1]), metric, difference)


def difference_words(groups: Groups, scale: float = 1.0, unit: str = "") -> str:
    """The experiment's answer in one line, as the projector shows it and ``armgame analyze --class`` prints it."""
    d = groups.difference
    if d is None:
        return "the two conditions are measured differently (a force field's error against a display's): no difference"
    per = f" {unit}" if unit else ""
    n = f"n = {d.a.n} and {d.b.n}"
    if not math.isfinite(d.difference):
        return f"after-effect, group A - group B: not yet ({n})"
    if not math.isfinite(d.low):
        return f"after-effect, group A - group B: {d.difference * scale:+.2f}{per} ({n}: too few for an interval)"
    return (f"after-effect, group A - group B: {d.difference * scale:+.2f}{per} (Welch's 95 % CI "
            f"{d.low * scale:+.2f} to {d.high * scale:+.2f}, {n})")
