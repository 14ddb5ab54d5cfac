"""Lab protocols are written as they always were: ``protocol_as_dict`` and what a replay stores of it, byte for byte.

``tests/data/lab_protocols.json`` holds, for every preset, every protocol file in the docs (``toml file=`` blocks
with ``[[blocks]]``) and the protocols below (every perturbation kind and every optional key of a protocol file),
what the code wrote when the file was made (before issue 42's split of ``lab/protocol.py``):

* ``as_dict``: ``json.dumps(protocol_as_dict(protocol))`` (``Protocol.as_dict()`` then), keys in their order (a
  class's digest of a hand-in hashes the task's ``repr``, so the order is part of what is written);
* ``replay``: ``dump_json`` of the same, the protocol's section of a lab replay's file;
* ``labels``: each block's ``perturbation.label()``, which a mixed block's replay keeps per trial, and
  ``opposites``: the label of each opposite a block has (a mixed block's ``opposite`` trials).

The file was written once by ``python tests/test_lab_protocol_golden.py --write`` from the code as it was; a change
that needs it written again changes what every lab replay holds, and says so.
"""

from __future__ import annotations

import functools
import json
import sys
import tomllib
from pathlib import Path

import pytest
from test_docs import DOCS, blocks

from armgame.lab.perturbations import Perturbation
from armgame.lab.presets import PRESETS, preset, savings
from armgame.lab.protocol import with_catch_trials, with_perturbation
from armgame.lab.protocol_file import protocol_as_dict, protocol_from_dict
from armgame.records.storage import dump_json

GOLDEN = Path(__file__).parent / "data" / "lab_protocols.json"

#: Every perturbation kind and every optional key of a protocol file, each set away from its default.
FILES = {
    "every-kind": """
name = "every kind"
targets = 4
[[blocks]]
trials = 4
[[blocks]]
name = "constant"
trials = 4
perturbation = "constant"
fx = 1.5
fy = -0.25
[[blocks]]
name = "spring"
trials = 4
perturbation = "spring"
stiffness = 20.0
[[blocks]]
name = "curl"
trials = 4
perturbation = "curl"
b = -1.75
[[blocks]]
name = "viscous"
trials = 4
perturbation = "viscous"
matrix = [[-1.0, 0.5], [0.125, 1.0]]
[[blocks]]
name = "joint"
trials = 4
perturbation = "joint_viscous"
matrix = [[0.1, -0.2], [0.3, 0.05]]
[[blocks]]
name = "rotation"
trials = 4
perturbation = "rotation"
angle = -45.5
[[blocks]]
name = "mirror"
trials = 4
perturbation = "mirror"
axis = 30.0
[[blocks]]
name = "jointspace"
trials = 4
perturbation = "jointspace"
gain = 0.3
[[blocks]]
name = "defaults"
trials = 4
perturbation = "jointspace"
[[blocks]]
name = "mirror default"
trials = 4
perturbation = "mirror"
""",
    "every-key": """
name = "every key"
targets = 6
distance = 0.12
target_radius = 0.015
home_radius = 0.025
hold_time = 0.3
delay_min = 0.25
delay_max = 0.75
timeout = 2.5
first_target_deg = 15.0
home_shoulder_deg = 40.0
home_elbow_deg = 95.0
channel_stiffness = 3000.0
channel_damping = 40.0
probe_schedule = "balanced"
consecutive_probes = true
[[blocks]]
name = "baseline"
trials = 12
catch_trials = 2
probe_feedback = "endpoint"
[[blocks]]
name = "exposure"
trials = 30
perturbation = "curl"
b = 2.0
catch_trials = 3
channel_trials = 4
instruction = "Keep going."
directions_deg = [75.0, 15.0]
probe_directions_deg = [15.0, 75.0, 135.0, 195.0]
home_shoulder_deg = 100.0
home_elbow_deg = 80.0
feedback = "endpoint"
probe_feedback = "none"
[[blocks]]
name = "mixed"
trials = 24
perturbation = "rotation"
angle = 20.0
mix = ["on", "off", "opposite"]
feedback = "none"
[[blocks]]
name = "clamp"
trials = 6
channel_trials = 6
""",
    "random-probes": """
name = "random probes"
probe_schedule = "random"
[[blocks]]
name = "exposure"
trials = 40
perturbation = "viscous"
matrix = [[1.0, 0.0], [0.0, 1.0]]
catch_trials = 10
channel_trials = 10
""",
    "custom-channel-only": """
channel_damping = 0.0
[[blocks]]
trials = 3
""",
}


@functools.cache
def protocols() -> dict[str, object]:
    """Every protocol the golden file holds, by name."""
    out: dict[str, object] = {f"preset {name}": preset(name) for name in PRESETS}
    for path in DOCS:
        for block in blocks(path):
            if block.language == "toml" and block.tag("file") and "[[blocks]]" in block.text:
                out[f"{block.path.name} {block.tag('file')}"] = protocol_from_dict(tomllib.loads(block.text))
    for name, text in FILES.items():
        out[f"file {name}"] = protocol_from_dict(tomllib.loads(text))
    out["savings counter=0"] = savings(0)
    out["curl with 4 catch trials"] = with_catch_trials(preset("curl"), 4)
    out["null with a viscous field"] = with_perturbation(
        preset("null"), Perturbation.make("viscous", b11=1.0, b12=-2.0, b21=0.5, b22=0.0))
    out["curl with none"] = with_perturbation(preset("curl"), Perturbation())
    out["recorded, no probe_schedule"] = protocol_from_dict(
        {"blocks": [{"trials": 20, "perturbation": "curl", "b": 2.0, "catch_trials": 2}]}, recorded=True)
    return out


@functools.cache
def _golden() -> dict[str, dict[str, object]]:
    return json.loads(GOLDEN.read_text(encoding="utf-8")) if GOLDEN.exists() else {}


def written(protocol) -> dict[str, object]:
    data = protocol_as_dict(protocol)
    return {"as_dict": json.dumps(data, ensure_ascii=False), "replay": dump_json(data).decode("utf-8"),
            "labels": [b.perturbation.label() for b in protocol.blocks],
            "opposites": [b.perturbation.opposite().label() for b in protocol.blocks
                          if b.perturbation.kind in ("curl", "constant", "viscous", "joint_viscous", "rotation")]}


def test_the_golden_file_covers_every_preset_kind_and_docs_file():
    golden = _golden()
    assert {f"preset {name}" for name in PRESETS} <= golden.keys()
    assert sum(name.endswith(".toml") for name in golden) >= 5  # docs/lab.md's four, docs/teaching.md's one
    kinds = {b["perturbation"] for entry in golden.values() for b in json.loads(entry["as_dict"])["blocks"]}
    assert kinds == {"none", "curl", "constant", "spring", "viscous", "joint_viscous", "rotation", "mirror",
                     "jointspace"}


@pytest.mark.parametrize("name", sorted(_golden()))
def test_a_protocol_is_written_as_it_was(name):
    golden = _golden()[name]
    protocol = protocols()[name]
    assert written(protocol) == golden
    # and what is written reads back as the same protocol
    assert protocol_from_dict(json.loads(golden["as_dict"]), recorded=True) == protocol


def test_every_protocol_made_is_in_the_golden_file():
    assert sorted(protocols()) == sorted(_golden())


if __name__ == "__main__" and sys.argv[1:] == ["--write"]:
    GOLDEN.parent.mkdir(exist_ok=True)
    GOLDEN.write_text(json.dumps({name: written(p) for name, p in protocols().items()}, indent=1,
                                 ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"wrote {GOLDEN}")
