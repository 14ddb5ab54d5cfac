"""A protocol as a file holds it: a teacher's TOML file, and the ``protocol`` of a lab replay's task section.

``protocol_as_dict`` writes a ``Protocol`` as plain data (what a replay stores, and a class's ``class.json``),
``protocol_from_dict`` reads it back (a TOML file's table or a replay's JSON) and ``load_protocol`` reads a TOML
file. A file's keys are the protocol's fields, with a few spelt out: ``delay_min`` and ``delay_max`` for
``delay``, ``home_shoulder_deg`` and ``home_elbow_deg`` for a posture, ``directions_deg`` (degrees, each one of
the targets' directions) for a block's ``directions``; a block's perturbation is written and read by its own
kind (``perturbations``). The reader checks the file's shape (its keys, its tables and lists) and turns its
words into values; the values themselves are checked by ``Protocol`` as it is built, so a file and a protocol
made in code meet the same checks and the same messages.

What is written only when it is used (the channel's settings, the probe settings, a block's channel trials,
directions and issue-41 settings) is left out otherwise, so a protocol without them is written byte for byte as
before they existed (``tests/data/lab_protocols.json`` holds it).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import UserError
from ..files import parse_toml
from ..records.storage import read_limited
from ..valid import check_float, check_int, check_keys, check_str
from .perturbations import KINDS, ProtocolError
from .protocol import (
    CHANNEL_DAMPING,
    CHANNEL_STIFFNESS,
    DEFAULT_INSTRUCTIONS,
    MAX_TARGETS,
    RANGES,
    Block,
    Protocol,
    check_block_count,
    target_angles_deg,
)

MAX_PROTOCOL_BYTES = 256 * 1024
_TOP = {"name", "targets", "distance", "target_radius", "home_radius", "hold_time", "delay_min", "delay_max",
        "timeout", "first_target_deg", "home_shoulder_deg", "home_elbow_deg", "channel_stiffness", "channel_damping",
        "probe_schedule", "consecutive_probes"}
#: The top-level keys that are a field of ``Protocol`` as they are.
_AS_IS = ("targets", "distance", "target_radius", "home_radius", "hold_time", "timeout", "first_target_deg",
          "channel_stiffness", "channel_damping", "consecutive_probes")
_BLOCK = {"name", "trials", "catch_trials", "channel_trials", "instruction", "perturbation", "directions_deg",
          "probe_directions_deg", "home_shoulder_deg", "home_elbow_deg", "feedback", "probe_feedback", "mix"}


# ----------------------------------------------------------------- writing
def protocol_as_dict(p: Protocol) -> dict[str, object]:
    """The protocol as plain data, in a file's keys (the order is kept: a class's digest of a lab hand-in hashes
    it)."""
    # The channel's settings and a block's channel_trials are written only when used, so a protocol
    # without channels is written as before.
    custom = (p.channel_stiffness, p.channel_damping) != (CHANNEL_STIFFNESS, CHANNEL_DAMPING)
    channel = {"channel_stiffness": p.channel_stiffness, "channel_damping": p.channel_damping} \
        if p.has_channels or custom else {}
    # Likewise the probe settings (a replay without them ran the ``random`` placement).
    probes: dict[str, object] = {"probe_schedule": p.probe_schedule} if p.has_probes else {}
    if p.consecutive_probes:
        probes["consecutive_probes"] = True
    angles = p.target_angles_deg()
    return {
        "name": p.name,
        "targets": p.targets,
        "distance": p.distance,
        "target_radius": p.target_radius,
        "home_radius": p.home_radius,
        "hold_time": p.hold_time,
        "delay_min": p.delay[0],
        "delay_max": p.delay[1],
        "timeout": p.timeout,
        "first_target_deg": p.first_target_deg,
        "home_shoulder_deg": p.home_posture_deg[0],
        "home_elbow_deg": p.home_posture_deg[1],
        **channel,
        **probes,
        "blocks": [_block_as_dict(b, angles) for b in p.blocks],
    }


def _block_as_dict(b: Block, angles: tuple[float, ...]) -> dict[str, object]:
    out: dict[str, object] = {"name": b.name, "trials": b.trials, "catch_trials": b.catch_trials,
                              "instruction": b.instruction}
    if b.channel_trials:
        out["channel_trials"] = b.channel_trials
    if b.directions is not None:
        out["directions_deg"] = [angles[t] % 360.0 for t in b.directions]
    if b.probe_directions is not None:
        out["probe_directions_deg"] = [angles[t] % 360.0 for t in b.probe_directions]
    # Issue 41's settings: only those set.
    if b.home_posture_deg is not None:
        out["home_shoulder_deg"], out["home_elbow_deg"] = b.home_posture_deg
    if b.feedback != "full":
        out["feedback"] = b.feedback
    if b.probe_feedback is not None:
        out["probe_feedback"] = b.probe_feedback
    if b.mix:
        out["mix"] = list(b.mix)
    return out | b.perturbation.as_dict()


# ----------------------------------------------------------------- reading
def protocol_from_dict(data: object, where: str = "protocol", recorded: bool = False) -> Protocol:
    """Build and check a protocol from plain data (a TOML file's or a replay's); raises ValueError.

    ``recorded``: the protocol of a replay. One recorded before ``probe_schedule`` existed says nothing of it and
    ran the ``random`` placement; a file without the key gets today's default, ``balanced``."""
    d = check_keys(where, data, {"blocks"}, frozenset(_TOP))
    check_block_count(d["blocks"])
    # A block's directions are read against the targets' (so these two first).
    targets = check_int("targets", d["targets"], 1, MAX_TARGETS) if "targets" in d else Protocol.targets
    first = check_float("first_target_deg", d["first_target_deg"], *RANGES["first_target_deg"]) \
        if "first_target_deg" in d else Protocol.first_target_deg
    angles = target_angles_deg(targets, first)
    return Protocol(
        d.get("name", "custom"),
        tuple(_block(f"blocks[{i}]", b, i, angles) for i, b in enumerate(d["blocks"])),
        delay=(d.get("delay_min", Protocol.delay[0]), d.get("delay_max", Protocol.delay[1])),
        home_posture_deg=(d.get("home_shoulder_deg", Protocol.home_posture_deg[0]),
                          d.get("home_elbow_deg", Protocol.home_posture_deg[1])),
        probe_schedule=d.get("probe_schedule", "random" if recorded else "balanced"),
        **{key: d[key] for key in _AS_IS if key in d},
    )


def _block(w: str, b: object, i: int, angles: tuple[float, ...]) -> Block:
    """A file's block: its keys checked against its perturbation's, its words turned into a ``Block``."""
    if not isinstance(b, dict):
        raise ValueError(f"{w} must be a table")
    kind_name = check_str(f"{w}.perturbation", b.get("perturbation", "none"), 20)
    kind = KINDS.get(kind_name)
    if kind is None:
        raise ValueError(f"{w}.perturbation must be one of {', '.join(KINDS)}, got {kind_name!r}")
    check_keys(w, b, {"trials"}, frozenset((_BLOCK - {"trials"}) | kind.file_keys()))
    try:
        perturbation = kind.read(b)
    except ProtocolError as exc:
        raise ProtocolError(f"{w}.{exc}") from None
    name = b.get("name", f"block {i + 1}")
    design: dict[str, object] = {key: b[key] for key in ("feedback", "probe_feedback", "mix") if key in b}
    if "home_shoulder_deg" in b or "home_elbow_deg" in b:
        if not ("home_shoulder_deg" in b and "home_elbow_deg" in b):
            raise ValueError(f"{w}: a block's posture needs both home_shoulder_deg and home_elbow_deg")
        design["home_posture_deg"] = (b["home_shoulder_deg"], b["home_elbow_deg"])
    return Block(
        name,
        b["trials"],
        perturbation,
        b.get("catch_trials", 0),
        b["instruction"] if "instruction" in b else DEFAULT_INSTRUCTIONS.get(name, "") if isinstance(name, str) else "",
        b.get("channel_trials", 0),
        _directions(f"{w}.directions_deg", b["directions_deg"], angles) if "directions_deg" in b else None,
        _directions(f"{w}.probe_directions_deg", b["probe_directions_deg"], angles)
        if "probe_directions_deg" in b else None,
        **design,  # type: ignore[arg-type]
    )


def _directions(where: str, value: object, angles: tuple[float, ...]) -> tuple[int, ...]:
    """A list of target directions (degrees, each one of the protocol's) as target indices, in the order given."""
    if not isinstance(value, list) or not 1 <= len(value) <= len(angles):
        raise ValueError(f"{where} must be a list of 1 to {len(angles)} of the targets' directions (degrees)")
    out: list[int] = []
    for i, item in enumerate(value):
        deg = check_float(f"{where}[{i}]", item, -360.0, 360.0)
        found = [t for t, a in enumerate(angles) if abs(((deg - a) + 180.0) % 360.0 - 180.0) < 1e-6]
        if not found:
            shown = ", ".join(f"{a % 360.0:g}" for a in angles)
            raise ValueError(f"{where}[{i}]: {deg:g} deg is not a target's direction (they are {shown})")
        if found[0] in out:
            raise ValueError(f"{where}[{i}]: {deg:g} deg is named twice")
        out.append(found[0])
    return tuple(out)


def load_protocol(path: Path) -> Protocol:
    """Read a TOML protocol file; one line naming the file and the bad key on any fault."""
    raw = read_limited(Path(path), MAX_PROTOCOL_BYTES, "protocol file")
    data = parse_toml(raw, path, "not a text file (UTF-8 TOML expected)")
    try:
        return protocol_from_dict(data)
    except (ValueError, TypeError, UserError) as exc:
        raise UserError(f"{path}: {exc}") from None
