"""Issue 41's classic tests, measured: which frame a field was learned in, and generalization probed without vision.

**Frames** (Shadmehr & Mussa-Ivaldi 1994). A velocity field can be held at the hand (``F = B v``: the same force
for the same hand velocity at any posture) or at the joints (``tau = W qdot``: the same torque for the same joint
velocities). At the posture ``q_T`` where it is learned the two are one field, ``W = J(q_T)^T B J(q_T)``; at another
posture ``q`` the joint field is seen at the hand as ``J(q)^-T W J(q)^-1``. For a pure shoulder rotation by ``phi``,
``J`` turns by ``phi``, so that is ``R(phi) B R(phi)^T``: a curl field is the same in both frames, a field with a
symmetric part (Shadmehr & Mussa-Ivaldi's) is not. ``frame_indices`` regresses a channel trial's force on what each
candidate would need cancelled at that trial's states (sample by sample, at its own joint angles and velocities):
``adaptation_index_hand`` and ``adaptation_index_joint``, 1 when that frame's field is fully compensated.

A channel trial takes the whole field away, its push along the path too, and the index regresses only the push across
it. A learner that holds the field still pushes against the part along the path; nothing meets that push in the
channel, so the reach runs slower or faster than the learner planned, and what it presses across the channel changes
with it. Where a field pushes along the path, the index of a learner that compensates it exactly is off, by a
different amount at each posture: the lab's model bot holding exactly the viscous preset's field read 1.03 at the
posture it learned at and 1.39 with the shoulder turned 90 deg, over 8 directions from 0 deg (issue 50).
``perturbations.across_path_deg`` finds the directions where a field pushes along the path only by its isotropic part
(``tr B / 2``); for the viscous preset's field that is 0.06 N s/m against 1.93 across, and a full compensator there
reads 1 in its own frame at both postures (``tests/test_lab_frames_calibration.py``). A shoulder turned by a multiple
of 90 deg keeps those directions (the joint twin ``R B R^T`` swaps the field's axes), so one set of targets serves
both frames.

**Probes without vision** (Krakauer et al. 2000). ``probe_generalization``: per probed direction, the initial
direction error of the no-cursor catch trials in a train-on-one block, less that direction's no-cursor baseline, as a
fraction of the rotation (1: the trained rotation fully expressed there, 0: nothing).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from .perturbations import Perturbation
from .protocol import Block, Protocol
from .session import LabSession, TrialOutcome, lab_config

Matrix = tuple[tuple[float, float], tuple[float, float]]


def jacobian(l1: float, l2: float, q1: float | np.ndarray, q2: float | np.ndarray) -> np.ndarray:
    """The hand Jacobian ``J(q)`` (rows x, y; columns shoulder, elbow), (..., 2, 2) for arrays of angles."""
    s1, c1 = np.sin(q1), np.cos(q1)
    s12, c12 = np.sin(np.add(q1, q2)), np.cos(np.add(q1, q2))
    return np.stack([np.stack([-l1 * s1 - l2 * s12, -l2 * s12], axis=-1),
                     np.stack([l1 * c1 + l2 * c12, l2 * c12], axis=-1)], axis=-2)


def joint_twin(hand: Matrix, l1: float, l2: float, posture: tuple[float, float]) -> np.ndarray:
    """``W = J^T B J`` (N m s/rad): the joint field that is the hand field ``B`` at ``posture`` (rad)."""
    j = jacobian(l1, l2, *posture)
    return j.T @ np.asarray(hand, dtype=float) @ j


def hand_twin(joint: Matrix, l1: float, l2: float, posture: tuple[float, float]) -> np.ndarray:
    """``B = J^-T W J^-1`` (N s/m): the hand field that is the joint field ``W`` at ``posture`` (rad)."""
    inverse = np.linalg.inv(jacobian(l1, l2, *posture))
    return inverse.T @ np.asarray(joint, dtype=float) @ inverse


def candidate_fields(protocol: Protocol, field: Perturbation, l1: float, l2: float) -> tuple[np.ndarray, np.ndarray]:
    """(``B``, ``W``): the field held at the hand and held at the joints, one field where it is first on."""
    posture = tuple(math.radians(a) for a in protocol.field_posture_deg(field))
    if field.kind == "joint_viscous":
        w = np.asarray(field.joint_matrix, dtype=float)
        return hand_twin(field.joint_matrix, l1, l2, posture), w  # type: ignore[arg-type]
    b = np.asarray(field.matrix, dtype=float)
    return b, joint_twin(field.matrix, l1, l2, posture)  # type: ignore[arg-type]


def _slope(force: np.ndarray, ideal: np.ndarray) -> float:
    power = float(ideal @ ideal)
    return float(ideal @ force) / power if power > 1e-12 else math.nan


def frame_indices(session: LabSession, outcome: TrialOutcome) -> tuple[float, float]:
    """A channel trial's (``adaptation_index_hand``, ``adaptation_index_joint``): the least-squares slope, through
    the origin, of the force pressed into the channel on the force that would cancel the reference field held at
    the hand (``-n . B v``) and held at the joints (``-n . J^-T W qdot``), at each sample's own state. NaN on other
    trials, or with no reference field."""
    plan = outcome.plan
    reference = session.protocol.reference_field(plan.block)
    if not plan.channel or reference is None or not outcome.q1s:
        return math.nan, math.nan
    f = np.asarray(outcome.channel_force, dtype=float)
    v = np.column_stack([outcome.vxs, outcome.vys])
    if f.size == 0 or not (np.isfinite(f).all() and np.isfinite(v).all()):
        return math.nan, math.nan
    arm = session.config.arm
    b, w = candidate_fields(session.protocol, reference, arm.l1, arm.l2)
    hx, hy = plan.home
    tx, ty = plan.position
    length = math.hypot(tx - hx, ty - hy)
    n = np.array([-(ty - hy) / length, (tx - hx) / length])
    jac = jacobian(arm.l1, arm.l2, np.asarray(outcome.q1s), np.asarray(outcome.q2s))
    qdot = np.linalg.solve(jac, v[..., None])[..., 0]
    torque = qdot @ w.T
    hand_force = np.linalg.solve(np.swapaxes(jac, -1, -2), torque[..., None])[..., 0]
    return _slope(f, -(v @ b.T) @ n), _slope(f, -hand_force @ n)


def calibration_protocol(protocol: Protocol) -> Protocol:
    """A frames protocol's calibration: its targets and reference field, a cycle of channel trials in the field at the
    posture it is learned at (block ``trained``) and one at the posture of its first frames test (block ``test``)."""
    field = next(b.perturbation for b in protocol.blocks if b.perturbation.is_velocity_field)
    learned = protocol.field_posture_deg(field)
    test = next(b.posture_of(protocol) for b in protocol.blocks
                if b.channel_trials and b.posture_of(protocol) != learned)
    n = protocol.targets
    return replace(protocol, blocks=(Block("trained", n, field, channel_trials=n, home_posture_deg=learned),
                                     Block("test", n, field, channel_trials=n, home_posture_deg=test)))


def held_field_indices(protocol: Protocol, frame: str, matrix: Matrix | np.ndarray, seed: int = 10,
                       ) -> dict[tuple[str, str], float]:
    """What a learner that holds ``matrix`` in ``frame`` (``bots.holding_bot``: the adaptive bot's learned field set
    to it) reads on ``calibration_protocol(protocol)``: per (block, index frame), the mean over the block's channel
    trials of its index less the field-free model bot's on the same trial (the same seed, so the same trials). With
    the true field in either frame it is the frames index's calibration: 1 in that frame at both postures."""
    from ..game.bots import Autopilot
    from .bots import holding_bot, make_lab_bot

    calibration = calibration_protocol(protocol)
    readings: dict[tuple[str, str], list[float]] = {}
    runs = []
    for bot in (holding_bot(frame, np.asarray(matrix, dtype=float)), make_lab_bot("model")):
        session = LabSession(lab_config(calibration, seed), calibration)
        Autopilot(session, bot).play()
        runs.append(session)
    held, free = runs
    for o, f in zip(held.outcomes, free.outcomes, strict=True):
        (h1, j1), (h0, j0) = frame_indices(held, o), frame_indices(free, f)
        readings.setdefault((o.plan.block_name, "hand"), []).append(h1 - h0)
        readings.setdefault((o.plan.block_name, "joint"), []).append(j1 - j0)
    return {k: float(np.mean(v)) for k, v in readings.items()}


def frames_table(session: LabSession, rows: Sequence[Mapping[str, object]]) -> list[dict[str, object]]:
    """Every channel trial of a frames test (a block of channel trials at a posture other than where its reference
    field was learned, after that field first came on): its block, trial number, direction and the hand-frame and
    joint-frame indices, each less that direction's baseline at that posture (the mean index of the channel trials
    to that direction at that posture before the field first came on), with ``less_baseline`` saying whether there
    was one."""
    protocol = session.protocol
    onset = next((i for i, b in enumerate(protocol.blocks) if not b.perturbation.is_null), len(protocol.blocks))
    base: dict[tuple[tuple[float, float], float], list[tuple[float, float]]] = {}
    for o, r in zip(session.outcomes, rows, strict=True):
        if o.plan.channel and o.plan.block < onset:
            key = (protocol.blocks[o.plan.block].posture_of(protocol), o.plan.target_deg)
            base.setdefault(key, []).append((float(r["adaptation_index_hand"]),  # type: ignore[arg-type]
                                             float(r["adaptation_index_joint"])))  # type: ignore[arg-type]
    offsets = {k: tuple(float(np.mean(c)) for c in zip(*v, strict=True)) for k, v in base.items()}
    tests = set()
    for b, block in enumerate(protocol.blocks):
        reference = protocol.reference_field(b)
        if block.channel_trials and reference is not None and b >= onset \
                and block.posture_of(protocol) != protocol.field_posture_deg(reference):
            tests.add(b)
    out: list[dict[str, object]] = []
    for o, r in zip(session.outcomes, rows, strict=True):
        if o.plan.block not in tests or not o.plan.channel:
            continue
        posture = protocol.blocks[o.plan.block].posture_of(protocol)
        hand, joint = float(r["adaptation_index_hand"]), float(r["adaptation_index_joint"])  # type: ignore[arg-type]
        offset = offsets.get((posture, o.plan.target_deg))
        if offset is not None:
            hand, joint = hand - offset[0], joint - offset[1]
        if math.isfinite(hand) and math.isfinite(joint):
            out.append({"block": o.plan.block_name, "trial": o.plan.index + 1, "target_deg": o.plan.target_deg,
                        "posture_deg": posture, "hand": hand, "joint": joint, "less_baseline": offset is not None})
    return out


def frames_summary(session: LabSession, rows: Sequence[Mapping[str, object]], first: int | None = None,
                   ) -> list[dict[str, object]]:
    """Per frames test block (``frames_table``): the mean hand-frame and joint-frame index over its first ``first``
    channel trials (default: a cycle of targets), and which frame the run reads as learned in."""
    first = first or session.protocol.targets
    table = frames_table(session, rows)
    out: list[dict[str, object]] = []
    for name in dict.fromkeys(str(r["block"]) for r in table):
        mine = [r for r in table if r["block"] == name][:first]
        hand = float(np.mean([r["hand"] for r in mine]))
        joint = float(np.mean([r["joint"] for r in mine]))
        out.append({"block": name, "posture_deg": mine[0]["posture_deg"], "trials": len(mine), "hand": hand,
                    "joint": joint, "less_baseline": all(r["less_baseline"] for r in mine),
                    "reads_as": "joint" if joint > hand else "hand"})
    return out


def probe_generalization(session: LabSession, rows: Sequence[Mapping[str, object]]) -> list[dict[str, object]]:
    """For each block that trains one direction with a rotation and sends catch trials (probes, with or without
    vision) to others: per probed direction, by its angle from the trained one, the mean initial direction error
    (deg) of its probes, that direction's baseline (the mean over probes to it before the first perturbed block,
    with the same feedback), and the generalization: ``-(error - baseline) / angle``, the fraction of the trained
    rotation the reach expresses there (probes run with the rotation off, so the hand is measured as it moved)."""
    protocol = session.protocol
    onset = next((i for i, b in enumerate(protocol.blocks) if not b.perturbation.is_null), len(protocol.blocks))
    base: dict[tuple[float, str], list[float]] = {}
    for o, r in zip(session.outcomes, rows, strict=True):
        error = float(r["initial_direction_error_deg"])  # type: ignore[arg-type]
        if o.plan.catch and o.plan.block < onset and math.isfinite(error):
            base.setdefault((o.plan.target_deg, o.plan.feedback), []).append(error)
    out: list[dict[str, object]] = []
    for b, block in enumerate(protocol.blocks):
        p = block.perturbation
        if p.kind != "rotation" or p.is_null or block.directions is None or len(block.directions) != 1 \
                or not block.catch_trials:
            continue
        trained = protocol.target_angles_deg()[block.directions[0]] % 360.0
        per: dict[float, list[float]] = {}
        for o, r in zip(session.outcomes, rows, strict=True):
            error = float(r["initial_direction_error_deg"])  # type: ignore[arg-type]
            if o.plan.block == b and o.plan.catch and math.isfinite(error):
                per.setdefault(o.plan.target_deg, []).append(error)
        feedback = block.probes_feedback
        for deg, errors in sorted(per.items(), key=lambda item: _signed(item[0] - trained)):
            mean = float(np.mean(errors))
            baseline = base.get((deg, feedback))
            offset = float(np.mean(baseline)) if baseline else math.nan
            out.append({"block": block.name, "trained_deg": trained, "target_deg": deg,
                        "angle_deg": _signed(deg - trained), "n": len(errors), "feedback": feedback,
                        "error_deg": mean, "baseline_deg": offset,
                        "generalization": -(mean - offset) / p["angle"]})
    return out


def _signed(deg: float) -> float:
    a = (deg + 180.0) % 360.0 - 180.0
    return 180.0 if a == -180.0 else a
