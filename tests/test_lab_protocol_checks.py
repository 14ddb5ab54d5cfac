"""A protocol is valid by construction (issue 42): built in code it meets the checks a protocol file meets, with the
same one-line messages, and each perturbation kind's record refuses its own bad values."""

from __future__ import annotations

import dataclasses
import math

import pytest

from armgame.errors import UserError
from armgame.lab.perturbations import (
    KINDS,
    NONE,
    Curl,
    Mirror,
    Perturbation,
    ProtocolError,
    Rotation,
    Viscous,
)
from armgame.lab.presets import PRESETS, preset
from armgame.lab.protocol import Block, Protocol, with_perturbation
from armgame.lab.protocol_file import load_protocol, protocol_as_dict, protocol_from_dict

CURL = {"perturbation": "curl", "b": 2.0}


def _file(*blocks: dict, **top: object) -> dict:
    return {**top, "blocks": list(blocks)}


#: Each bad protocol twice: as a protocol file's data and built in code, independently.
CASES = {
    "delay order": (_file({"trials": 4}, delay_min=2.0, delay_max=1.0),
                    lambda: Protocol("custom", (Block("block 1", 4),), delay=(2.0, 1.0))),
    "a number out of range": (_file({"trials": 4}, distance=5.0),
                              lambda: Protocol("custom", (Block("block 1", 4),), distance=5.0)),
    "a posture out of range": (_file({"trials": 4}, home_elbow_deg=1.0),
                               lambda: Protocol("custom", (Block("block 1", 4),), home_posture_deg=(45.0, 1.0))),
    "a channel spring of zero": (_file({"trials": 3, "channel_trials": 3}, channel_stiffness=0.0),
                                 lambda: Protocol("custom", (Block("block 1", 3, channel_trials=3),),
                                                  channel_stiffness=0.0)),
    "no blocks": (_file(), lambda: Protocol("custom", ())),
    "too many trials": (_file(*[{"trials": 2000}] * 2),
                        lambda: Protocol("custom", (Block("block 1", 2000), Block("block 2", 2000)))),
    "a block of no trials": (_file({"trials": 0}), lambda: Protocol("custom", (Block("block 1", 0),))),
    "a long name": (_file({"trials": 4, "name": "x" * 41}), lambda: Protocol("custom", (Block("x" * 41, 4),))),
    "an unknown feedback": (_file({"trials": 4, "feedback": "blurry"}),
                            lambda: Protocol("custom", (Block("block 1", 4, feedback="blurry"),))),
    "an unknown schedule": (_file({"trials": 12, "catch_trials": 2, **CURL}, probe_schedule="even"),
                            lambda: Protocol("custom", (Block("block 1", 12, Curl(2.0), 2),), probe_schedule="even")),
    "a block's posture out of range": (
        _file({"trials": 4, "home_shoulder_deg": 45.0, "home_elbow_deg": 200.0}),
        lambda: Protocol("custom", (Block("block 1", 4, home_posture_deg=(45.0, 200.0)),))),
    "catch trials in the first cycle": (_file({"trials": 8, "catch_trials": 1, **CURL}),
                                        lambda: Protocol("custom", (Block("block 1", 8, Curl(2.0), 1),))),
    "catch trials with nothing to switch off": (_file({"trials": 12, "catch_trials": 2}),
                                                lambda: Protocol("custom", (Block("block 1", 12, NONE, 2),))),
    "more channel trials than trials": (_file({"trials": 12, "channel_trials": 13}),
                                        lambda: Protocol("custom", (Block("block 1", 12, channel_trials=13),))),
    "probes crowded together": (_file({"trials": 12, "catch_trials": 3, **CURL}),
                                lambda: Protocol("custom", (Block("block 1", 12, Curl(2.0), 3),))),
    "probe directions without probes": (
        _file({"trials": 12, "probe_directions_deg": [0.0, 90.0], **CURL}),
        lambda: Protocol("custom", (Block("block 1", 12, Curl(2.0), probe_directions=(0, 2)),))),
    "a mirror mixed": (_file({"trials": 12, "perturbation": "mirror", "mix": ["on", "off"]}),
                       lambda: Protocol("custom", (Block("block 1", 12, Mirror(), mix=("on", "off")),))),
    "a mix of one": (_file({"trials": 12, "mix": ["on"], **CURL}),
                     lambda: Protocol("custom", (Block("block 1", 12, Curl(2.0), mix=("on",)),))),
    "a mixed block's catch trials": (
        _file({"trials": 12, "catch_trials": 2, "mix": ["on", "off"], **CURL}),
        lambda: Protocol("custom", (Block("block 1", 12, Curl(2.0), 2, mix=("on", "off")),))),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_protocol_built_in_code_is_refused_as_its_file_is(case):
    data, build = CASES[case]
    with pytest.raises(ValueError) as read:
        protocol_from_dict(data)
    with pytest.raises(ProtocolError) as built:
        build()
    assert str(built.value) == str(read.value)
    assert "\n" not in str(built.value) and isinstance(built.value, UserError)  # the CLI's one line


def test_the_messages_name_the_files_keys(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text("[[blocks]]\ntrials = 4\n[[blocks]]\ntrials = 12\ncatch_trials = 2\n")
    with pytest.raises(UserError) as err:
        load_protocol(path)
    assert str(err.value) == (f"{path}: blocks[1].catch_trials: block 'block 2' has no perturbation to switch off (in "
                              "a block without one, catch trials need probe_feedback = \"endpoint\" or \"none\")")
    with pytest.raises(ProtocolError, match=r"^blocks\[0\]\.directions_deg must name distinct targets of the "
                                            r"protocol's 8$"):
        Protocol("p", (Block("a", 12, directions=(8,)),))  # a file names directions in degrees: only code can


def test_a_protocol_changed_in_code_is_checked_again():
    mixed = preset("random-fields")
    with pytest.raises(ProtocolError, match=r"blocks\[1\]\.mix: block 'random' needs a field or a rotation to mix"):
        with_perturbation(mixed, Mirror())
    with pytest.raises(ProtocolError, match=r"^timeout must be a finite number from 0\.2 to 60, got 0\.0$"):
        dataclasses.replace(mixed, timeout=0)


def test_numbers_are_kept_as_a_file_reader_keeps_them():
    """Whole numbers where a float is meant are floats, so a protocol built in code is written as its file is."""
    p = Protocol("p", [Block("a", 4, Rotation(30), home_posture_deg=[135, 90], mix=["on", "off"])],
                 delay=[1, 2], timeout=3, home_posture_deg=(45, 90))
    written = protocol_as_dict(p)
    assert [type(written[k]) for k in ("delay_min", "delay_max", "timeout", "home_elbow_deg")] == [float] * 4
    block = p.blocks[0]
    assert block.home_posture_deg == (135.0, 90.0) and type(block.home_posture_deg[0]) is float
    assert block.mix == ("on", "off") and block.perturbation.angle == 30.0 and type(block.perturbation.angle) is float
    assert protocol_from_dict(written) == p and hash(p)


@pytest.mark.parametrize("name", PRESETS)
def test_every_preset_is_built_checked(name):
    p = preset(name)
    assert dataclasses.replace(p) == p  # rebuilt, checked again, the same


# ----------------------------------------------------------------- the perturbation kinds
def _records():
    """Every record of a kind: the registered kinds and any kind defined and not registered."""
    def below(cls):
        for sub in cls.__subclasses__():
            yield sub
            yield from below(sub)
    return {Perturbation, *(c for c in below(Perturbation) if not c.__name__.startswith("_"))}


def test_every_kind_is_registered_once_by_its_name():
    assert set(KINDS.values()) == _records()
    assert all(KINDS[name].kind == name for name in KINDS)
    assert list(KINDS) == ["none", "curl", "constant", "spring", "viscous", "joint_viscous", "rotation", "mirror",
                           "jointspace"]


@pytest.mark.parametrize("kind", [k for k in KINDS if KINDS[k].parameters()])
@pytest.mark.parametrize("bad", ["below", "above", math.nan, math.inf, "2", True, None])
def test_each_kind_refuses_its_own_bad_values(kind, bad):
    cls = KINDS[kind]
    for p in cls.parameters():
        value = {"below": p.low - 1.0, "above": p.high + 1.0}.get(bad, bad) if isinstance(bad, str) else bad
        with pytest.raises(ProtocolError) as err:
            cls(**{p.name: value})
        key = cls.file_key(p.name)
        assert str(err.value).startswith(f"{key} must be a ") and "\n" not in str(err.value)
        # ... and a file's block is refused with the same words, after where the block is
        table = {"trials": 4, "perturbation": kind}
        if "matrix" in cls.file_keys():
            entries = [[0.0, 0.0], [0.0, 0.0]]
            k = [q.name for q in cls.parameters()].index(p.name)
            entries[k // 2][k % 2] = value
            table["matrix"] = entries
        else:
            table[p.name] = value
        if value is None:
            continue  # a file has no null
        with pytest.raises(ValueError) as read:
            protocol_from_dict({"blocks": [table]})
        assert str(read.value) == f"blocks[0].{err.value}"


@pytest.mark.parametrize("kind", list(KINDS))
def test_each_kind_writes_and_reads_itself(kind):
    cls = KINDS[kind]
    values = [p.low + (p.high - p.low) / 3.0 for p in cls.parameters()]
    if hasattr(cls, "max_feeding"):  # a matrix field whose opposite feeds within the limit too: a saddle and a curl
        half = cls.max_feeding / 2
        values = [half, values[1], -values[1], -half]
    record = cls(*values)
    written = record.as_dict()
    assert written["perturbation"] == kind and set(written) - {"perturbation"} == cls.file_keys()
    assert cls.read(written) == record and Perturbation.make(kind, **dict(record.items())) == record
    assert record.label().startswith(kind)
    if record.has_opposite:
        assert record.opposite().opposite() == record and record.opposite() != record
    else:
        with pytest.raises(ProtocolError, match=f"perturbation {kind} has no opposite"):
            record.opposite()


def test_a_kind_by_name_refuses_what_it_does_not_have():
    with pytest.raises(ProtocolError, match="unknown perturbation 'crul': did you mean curl"):
        Perturbation.make("crul", b=1.0)
    with pytest.raises(ProtocolError, match="perturbation curl has no parameter k"):
        Perturbation.make("curl", k=1.0)
    with pytest.raises(ProtocolError, match=r"^matrix must be \[\[b11, b12\], \[b21, b22\]\] \(N s/m\)$"):
        Viscous.read({"matrix": [1, 2, 3, 4]})
    assert Perturbation() == NONE != Curl(0.0) and Curl(0.0).is_null and not Mirror().is_null
