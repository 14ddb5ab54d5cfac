"""Replays: a game's full configuration, its input timeline and its result, as a JSON file.

A game is fully determined by its ``GameConfig`` and its input timeline (see
``armgame.game.session``), so a replay recomputes its result exactly: ``verify`` replays
the timeline and compares. Floats are written with ``repr`` (Python's JSON does), which
reads back bit for bit, so the rebuilt configuration equals the original one.

A replay file is parsed strictly as data: JSON with an explicit schema check of every
field, NaN/Infinity refused, sizes bounded. Nothing in it is ever executed or unpickled.

What a replay cannot prove: that a human pressed the keys. A timeline written by a
program replays like any other; the table shows how each game says it was driven.

A run that is more than a game (the lab's centre-out runs) adds a task section, which its own
layer reads, writes and verifies: that layer registers a reader for its kind of section
(``register_task``; ``armgame.lab.record`` does when imported) and records never imports it, so
this layer stays below the lab. The commands that read replays import the lab first.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Protocol

from .. import __version__
from .._native import load
from ..errors import UserError
from ..game.muscles import MuscleSet, MuscleSpec
from ..game.rules import GAME_RANGES, MAX_TRIES, GameConfig
from ..game.session import DOWN, UP, GameResult, GameSession, InputEvent, TimelineInput
from ..limits import MAX_EVENTS, MAX_GAME_SECONDS, MAX_GAME_STEPS, MAX_HITS, MAX_REPLAY_BYTES, MAX_VERIFY_WORK
from ..physics.integrators import SCHEMES
from ..physics.params import TwoJointParams
from ..valid import (
    COUNT_MAX,
    INT64_MAX,
    check_date,
    check_float,
    check_int,
    check_keys,
    check_name,
    check_str,
    check_word,
)
from .storage import DataFileError, atomic_write_bytes, dump_json, parse_json, read_limited

FORMAT = "armgame-replay"
FORMAT_VERSION = 1
#: Shared with the writers (``armgame.limits``): nothing is recorded that this reader refuses.
MAX_STEPS = MAX_GAME_STEPS
DRIVEN = ("keyboard", "script", "bot")
#: What a keyboard game may name as its driver and still be a person's: the device it was played on (the
#: class's browser game, ``/play``). Any other driver named makes the game a program's.
KEYBOARD_DEVICES = ("browser",)
#: A key or action that JSON writes as itself in quotes, with no comma or bracket a replacement could touch.
_PLAIN = re.compile(r"[A-Za-z0-9_]+")
#: A replay file's timeline as ``Replay.to_bytes`` writes it, every key and action a plain word (``_PLAIN``): the
#: text between ``_TIMELINE_OPEN`` and ``_TIMELINE_CLOSE``, the file's last key. A file read whose timeline is
#: this text (and it is the top-level one: the object closes right after it) keeps it, so that the replay
#: written again (a class's table: the same game under the player's name) takes it as it is rather than
#: encoding 15,000 events again: the same bytes, as every event is written the one way ``to_bytes`` writes it
#: (a step's digits with no sign or leading zero, JSON's only way; a plain word in quotes).
_EVENT_TEXT = rb'\[\n   [0-9]+,\n   "[A-Za-z0-9_]+",\n   "[A-Za-z0-9_]+"\n  \]'
_TIMELINE_TEXT = re.compile(_EVENT_TEXT + rb'(?:,\n  ' + _EVENT_TEXT + rb')*')
_TIMELINE_OPEN = b'"timeline": [\n  '
_TIMELINE_CLOSE = b'\n ]\n}\n'


def now_iso() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


# --------------------------------------------------------------- GameConfig <-> JSON

def config_to_dict(config: GameConfig) -> dict[str, object]:
    return {
        "arm": config.arm.as_dict(),
        "start_posture": list(config.start_posture),
        "time_limit": config.time_limit,
        "target_radius": config.target_radius,
        "target_shoulder_range": list(config.target_shoulder_range),
        "target_elbow_range": list(config.target_elbow_range),
        "seed": config.seed,
        "muscles": [
            {"name": m.name, "key": m.key, "moment": list(m.moment), "rise_time": m.rise_time,
             "decay_time": m.decay_time}
            for m in config.muscles
        ],
        "integrator": config.integrator,
        "dt": config.dt,
        "reset_cost": config.reset_cost,
        "view": list(config.view),
        "scene": config.scene,
    }


CONFIG_FIELDS = frozenset(f.name for f in fields(GameConfig))
_ARM_FIELDS = frozenset(f.name for f in fields(TwoJointParams))

def _ranged(name: str, value: object, kind: str, low_open: bool = False) -> float:
    """``value`` checked against a replay's range of ``kind`` (``game.rules.GAME_RANGES``)."""
    setting = GAME_RANGES[kind]
    return check_float(name, value, setting.low, setting.high, low_open)


def _floats(name: str, value: object, n: int, kind: str) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != n:
        raise ValueError(f"{name} must be a list of {n} numbers")
    return tuple(_ranged(f"{name}[{i}]", v, kind) for i, v in enumerate(value))


def _ordered(name: str, pair: tuple[float, ...]) -> tuple[float, ...]:
    if not pair[0] <= pair[1]:
        raise ValueError(f"{name} must be [low, high], got {list(pair)}")
    return pair


def config_from_dict(data: object) -> GameConfig:
    """Rebuild a ``GameConfig``, checking every field against its range; raises ValueError naming it."""
    d = check_keys("config", data, set(CONFIG_FIELDS))
    arm = check_keys("config.arm", d["arm"], set(_ARM_FIELDS))
    arm_values = {k: check_float(f"config.arm.{k}", v, -1e300, 1e300) for k, v in arm.items()}
    try:
        arm_params = TwoJointParams(**arm_values)
    except ValueError as exc:  # ParameterError names the field and its range
        raise ValueError(f"config.arm.{exc}") from None
    dt = _ranged("config.dt", d["dt"], "dt")
    muscles_data = d["muscles"]
    if not isinstance(muscles_data, list) or len(muscles_data) != MuscleSet.COUNT:
        raise ValueError(f"config.muscles must be a list of {MuscleSet.COUNT} muscles")
    muscles = []
    for i, m in enumerate(muscles_data):
        where = f"config.muscles[{i}]"
        m = check_keys(where, m, {"name", "key", "moment", "rise_time", "decay_time"})
        times = {}
        for t in ("rise_time", "decay_time"):
            times[t] = _ranged(f"{where}.{t}", m[t], "muscle_time")
            if times[t] < dt:
                raise ValueError(f"{where}.{t} must be at least the physics step {dt:g} s, got {times[t]!r}")
        muscles.append(MuscleSpec(
            check_str(f"{where}.name", m["name"], 40),
            check_str(f"{where}.key", m["key"], 20),
            _floats(f"{where}.moment", m["moment"], 2, "moment"),  # type: ignore[arg-type]
            times["rise_time"], times["decay_time"],
        ))
    keys = [m.key for m in muscles]
    if len(set(keys)) != len(keys) or {"space", "tab"} & set(keys):
        raise ValueError(f"config.muscles keys must differ from each other and from space and tab, got {keys}")
    integrator = check_str("config.integrator", d["integrator"], 40)
    if integrator not in SCHEMES:
        raise ValueError(f"config.integrator must be one of {', '.join(SCHEMES)}, got {integrator!r}")
    time_limit = _ranged("config.time_limit", d["time_limit"], "time_limit", low_open=True)
    if round(time_limit / dt) > MAX_GAME_STEPS:
        raise ValueError(f"the game is {round(time_limit / dt)} physics steps long (config.time_limit / config.dt), "
                         f"more than a replay may be ({MAX_GAME_STEPS})")
    view = _floats("config.view", d["view"], 4, "view")
    if not (view[0] < view[1] and view[2] < view[3]):
        raise ValueError(f"config.view must be [xmin, xmax, ymin, ymax] with min < max, got {list(view)}")
    config = GameConfig(
        arm=arm_params,
        start_posture=_floats("config.start_posture", d["start_posture"], 2, "start_posture"),  # type: ignore[arg-type]
        time_limit=time_limit,
        target_radius=_ranged("config.target_radius", d["target_radius"], "target_radius"),
        target_shoulder_range=_ordered("config.target_shoulder_range", _floats(  # type: ignore[arg-type]
            "config.target_shoulder_range", d["target_shoulder_range"], 2, "target_range")),
        target_elbow_range=_ordered("config.target_elbow_range", _floats(  # type: ignore[arg-type]
            "config.target_elbow_range", d["target_elbow_range"], 2, "target_range")),
        seed=check_int("config.seed", d["seed"], 0, INT64_MAX),
        muscles=tuple(muscles),
        integrator=integrator,
        dt=dt,
        reset_cost=check_int("config.reset_cost", d["reset_cost"], 0, 1000),
        view=view,  # type: ignore[arg-type]
        scene=check_word("config.scene", d["scene"]),
    )
    return config


# ----------------------------------------------------------------------- results

_RESULT_FIELDS = frozenset(f.name for f in fields(GameResult))
_VERIFY_CHUNK = 2_500  # steps between checks of the running score during verification

# The work of verifying a game, in physics steps of the game's compiled loop (0.12 us each on the 2-core build
# machine), the loop every install with a C compiler runs; measured with ``python benchmarks/honest_work.py``. In
# the Python loop a step costs 20 times more and an event or a try no more, so these overcount there.
# ``Replay.verify`` counts it as the game runs, ``checking.replay_work`` before it runs, in these units.
#: A target posture tried (``GameRules._draw_target``): measured at 5.8 to 6.1 steps (0.72 to 0.75 us) over runs.
TRY_WORK = 6
#: An input event: reading it, ``key_event`` and a call of the loop between steps (20.5 steps).
EVENT_WORK = 20


class VerifyCostError(UserError):
    """A game whose verification would cost more than its caller spends (``Replay.verify``'s ``max_work``):
    not checked, rather than run for minutes."""


def result_from_dict(data: object) -> GameResult:
    d = check_keys("result", data, set(_RESULT_FIELDS))
    return GameResult(
        score=check_int("result.score", d["score"], 0, COUNT_MAX),
        hits=check_int("result.hits", d["hits"], 0, MAX_HITS),
        resets=check_int("result.resets", d["resets"], 0, COUNT_MAX),
        seed=check_int("result.seed", d["seed"], 0, INT64_MAX),
        duration=check_float("result.duration", d["duration"], 0.0, MAX_GAME_SECONDS, low_open=True),
        steps=check_int("result.steps", d["steps"], 0, MAX_STEPS),
        scene=check_word("result.scene", d["scene"]),
        integrator=check_word("result.integrator", d["integrator"]),
        dt=_ranged("result.dt", d["dt"], "dt"),
        version=check_word("result.version", d["version"]),
    )


def same_outcome(a: GameResult, b: GameResult) -> bool:
    """Whether two results are the same game outcome; the armgame version may differ."""
    # replace() rather than as_dict(): asdict's deep copies were a tenth of a batch's verification.
    return replace(a, version=b.version) == b


# ------------------------------------------------------------------- task sections

class ReplayTask(Protocol):
    """A replay's task section, as its layer reads it: what records asks of one."""

    def as_dict(self) -> dict[str, object]:
        """The section as JSON data, with its ``"kind"``."""
        ...

    def session(self, config: GameConfig, timeline: Sequence[InputEvent], steps: int) -> Any:
        """The run re-simulated from its timeline to ``steps``; its ``result()`` is the game's result."""
        ...

    def verify(self, config: GameConfig, timeline: Sequence[InputEvent],
               result: GameResult) -> tuple[bool, GameResult, Any]:
        """Replay and compare everything the section claims: (ok, the recomputed result, the session)."""
        ...


#: ``read(section, config, last_step)``: rebuild and check a task section, raising ValueError naming the field.
TaskReader = Callable[[object, GameConfig, int], ReplayTask]

#: The kinds of task section this program reads, filled by the layers that record them.
_TASK_READERS: dict[str, TaskReader] = {}


def register_task(kind: str, read: TaskReader) -> None:
    """Let replays carry task sections whose ``"kind"`` is ``kind``, read by ``read``.

    Called by the layer that records such runs (``armgame.lab.record`` registers ``"centre-out"``
    when it is imported); registering the same reader again does nothing.
    """
    known = _TASK_READERS.get(kind)
    if known is not None and known != read:
        raise ValueError(f"task kind {kind!r} has a reader already")
    _TASK_READERS[kind] = read


def read_task(section: object, config: GameConfig, last_step: int) -> ReplayTask:
    """A replay's task section, by the reader registered for its kind; raises ValueError naming the field."""
    data = check_keys("task", section, {"kind"}, frozenset(section) if isinstance(section, dict) else frozenset())
    kind = check_str("task.kind", data["kind"], 40)
    read = _TASK_READERS.get(kind)
    if read is None:
        if not _TASK_READERS:
            raise ValueError(f"task.kind {kind!r}: no kind of task section is registered to read it")
        raise ValueError(f"task.kind must be {' or '.join(map(repr, sorted(_TASK_READERS)))}, got {kind!r}")
    return read(data, config, last_step)


# ------------------------------------------------------------------------ replay

@dataclass(frozen=True)
class Replay:
    config: GameConfig
    timeline: tuple[InputEvent, ...]
    #: The result as recorded; ``replay()`` recomputes it from the timeline.
    result: GameResult
    driven: str = "keyboard"
    #: The bot's or the script's name, if any.
    driver: str | None = None
    player: str | None = None
    date: str = ""
    version: str = __version__
    #: The task section of a run that is more than a game (see ``register_task``; the lab's: its protocol
    #: and trials); None for a game.
    task: ReplayTask | None = None
    #: The timeline as the file read wrote it, if that is as ``to_bytes`` writes it (``_TIMELINE_TEXT``), with the
    #: timeline it is the text of: ``to_bytes`` takes it only for that very timeline (a replay rebuilt with another,
    #: by ``dataclasses.replace``, writes its own). Not part of what the replay is (equality, repr).
    timeline_text: tuple[tuple[InputEvent, ...], bytes] | None = field(default=None, compare=False, repr=False)

    @property
    def steps(self) -> int:
        return self.result.steps

    @property
    def complete(self) -> bool:
        """Whether the game ran to the end of its clock (a game quit early is not a score)."""
        return self.result.steps >= self.config.total_steps

    @classmethod
    def from_session(cls, session: GameSession, driven: str, driver: str | None = None,
                     player: str | None = None) -> Replay:
        if driven not in DRIVEN:
            raise ValueError(f"driven must be one of {', '.join(DRIVEN)}, got {driven!r}")
        return cls(session.config, tuple(session.timeline), session.result(), driven, driver, player, now_iso())

    def with_player(self, player: str) -> Replay:
        return replace(self, player=check_name(player))

    def replay(self, max_work: int | None = None) -> GameResult:
        """Recompute the result: the timeline replayed on a fresh session, no clock. With ``max_work``, a game
        that would cost more (``verify``'s units: a hit storm) raises ``VerifyCostError`` on the way."""
        if self.task is not None:
            return self.task.session(self.config, self.timeline, self.result.steps).result()
        if max_work is None:
            return GameSession(self.config).play(self.timeline, self.result.steps)
        return self._run(max_work, stop_at_excess=False)

    def verify(self, max_work: int | None = MAX_VERIFY_WORK) -> tuple[bool, GameResult]:
        """Replay and compare. Bounded: the game is at most ``MAX_GAME_STEPS`` long (checked at load),
        and the replay stops as soon as it scores more hits or resets than recorded, so a replay
        that claims little cannot make its verifier draw a target at every step for hours. A lab
        run is compared trial by trial as well (its length was checked at load like a game's).

        A replay that claims much (a "hit storm": its targets drawn on the hand, so every step hits and
        each hit tries 1,000 postures) is bounded by ``max_work``, in ``checking.replay_work``'s units
        counted as the game runs (its steps, ``TRY_WORK`` a posture tried, ``EVENT_WORK`` an event): past
        it, ``VerifyCostError`` (not checked). A game whose ``replay_work`` is at most ``max_work`` stays
        under it (but for its first target's drawing); None spends whatever it takes."""
        if self.task is not None:
            ok, recomputed, _ = self.task.verify(self.config, self.timeline, self.result)
            return ok, recomputed
        recomputed = self._run(max_work, stop_at_excess=True)
        return same_outcome(recomputed, self.result), recomputed

    def _run(self, max_work: int | None, stop_at_excess: bool) -> GameResult:
        """The game replayed in chunks within ``max_work``; ``stop_at_excess``: stop once it scores more hits
        or resets than recorded (a verifier's answer is known then)."""
        claimed = self.result
        fixed = EVENT_WORK * len(self.timeline)
        if max_work is not None and claimed.steps + fixed > max_work:
            raise VerifyCostError(f"its {claimed.steps:,} steps and {len(self.timeline):,} input events are more "
                                  f"work ({claimed.steps + fixed:,} steps) than one verification spends "
                                  f"({max_work:,})")
        session = GameSession(self.config)
        rules = session.rules
        feed = TimelineInput(self.timeline, claimed.steps)
        board = rules.board
        step = 0
        while step < claimed.steps:
            chunk = _VERIFY_CHUNK
            if max_work is not None:
                left = max_work - fixed - step - TRY_WORK * rules.tries
                if left < 0:
                    raise VerifyCostError(
                        f"by step {step:,} of {claimed.steps:,} its game had tried {rules.tries:,} target postures "
                        f"for {board.hits:,} hits ({claimed.hits:,} claimed): more work than one verification "
                        f"spends ({max_work:,} steps), its targets keep landing on the hand")
                # A step costs itself and at most one hit's drawing: the budget is never passed by more than one.
                chunk = min(chunk, max(1, left // (1 + TRY_WORK * MAX_TRIES)))
            step = min(step + chunk, claimed.steps)
            feed.run_to(session, step)
            if stop_at_excess and (board.hits > claimed.hits or board.resets > claimed.resets):
                break
        return session.result()

    # ------------------------------------------------------------------ files
    def as_dict(self) -> dict[str, object]:
        return self._as_dict([[e.step, e.key, e.action] for e in self.timeline])

    def _as_dict(self, timeline: list[list[object]]) -> dict[str, object]:
        return {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "armgame_version": self.version,
            "date": self.date,
            "player": self.player,
            "driven": self.driven,
            "driver": self.driver,
            "scene": self.config.scene,
            "config": config_to_dict(self.config),
            "timeline": timeline,
            "result": self.result.as_dict(),
        } | ({} if self.task is None else {"task": self.task.as_dict()})

    def to_bytes(self) -> bytes:
        """The replay's file: ``dump_json(self.as_dict())``, byte for byte. The timeline (nearly all of a game's
        bytes: a bot's game has 15,000 events) is written here rather than by ``json``'s indenting encoder, which
        is pure Python and took 1.7 ms of a class server's 4 ms a hand-in, and 20 ms for a bot's game: every other
        field goes through ``dump_json`` as before, with the timeline, the last key in sorted order, left empty
        and then filled in: by ``json``'s compact C encoder and three replacements where every key is a plain
        word (so no comma or bracket is inside a string), else an event at a time."""
        if not self.timeline:
            return dump_json(self.as_dict())
        head = dump_json(self._as_dict([]))
        tail = b'"timeline": []\n}\n'
        if not head.endswith(tail):  # a key after "timeline" (none today): the general encoder, never a guess
            return dump_json(self.as_dict())
        read = self.timeline_text
        if read is not None and read[0] is self.timeline:  # the file read's own text of this timeline
            return head[:-len(tail)] + _TIMELINE_OPEN + read[1] + _TIMELINE_CLOSE
        timeline = [[e.step, e.key, e.action] for e in self.timeline]
        # json.dumps(indent=1) at the timeline's depth: the list at 1 space, its events at 2, their fields at 3.
        words = {e.key for e in self.timeline} | {e.action for e in self.timeline}
        if all(_PLAIN.fullmatch(word) for word in words):
            compact = json.dumps(timeline, separators=(",", ":"))[2:-2]  # 12,"d","down"],[13,"f","up"
            events = compact.replace("],[", "\0").replace(",", ",\n   ").replace("\0", "\n  ],\n  [\n   ")
            body = f"[\n   {events}\n  ]"
        else:
            quoted = {word: json.dumps(word, ensure_ascii=False) for word in words}
            body = ",\n  ".join(f'[\n   {e.step},\n   {quoted[e.key]},\n   {quoted[e.action]}\n  ]'
                                 for e in self.timeline)
        return head[:-len(tail)] + f'"timeline": [\n  {body}\n ]\n}}\n'.encode()

    def save(self, path: Path) -> None:
        data = self.to_bytes()
        if len(data) > MAX_REPLAY_BYTES:  # cannot happen within MAX_EVENTS; kept as the writer's half of the limit
            raise DataFileError(f"{path}: the replay would be {len(data)} bytes, more than a replay may be")
        atomic_write_bytes(Path(path), data, "replay")

    @classmethod
    def from_dict(cls, data: object) -> Replay:
        """Rebuild a replay from parsed JSON; raises ValueError (or UserError) naming the bad field."""
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise ValueError("not an armgame replay (no \"format\": \"armgame-replay\")")
        d = check_keys("replay", data, {"format", "format_version", "armgame_version", "date", "player", "driven",
                                        "driver", "scene", "config", "timeline", "result"}, frozenset({"task"}))
        fmt = check_int("format_version", d["format_version"], 1, 10**6)
        if fmt != FORMAT_VERSION:
            raise ValueError(f"replay format {fmt} is not supported by armgame {__version__} "
                             f"(it reads format {FORMAT_VERSION})")
        config = config_from_dict(d["config"])
        if d["scene"] != config.scene:
            raise ValueError(f"scene {d['scene']!r} differs from config.scene {config.scene!r}")
        result = result_from_dict(d["result"])
        if result.steps > config.total_steps:
            raise ValueError(f"result.steps {result.steps} is past the game's end ({config.total_steps} steps)")
        for name in ("seed", "scene", "integrator", "dt"):
            if getattr(result, name) != getattr(config, name):
                raise ValueError(f"result.{name} {getattr(result, name)!r} differs from config.{name}")
        if result.duration != config.time_limit:
            raise ValueError(f"result.duration {result.duration!r} differs from config.time_limit")
        driven = check_str("driven", d["driven"], 20)
        if driven not in DRIVEN:
            raise ValueError(f"driven must be one of {', '.join(DRIVEN)}, got {driven!r}")
        driver = None if d["driver"] is None else check_str("driver", d["driver"], 200)
        player = None if d["player"] is None else check_name(d["player"])
        timeline = _timeline_from_list(d["timeline"], config, result.steps)
        task = read_task(d["task"], config, result.steps) if "task" in d else None
        return cls(config, timeline, result, driven, driver, player, check_date("date", d["date"]),
                   check_word("armgame_version", d["armgame_version"]), task)

    @classmethod
    def from_bytes(cls, data: bytes, source: str = "replay") -> Replay:
        try:
            replay = cls.from_dict(parse_json(data))
        except DataFileError:
            raise
        except UnicodeDecodeError:
            raise DataFileError(f"{source}: not a text file (UTF-8 JSON expected)") from None
        except (ValueError, TypeError, UserError, RecursionError) as exc:  # UserError: GameConfig's own checks
            raise DataFileError(f"{source}: {exc}") from None
        if (len(replay.timeline) >= _KEEP_TEXT_EVENTS and isinstance(data, bytes)
                and data.endswith(_TIMELINE_CLOSE)):
            # A "timeline" key's value running to the file's end, nothing but plain events: the top-level one (the
            # object closes there), the one the parse kept (JSON's last of a key: no other key follows), and its only
            # writing. The first such key is found from the start (the head is short; the events hold none).
            start = data.find(_TIMELINE_OPEN)
            end = len(data) - len(_TIMELINE_CLOSE)
            if start >= 0 and _TIMELINE_TEXT.fullmatch(data, start + len(_TIMELINE_OPEN), end):
                object.__setattr__(replay, "timeline_text",
                                   (replay.timeline, bytes(data[start + len(_TIMELINE_OPEN):end])))
        return replay

    @classmethod
    def load(cls, path: Path, follow: bool = True) -> Replay:
        return cls.from_bytes(read_limited(Path(path), MAX_REPLAY_BYTES, "replay file", follow), str(path))


#: From how many events a replay read keeps its timeline's text (``Replay.timeline_text``), which writes it again in
#: a tenth of the time (a bot's 15,000 events; a student's 200 in 0.1 ms, not 0.4: a fifth of a class server's
#: time for a hand-in). A replay of a few events gains nothing from it.
_KEEP_TEXT_EVENTS = 64


#: ``_ctimeline.c``: this module's timeline read in C, where built (``armgame._native``).
_CTIMELINE = load("armgame.records._ctimeline", 1)
_ACTIONS = frozenset((DOWN, UP))


def _timeline_from_list(data: object, config: GameConfig, last_step: int) -> tuple[InputEvent, ...]:
    if not isinstance(data, list):
        raise ValueError("timeline must be a list of [step, key, action]")
    if len(data) > MAX_EVENTS:
        raise ValueError(f"timeline has {len(data)} events, more than {MAX_EVENTS}")
    keys = (*(m.key for m in config.muscles), "space", "tab")
    known = frozenset(keys)
    actions = (DOWN, UP)
    if _CTIMELINE is not None and 0 <= last_step <= INT64_MAX:
        # The same loop's fast test in C (a bot's 15,000 events in a twentieth of the time); an index where it
        # refuses an event: the loop below reads them all again and says what is wrong.
        read = _CTIMELINE.read_events(data, known, _ACTIONS, last_step, InputEvent)
        if type(read) is tuple:
            return read
    events: list[InputEvent] = []
    add = events.append
    # An event made as ``InputEvent(step, key, action)`` makes it (the same fields, in order), without the frozen
    # dataclass's __init__ and its three object.__setattr__ calls: half the time of a bot's 15,000 events.
    new = object.__new__
    previous = 0
    for i, item in enumerate(data):
        # The fast test first (a bot's game has tens of thousands of events, and checking each field by the
        # general checks was most of a class server's time for it); any event it does not pass, the checks
        # below refuse with their own message.
        if type(item) is list and len(item) == 3:
            step, key, action = item
            if (type(step) is int and previous <= step <= last_step and type(key) is str and key in known
                    and type(action) is str and action in actions):
                event = new(InputEvent)
                fields_ = event.__dict__
                fields_["step"] = step
                fields_["key"] = key
                fields_["action"] = action
                add(event)
                previous = step
                continue
        where = f"timeline[{i}]"
        if not isinstance(item, list) or len(item) != 3:
            raise ValueError(f"{where} must be [step, key, action]")
        step, key, action = item
        step = check_int(f"{where} step", step, previous, last_step)
        if key not in keys:
            raise ValueError(f"{where}: unknown key {key!r}; keys are {' '.join(keys)}")
        if action not in (DOWN, UP):
            raise ValueError(f"{where}: action must be 'down' or 'up', got {action!r}")
        events.append(InputEvent(step, key, action))
        previous = step
    return tuple(events)

