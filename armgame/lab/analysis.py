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
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .metrics import NO_CHANNEL, ChannelMeasures, Reach, channel_measures, reach_metrics
from .session import LabSession, TrialOutcome

#: The paths figure's groups: (label, block kind, which trials of the block).
PATH_GROUPS = (("baseline", 0, "late"), ("early exposure", 1, "early"), ("late exposure", 1, "late"),
               ("early washout", 2, "early"))


def perturbation_label(outcome: TrialOutcome) -> str:
    """The perturbation the trial ran with, by kind: ``none`` on a catch trial of a perturbed block (so a
    catch trial is a row whose perturbation differs from its block's), ``channel`` on an error-clamp trial."""
    return "channel" if outcome.plan.channel else outcome.plan.active.kind


def channel_of(session: LabSession, outcome: TrialOutcome) -> ChannelMeasures:
    """An error-clamp trial's channel force and adaptation index (NaN on other trials), against the field
    ``Protocol.reference_field`` names for its block."""
    if not outcome.plan.channel:
        return NO_CHANNEL
    hx, hy = outcome.plan.home
    tx, ty = outcome.plan.position
    length = math.hypot(tx - hx, ty - hy)
    reference = session.protocol.reference_field(outcome.plan.block)
    n = outcome.reach_samples  # the channel's samples are the path's: none after the hand was sent home
    measures = channel_measures(np.asarray(outcome.channel_force[:n]),
                                np.column_stack([outcome.vxs[:n], outcome.vys[:n]]).reshape(-1, 2),
                                (-(ty - hy) / length, (tx - hx) / length),
                                None if reference is None else reference.matrix)
    if reference is not None and reference.kind == "joint_viscous":  # its index: against the field at the joints
        from .designs import frame_indices

        measures = replace(measures, adaptation_index=frame_indices(session, outcome)[1])
    return measures


def reach_of(session: LabSession, outcome: TrialOutcome) -> Reach:
    """The reach a trial's measures are taken on: the shown hand from the go cue to the trial's end, or to the
    moment space sent the hand home if it did (``TrialOutcome.home_at``): the jump home is no movement."""
    dt = session.config.dt
    n = outcome.reach_samples
    t = (outcome.go_step + np.arange(n)) * dt
    return Reach(t=t, hand=np.column_stack([outcome.xs[:n], outcome.ys[:n]]).reshape(-1, 2), start=outcome.plan.home,
                 target=outcome.plan.position, go_time=outcome.go_step * dt, hit=outcome.hit)


def trial_rows(session: LabSession) -> list[dict[str, object]]:
    """One row per finished trial, with the columns of ``metrics.TRIAL_COLUMNS``."""
    try:
        disturbance = fit_schedule(session)[0].tolist()
    except ValueError:  # no perturbation, or ones that are not multiples of one another: no one unit
        disturbance = [math.nan] * len(session.outcomes)
    return [trial_row(session, o, d) for o, d in zip(session.outcomes, disturbance, strict=True)]


def trial_row(session: LabSession, o: TrialOutcome, disturbance: float = math.nan,
              reach: Reach | None = None) -> dict[str, object]:
    """One finished trial's row, with the columns of ``metrics.TRIAL_COLUMNS`` (``disturbance``: the trial's, in
    units of the run's first perturbation, ``disturbance_schedule``; NaN when not given). ``reach``: the trial's
    ``reach_of``, where the caller has it as arrays already (the CenterOut batch: its paths are numpy rows)."""
    from .designs import frame_indices

    m = reach_metrics(reach_of(session, o) if reach is None else reach)
    hand, joint = frame_indices(session, o)
    shoulder, elbow = session.protocol.blocks[o.plan.block].posture_of(session.protocol)
    return {
        "block": o.plan.block_name,
        "trial": o.plan.index + 1,
        "target_deg": o.plan.target_deg,
        "perturbation": perturbation_label(o),
        "reaction_time_s": m.reaction_time_s,
        "movement_time_s": m.movement_time_s,
        "peak_speed_m_per_s": m.peak_speed_m_per_s,
        "initial_direction_error_deg": m.initial_direction_error_deg,
        "max_perpendicular_error_m": m.max_perpendicular_error_m,
        "path_length_ratio": m.path_length_ratio,
        "hit": o.hit,
        **channel_of(session, o).as_dict(),
        "hand_sent_home": o.home_at is not None,
        "feedback": o.plan.feedback,
        "disturbance": disturbance,
        "adaptation_index_hand": hand,
        "adaptation_index_joint": joint,
        "home_shoulder_deg": float(shoulder),
        "home_elbow_deg": float(elbow),
    }


def path_groups(session: LabSession, per_group: int | None = None) -> dict[str, list[np.ndarray]]:
    """Hand paths (n, 2) of late baseline, early and late exposure, early washout (one cycle of targets
    each by default), for blocks the protocol has; catch and channel trials left out."""
    per_group = per_group or session.protocol.targets
    by_block: dict[int, list[TrialOutcome]] = {}
    for o in session.outcomes:
        if not (o.plan.catch or o.plan.channel):
            by_block.setdefault(o.plan.block, []).append(o)
    groups: dict[str, list[np.ndarray]] = {}
    for label, block, which in PATH_GROUPS:
        trials = by_block.get(block, [])
        if len(session.protocol.blocks) < 3 and block > 0:
            continue
        chosen = trials[:per_group] if which == "early" else trials[-per_group:]
        if chosen:
            groups[label] = [np.column_stack([o.xs[:o.reach_samples], o.ys[:o.reach_samples]]) for o in chosen]
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


def channel_summary(rows: Sequence[Mapping[str, object]], cycle: int = 8) -> list[dict[str, object]]:
    """Per block with channel trials that have an adaptation index: how many, the first one's index, the mean
    index of its first and
    last ``cycle`` channel trials, and the largest mean over ``cycle`` consecutive ones (a cycle of targets
    averages out each direction's own offset), with the place of that run's first trial (from 1)."""
    blocks: dict[str, list[float]] = {}
    for r in rows:
        index = float(r["adaptation_index"])  # type: ignore[arg-type]
        if r["perturbation"] == "channel" and math.isfinite(index):
            blocks.setdefault(str(r["block"]), []).append(index)
    out: list[dict[str, object]] = []
    for name, v in blocks.items():
        n = min(cycle, len(v))
        runs = [float(np.mean(v[i:i + n])) for i in range(len(v) - n + 1)]
        best = int(np.argmax(runs))
        out.append({"block": name, "channels": len(v), "cycle": n, "first": v[0], "early": runs[0], "late": runs[-1],
                    "largest": runs[best], "at": best + 1})
    return out


def fit_schedule(session: LabSession) -> tuple[np.ndarray, np.ndarray]:
    """``disturbance_schedule`` of a run's finished trials."""
    return disturbance_schedule(session.protocol, [o.plan for o in session.outcomes])


def disturbance_schedule(protocol, plans: Sequence) -> tuple[np.ndarray, np.ndarray]:
    """Each finished trial's disturbance, in units of the run's first perturbation (the reference: +1 that
    perturbation, -1 its opposite, 0 none and catch trials), and whether it was an error-clamp (channel)
    trial: the schedule ``fit.fit_two_rate`` fits the learner to. Raises ValueError for a run with no
    perturbation or only zero ones (curl ``b = 0``, ``angle = 0``: the unit a disturbance is counted in
    would be zero), or one whose perturbations are not multiples of each other (a curl and a rotation)."""
    perturbed = [b.perturbation for b in protocol.blocks if b.perturbation.kind != "none"]
    reference = next((p for p in perturbed if not p.is_null), None)
    if reference is None:
        if perturbed:
            raise ValueError(f"its perturbation is zero ({perturbed[0].label()}): nothing to learn; a fit needs "
                             "a field (or a changed display) to fit")
        raise ValueError("the protocol has no perturbation: nothing to learn, nothing to fit")

    def scale(p) -> float:
        if p.is_null:  # none, or a zero field: no disturbance (and no division by a zero reference)
            return 0.0
        for mine, theirs in ((p.matrix, reference.matrix), (p.joint_matrix, reference.joint_matrix)):
            if mine is not None and theirs is not None:  # two hand fields (curl or viscous), or two joint fields
                m, r = np.asarray(mine), np.asarray(theirs)
                along = float(np.sum(m * r)) / float(np.sum(r * r))
                if np.allclose(m, along * r):
                    return along
        if p.kind == reference.kind == "rotation":
            return p["angle"] / reference["angle"]
        if p == reference:
            return 1.0
        raise ValueError(f"{p.label()} is not a multiple of the run's first perturbation ({reference.label()}): "
                         "one learner cannot be fitted to both")

    disturbance = np.array([0.0 if plan.channel else scale(plan.active) for plan in plans])
    clamped = np.array([plan.channel for plan in plans], dtype=bool)
    return disturbance, clamped


def figure_metric(protocol) -> str:
    """What a learning curve plots: the perpendicular error for force fields (a velocity-dependent field
    bends the path after the first 100 ms), the initial direction error for visual transforms."""
    forces = any(b.perturbation.is_force for b in protocol.blocks)
    return "max_perpendicular_error_m" if forces else "initial_direction_error_deg"


def write_run_outputs(session: LabSession, out: Path, figures: bool = True) -> list[Path]:
    """``trials.csv`` and, with matplotlib, ``learning.png``, ``paths.png`` and, with channel trials,
    ``adaptation.png`` in ``out``; returns what was written."""
    from .metrics import write_trials_csv

    out = Path(out)
    rows = trial_rows(session)
    written = [out / "trials.csv"]
    write_trials_csv(written[0], rows)
    if figures:
        from .figures import learning_figure, paths_figure

        learning_figure(rows, out / "learning.png", metric=figure_metric(session.protocol))
        perturbed = [b.perturbation.label() for b in session.protocol.blocks if b.perturbation.kind != "none"]
        caption = f"{session.protocol.name}: {', '.join(dict.fromkeys(perturbed)) or 'no perturbation'}; " \
                  f"seed {session.config.seed}"
        paths_figure(path_groups(session), session.home, session.protocol.target_positions(session.home),
                     out / "paths.png", target_radius=session.protocol.target_radius, caption=caption)
        written += [out / "learning.png", out / "paths.png"]
        if any(r["perturbation"] == "channel" and math.isfinite(float(r["adaptation_index"])) for r in rows):
            from .figures import adaptation_figure

            adaptation_figure(rows, out / "adaptation.png")
            written.append(out / "adaptation.png")
        from .figures_designs import design_figures

        written += design_figures(session, rows, out)
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


def outcome_word(session: LabSession, outcome: TrialOutcome) -> str | None:
    """What the player is told of how a reach ended: "hit", "missed" (the hand stopped off the target, on a trial
    without a cursor) or "time out"; None on a trial that gives no feedback (a no-vision probe tells nothing, not
    even whether it hit)."""
    if outcome.plan.feedback == "none":
        return None
    if outcome.hit:
        return "hit"
    return "time out" if outcome.end_step - outcome.go_step >= session.timeout_steps else "missed"


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


def display_unit(metric: str) -> tuple[float, str]:
    """The factor from a measure's SI unit (its column's) to the unit every screen and figure shows, and
    that unit: one unit for distances a student reads, cm, wherever they read it."""
    for suffix, shown in (("_m_per_s", (1.0, "m/s")), ("_m", (100.0, "cm")), ("_s", (1000.0, "ms")),
                          ("_deg", (1.0, "deg"))):
        if metric.endswith(suffix):
            return shown
    return 1.0, ""  # a ratio or an index


def learning_curve(rows: Sequence[Mapping[str, object]], metric: str) -> LearningCurve:
    """The learning curve of a run's trial rows (``trial_rows``), in cm or degrees."""
    from .figures import blocks_of

    scale, unit = display_unit(metric)
    label = "perpendicular error" if metric == "max_perpendicular_error_m" else "initial direction error"
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


# ------------------------------------------------------------------ probes by direction (issue 29)
def baseline_offsets(session: LabSession, rows: Sequence[Mapping[str, object]]) -> dict[float, float]:
    """Each direction's baseline adaptation index: the mean over the channel trials to it in the blocks before
    the run's first perturbed block (a bot or a person that has learned nothing still reads an offset of its
    own in each direction: the arm's dynamics differ by direction). Directions without such a trial are
    missing."""
    first = next((i for i, b in enumerate(session.protocol.blocks) if not b.perturbation.is_null),
                 len(session.protocol.blocks))
    seen: dict[float, list[float]] = {}
    for o, r in zip(session.outcomes, rows, strict=True):
        index = float(r["adaptation_index"])  # type: ignore[arg-type]
        if o.plan.channel and o.plan.block < first and math.isfinite(index):
            seen.setdefault(o.plan.target_deg, []).append(index)
    return {deg: float(np.mean(v)) for deg, v in sorted(seen.items())}


def baseline_for(offsets: Mapping[float, float], deg: float) -> tuple[float, tuple[float, ...]]:
    """The baseline subtracted from a channel trial to ``deg``, and the probed directions it came from: the
    direction's own (``baseline_offsets``), or for a direction the baseline never probed (the ``spontaneous``
    preset's baseline probes 4 of its 8), the nearest probed direction's, the mean of the two when two are as
    near. NaN with no offsets at all."""
    if deg in offsets:
        return offsets[deg], (deg,)
    if not offsets:
        return math.nan, ()
    away = {d: abs(signed_angle(d - deg)) for d in offsets}
    nearest = min(away.values())
    chosen = tuple(sorted(d for d in offsets if away[d] == nearest))
    return float(np.mean([offsets[d] for d in chosen])), chosen


def subtract_baseline(session: LabSession, rows: Sequence[Mapping[str, object]]) -> list[dict[str, object]]:
    """The rows with each channel trial's adaptation index less its direction's baseline (``baseline_for``: its
    own, else the nearest probed direction's). Raises ValueError for a run with no baseline channel trial."""
    offsets = baseline_offsets(session, rows)
    if not offsets:
        raise ValueError("the run has no channel trial before its first perturbed block: no baseline to subtract")
    out = []
    for r in rows:
        r = dict(r)
        if r["perturbation"] == "channel":
            base = baseline_for(offsets, float(r["target_deg"]))[0]  # type: ignore[arg-type]
            r["adaptation_index"] = float(r["adaptation_index"]) - base  # type: ignore[arg-type]
        out.append(r)
    return out


def signed_angle(deg: float) -> float:
    """An angle in (-180, 180]."""
    a = (deg + 180.0) % 360.0 - 180.0
    return 180.0 if a == -180.0 else a


def generalization(session: LabSession, rows: Sequence[Mapping[str, object]]) -> list[dict[str, object]]:
    """The generalization function of a train-on-one, probe-the-others run: for each block whose ordinary trials
    go to one direction and whose channel trials probe others, per probed direction (by its angle from the
    trained one, + counter-clockwise): the mean adaptation index of its channel trials, raw and less the
    direction's baseline (``baseline_offsets``; NaN without one), and how many. Empty when no block is such."""
    offsets = baseline_offsets(session, rows)
    out: list[dict[str, object]] = []
    for b, block in enumerate(session.protocol.blocks):
        if block.directions is None or len(block.directions) != 1 or not block.channel_trials or block.channel_block:
            continue
        trained = session.protocol.target_angles_deg()[block.directions[0]] % 360.0
        per: dict[float, list[float]] = {}
        for o, r in zip(session.outcomes, rows, strict=True):
            index = float(r["adaptation_index"])  # type: ignore[arg-type]
            if o.plan.block == b and o.plan.channel and math.isfinite(index):
                per.setdefault(o.plan.target_deg, []).append(index)
        for deg, values in sorted(per.items(), key=lambda item: signed_angle(item[0] - trained)):
            raw = float(np.mean(values))
            out.append({"block": block.name, "trained_deg": trained, "target_deg": deg,
                        "angle_deg": signed_angle(deg - trained), "n": len(values), "index": raw,
                        "index_less_baseline": raw - offsets.get(deg, math.nan)})
    return out


CHANNEL_TRACE_COLUMNS = ("trial", "block", "target_deg", "time_s", "channel_force_n", "cancelling_force_n",
                         "hand_speed_m_per_s")


def channel_traces(session: LabSession) -> list[tuple[object, ...]]:
    """Every channel trial's force over time, one row per physics step from the go cue to the trial's end
    (``CHANNEL_TRACE_COLUMNS``): the force the arm pressed into the channel (N, + counter-clockwise side), the
    force that would exactly cancel the reference field at that velocity (``-n . B v``, the adaptation index's
    regressor; NaN with no reference field) and the hand's speed."""
    out: list[tuple[object, ...]] = []
    dt = session.config.dt
    for o in session.outcomes:
        if not o.plan.channel:
            continue
        hx, hy = o.plan.home
        tx, ty = o.plan.position
        length = math.hypot(tx - hx, ty - hy)
        normal = np.array([-(ty - hy) / length, (tx - hx) / length])
        v = np.column_stack([o.vxs, o.vys]) if o.vxs else np.zeros((0, 2))
        reference = session.protocol.reference_field(o.plan.block)
        if reference is not None and reference.kind == "joint_viscous":  # held at the joints: at each sample's q
            from .designs import candidate_fields, jacobian

            arm = session.config.arm
            w = candidate_fields(session.protocol, reference, arm.l1, arm.l2)[1]
            jac = jacobian(arm.l1, arm.l2, np.asarray(o.q1s), np.asarray(o.q2s))
            torque = np.linalg.solve(jac, v[..., None])[..., 0] @ w.T
            cancel = -np.linalg.solve(np.swapaxes(jac, -1, -2), torque[..., None])[..., 0] @ normal
        else:
            cancel = -(v @ np.asarray(reference.matrix).T) @ normal if reference is not None \
                else np.full(len(v), math.nan)
        speed = np.hypot(v[:, 0], v[:, 1])
        for k, force in enumerate(o.channel_force[:o.reach_samples]):  # not past the hand sent home
            out.append((o.plan.index + 1, o.plan.block_name, o.plan.target_deg, k * dt, force, float(cancel[k]),
                        float(speed[k])))
    return out


def write_channel_traces(path: Path, session: LabSession) -> None:
    """``channel_traces`` as CSV (numbers written exactly, NaN as an empty field), atomically."""
    import csv
    import io

    from .metrics import _write_text

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CHANNEL_TRACE_COLUMNS)
    for trial, block, deg, t, force, cancel, speed in channel_traces(session):
        block = f"'{block}" if str(block)[:1] in "=+-@" else block  # a spreadsheet would take it for a formula
        writer.writerow([trial, block, repr(deg), repr(t), repr(force), "" if math.isnan(cancel) else repr(cancel),
                         repr(speed)])
    _write_text(Path(path), buffer.getvalue())


# ------------------------------------------------------------------ the class curve (issue 39)
@dataclass(frozen=True)
class ClassRun:
    """A lab run offered to a class curve: the name its replay carries (None: none), whether a program played it
    (a bot's run: its replay is not ``driven`` by the keyboard), its protocol and its trial rows (``trial_rows``)."""

    player: str | None
    program: bool
    protocol: object
    rows: Sequence[Mapping[str, object]]


@dataclass(frozen=True)
class ClassCurve:
    """A class curve and how it was made: the protocol and measure, which runs are in it (their places in the
    runs given), the programs' runs kept apart, every other run left out with why, and the curve's rows
    (``figures.class_curve``: ``trial, block, perturbation, mean, sem, n``, in the measure's SI unit)."""

    protocol: object
    metric: str | None
    members: tuple[int, ...]
    programs: int
    left_out: tuple[tuple[int, str], ...]
    trials: tuple[dict[str, object], ...]

    @property
    def students(self) -> int:
        return len(self.members)


def curve_protocol(choice: object):
    """The class curve's protocol from the teacher's choice as a class keeps it (``Roster.lab`` in ``class.json``):
    a preset's name, a protocol as plain data, or None (no protocol chosen)."""
    from .presets import preset
    from .protocol_file import protocol_from_dict

    if isinstance(choice, dict):
        return protocol_from_dict(choice, "lab")
    return preset(choice) if isinstance(choice, str) and choice else None


def class_curve_of(runs: Sequence[ClassRun], protocol, metric: str | None = None, *,
                   people_only: bool = True) -> ClassCurve:
    """The class curve of ``protocol`` over ``runs``: what the live class's ``/lab`` page draws
    (``classroom.views.lab_curve``) and ``armgame analyze --class`` writes, built here once so that the
    two agree by construction.

    ``people_only`` (a class's rule): programs' runs are counted apart and never in the curve, and each person
    (by ``records.standings.player_key`` of their name) counts once, with their first run of the protocol in the
    order given. Without it (a folder of replays that is no class's, where bots may stand in for volunteers in
    a rehearsal) every run of the protocol counts. Runs of another protocol are left out. ``metric``: the
    curve's measure (default: the one the learning figure plots, ``figure_metric``).
    """
    from ..records.standings import player_key
    from .figures import class_curve

    members: list[int] = []
    left_out: list[tuple[int, str]] = []
    seen: dict[str, str] = {}
    programs = 0
    for i, run in enumerate(runs):
        if people_only and run.program:
            programs += 1
            left_out.append((i, "a program's run: counted apart, never in the class curve"))
        elif protocol is None or run.protocol != protocol:
            left_out.append((i, "another protocol than the class curve's"))
        elif people_only and run.player and player_key(run.player) in seen:
            left_out.append((i, f"not {run.player}'s first run of the protocol (that one is in the curve)"))
        else:
            if people_only and run.player:
                seen[player_key(run.player)] = run.player
            members.append(i)
    if protocol is None or not members:
        return ClassCurve(protocol, None, (), programs, tuple(left_out), ())
    metric = metric or figure_metric(protocol)
    curve = class_curve([runs[i].rows for i in members], metric)
    return ClassCurve(protocol, metric, tuple(members), programs, tuple(left_out), tuple(curve))
