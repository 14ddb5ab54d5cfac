"""From a lab run to its table and figures: one row per reach, computed on the re-simulated run.

``trial_rows`` measures every finished trial of a ``LabSession`` with the metrics helper's
``reach_metrics`` on the hand as shown and scored (after any visual transform). ``armgame
analyze`` feeds it sessions re-simulated from replays that verified, so only verified data
is measured; ``armgame lab --out`` feeds it the run it has just played.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .metrics import Reach, reach_metrics
from .session import LabSession, TrialOutcome

#: The paths figure's groups: (label, block kind, which trials of the block).
PATH_GROUPS = (("baseline", 0, "late"), ("early exposure", 1, "early"), ("late exposure", 1, "late"),
               ("early washout", 2, "early"))


def perturbation_label(outcome: TrialOutcome) -> str:
    """The perturbation the trial ran with, by kind: ``none`` on a catch trial of a perturbed block (so a
    catch trial is a row whose perturbation differs from its block's)."""
    return outcome.plan.active.kind


def reach_of(session: LabSession, outcome: TrialOutcome) -> Reach:
    dt = session.config.dt
    n = len(outcome.xs)
    t = (outcome.go_step + np.arange(n)) * dt
    return Reach(t=t, hand=np.column_stack([outcome.xs, outcome.ys]), start=session.home,
                 target=outcome.plan.position, go_time=outcome.go_step * dt, hit=outcome.hit)


def trial_rows(session: LabSession) -> list[dict[str, object]]:
    """One row per finished trial, with the columns of ``metrics.TRIAL_COLUMNS``."""
    return [trial_row(session, o) for o in session.outcomes]


def trial_row(session: LabSession, o: TrialOutcome) -> dict[str, object]:
    """One finished trial's row, with the columns of ``metrics.TRIAL_COLUMNS``."""
    m = reach_metrics(reach_of(session, o))
    return {
        "block": o.plan.block_name,
        "trial": o.plan.index + 1,
        "target_deg": o.plan.target_deg,
        "perturbation": perturbation_label(o),
        "reaction_time": m.reaction_time,
        "movement_time": m.movement_time,
        "peak_speed": m.peak_speed,
        "initial_direction_error_deg": m.initial_direction_error_deg,
        "max_perpendicular_error_m": m.max_perpendicular_error_m,
        "path_length_ratio": m.path_length_ratio,
        "hit": o.hit,
    }


def path_groups(session: LabSession, per_group: int | None = None) -> dict[str, list[np.ndarray]]:
    """Hand paths (n, 2) of late baseline, early and late exposure, early washout (one cycle of targets
    each by default), for blocks the protocol has; catch trials left out."""
    per_group = per_group or session.protocol.targets
    by_block: dict[int, list[TrialOutcome]] = {}
    for o in session.outcomes:
        if not o.plan.catch:
            by_block.setdefault(o.plan.block, []).append(o)
    groups: dict[str, list[np.ndarray]] = {}
    for label, block, which in PATH_GROUPS:
        trials = by_block.get(block, [])
        if len(session.protocol.blocks) < 3 and block > 0:
            continue
        chosen = trials[:per_group] if which == "early" else trials[-per_group:]
        if chosen:
            groups[label] = [np.column_stack([o.xs, o.ys]) for o in chosen]
    return groups


def block_summary(rows: Sequence[Mapping[str, object]], metric: str = "max_perpendicular_error_m",
                  first: int = 8) -> list[dict[str, object]]:
    """Per block: trials, hits, and the mean of ``metric`` over its first and last ``first`` trials."""
    blocks: dict[str, list[Mapping[str, object]]] = {}
    for r in rows:
        blocks.setdefault(str(r["block"]), []).append(r)

    def mean(rs: Sequence[Mapping[str, object]]) -> float:
        usual = Counter(str(r["perturbation"]) for r in rs).most_common(1)[0][0]  # catch trials left out
        values = [float(r[metric]) for r in rs if r["perturbation"] == usual]  # type: ignore[arg-type]
        values = [v for v in values if math.isfinite(v)]
        return float(np.mean(values)) if values else math.nan

    return [{"block": name, "trials": len(rs), "hits": sum(bool(r["hit"]) for r in rs),
             "early": mean(rs[:first]), "late": mean(rs[-first:])} for name, rs in blocks.items()]


def figure_metric(protocol) -> str:
    """What a learning curve plots: the perpendicular error for force fields (a velocity-dependent field
    bends the path after the first 100 ms), the initial direction error for visual transforms."""
    kinds = {b.perturbation.kind for b in protocol.blocks}
    return "max_perpendicular_error_m" if kinds & {"curl", "constant", "spring"} else "initial_direction_error_deg"


def write_run_outputs(session: LabSession, out: Path, figures: bool = True) -> list[Path]:
    """``trials.csv`` and, with matplotlib, ``learning.png`` and ``paths.png`` in ``out``; returns what was written."""
    from .metrics import write_trials_csv

    out = Path(out)
    rows = trial_rows(session)
    written = [out / "trials.csv"]
    write_trials_csv(written[0], rows)
    if figures:
        from .figures import learning_figure, paths_figure
        from .protocol import target_positions

        learning_figure(rows, out / "learning.png", metric=figure_metric(session.protocol))
        perturbed = [b.perturbation.label() for b in session.protocol.blocks if b.perturbation.kind != "none"]
        caption = f"{session.protocol.name}: {', '.join(dict.fromkeys(perturbed)) or 'no perturbation'}; " \
                  f"seed {session.config.seed}"
        paths_figure(path_groups(session), session.home, target_positions(session.protocol, session.home),
                     out / "paths.png", target_radius=session.protocol.target_radius, caption=caption)
        written += [out / "learning.png", out / "paths.png"]
    return written


def result_words(session: LabSession, outcome: TrialOutcome) -> str:
    """Knowledge of results for one reach, in the measure its learning curve plots: "1.9 cm off the line"
    under a force field, "12 deg clockwise of the target" under a changed display."""
    row = trial_row(session, outcome)
    metric = figure_metric(session.protocol)
    value = float(row[metric])  # type: ignore[arg-type]
    if not math.isfinite(value):
        return "no reach" if not outcome.hit else "on target"
    if metric == "max_perpendicular_error_m":
        side = "" if abs(value) < 0.0005 else (" (left)" if value > 0 else " (right)")
        return f"{abs(value) * 100:.1f} cm off the line{side}"
    if abs(value) < 0.5:
        return "aimed straight at the target"
    return f"aimed {abs(value):.0f} deg {'anticlockwise' if value > 0 else 'clockwise'} of the target"


@dataclass(frozen=True)
class CurveBlock:
    name: str
    first: int  # trial numbers, from 1
    last: int
    perturbed: bool
    mean: float  # the block's mean of the curve's measure, catch trials left out (NaN: none measured)


@dataclass(frozen=True)
class LearningCurve:
    """What the lab window draws at the end: one point per trial, the blocks and where the after-effect is."""

    label: str  # the measure and its unit, for the axis
    unit: str
    points: tuple[tuple[int, float, bool], ...]  # trial, value (in unit), catch trial
    blocks: tuple[CurveBlock, ...]
    after_effect: tuple[int, float] | None  # the first measured washout trial after a perturbed block


def learning_curve(rows: Sequence[Mapping[str, object]], metric: str) -> LearningCurve:
    """The learning curve of a run's trial rows (``trial_rows``), in cm or degrees."""
    from .figures import blocks_of

    scale, label, unit = (100.0, "perpendicular error", "cm") if metric == "max_perpendicular_error_m" \
        else (1.0, "initial direction error", "deg")
    spans = blocks_of(rows) if rows else []
    points, blocks = [], []
    unperturbed = spans[0]["perturbation"] if spans else "none"
    after: tuple[int, float] | None = None
    previous_perturbed = False
    for span in spans:
        perturbed = span["perturbation"] != unperturbed
        values = []
        for r in span["rows"]:
            v = float(r[metric]) * scale  # type: ignore[arg-type]
            catch = r["trial"] in span["catch"]
            points.append((int(r["trial"]), v, catch))  # type: ignore[arg-type]
            if math.isfinite(v) and not catch:
                values.append(v)
                if after is None and previous_perturbed and not perturbed:
                    after = (int(r["trial"]), v)  # type: ignore[arg-type]
        blocks.append(CurveBlock(str(span["block"]), int(span["first"]), int(span["last"]), perturbed,
                                 float(np.mean(values)) if values else math.nan))
        previous_perturbed = perturbed
    return LearningCurve(label, unit, tuple(points), tuple(blocks), after)
