"""A lab run's plan for the browser: its config, protocol and every trial resolved to numbers.

The browser's lab (``classroom/static/labengine.js``) plays ``LabSession``'s rules and physics step by step,
but draws nothing at random and builds nothing from the protocol: the server hands it the run's trials as
``schedule`` made them from the protocol and the seed, each with the numbers its physics and display run on
(the target's position, the go cue's delay in steps, the load at the hand or the joints, the shown hand's
transform, the channel's line, the home and its posture). So the page carries only what it runs, and every
number the run depends on and that Python computes once with the C library (a target's ``cos``, a rotation's
``sin``, the channel's ``hypot``) reaches it as Python computed it. Each step's own sines are the arm's
(``physics.trig``, which ``engine.js`` has to the bit): the plan is of a run with ``sine="arm"``.
"""

from __future__ import annotations

import functools
import json

from ..errors import UserError
from ..game.rules import GameConfig
from ..physics.loads import ChannelField, ConstantForce, CurlField, Loads, SpringField, ViscousField
from ..records.replay import config_to_dict
from .protocol import STILL_SPEED, Protocol
from .protocol_file import protocol_as_dict
from .session import LabSession, TrialPlan, lab_config

PLAN_FORMAT = "armgame-lab-plan"
PLAN_VERSION = 1
#: The most trials a class's plan holds (about 0.4 kB a trial: 0.8 MB); every preset has at most 216.
MAX_PLAN_TRIALS = 2000


def _pair(values: tuple[float, float]) -> list[float]:
    return [float(values[0]), float(values[1])]


def _loads(loads: Loads | None) -> dict[str, object] | None:
    """A perturbation's loads as the page's engine takes them: the hand force by kind, the joints' torque and
    viscosity."""
    if loads is None or loads.empty:
        return None
    out: dict[str, object] = {}
    hand = loads.hand
    if isinstance(hand, CurlField):
        out["hand"] = ["curl", hand.b]
    elif isinstance(hand, ViscousField):
        (b11, b12), (b21, b22) = hand.matrix
        out["hand"] = ["viscous", b11, b12, b21, b22]
    elif isinstance(hand, ConstantForce):
        out["hand"] = ["constant", hand.fx, hand.fy]
    elif isinstance(hand, SpringField):
        out["hand"] = ["spring", hand.stiffness, *hand.anchor]
    elif hand is not None:
        raise ValueError(f"the browser's lab has no hand force {type(hand).__name__}")
    if loads.joint is not None:
        (v11, v12), (v21, v22) = loads.joint.viscosity
        out["joint"] = [*loads.joint.torque, v11, v12, v21, v22]
    return out


def _channel(channel: ChannelField) -> dict[str, object]:
    return {"stiffness": channel.stiffness, "damping": channel.damping, "origin": _pair(channel.origin),
            "direction": _pair(channel.direction)}


def _trial(session: LabSession, plan: TrialPlan, mixed: bool) -> dict[str, object]:
    # What the session builds at this trial's go cue, with the home it has then (its block's).
    session.home, session.home_q = plan.home, plan.home_q
    trial: dict[str, object] = {
        "block": plan.block, "target": plan.target, "position": _pair(plan.position),
        "delay_steps": plan.delay_steps, "catch": plan.catch, "channel": plan.channel, "feedback": plan.feedback,
        "home": _pair(plan.home), "home_q": _pair(plan.home_q), "load": None, "display": None,
        "channel_field": None,
    }
    if plan.channel:
        trial["channel_field"] = _channel(session.channel_for(plan.target)[1])
    else:
        trial["load"] = _loads(plan.active.loads(plan.home))
        show = plan.active.display(plan.home, plan.home_q)
        trial["display"] = None if show is None else list(show.plan)  # type: ignore[attr-defined]
    if mixed:
        trial["field"] = "channel" if plan.channel else plan.active.label()
    return trial


def lab_plan(config: GameConfig, protocol: Protocol) -> dict[str, object]:
    """The plan of a lab run of ``protocol`` on ``config`` (``lab_config``'s), for the browser's lab: JSON data,
    every float exactly as Python has it (``json`` writes the shortest text that reads back to the same double)."""
    session = LabSession(config, protocol, sine="arm")
    start_home, start_q = session.home, session.home_q
    mixed = any(b.mix for b in protocol.blocks)
    trials = [_trial(session, plan, mixed) for plan in session.plans]
    session.home, session.home_q = start_home, start_q
    seed = config.seed
    data = config_to_dict(config)
    if seed > 2**53:  # a JavaScript Number would round it: its digits, as the game's config is sent
        data["seed"] = str(seed)
    return {
        "format": PLAN_FORMAT, "format_version": PLAN_VERSION, "sine": "arm",
        "config": data, "protocol": protocol_as_dict(protocol),
        "home": _pair(start_home), "home_q": _pair(start_q),
        "home_radius": protocol.home_radius, "target_radius": protocol.target_radius,
        "distance": protocol.distance, "still_speed": STILL_SPEED,
        "hold_steps": session.hold_steps, "timeout_steps": session.timeout_steps,
        "mixed": mixed, "trials": trials,
    }



@functools.lru_cache(maxsize=8)
def class_plan_json(protocol: Protocol, seed: int) -> bytes:
    """The plan of a class's lab run as the class serves it (``/api/labplan``): ``protocol`` on the class's
    ``seed``, on a person's clock (``lab_config(person=True)``), as JSON text; made once a protocol and seed."""
    if protocol.trials > MAX_PLAN_TRIALS:
        raise UserError(f"the lab protocol {protocol.name} has {protocol.trials} trials, more than a browser's run "
                        f"plays ({MAX_PLAN_TRIALS})")
    return json.dumps(lab_plan(lab_config(protocol, seed, person=True), protocol)).encode()
