"""Lab protocols: the blocks of a centre-out experiment, the perturbation of each, presets and TOML files.

A protocol is data: which targets (count, distance, size), the timing (hold, go-cue delay,
time-out) and a list of blocks, each with its number of trials, its perturbation and its catch
trials. The same protocol, seed and input timeline give the same trials, bit for bit.

Perturbation kinds (parameters in brackets, with their TOML names):

* ``none``;
* ``curl`` (``b``, N s/m): the force field ``F = b [[0, 1], [-1, 0]] v`` at the hand;
  ``b > 0`` pushes clockwise of the hand's motion;
* ``constant`` (``fx``, ``fy``, N): a steady force at the hand;
* ``spring`` (``stiffness``, N/m): a spring from the hand to the home position;
* ``viscous`` (``matrix = [[b11, b12], [b21, b22]]``, N s/m): the field ``F = B v`` with a full
  matrix, as Shadmehr & Mussa-Ivaldi (1994) used; its symmetric part does work on the arm;
* ``rotation`` (``angle``, degrees): the hand is shown, and scored, rotated about home,
  counter-clockwise for ``angle > 0``;
* ``mirror`` (``axis``, degrees): the hand is shown mirrored in the line through home at that
  angle from +x (90: left and right swap);
* ``jointspace`` (``gain``, m/rad): Flanagan & Rao's display: the hand is shown at
  ``home + gain (q1 - q1_home, q2 - q2_home)``, shoulder angle across, elbow angle up;
* ``joint_viscous`` (``matrix = [[w11, w12], [w21, w22]]``, N m s/rad): a viscous field in joint
  coordinates, the torque ``tau = W qdot`` at the joints (issue 41: Shadmehr & Mussa-Ivaldi's
  test of the frame a field is learned in). Seen at the hand it is ``J^-T W J^-1``, which changes
  with the posture, where a hand field ``B`` stays ``B``.

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
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import UserError
from ..records.storage import read_limited
from ..valid import check_float, check_int, check_keys, check_str
from ..words import unknown_name

FORCE_KINDS = ("curl", "constant", "spring", "viscous", "joint_viscous")
#: Fields ``F = B v``: the adaptation index of a channel trial is measured against one of these.
VELOCITY_KINDS = ("curl", "viscous", "joint_viscous")
VISUAL_KINDS = ("rotation", "mirror", "jointspace")
KINDS = ("none", *FORCE_KINDS, *VISUAL_KINDS)

#: Each kind's parameters: (name, low, high, default, unit).
PARAMETERS: dict[str, tuple[tuple[str, float, float, float, str], ...]] = {
    "none": (),
    "curl": (("b", -50.0, 50.0, 0.0, "N s/m"),),
    "constant": (("fx", -20.0, 20.0, 0.0, "N"), ("fy", -20.0, 20.0, 0.0, "N")),
    "spring": (("stiffness", 0.0, 500.0, 0.0, "N/m"),),
    "viscous": (("b11", -50.0, 50.0, 0.0, "N s/m"), ("b12", -50.0, 50.0, 0.0, "N s/m"),
                ("b21", -50.0, 50.0, 0.0, "N s/m"), ("b22", -50.0, 50.0, 0.0, "N s/m")),
    "rotation": (("angle", -180.0, 180.0, 0.0, "deg"),),
    "mirror": (("axis", -180.0, 180.0, 90.0, "deg"),),
    "jointspace": (("gain", 0.01, 2.0, 0.25, "m/rad"),),
    "joint_viscous": (("w11", -5.0, 5.0, 0.0, "N m s/rad"), ("w12", -5.0, 5.0, 0.0, "N m s/rad"),
                      ("w21", -5.0, 5.0, 0.0, "N m s/rad"), ("w22", -5.0, 5.0, 0.0, "N m s/rad")),
}
#: The kinds whose parameters are a 2 x 2 matrix, written ``matrix = [[.., ..], [.., ..]]`` in a file.
MATRIX_KINDS = {"viscous": ("b11", "b12", "b21", "b22"), "joint_viscous": ("w11", "w12", "w21", "w22")}

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

#: The curl preset's field. Chosen by measurement (docs/lab.md, ``tests/test_lab.py``): the model
#: bot, which knows the arm but not the field, is pushed 2-3 cm off its 10 cm reaches, and a bot
#: that knows the field cancels it within its muscles' strength and reaches straight.
CURL_B = 2.0
#: Shadmehr & Mussa-Ivaldi's (1994) field (N s/m), and the ``viscous`` preset's: one eighth of it, which
#: takes its largest gain (its spectral norm, 15.92 N s/m) to 1.99 N s/m, the curl preset's b. Checked
#: by measurement as b was (docs/lab.md, ``tests/test_lab.py``).
PUBLISHED_VISCOUS_B = ((-10.1, -11.2), (-11.2, 11.1))
VISCOUS_SCALE = 0.125
VISCOUS_B = tuple(tuple(VISCOUS_SCALE * v for v in row) for row in PUBLISHED_VISCOUS_B)
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
ROTATION_ANGLE = 30.0
JOINTSPACE_GAIN = 0.25

#: The paradigms' block lengths (docs/lab.md: chosen with the adaptive bot's default learner).
SAVINGS_EXPOSURE = 80
SAVINGS_COUNTER = 4
SAVINGS_WASHOUT = 160
SPONTANEOUS_EXPOSURE = 160
SPONTANEOUS_COUNTER = 4
SPONTANEOUS_CLAMP = 48

#: The generalization preset: the trained direction (one of the 8 targets) and the training, test and probe counts.
GENERALIZATION_TRAINED_DEG = 90
GENERALIZATION_BLOCKS = (64, 48, 16)

MAX_BLOCKS = 20
PROBE_SCHEDULES = ("balanced", "random")
MAX_TRIALS = 2000
MAX_TARGETS = 64


@dataclass(frozen=True)
class Perturbation:
    """One perturbation: ``kind`` and its parameters (only the kind's own are used)."""

    kind: str = "none"
    params: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise UserError(unknown_name("perturbation", self.kind, KINDS))

    @classmethod
    def make(cls, kind: str, **values: float) -> Perturbation:
        if kind not in KINDS:
            raise UserError(unknown_name("perturbation", kind, KINDS))
        params = []
        for name, _low, _high, default, _unit in PARAMETERS[kind]:
            params.append((name, float(values.pop(name, default))))
        if values:
            raise UserError(f"perturbation {kind} has no parameter {', '.join(sorted(values))}")
        return cls(kind, tuple(params))

    def __getitem__(self, name: str) -> float:
        return dict(self.params)[name]

    def opposite(self) -> Perturbation:
        """Every parameter negated: the opposite field or rotation (a mixed block's ``opposite`` trials)."""
        if self.kind in ("none", "mirror", "jointspace", "spring"):
            raise UserError(f"perturbation {self.kind} has no opposite")
        return Perturbation(self.kind, tuple((name, -value) for name, value in self.params))

    @property
    def joint_matrix(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """``W`` of a joint-space field ``tau = W qdot`` (``joint_viscous``), else None."""
        if self.kind != "joint_viscous":
            return None
        return (self["w11"], self["w12"]), (self["w21"], self["w22"])

    @property
    def is_force(self) -> bool:
        return self.kind in FORCE_KINDS

    @property
    def is_visual(self) -> bool:
        return self.kind in VISUAL_KINDS

    @property
    def is_null(self) -> bool:
        """Whether it changes nothing: ``none``, or a field or rotation of size zero (curl ``b = 0``, a zero
        matrix, no force, no stiffness, ``angle = 0``). A mirror or a joint-space display always changes
        the display."""
        if self.kind in ("mirror", "jointspace"):
            return False
        return all(value == 0.0 for _name, value in self.params)

    def label(self) -> str:
        """e.g. ``curl b=2 N s/m``; ``none`` for none."""
        if self.kind == "viscous":
            (b11, b12), (b21, b22) = self.matrix  # type: ignore[misc]
            return f"viscous B=[[{b11:g}, {b12:g}], [{b21:g}, {b22:g}]] N s/m"
        if self.kind == "joint_viscous":
            (w11, w12), (w21, w22) = self.joint_matrix  # type: ignore[misc]
            return f"joint_viscous W=[[{w11:.4g}, {w12:.4g}], [{w21:.4g}, {w22:.4g}]] N m s/rad"
        units = {name: unit for name, _l, _h, _d, unit in PARAMETERS[self.kind]}
        parts = [f"{name}={value:g} {units[name]}" for name, value in self.params]
        return " ".join([self.kind, *parts])

    @property
    def matrix(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """``B`` of a velocity field ``F = B v`` (curl or viscous), else None."""
        if self.kind == "curl":
            return (0.0, self["b"]), (-self["b"], 0.0)
        if self.kind == "viscous":
            return (self["b11"], self["b12"]), (self["b21"], self["b22"])
        return None

    def as_dict(self) -> dict[str, object]:
        if self.kind == "viscous":
            return {"perturbation": self.kind, "matrix": [list(row) for row in self.matrix]}  # type: ignore[union-attr]
        if self.kind == "joint_viscous":
            return {"perturbation": self.kind, "matrix": [list(row) for row in self.joint_matrix]}  # type: ignore[union-attr]
        return {"perturbation": self.kind, **dict(self.params)}


NONE = Perturbation()


@dataclass(frozen=True)
class Block:
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
    """A centre-out experiment. Distances in m, times in s, angles in degrees."""

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
        object.__setattr__(self, "perturbations", tuple(dict.fromkeys(b.perturbation for b in self.blocks)))
        if not self.has_probes:
            # Without probe trials the settings change no trial: one form, so that an old replay's protocol
            # and a new run's compare equal (the class curve groups runs by protocol).
            object.__setattr__(self, "probe_schedule", "balanced")
            object.__setattr__(self, "consecutive_probes", False)
        if self.probe_schedule not in PROBE_SCHEDULES:
            raise ValueError(f"probe_schedule must be one of {', '.join(PROBE_SCHEDULES)}, got {self.probe_schedule!r}")

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
        if own.kind in VELOCITY_KINDS:
            return own
        return next((b.perturbation for b in self.blocks if b.perturbation.kind in VELOCITY_KINDS), None)

    @property
    def start_posture_deg(self) -> tuple[float, float]:
        """Where the run starts: its first block's posture (the protocol's unless that block sets its own)."""
        return self.blocks[0].posture_of(self) if self.blocks else self.home_posture_deg

    @property
    def postures_deg(self) -> tuple[tuple[float, float], ...]:
        """Every posture its blocks reach from, the start first."""
        return tuple(dict.fromkeys(b.posture_of(self) for b in self.blocks)) or (self.home_posture_deg,)

    def field_posture_deg(self, field: Perturbation) -> tuple[float, float]:
        """The posture of the first block that has ``field`` on: where it is learned (for the frames' indices)."""
        return next((b.posture_of(self) for b in self.blocks if b.perturbation == field), self.start_posture_deg)

    def target_angles_deg(self) -> tuple[float, ...]:
        return tuple(self.first_target_deg + 360.0 * i / self.targets for i in range(self.targets))

    def as_dict(self) -> dict[str, object]:
        # The channel's settings and a block's channel_trials are written only when used, so a protocol
        # without channels is written as before.
        custom = (self.channel_stiffness, self.channel_damping) != (CHANNEL_STIFFNESS, CHANNEL_DAMPING)
        channel = {"channel_stiffness": self.channel_stiffness, "channel_damping": self.channel_damping} \
            if self.has_channels or custom else {}
        # Likewise the probe settings (a replay without them ran the ``random`` placement) and a block's
        # directions.
        probes: dict[str, object] = {"probe_schedule": self.probe_schedule} if self.has_probes else {}
        if self.consecutive_probes:
            probes["consecutive_probes"] = True
        angles = self.target_angles_deg()

        def directions(b: Block) -> dict[str, object]:
            out: dict[str, object] = {}
            if b.directions is not None:
                out["directions_deg"] = [angles[t] % 360.0 for t in b.directions]
            if b.probe_directions is not None:
                out["probe_directions_deg"] = [angles[t] % 360.0 for t in b.probe_directions]
            return out
        return {
            "name": self.name,
            "targets": self.targets,
            "distance": self.distance,
            "target_radius": self.target_radius,
            "home_radius": self.home_radius,
            "hold_time": self.hold_time,
            "delay_min": self.delay[0],
            "delay_max": self.delay[1],
            "timeout": self.timeout,
            "first_target_deg": self.first_target_deg,
            "home_shoulder_deg": self.home_posture_deg[0],
            "home_elbow_deg": self.home_posture_deg[1],
            **channel,
            **probes,
            "blocks": [
                {"name": b.name, "trials": b.trials, "catch_trials": b.catch_trials, "instruction": b.instruction,
                 **({"channel_trials": b.channel_trials} if b.channel_trials else {}), **directions(b),
                 **_design_keys(b), **b.perturbation.as_dict()}
                for b in self.blocks
            ],
        }


def _design_keys(b: Block) -> dict[str, object]:
    """A block's issue-41 settings as a file writes them: only those set, so a protocol without them is written
    byte for byte as before."""
    out: dict[str, object] = {}
    if b.home_posture_deg is not None:
        out["home_shoulder_deg"], out["home_elbow_deg"] = b.home_posture_deg
    if b.feedback != "full":
        out["feedback"] = b.feedback
    if b.probe_feedback is not None:
        out["probe_feedback"] = b.probe_feedback
    if b.mix:
        out["mix"] = list(b.mix)
    return out


def _blocks(exposure: Perturbation, baseline: int = 16, exposure_trials: int = 80, washout: int = 24,
            catch: int = 0) -> tuple[Block, ...]:
    return (
        Block("baseline", baseline, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
        Block("exposure", exposure_trials, exposure, catch, DEFAULT_INSTRUCTIONS["exposure"]),
        Block("washout", washout, NONE, 0, DEFAULT_INSTRUCTIONS["washout"]),
    )


#: The lesson's preset: blocks of 4, 16 and 4 reaches to 4 targets in the curl field. About two minutes at
#: the keys (each reach is 0.5 to 1 s at home, the reach, 0.2 s on the target and 1.2 s of its path shown:
#: 3.5 to 5 s for a person, at most 5 s when every reach times out), so two volunteers and the bot fit
#: the lesson's 12 minutes; 16 exposure reaches leave the adapting bot a clear after-effect (+1.0 to +1.4 cm
#: on the first washout reach against +0.1 cm in baseline, seeds 10, 1 and 2).
LESSON_BLOCKS = (4, 16, 4)


def lesson() -> Protocol:
    """The 50-minute lesson's lab (docs/teaching.md): a short curl-field experiment for volunteers."""
    baseline, exposure, washout = LESSON_BLOCKS
    return Protocol("lesson", _blocks(Perturbation.make("curl", b=CURL_B), baseline, exposure, washout), targets=4)


def preset(name: str) -> Protocol:
    """A named protocol: ``lesson``, ``null``, ``curl``, ``rotation``, ``mirror``, ``jointspace``, ``viscous``,
    ``savings``, ``spontaneous`` or ``generalization``."""
    if name == "lesson":
        return lesson()
    if name == "null":
        return Protocol("null", _blocks(NONE))
    if name == "curl":
        return Protocol("curl", _blocks(Perturbation.make("curl", b=CURL_B)))
    if name == "rotation":
        return Protocol("rotation", _blocks(Perturbation.make("rotation", angle=ROTATION_ANGLE)))
    if name == "mirror":
        return Protocol("mirror", _blocks(Perturbation.make("mirror", axis=90.0)))
    if name == "jointspace":
        return Protocol("jointspace", _blocks(Perturbation.make("jointspace", gain=JOINTSPACE_GAIN)))
    if name == "viscous":
        (b11, b12), (b21, b22) = VISCOUS_B
        return Protocol("viscous", _blocks(Perturbation.make("viscous", b11=b11, b12=b12, b21=b21, b22=b22)))
    if name == "savings":
        return savings()
    if name == "spontaneous":
        return spontaneous()
    if name == "generalization":
        return generalization()
    if name == "frames":
        return frames()
    if name == "rotation-generalization":
        return rotation_generalization()
    if name == "random-fields":
        return random_fields()
    raise UserError(unknown_name("lab preset", name, PRESETS, "or give a .toml file"))


PRESETS = ("lesson", "null", "curl", "rotation", "mirror", "jointspace", "viscous", "savings", "spontaneous",
           "generalization", "frames", "rotation-generalization", "random-fields")

#: ``--motor-noise human``: the s.d. of a bot's motor command as a fraction of it. A choice, not a fit to a
#: published data set (docs/lab.md, "Motor noise"): it makes the ``model`` bot's baseline reaches vary from trial
#: to trial by a few degrees and millimetres, the order people show, while it still hits every target.
HUMAN_NOISE = 0.3

#: The motor noise a bot brings to each preset when ``--motor-noise`` does not say. The experiments a lab
#: report runs, fits and compares carry a person's (a control group, ``null``, as much as the field it is the
#: control for: a noiseless group beside a noisy one would differ by the noise alone); ``lesson`` is the class's
#: demo, whose bot is shown beside the volunteers and rehearsed to the digit (docs/teaching.md): none. Seeded by
#: the run's seed, so a noisy run is as reproducible as a quiet one; a protocol file's bot has none unless asked.
PRESET_MOTOR_NOISE = {name: 0.0 if name == "lesson" else HUMAN_NOISE for name in PRESETS}

#: The adapting bot's learner on each preset when ``--representation`` does not say: ``generalization``'s point is
#: local generalization, so its bot learns locally (the global learner, a control, is asked for by name); every
#: other preset's learns one estimate for every direction. A bot's replay records its keys, not its learner, so
#: an old run of the preset replays as it was recorded.
PRESET_REPRESENTATION = {name: "local" if name == "generalization" else "global" for name in PRESETS}


def savings(counter: int = SAVINGS_COUNTER) -> Protocol:
    """Exposure to the curl field, de-adaptation, re-exposure: re-learning is faster (savings).

    In the two-rate model savings needs the fast and slow states apart when re-exposure begins. A null
    washout long enough to bring the net adaptation back to zero lets both decay together, and re-learning
    is barely faster than learning (docs/lab.md measures it: ``counter = 0`` here gives that protocol, with
    a ``SAVINGS_WASHOUT``-trial washout). So the preset de-adapts as Smith, Ghazizadeh & Shadmehr (2006) did:
    ``counter`` trials of the opposite field bring the net adaptation back to about zero quickly, with the
    fast state holding the counter-field and the slow state still holding the field, and re-exposure follows.
    """
    curl = Perturbation.make("curl", b=CURL_B)
    blocks = [Block("baseline", 16, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
              Block("exposure", SAVINGS_EXPOSURE, curl, 0, DEFAULT_INSTRUCTIONS["exposure"])]
    if counter:
        blocks.append(Block("counter", counter, Perturbation.make("curl", b=-CURL_B), 0,
                            DEFAULT_INSTRUCTIONS["exposure"]))
    else:
        blocks.append(Block("washout", SAVINGS_WASHOUT, NONE, 0, DEFAULT_INSTRUCTIONS["washout"]))
    blocks.append(Block("re-exposure", SAVINGS_EXPOSURE, curl, 0, DEFAULT_INSTRUCTIONS["exposure"]))
    return _checked(Protocol("savings", tuple(blocks)))


def spontaneous() -> Protocol:
    """Smith, Ghazizadeh & Shadmehr's (2006) paradigm: a long exposure to the curl field, a brief exposure to
    the opposite field (long enough to bring the adaptation back to about zero), then a block of error-clamp
    trials, in which the adaptation rebounds toward the first field. Channel trials in baseline and
    exposure measure the adaptation index along the way."""
    curl = Perturbation.make("curl", b=CURL_B)
    return _checked(Protocol("spontaneous", (
        Block("baseline", 16, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"], channel_trials=4),
        Block("exposure", SPONTANEOUS_EXPOSURE, curl, 0, DEFAULT_INSTRUCTIONS["exposure"], channel_trials=16),
        Block("counter", SPONTANEOUS_COUNTER, Perturbation.make("curl", b=-CURL_B), 0,
              DEFAULT_INSTRUCTIONS["exposure"]),
        Block("clamp", SPONTANEOUS_CLAMP, curl, 0, DEFAULT_INSTRUCTIONS["clamp"], channel_trials=SPONTANEOUS_CLAMP),
    )))


def generalization() -> Protocol:
    """Train on one direction, probe them all (Shadmehr & Mussa-Ivaldi 1994; Gandolfo, Mussa-Ivaldi & Bizzi 1996;
    Donchin et al. 2003): a baseline to the 8 targets with a channel trial to each (the per-direction
    baseline), training in the curl field to ``GENERALIZATION_TRAINED_DEG`` only, then a test block that
    keeps training there while its channel trials probe every direction twice, spread evenly. The adaptation
    index by angle from the trained direction is the generalization function (docs/lab.md)."""
    curl = Perturbation.make("curl", b=CURL_B)
    trained = (GENERALIZATION_TRAINED_DEG // 45,)
    train, test, probes = GENERALIZATION_BLOCKS
    return _checked(Protocol("generalization", (
        Block("baseline", 24, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"], channel_trials=8),
        Block("exposure", train, curl, 0, DEFAULT_INSTRUCTIONS["exposure"], directions=trained),
        Block("test", test, curl, 0, DEFAULT_INSTRUCTIONS["exposure"], channel_trials=probes, directions=trained,
              probe_directions=tuple(range(8))),
    )))


#: The frames preset (Shadmehr & Mussa-Ivaldi 1994): training at the game's posture, testing with the shoulder
#: rotated 90 deg (the elbow as it was). A pure shoulder rotation by phi turns the hand Jacobian by phi, so a joint
#: field learned at the first posture is seen at the hand of the second as ``R B R^T``: for their (symmetric)
#: matrix, at 90 deg, nearly ``-B`` (the two frames predict opposite after-effects); a curl field would be the same
#: in both frames, which is why the test needs the viscous field. Blocks: baseline at the training posture, a
#: baseline at the test posture with a channel trial to each target (each direction's baseline there), exposure
#: at the training posture, then a block of channel trials at the test posture.
FRAMES_TEST_POSTURE = (135.0, 90.0)
FRAMES_BLOCKS = (16, 24, 160, 16)
#: Krakauer et al.'s (2000) design on the rotation: baseline with a no-cursor probe to each target, training to one
#: direction with the cursor rotated, a test that keeps training while no-cursor probes go to every direction twice.
ROTATION_GENERALIZATION_BLOCKS = (24, 64, 48, 16)
#: The random-fields preset (Thoroughman & Shadmehr 2000; Donchin et al. 2003): the curl field on or off at random
#: trial by trial, balanced per direction, so the trial-by-trial fit can read how an error in one direction
#: changes the next reach in another.
RANDOM_FIELDS_BLOCKS = (16, 192)


def frames() -> Protocol:
    """Train at one posture, test at another (Shadmehr & Mussa-Ivaldi 1994): which frame was the field learned in?
    The channel trials at the test posture are measured against the field held in hand coordinates and the same
    field held in joint coordinates (``adaptation_index_hand``, ``adaptation_index_joint``; docs/lab.md)."""
    (b11, b12), (b21, b22) = VISCOUS_B
    field = Perturbation.make("viscous", b11=b11, b12=b12, b21=b21, b22=b22)
    base_a, base_b, train, test = FRAMES_BLOCKS
    return _checked(Protocol("frames", (
        Block("baseline", base_a, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
        Block("baseline 2", base_b, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"], channel_trials=8,
              home_posture_deg=FRAMES_TEST_POSTURE),
        Block("exposure", train, field, 0, DEFAULT_INSTRUCTIONS["exposure"]),
        Block("test", test, field, 0, DEFAULT_INSTRUCTIONS["clamp"], channel_trials=test,
              home_posture_deg=FRAMES_TEST_POSTURE),
    )))


def rotation_generalization() -> Protocol:
    """Krakauer, Pine, Ghilardi & Ghez (2000): a 30 deg rotation trained to one target, generalization measured with
    probes without vision (no cursor from the go cue on, the rotation off) to every target, each direction's
    baseline probes subtracted (docs/lab.md)."""
    base, train, test, probes = ROTATION_GENERALIZATION_BLOCKS
    rotation = Perturbation.make("rotation", angle=ROTATION_ANGLE)
    trained = (GENERALIZATION_TRAINED_DEG // 45,)
    return _checked(Protocol("rotation-generalization", (
        Block("baseline", base, NONE, 8, DEFAULT_INSTRUCTIONS["baseline"], probe_feedback="none"),
        Block("exposure", train, rotation, 0, DEFAULT_INSTRUCTIONS["exposure"], directions=trained),
        Block("test", test, rotation, probes, DEFAULT_INSTRUCTIONS["exposure"], directions=trained,
              probe_directions=tuple(range(8)), probe_feedback="none"),
    )))


def random_fields() -> Protocol:
    """Thoroughman & Shadmehr (2000), Donchin, Francis & Shadmehr (2003): the curl field on or off at random, trial
    by trial (``mix``, balanced per direction), for ``armgame analyze --fit trial-by-trial``."""
    base, mixed = RANDOM_FIELDS_BLOCKS
    return _checked(Protocol("random-fields", (
        Block("baseline", base, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
        Block("random", mixed, Perturbation.make("curl", b=CURL_B), 0, DEFAULT_INSTRUCTIONS["exposure"],
              mix=("on", "off")),
    )))


def with_catch_trials(protocol: Protocol, catch: int) -> Protocol:
    """The protocol with ``catch`` catch trials in each block that has a perturbation."""
    blocks = tuple(replace(b, catch_trials=catch) if b.perturbation.kind != "none" else b for b in protocol.blocks)
    return _checked(replace(protocol, blocks=blocks))


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


# ----------------------------------------------------------------- from data
MAX_PROTOCOL_BYTES = 256 * 1024
_TOP = {"name", "targets", "distance", "target_radius", "home_radius", "hold_time", "delay_min", "delay_max",
        "timeout", "first_target_deg", "home_shoulder_deg", "home_elbow_deg", "channel_stiffness", "channel_damping",
        "probe_schedule", "consecutive_probes"}
_BLOCK = {"name", "trials", "catch_trials", "channel_trials", "instruction", "perturbation", "directions_deg",
          "probe_directions_deg", "home_shoulder_deg", "home_elbow_deg", "feedback", "probe_feedback", "mix"}


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


def viscous_matrix(where: str, value: object, kind: str = "viscous") -> dict[str, float]:
    """``matrix = [[b11, b12], [b21, b22]]`` (N s/m, each within the viscous field's range; for ``joint_viscous``
    ``[[w11, w12], [w21, w22]]`` in N m s/rad) as parameters."""
    names = MATRIX_KINDS[kind]
    unit = PARAMETERS[kind][0][4]
    if not (isinstance(value, list) and len(value) == 2
            and all(isinstance(row, list) and len(row) == 2 for row in value)):
        raise ValueError(f"{where} must be [[{names[0]}, {names[1]}], [{names[2]}, {names[3]}]] ({unit})")
    limits = {name: (low, high) for name, low, high, _d, _u in PARAMETERS[kind]}
    return {name: check_float(f"{where}[{i}][{j}]", value[i][j], *limits[name])
            for (i, j), name in zip(((0, 0), (0, 1), (1, 0), (1, 1)), names, strict=True)}


def _block_design(w: str, b: dict) -> dict[str, object]:
    """A file's block's issue-41 settings, checked: its posture, feedback and mix (absent: today's behaviour)."""
    out: dict[str, object] = {}
    if "home_shoulder_deg" in b or "home_elbow_deg" in b:
        if not ("home_shoulder_deg" in b and "home_elbow_deg" in b):
            raise ValueError(f"{w}: a block's posture needs both home_shoulder_deg and home_elbow_deg")
        out["home_posture_deg"] = (check_float(f"{w}.home_shoulder_deg", b["home_shoulder_deg"], -180.0, 180.0),
                                   check_float(f"{w}.home_elbow_deg", b["home_elbow_deg"], 5.0, 175.0))
    for key in ("feedback", "probe_feedback"):
        if key in b:
            value = check_str(f"{w}.{key}", b[key], 20)
            if value not in FEEDBACK:
                raise ValueError(f"{w}.{key} must be one of {', '.join(FEEDBACK)}, got {value!r}")
            out[key] = value
    if "mix" in b:
        mix = b["mix"]
        if not isinstance(mix, list) or not 2 <= len(mix) <= 12:
            raise ValueError(f"{w}.mix must be a list of 2 to 12 of {', '.join(MIX_KINDS)}")
        for i, item in enumerate(mix):
            if item not in MIX_KINDS:
                raise ValueError(f"{w}.mix[{i}] must be one of {', '.join(MIX_KINDS)}, got {item!r}")
        out["mix"] = tuple(mix)
    return out


def protocol_from_dict(data: object, where: str = "protocol", recorded: bool = False) -> Protocol:
    """Build and check a protocol from plain data (a TOML file's or a replay's); raises ValueError.

    ``recorded``: the protocol of a replay. One recorded before ``probe_schedule`` existed says nothing of it and
    ran the ``random`` placement; a file without the key gets today's default, ``balanced``."""
    optional = frozenset(_TOP - {"blocks"})
    d = check_keys(where, data, {"blocks"}, optional)
    defaults = Protocol("custom", ())

    def number(key: str, low: float, high: float, default: float, low_open: bool = False) -> float:
        return check_float(f"{key}", d[key], low, high, low_open) if key in d else default

    name = check_str("name", d["name"], 40) if "name" in d else "custom"
    blocks_data = d["blocks"]
    if not isinstance(blocks_data, list) or not 1 <= len(blocks_data) <= MAX_BLOCKS:
        raise ValueError(f"blocks must be a list of 1 to {MAX_BLOCKS} blocks")
    targets = check_int("targets", d["targets"], 1, MAX_TARGETS) if "targets" in d else defaults.targets
    first_deg = number("first_target_deg", -360.0, 360.0, defaults.first_target_deg)
    angles = replace(defaults, targets=targets, first_target_deg=first_deg).target_angles_deg()
    blocks = []
    for i, b in enumerate(blocks_data):
        w = f"blocks[{i}]"
        if not isinstance(b, dict):
            raise ValueError(f"{w} must be a table")
        kind = check_str(f"{w}.perturbation", b.get("perturbation", "none"), 20)
        if kind not in KINDS:
            raise ValueError(f"{w}.perturbation must be one of {', '.join(KINDS)}, got {kind!r}")
        param_names = {"matrix"} if kind in MATRIX_KINDS else {p[0] for p in PARAMETERS[kind]}
        check_keys(w, b, {"trials"}, frozenset((_BLOCK - {"trials"}) | param_names))
        if kind in MATRIX_KINDS:
            values = viscous_matrix(f"{w}.matrix", b["matrix"], kind) if "matrix" in b else {}
        else:
            values = {p: check_float(f"{w}.{p}", b[p], low, high)
                      for p, low, high, _d, _u in PARAMETERS[kind] if p in b}
        block_name = check_str(f"{w}.name", b.get("name", f"block {i + 1}"), 40)
        blocks.append(Block(
            block_name,
            check_int(f"{w}.trials", b["trials"], 1, MAX_TRIALS),
            Perturbation.make(kind, **values),
            check_int(f"{w}.catch_trials", b.get("catch_trials", 0), 0, MAX_TRIALS),
            check_str(f"{w}.instruction", b.get("instruction", DEFAULT_INSTRUCTIONS.get(block_name, "")), 200),
            check_int(f"{w}.channel_trials", b.get("channel_trials", 0), 0, MAX_TRIALS),
            _directions(f"{w}.directions_deg", b["directions_deg"], angles) if "directions_deg" in b else None,
            _directions(f"{w}.probe_directions_deg", b["probe_directions_deg"], angles)
            if "probe_directions_deg" in b else None,
            **_block_design(w, b),  # type: ignore[arg-type]
        ))
    schedule = check_str("probe_schedule", d["probe_schedule"], 20) if "probe_schedule" in d \
        else "random" if recorded else "balanced"
    if schedule not in PROBE_SCHEDULES:
        raise ValueError(f"probe_schedule must be one of {', '.join(PROBE_SCHEDULES)}, got {schedule!r}")
    consecutive = d.get("consecutive_probes", False)
    if not isinstance(consecutive, bool):
        raise ValueError(f"consecutive_probes must be true or false, got {consecutive!r}")
    protocol = Protocol(
        name,
        tuple(blocks),
        targets=targets,
        distance=number("distance", 0.01, 0.3, defaults.distance),
        target_radius=number("target_radius", 0.002, 0.1, defaults.target_radius),
        home_radius=number("home_radius", 0.002, 0.1, defaults.home_radius),
        hold_time=number("hold_time", 0.0, 5.0, defaults.hold_time),
        delay=(number("delay_min", 0.0, 10.0, defaults.delay[0]), number("delay_max", 0.0, 10.0, defaults.delay[1])),
        timeout=number("timeout", 0.2, 60.0, defaults.timeout),
        first_target_deg=first_deg,
        home_posture_deg=(number("home_shoulder_deg", -180.0, 180.0, defaults.home_posture_deg[0]),
                          number("home_elbow_deg", 5.0, 175.0, defaults.home_posture_deg[1])),
        channel_stiffness=number("channel_stiffness", 0.0, MAX_CHANNEL_STIFFNESS, CHANNEL_STIFFNESS, low_open=True),
        channel_damping=number("channel_damping", 0.0, MAX_CHANNEL_DAMPING, CHANNEL_DAMPING),
        probe_schedule=schedule,
        consecutive_probes=consecutive,
    )
    return _checked(protocol)


def _checked(p: Protocol) -> Protocol:
    if p.delay[0] > p.delay[1]:
        raise ValueError(f"delay_min ({p.delay[0]:g} s) must not exceed delay_max ({p.delay[1]:g} s)")
    if p.trials > MAX_TRIALS:
        raise ValueError(f"the protocol has {p.trials} trials, more than {MAX_TRIALS}")
    balanced = p.probe_schedule == "balanced"
    for i, b in enumerate(p.blocks):
        for name, chosen in (("directions_deg", b.directions), ("probe_directions_deg", b.probe_directions)):
            if chosen is not None and (not chosen or len(set(chosen)) != len(chosen)
                                       or not all(0 <= t < p.targets for t in chosen)):
                raise ValueError(f"blocks[{i}].{name} must name distinct targets of the protocol's {p.targets}")
        if b.probe_directions is not None and not b.probes:
            raise ValueError(f"blocks[{i}].probe_directions_deg: block {b.name!r} has no catch or channel trials")
        if b.probe_directions is not None and not balanced:
            raise ValueError(f"blocks[{i}].probe_directions_deg needs probe_schedule = \"balanced\"")
        if b.catch_trials and b.perturbation.kind == "none" and b.probes_feedback == "full":
            # Without a perturbation a catch trial is only a probe of what the player does without vision.
            raise ValueError(f"blocks[{i}].catch_trials: block {b.name!r} has no perturbation to switch off "
                             "(in a block without one, catch trials need probe_feedback = \"endpoint\" or \"none\")")
        if b.feedback not in FEEDBACK or b.probes_feedback not in FEEDBACK:
            raise ValueError(f"blocks[{i}].feedback must be one of {', '.join(FEEDBACK)}")
        if b.mix:
            if any(m not in MIX_KINDS for m in b.mix) or len(b.mix) < 2:
                raise ValueError(f"blocks[{i}].mix must list 2 or more of {', '.join(MIX_KINDS)}")
            if b.perturbation.kind in ("none", "mirror", "jointspace", "spring") \
                    or ("opposite" in b.mix and b.perturbation.is_null):
                raise ValueError(f"blocks[{i}].mix: block {b.name!r} needs a field or a rotation to mix "
                                 f"(it has {b.perturbation.kind})")
            if b.catch_trials:
                raise ValueError(f"blocks[{i}].mix: a mixed block's off trials are its catch trials: give no "
                                 "catch_trials")
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
    return p


def load_protocol(path: Path) -> Protocol:
    """Read a TOML protocol file; one line naming the file and the bad key on any fault."""
    raw = read_limited(Path(path), MAX_PROTOCOL_BYTES, "protocol file")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise UserError(f"{path}: not a text file (UTF-8 TOML expected)") from None
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:  # tomllib recurses into nested arrays and tables
        raise UserError(f"{path}: not valid TOML: nested too deeply") from None
    try:
        return protocol_from_dict(data)
    except (ValueError, TypeError, UserError) as exc:
        raise UserError(f"{path}: {exc}") from None


def target_positions(protocol: Protocol, home: tuple[float, float]) -> tuple[tuple[float, float], ...]:
    hx, hy = home
    r = protocol.distance
    return tuple((hx + r * math.cos(math.radians(a)), hy + r * math.sin(math.radians(a)))
                 for a in protocol.target_angles_deg())
