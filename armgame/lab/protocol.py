"""A lab protocol: the blocks of a centre-out experiment, valid by construction.

A protocol is data: which targets (count, distance, size), the timing (hold, go-cue delay,
time-out) and a list of blocks, each with its number of trials, its perturbation
(``perturbations``: one record per kind) and its catch trials. The same protocol, seed and input
timeline give the same trials, bit for bit. ``Protocol.__post_init__`` checks every value and
every rule between them, with the messages a protocol file's reader gives (they name the file's
keys), so a protocol built in code is held to what a file is. The presets are in ``presets``, the
file format (reading and writing) in ``protocol_file``.

Issue 41's block settings (each defaults to today's behaviour and is written only when set): a
block's own home posture (``home_shoulder_deg``, ``home_elbow_deg``: a second workspace), what the
player sees of the hand (``feedback`` on its ordinary trials, ``probe_feedback`` on its catch and
channel trials: ``full``, ``endpoint`` or ``none``, see ``FEEDBACK``) and fields mixed at random
trial by trial (``mix``: ``MIX_KINDS``, balanced per direction; ``session.schedule``).

Error-clamp (force-channel) trials: ``channel_trials = N`` in a block makes N of its trials
channels, drawn as catch trials are (never in the block's first cycle of targets, never a catch
trial), or every trial of the block when N equals its trials (a channel block). A channel trial
runs a stiff spring and damper across the straight home-to-target line instead of the block's
perturbation (``channel_stiffness``, N/m, and ``channel_damping``, N s/m, in the protocol; the
defaults are ``CHANNEL_STIFFNESS`` and ``CHANNEL_DAMPING``), so the hand is held on the line, and
the force the arm presses into the channel is recorded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ..errors import UserError
from ..valid import check_float, check_int, check_str
from .perturbations import NONE, Perturbation, ProtocolError

#: What the player sees of the hand on a trial (Krakauer et al. 2000's probes without vision): ``full``, the
#: cursor throughout; ``endpoint``, no cursor from the go cue until the trial ends, then the hand's endpoint
#: (knowledge of results, not of the path); ``none``, no cursor from the go cue on and nothing after. The cursor is
#: always shown at home, to bring the hand there. A trial without a cursor also ends when the hand has left home
#: and stopped (``STILL_SPEED``, for the hold time), wherever that is: a player who cannot see cannot home in.
FEEDBACK = ("full", "endpoint", "none")
#: Below this hand speed (m/s), held for the hold time once the hand is more than half the target distance from
#: home, a trial without a cursor ends: the reach is over.
STILL_SPEED = 0.02
#: A mixed block's trial kinds (Thoroughman & Shadmehr 2000; Donchin et al. 2003): the block's perturbation
#: (``on``), none (``off``), or its opposite (``opposite``: every parameter negated).
MIX_KINDS = ("on", "off", "opposite")
MAX_MIX = 12

#: The force channel of error-clamp trials (docs/lab.md): this arm's lightest endpoint mass is 0.77 kg
#: (a human arm's), its fields push with about 1 N, so the low end of the robots' 2,000-6,000 N/m holds
#: the hand within about 1 mm of the line (tests/test_lab.py; the field deflects a free reach by 2.9 cm),
#: and the robots' 50 N s/m damps it (damping ratio 0.64 at the lightest mass). ``LabSession`` checks a
#: protocol's channel against the physics step: its fastest mode must satisfy |lambda| dt <= ``MAX_CHANNEL_LAMBDA_DT``.
CHANNEL_STIFFNESS = 2000.0
CHANNEL_DAMPING = 50.0
MAX_CHANNEL_LAMBDA_DT = 1.0
MAX_CHANNEL_STIFFNESS = 20000.0
MAX_CHANNEL_DAMPING = 500.0

MAX_BLOCKS = 20
PROBE_SCHEDULES = ("balanced", "random")
MAX_TRIALS = 2000
MAX_TARGETS = 64
MAX_NAME = 40
MAX_INSTRUCTION = 200

#: Each number's range (low, high), by its name in a protocol file; ``channel_stiffness`` is above its low end.
RANGES = {
    "first_target_deg": (-360.0, 360.0),
    "distance": (0.01, 0.3),
    "target_radius": (0.002, 0.1),
    "home_radius": (0.002, 0.1),
    "hold_time": (0.0, 5.0),
    "delay_min": (0.0, 10.0),
    "delay_max": (0.0, 10.0),
    "timeout": (0.2, 60.0),
    "home_shoulder_deg": (-180.0, 180.0),
    "home_elbow_deg": (5.0, 175.0),
    "channel_stiffness": (0.0, MAX_CHANNEL_STIFFNESS),
    "channel_damping": (0.0, MAX_CHANNEL_DAMPING),
}


@dataclass(frozen=True)
class Block:
    """A run of trials with one perturbation. Checked as part of its ``Protocol`` (its messages say which block)."""

    name: str
    trials: int
    perturbation: Perturbation = NONE
    #: Trials of this block run with the perturbation off, unannounced (never among its first cycle of targets).
    catch_trials: int = 0
    instruction: str = ""
    #: Error-clamp trials: the channel instead of the perturbation (all of the block's when equal to ``trials``).
    channel_trials: int = 0
    #: The targets (indices into the protocol's directions) this block's ordinary trials go to; None: all of them.
    directions: tuple[int, ...] | None = None
    #: The targets its catch and channel trials go to (a generalization test probes directions never trained);
    #: None: the block's own ``directions``.
    probe_directions: tuple[int, ...] | None = None
    #: Issue 41. This block's home posture (shoulder, elbow; degrees), a second workspace; None: the protocol's.
    home_posture_deg: tuple[float, float] | None = None
    #: What the player sees of the hand on the block's ordinary trials (``FEEDBACK``).
    feedback: str = "full"
    #: ... and on its catch and channel trials (the probes); None: as on its ordinary trials.
    probe_feedback: str | None = None
    #: Its ordinary trials' kinds drawn at random (``MIX_KINDS``), balanced per direction; empty: all ``on``.
    mix: tuple[str, ...] = ()

    @property
    def probes_feedback(self) -> str:
        return self.feedback if self.probe_feedback is None else self.probe_feedback

    def posture_of(self, protocol: Protocol) -> tuple[float, float]:
        return protocol.home_posture_deg if self.home_posture_deg is None else self.home_posture_deg

    @property
    def channel_block(self) -> bool:
        return self.channel_trials == self.trials

    @property
    def probes(self) -> int:
        """Its catch and channel trials."""
        return self.catch_trials + self.channel_trials

    def targets_of(self, protocol: Protocol) -> tuple[int, ...]:
        return tuple(range(protocol.targets)) if self.directions is None else self.directions

    def probe_targets_of(self, protocol: Protocol) -> tuple[int, ...]:
        return self.targets_of(protocol) if self.probe_directions is None else self.probe_directions


#: What a block's card asks, by block name. What to do, never what will happen ("something has changed",
#: "back to normal"): a volunteer told the field is gone stops expecting it, and the after-effect shrinks.
DEFAULT_INSTRUCTIONS = {
    "baseline": "Reach straight to each target as soon as it appears, and hold it.",
    "exposure": "Keep reaching straight to each target, and hold it.",
    "washout": "Keep reaching straight to each target, and hold it.",
    "clamp": "Keep reaching straight to each target, and hold it.",
}


@dataclass(frozen=True)
class Protocol:
    """A centre-out experiment. Distances in m, times in s, angles in degrees.

    Built, it is checked (``ProtocolError``, one line naming the value by its key in a protocol file, e.g.
    ``blocks[1].catch_trials``), and its numbers are made floats, as a file's reader would."""

    name: str
    blocks: tuple[Block, ...]
    targets: int = 8
    distance: float = 0.10
    target_radius: float = 0.02
    home_radius: float = 0.02
    #: The hand must stay on the target this long to end the trial with a hit.
    hold_time: float = 0.2
    #: The go cue comes after the hand has stayed at home for a random time in this range.
    delay: tuple[float, float] = (0.5, 1.0)
    #: A trial with no hit ends this long after its go cue.
    timeout: float = 3.0
    #: The first target's direction from home (degrees counter-clockwise from +x); the rest follow evenly.
    first_target_deg: float = 0.0
    #: The arm's posture at home (shoulder, elbow; degrees): the game's start posture.
    home_posture_deg: tuple[float, float] = (45.0, 90.0)
    #: The error-clamp channel's spring (N/m) and damper (N s/m) across the home-to-target line.
    channel_stiffness: float = CHANNEL_STIFFNESS
    channel_damping: float = CHANNEL_DAMPING
    #: How a block's catch and channel trials are placed (``session.schedule``): ``balanced`` (spread evenly over
    #: the block's probe directions and its trials, issue 29) or ``random`` (drawn uniformly among the block's
    #: trials after its first cycle, as before; what a replay recorded without the key ran).
    probe_schedule: str = "balanced"
    #: ``balanced`` only: whether two probe trials may follow one another (never, unless asked).
    consecutive_probes: bool = False
    perturbations: tuple[Perturbation, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        try:
            _check(self)
        except ValueError as exc:  # the schema checks' ValueError: one line a teacher or a script can act on
            raise ProtocolError(str(exc)) from None
        object.__setattr__(self, "perturbations", tuple(dict.fromkeys(b.perturbation for b in self.blocks)))
        if not self.has_probes:
            # Without probe trials the settings change no trial: one form, so that an old replay's protocol
            # and a new run's compare equal (the class curve groups runs by protocol).
            object.__setattr__(self, "probe_schedule", "balanced")
            object.__setattr__(self, "consecutive_probes", False)

    @property
    def trials(self) -> int:
        return sum(b.trials for b in self.blocks)

    @property
    def has_channels(self) -> bool:
        return any(b.channel_trials for b in self.blocks)

    @property
    def has_probes(self) -> bool:
        """Whether any block has catch or channel trials (the only trials ``probe_schedule`` places)."""
        return any(b.probes for b in self.blocks)

    def reference_field(self, block: int) -> Perturbation | None:
        """The field a channel trial of ``block`` is measured against (its adaptation index): the block's
        own if it is a velocity field, else the protocol's first velocity field (baseline, washout and
        clamp blocks are measured against the field the experiment is about); None if there is none."""
        own = self.blocks[block].perturbation
        if own.is_velocity_field:
            return own
        return next((b.perturbation for b in self.blocks if b.perturbation.is_velocity_field), None)

    @property
    def start_posture_deg(self) -> tuple[float, float]:
        """Where the run starts: its first block's posture (the protocol's unless that block sets its own)."""
        return self.blocks[0].posture_of(self)

    @property
    def postures_deg(self) -> tuple[tuple[float, float], ...]:
        """Every posture its blocks reach from, the start first."""
        return tuple(dict.fromkeys(b.posture_of(self) for b in self.blocks))

    def field_posture_deg(self, field: Perturbation) -> tuple[float, float]:
        """The posture of the first block that has ``field`` on: where it is learned (for the frames' indices)."""
        return next((b.posture_of(self) for b in self.blocks if b.perturbation == field), self.start_posture_deg)

    def target_angles_deg(self) -> tuple[float, ...]:
        return target_angles_deg(self.targets, self.first_target_deg)

    def target_positions(self, home: tuple[float, float]) -> tuple[tuple[float, float], ...]:
        """Where the targets are (m) around ``home``: ``distance`` away, in the directions ``target_angles_deg``."""
        hx, hy = home
        r = self.distance
        return tuple((hx + r * math.cos(math.radians(a)), hy + r * math.sin(math.radians(a)))
                     for a in self.target_angles_deg())


def target_angles_deg(targets: int, first_deg: float) -> tuple[float, ...]:
    """The directions (degrees) of ``targets`` targets evenly around home, the first at ``first_deg``."""
    return tuple(first_deg + 360.0 * i / targets for i in range(targets))


def check_block_count(value: object) -> None:
    """A protocol's blocks are a list of 1 to ``MAX_BLOCKS`` (a file's reader asks first: it reads no more)."""
    if not isinstance(value, list | tuple) or not 1 <= len(value) <= MAX_BLOCKS:
        raise ValueError(f"blocks must be a list of 1 to {MAX_BLOCKS} blocks")


# ----------------------------------------------------------------- the checks
def _number(name: str, value: object, where: str = "") -> float:
    """A number within its range, named by its key in a protocol file (after ``where``, e.g. ``blocks[0].``)."""
    low, high = RANGES[name]
    return check_float(where + name, value, low, high, low_open=name == "channel_stiffness")


def _pair(where: str, field_name: str, value: object, first: str, second: str) -> tuple[float, float]:
    """A pair a file writes as two keys (``delay``: ``delay_min`` and ``delay_max``), each number checked as its key."""
    if not isinstance(value, tuple | list) or len(value) != 2:
        raise ValueError(f"{where}{field_name} must be a pair ({first}, {second}), got {value!r}")
    return _number(first, value[0], where), _number(second, value[1], where)


def _choice(name: str, value: object, choices: tuple[str, ...]) -> str:
    text = check_str(name, value, 20)
    if text not in choices:
        raise ValueError(f"{name} must be one of {', '.join(choices)}, got {text!r}")
    return text


def _checked_block(p: Protocol, i: int, b: object) -> Block:
    """Block ``i``'s own values, checked, as the protocol keeps it (numbers as floats, lists as tuples)."""
    w = f"blocks[{i}]"
    if not isinstance(b, Block):
        raise ValueError(f"{w} must be a Block, got {type(b).__name__}")
    if not isinstance(b.perturbation, Perturbation):
        raise ValueError(f"{w}.perturbation must be a Perturbation, got {type(b.perturbation).__name__}")
    check_str(f"{w}.name", b.name, MAX_NAME)
    check_int(f"{w}.trials", b.trials, 1, MAX_TRIALS)
    check_int(f"{w}.catch_trials", b.catch_trials, 0, MAX_TRIALS)
    check_str(f"{w}.instruction", b.instruction, MAX_INSTRUCTION)
    check_int(f"{w}.channel_trials", b.channel_trials, 0, MAX_TRIALS)
    directions: dict[str, tuple[int, ...] | None] = {}
    for field_name, name in (("directions", "directions_deg"), ("probe_directions", "probe_directions_deg")):
        chosen = getattr(b, field_name)
        if chosen is not None and (not isinstance(chosen, tuple | list) or not chosen
                                   or not all(type(t) is int and 0 <= t < p.targets for t in chosen)
                                   or len(set(chosen)) != len(chosen)):
            raise ValueError(f"{w}.{name} must name distinct targets of the protocol's {p.targets}")
        directions[field_name] = None if chosen is None else tuple(chosen)
    posture = None if b.home_posture_deg is None else \
        _pair(f"{w}.", "home_posture_deg", b.home_posture_deg, "home_shoulder_deg", "home_elbow_deg")
    _choice(f"{w}.feedback", b.feedback, FEEDBACK)
    if b.probe_feedback is not None:
        _choice(f"{w}.probe_feedback", b.probe_feedback, FEEDBACK)
    mix = b.mix
    if mix != ():
        if not isinstance(mix, list | tuple) or not 2 <= len(mix) <= MAX_MIX:
            raise ValueError(f"{w}.mix must be a list of 2 to {MAX_MIX} of {', '.join(MIX_KINDS)}")
        for k, item in enumerate(mix):
            if item not in MIX_KINDS:
                raise ValueError(f"{w}.mix[{k}] must be one of {', '.join(MIX_KINDS)}, got {item!r}")
        mix = tuple(mix)
    kept = {"home_posture_deg": posture, "mix": mix, **directions}
    return replace(b, **kept) if any(kept[name] is not getattr(b, name) for name in kept) else b  # type: ignore[arg-type]


def _check(p: Protocol) -> None:
    """Every value of ``p`` and every rule between them, in the order a protocol file's reader met them; its
    numbers made floats and its lists tuples."""
    def keep(name: str, value: object) -> None:
        object.__setattr__(p, name, value)

    check_str("name", p.name, MAX_NAME)
    check_block_count(p.blocks)
    check_int("targets", p.targets, 1, MAX_TARGETS)
    keep("first_target_deg", _number("first_target_deg", p.first_target_deg))
    keep("blocks", tuple(_checked_block(p, i, b) for i, b in enumerate(p.blocks)))
    _choice("probe_schedule", p.probe_schedule, PROBE_SCHEDULES)
    if not isinstance(p.consecutive_probes, bool):
        raise ValueError(f"consecutive_probes must be true or false, got {p.consecutive_probes!r}")
    for name in ("distance", "target_radius", "home_radius", "hold_time"):
        keep(name, _number(name, getattr(p, name)))
    keep("delay", _pair("", "delay", p.delay, "delay_min", "delay_max"))
    keep("timeout", _number("timeout", p.timeout))
    keep("home_posture_deg", _pair("", "home_posture_deg", p.home_posture_deg, "home_shoulder_deg", "home_elbow_deg"))
    keep("channel_stiffness", _number("channel_stiffness", p.channel_stiffness))
    keep("channel_damping", _number("channel_damping", p.channel_damping))

    if p.delay[0] > p.delay[1]:
        raise ValueError(f"delay_min ({p.delay[0]:g} s) must not exceed delay_max ({p.delay[1]:g} s)")
    if p.trials > MAX_TRIALS:
        raise ValueError(f"the protocol has {p.trials} trials, more than {MAX_TRIALS}")
    balanced = p.probe_schedule == "balanced"
    for i, b in enumerate(p.blocks):
        if b.probe_directions is not None and not b.probes:
            raise ValueError(f"blocks[{i}].probe_directions_deg: block {b.name!r} has no catch or channel trials")
        if b.probe_directions is not None and not balanced:
            raise ValueError(f"blocks[{i}].probe_directions_deg needs probe_schedule = \"balanced\"")
        if b.catch_trials and b.perturbation.kind == "none" and b.probes_feedback == "full":
            # Without a perturbation a catch trial is only a probe of what the player does without vision.
            raise ValueError(f"blocks[{i}].catch_trials: block {b.name!r} has no perturbation to switch off "
                             "(in a block without one, catch trials need probe_feedback = \"endpoint\" or \"none\")")
        if b.mix:
            if not b.perturbation.has_opposite or ("opposite" in b.mix and b.perturbation.is_null):
                raise ValueError(f"blocks[{i}].mix: block {b.name!r} needs a field or a rotation to mix "
                                 f"(it has {b.perturbation.kind})")
            if b.catch_trials:
                raise ValueError(f"blocks[{i}].mix: a mixed block's off trials are its catch trials: give no "
                                 "catch_trials")
            if "opposite" in b.mix:  # a damping matrix's opposite feeds the arm: it must be a field the lab runs
                try:
                    b.perturbation.opposite()
                except ValueError as exc:
                    raise ValueError(f"blocks[{i}].mix: \"opposite\" runs every parameter negated, which the lab "
                                     f"refuses: {exc}") from None
        if b.channel_trials > b.trials:
            raise ValueError(f"blocks[{i}].channel_trials must be at most the block's trials ({b.trials})")
        if b.channel_block:
            if b.catch_trials:
                raise ValueError(f"blocks[{i}].catch_trials: block {b.name!r} is all channel trials: none to catch")
            continue
        cycle = len(b.targets_of(p))
        if b.catch_trials > max(0, b.trials - cycle):
            raise ValueError(f"blocks[{i}].catch_trials must be at most trials - targets "
                             f"({max(0, b.trials - cycle)}): catch trials never fall in a block's first cycle")
        if b.probes > max(0, b.trials - cycle):
            raise ValueError(f"blocks[{i}].channel_trials must be at most trials - targets - catch_trials "
                             f"({max(0, b.trials - cycle - b.catch_trials)}), or all of the block's trials: "
                             "channel trials never fall in a block's first cycle nor on a catch trial")
        room = max(1, (b.trials - cycle) // 2)  # one probe a run of two trials or more (session.balanced_probes)
        if balanced and not p.consecutive_probes and b.probes > room:
            raise ValueError(f"blocks[{i}]: {b.probes} catch and channel trials in the {b.trials - cycle} trials after "
                             f"its first cycle: at most {room} when no two follow one another "
                             "(consecutive_probes = true allows it)")


# ----------------------------------------------------------------- protocols made from others
def with_catch_trials(protocol: Protocol, catch: int) -> Protocol:
    """The protocol with ``catch`` catch trials in each block that has a perturbation."""
    blocks = tuple(replace(b, catch_trials=catch) if b.perturbation.kind != "none" else b for b in protocol.blocks)
    return replace(protocol, blocks=blocks)


def with_perturbation(protocol: Protocol, perturbation: Perturbation) -> Protocol:
    """The protocol with ``perturbation`` in place of its own: in every perturbed block or, for a protocol
    with none (the ``null`` preset), in its blocks named ``exposure``. ``NONE`` switches the perturbed
    blocks off (and their catch trials, which would have nothing to switch off)."""
    perturbed = [b.perturbation.kind != "none" for b in protocol.blocks]
    distinct = dict.fromkeys(b.perturbation for b, on in zip(protocol.blocks, perturbed, strict=True) if on)
    if len(distinct) > 1:
        raise UserError(f"protocol {protocol.name!r} has {len(distinct)} different perturbations "
                        f"({', '.join(p.label() for p in distinct)}): one cannot stand for them all")
    if not any(perturbed):
        perturbed = [b.name == "exposure" for b in protocol.blocks]
    if not any(perturbed):
        raise UserError(f"protocol {protocol.name!r} has no perturbed block and no block named exposure "
                        "to put a perturbation in")
    catch_ok = perturbation.kind != "none"
    blocks = tuple(replace(b, perturbation=perturbation, catch_trials=b.catch_trials if catch_ok else 0) if on else b
                   for b, on in zip(protocol.blocks, perturbed, strict=True))
    return replace(protocol, blocks=blocks)
