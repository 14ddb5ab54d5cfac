"""The lab's named protocols (``armgame lab curl``): the lesson's, each perturbation's, and the classic paradigms.

Each preset is a function that builds its ``Protocol``, registered by name in ``PRESETS``; with it go what a bot
brings to each preset when a command does not say (``PRESET_MOTOR_NOISE``, ``PRESET_REPRESENTATION``) and the
numbers the presets were chosen with (the curl field's ``CURL_B``, the blocks' lengths), each measured as its
comment says.
"""

from __future__ import annotations

from collections.abc import Callable

from ..errors import UserError
from ..words import unknown_name
from .perturbations import NONE, Curl, JointSpace, Mirror, Perturbation, Rotation, Viscous, across_path_deg
from .protocol import DEFAULT_INSTRUCTIONS, Block, Protocol

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

#: The lesson's preset: blocks of 4, 16 and 4 reaches to 4 targets in the curl field. About two minutes at
#: the keys (each reach is 0.5 to 1 s at home, the reach, 0.2 s on the target and 1.2 s of its path shown:
#: 3.5 to 5 s for a person, at most 5 s when every reach times out), so two volunteers and the bot fit
#: the lesson's 12 minutes; 16 exposure reaches leave the adapting bot a clear after-effect (+1.0 to +1.4 cm
#: on the first washout reach against +0.1 cm in baseline, seeds 10, 1 and 2).
LESSON_BLOCKS = (4, 16, 4)

#: The frames preset (Shadmehr & Mussa-Ivaldi 1994): training at the game's posture, testing with the shoulder
#: rotated 90 deg (the elbow as it was). A pure shoulder rotation by phi turns the hand Jacobian by phi, so a joint
#: field learned at the first posture is seen at the hand of the second as ``R B R^T``: for their (symmetric)
#: matrix, at 90 deg, nearly ``-B`` (the two frames predict opposite after-effects); a curl field would be the same
#: in both frames, which is why the test needs the viscous field. Blocks: baseline at the training posture, a
#: baseline at the test posture with channel trials to each target (each direction's baseline there), exposure
#: at the training posture, then a block of channel trials at the test posture.
FRAMES_TEST_POSTURE = (135.0, 90.0)
FRAMES_BLOCKS = (16, 24, 160, 16)
#: Its targets: the four directions in which the field pushes a reach along its path only by ``tr B / 2`` (0.06 N s/m,
#: against 1.93 across it), in both frames at both postures (``perturbations.across_path_deg``; the 90 deg turn keeps
#: them). A channel trial takes away the field's push along the path, which a learner's compensation then meets
#: nowhere: with the 8 targets from 0 deg a bot holding exactly the field read 1.03 at the training posture and 1.39
#: at the test posture (issue 50); here it reads 1 at both (``tests/test_lab_frames_calibration.py``).
FRAMES_TARGETS = 4
FRAMES_FIRST_TARGET_DEG = across_path_deg(VISCOUS_B)  # type: ignore[arg-type]
#: What a keyboard player meets at the test posture: the keys turn the joints as before, and a shoulder turned by 90
#: deg turns the hand's Jacobian by 90 deg, so every key starts the hand moving 90 deg counter-clockwise of where it
#: did at the training posture (the arm's model, ``tests/test_lab_frames_calibration.py``). The blocks' cards say so.
FRAMES_KEY_TURN_DEG = round(FRAMES_TEST_POSTURE[0] - Protocol.home_posture_deg[0])  # the default posture's
FRAMES_TURNED = (f"The shoulder is turned {FRAMES_KEY_TURN_DEG} deg: every key moves the hand "
                 f"{FRAMES_KEY_TURN_DEG} deg counter-clockwise of where it did. ")
FRAMES_BACK = "The arm is back where it began: the keys move the hand as in block 1. "
#: Krakauer et al.'s (2000) design on the rotation: baseline with a no-cursor probe to each target, training to one
#: direction with the cursor rotated, a test that keeps training while no-cursor probes go to every direction twice.
ROTATION_GENERALIZATION_BLOCKS = (24, 64, 48, 16)
#: The random-fields preset (Thoroughman & Shadmehr 2000; Donchin et al. 2003): the curl field on or off at random
#: trial by trial, balanced per direction, so the trial-by-trial fit can read how an error in one direction
#: changes the next reach in another.
RANDOM_FIELDS_BLOCKS = (16, 192)


def _blocks(exposure: Perturbation, baseline: int = 16, exposure_trials: int = 80, washout: int = 24,
            catch: int = 0) -> tuple[Block, ...]:
    return (
        Block("baseline", baseline, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
        Block("exposure", exposure_trials, exposure, catch, DEFAULT_INSTRUCTIONS["exposure"]),
        Block("washout", washout, NONE, 0, DEFAULT_INSTRUCTIONS["washout"]),
    )


def lesson() -> Protocol:
    """The 50-minute lesson's lab (docs/teaching.md): a short curl-field experiment for volunteers."""
    baseline, exposure, washout = LESSON_BLOCKS
    return Protocol("lesson", _blocks(Curl(CURL_B), baseline, exposure, washout), targets=4)


def savings(counter: int = SAVINGS_COUNTER) -> Protocol:
    """Exposure to the curl field, de-adaptation, re-exposure: re-learning is faster (savings).

    In the two-rate model savings needs the fast and slow states apart when re-exposure begins. A null
    washout long enough to bring the net adaptation back to zero lets both decay together, and re-learning
    is barely faster than learning (docs/lab.md measures it: ``counter = 0`` here gives that protocol, with
    a ``SAVINGS_WASHOUT``-trial washout). So the preset de-adapts as Smith, Ghazizadeh & Shadmehr (2006) did:
    ``counter`` trials of the opposite field bring the net adaptation back to about zero quickly, with the
    fast state holding the counter-field and the slow state still holding the field, and re-exposure follows.
    """
    curl = Curl(CURL_B)
    blocks = [Block("baseline", 16, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
              Block("exposure", SAVINGS_EXPOSURE, curl, 0, DEFAULT_INSTRUCTIONS["exposure"])]
    if counter:
        blocks.append(Block("counter", counter, curl.opposite(), 0, DEFAULT_INSTRUCTIONS["exposure"]))
    else:
        blocks.append(Block("washout", SAVINGS_WASHOUT, NONE, 0, DEFAULT_INSTRUCTIONS["washout"]))
    blocks.append(Block("re-exposure", SAVINGS_EXPOSURE, curl, 0, DEFAULT_INSTRUCTIONS["exposure"]))
    return Protocol("savings", tuple(blocks))


def spontaneous() -> Protocol:
    """Smith, Ghazizadeh & Shadmehr's (2006) paradigm: a long exposure to the curl field, a brief exposure to
    the opposite field (long enough to bring the adaptation back to about zero), then a block of error-clamp
    trials, in which the adaptation rebounds toward the first field. Channel trials in baseline and
    exposure measure the adaptation index along the way."""
    curl = Curl(CURL_B)
    return Protocol("spontaneous", (
        Block("baseline", 16, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"], channel_trials=4),
        Block("exposure", SPONTANEOUS_EXPOSURE, curl, 0, DEFAULT_INSTRUCTIONS["exposure"], channel_trials=16),
        Block("counter", SPONTANEOUS_COUNTER, curl.opposite(), 0, DEFAULT_INSTRUCTIONS["exposure"]),
        Block("clamp", SPONTANEOUS_CLAMP, curl, 0, DEFAULT_INSTRUCTIONS["clamp"], channel_trials=SPONTANEOUS_CLAMP),
    ))


def generalization() -> Protocol:
    """Train on one direction, probe them all (Shadmehr & Mussa-Ivaldi 1994; Gandolfo, Mussa-Ivaldi & Bizzi 1996;
    Donchin et al. 2003): a baseline to the 8 targets with a channel trial to each (the per-direction
    baseline), training in the curl field to ``GENERALIZATION_TRAINED_DEG`` only, then a test block that
    keeps training there while its channel trials probe every direction twice, spread evenly. The adaptation
    index by angle from the trained direction is the generalization function (docs/lab.md)."""
    curl = Curl(CURL_B)
    trained = (GENERALIZATION_TRAINED_DEG // 45,)
    train, test, probes = GENERALIZATION_BLOCKS
    return Protocol("generalization", (
        Block("baseline", 24, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"], channel_trials=8),
        Block("exposure", train, curl, 0, DEFAULT_INSTRUCTIONS["exposure"], directions=trained),
        Block("test", test, curl, 0, DEFAULT_INSTRUCTIONS["exposure"], channel_trials=probes, directions=trained,
              probe_directions=tuple(range(8))),
    ))


def frames() -> Protocol:
    """Train at one posture, test at another (Shadmehr & Mussa-Ivaldi 1994): which frame was the field learned in?
    The channel trials at the test posture are measured against the field held in hand coordinates and the same
    field held in joint coordinates (``adaptation_index_hand``, ``adaptation_index_joint``; docs/lab.md), to the
    four targets where the field pushes across the path (``FRAMES_FIRST_TARGET_DEG``). At the test posture every key
    moves the hand ``FRAMES_KEY_TURN_DEG`` counter-clockwise of where it did, and its blocks' cards say so."""
    field = Viscous.from_matrix(VISCOUS_B)  # type: ignore[arg-type]
    base_a, base_b, train, test = FRAMES_BLOCKS
    return Protocol("frames", (
        Block("baseline", base_a, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
        Block("baseline 2", base_b, NONE, 0, FRAMES_TURNED + DEFAULT_INSTRUCTIONS["baseline"], channel_trials=8,
              home_posture_deg=FRAMES_TEST_POSTURE),
        Block("exposure", train, field, 0, FRAMES_BACK + DEFAULT_INSTRUCTIONS["exposure"]),
        Block("test", test, field, 0, FRAMES_TURNED + DEFAULT_INSTRUCTIONS["clamp"], channel_trials=test,
              home_posture_deg=FRAMES_TEST_POSTURE),
    ), targets=FRAMES_TARGETS, first_target_deg=FRAMES_FIRST_TARGET_DEG)


def rotation_generalization() -> Protocol:
    """Krakauer, Pine, Ghilardi & Ghez (2000): a 30 deg rotation trained to one target, generalization measured with
    probes without vision (no cursor from the go cue on, the rotation off) to every target, each direction's
    baseline probes subtracted (docs/lab.md)."""
    base, train, test, probes = ROTATION_GENERALIZATION_BLOCKS
    rotation = Rotation(ROTATION_ANGLE)
    trained = (GENERALIZATION_TRAINED_DEG // 45,)
    return Protocol("rotation-generalization", (
        Block("baseline", base, NONE, 8, DEFAULT_INSTRUCTIONS["baseline"], probe_feedback="none"),
        Block("exposure", train, rotation, 0, DEFAULT_INSTRUCTIONS["exposure"], directions=trained),
        Block("test", test, rotation, probes, DEFAULT_INSTRUCTIONS["exposure"], directions=trained,
              probe_directions=tuple(range(8)), probe_feedback="none"),
    ))


def random_fields() -> Protocol:
    """Thoroughman & Shadmehr (2000), Donchin, Francis & Shadmehr (2003): the curl field on or off at random, trial
    by trial (``mix``, balanced per direction), for ``armgame analyze --fit trial-by-trial``."""
    base, mixed = RANDOM_FIELDS_BLOCKS
    return Protocol("random-fields", (
        Block("baseline", base, NONE, 0, DEFAULT_INSTRUCTIONS["baseline"]),
        Block("random", mixed, Curl(CURL_B), 0, DEFAULT_INSTRUCTIONS["exposure"], mix=("on", "off")),
    ))


def _exposure(name: str, perturbation: Perturbation) -> Callable[[], Protocol]:
    """A preset of baseline, exposure to ``perturbation`` and washout."""
    return lambda: Protocol(name, _blocks(perturbation))


#: Every preset's builder, by name (the order ``armgame lab --help`` lists them in).
_BUILDERS: dict[str, Callable[[], Protocol]] = {
    "lesson": lesson,
    "null": _exposure("null", NONE),
    "curl": _exposure("curl", Curl(CURL_B)),
    "rotation": _exposure("rotation", Rotation(ROTATION_ANGLE)),
    "mirror": _exposure("mirror", Mirror(90.0)),
    "jointspace": _exposure("jointspace", JointSpace(JOINTSPACE_GAIN)),
    "viscous": _exposure("viscous", Viscous.from_matrix(VISCOUS_B)),  # type: ignore[arg-type]
    "savings": savings,
    "spontaneous": spontaneous,
    "generalization": generalization,
    "frames": frames,
    "rotation-generalization": rotation_generalization,
    "random-fields": random_fields,
}
PRESETS = tuple(_BUILDERS)


def preset(name: str) -> Protocol:
    """The protocol named ``name``, one of ``PRESETS``."""
    build = _BUILDERS.get(name)
    if build is None:
        raise UserError(unknown_name("lab preset", name, PRESETS, "or give a .toml file"))
    return build()


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
