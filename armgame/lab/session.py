"""The centre-out task on the game's fixed-step session.

``LabSession`` is a ``GameSession``: the same arm, muscles, integrator, key events, input
timeline, ``TimelineInput`` and ``Autopilot``, so a lab run is recorded and replayed exactly
as a game is. Only the rules differ, and the physics of perturbed trials:

1. Hold: home is shown; once the (shown) hand has stayed inside it for the trial's delay (a
   seeded random 0.5-1.0 s), the go cue comes: home goes and the target appears.
2. Reach: the trial ends with a hit when the shown hand has stayed inside the target for the
   hold time (0.2 s), or with a miss at the time-out.
3. The arm is put back at home, at rest, with the muscles relaxed (a robot returning the hand),
   and the next trial's hold begins. After the last trial the session is over.

Each trial's perturbation (its block's; none on a catch trial) is on from its go cue to its end,
as a robot switches its field on for the movement: a force field through a ``LoadedArm``'s
closures, a visual transform on the shown hand. So the hold at home is never disturbed (a steady
force there would keep the go cue from ever coming). The shown hand is recorded every physics
step from the go cue to the trial's end, for the per-reach metrics.

Issue 41: a block may have a home posture of its own (the arm is put there at the end of the
trial before, as a robot moves the arm to a second workspace); a trial may hide the cursor from
its go cue on (``TrialPlan.feedback``: ``endpoint`` shows where the reach ended once it is over,
``none`` nothing), and such a trial also ends when the hand has left home and stopped; a block may
mix its field on, off or reversed at random, balanced per direction (``Block.mix``).
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from .. import __version__
from ..errors import UserError
from ..game.muscles import DEFAULT_MUSCLES, MuscleSpec
from ..game.rules import MAX_CONFIG_SECONDS, GameConfig, Target
from ..game.session import GameResult, GameSession
from ..game.variant import RunawayError, guarded
from ..limits import MAX_GAME_SECONDS
from ..physics.hand import hand_from_trig, hand_xy, hand_xy_arm_sine
from ..physics.integrators import Integrator
from ..physics.loads import ChannelField, Loads, loaded_arm
from ..physics.trig import sin_cos
from .perturbations import NONE, Display, Perturbation
from .protocol import MAX_CHANNEL_LAMBDA_DT, STILL_SPEED, Block, Protocol

HOLD, REACH = "hold", "reach"
#: Which sine a run's hand takes, every step (its cursor, its path, the hand a field pushes): ``library``, the C
#: library's (``math``: every run recorded before the browser's lab, and the envs'), or ``arm``, the arm's own
#: (``physics.trig``: the same bits on every machine and in the browser's lab, ``classroom/static/labengine.js``).
SINES = ("library", "arm")
_WENT, _ENDED = 1, 2
LAB_SCENE = "lab"


@dataclass(frozen=True)
class TrialPlan:
    """What a trial will be, fixed before it starts by the protocol and the seed."""

    index: int
    block: int
    block_name: str
    target: int
    target_deg: float
    position: tuple[float, float]
    delay_steps: int
    perturbation: Perturbation
    catch: bool
    #: An error-clamp trial: the force channel along the home-to-target line instead of the perturbation.
    channel: bool = False
    #: Where the trial starts: the home position (m) and posture (rad) of its block.
    home: tuple[float, float] = (0.0, 0.0)
    home_q: tuple[float, float] = (0.0, 0.0)
    #: What the player sees of the hand from the go cue on (``protocol.FEEDBACK``).
    feedback: str = "full"

    @property
    def active(self) -> Perturbation:
        """The perturbation actually on: none on a catch or channel trial."""
        return NONE if self.catch or self.channel else self.perturbation


@dataclass
class TrialOutcome:
    plan: TrialPlan
    go_step: int
    end_step: int
    hit: bool
    #: The shown hand (m) after every physics step from the go cue to the end, both included.
    xs: list[float] = field(default_factory=list, repr=False)
    ys: list[float] = field(default_factory=list, repr=False)
    #: On a channel trial: the force (N) the arm pressed into the channel at the same steps as ``xs``, signed
    #: along the left normal of the home-to-target line (+ = counter-clockwise side); empty otherwise.
    channel_force: list[float] = field(default_factory=list, repr=False)
    #: On a channel trial: the hand's true velocity (m/s) at those steps, for the adaptation index.
    vxs: list[float] = field(default_factory=list, repr=False)
    vys: list[float] = field(default_factory=list, repr=False)
    #: On a channel trial: the joint angles (rad) at those steps, for a field held in joint coordinates.
    q1s: list[float] = field(default_factory=list, repr=False)
    q2s: list[float] = field(default_factory=list, repr=False)
    #: Where space ("hand home") sent the hand home during the reach: the number of samples of ``xs`` taken before
    #: the jump (None: it never was). The samples from there on are not the reach: a jump of tens of centimetres in
    #: one physics step is no movement, and measured as one it reads as a reach of tens of metres a second.
    home_at: int | None = None

    @property
    def reach_samples(self) -> int:
        """How many samples of ``xs`` (and of the channel's) are the reach: all, or those before the hand was sent
        home."""
        return len(self.xs) if self.home_at is None else self.home_at


def schedule(protocol: Protocol, seed: int, dt: float, home: tuple[float, float],
             homes: dict[tuple[float, float], tuple[tuple[float, float], tuple[float, float]]] | None = None,
             limit: int | None = None) -> tuple[TrialPlan, ...]:
    """Every trial of the protocol: targets in shuffled cycles (each of the block's targets once a cycle),
    go-cue delays, catch trials and channel trials, all drawn from one ``random.Random(seed)`` in a fixed
    order. A block without catch or channel trials draws nothing for them, so the schedules of protocols
    without probes are those they always were; how the probes are placed is ``protocol.probe_schedule``'s
    (``balanced_probes``, or ``random``: drawn uniformly among the trials after the block's first cycle).

    ``homes``: each posture's (home position, posture in rad), by the posture in degrees, for protocols whose blocks
    move home (``LabSession`` works them out); by default every block starts at ``home``. A mixed block (``mix``)
    draws its trials' kinds after its targets and probes: per target, in order, shuffled cycles of the mix.

    ``limit``: only the first ``limit`` trials, the same as the full schedule's (every draw for a trial comes before
    the next trial's), for a caller that may never reach the others (the CenterOut batch's short episodes)."""
    rng = random.Random(seed)
    angles = protocol.target_angles_deg()
    start_q = tuple(math.radians(a) for a in protocol.start_posture_deg)
    plans: list[TrialPlan] = []
    for b, block in enumerate(protocol.blocks):
        if limit is not None and len(plans) >= limit:
            break
        if homes is None:
            block_home, block_q = home, start_q
        else:
            block_home, block_q = homes[block.posture_of(protocol)]
        positions = protocol.target_positions(block_home)
        own = block.targets_of(protocol)
        if block.channel_block:
            order = _cycles(rng, block.probe_targets_of(protocol), block.trials)
            catch: set[int] = set()
            channel = set(range(block.trials))
        elif protocol.probe_schedule == "balanced" and block.probes:
            order, catch, channel = balanced_probes(rng, block, own, block.probe_targets_of(protocol),
                                                    protocol.consecutive_probes)
        else:
            order = _cycles(rng, own, block.trials)
            catch = set(rng.sample(range(len(own), block.trials), block.catch_trials))
            if block.channel_trials:
                free = [i for i in range(len(own), block.trials) if i not in catch]
                channel = set(rng.sample(free, block.channel_trials))
            else:
                channel = set()
        kinds = _mixed(rng, block, order, catch | channel) if block.mix else {}
        opposite = block.perturbation.opposite() if "opposite" in block.mix else None
        for i in range(block.trials if limit is None else min(block.trials, limit - len(plans))):
            delay = rng.uniform(*protocol.delay)
            t = order[i]
            kind = kinds.get(i, "on")
            perturbation = block.perturbation if kind == "on" else NONE if kind == "off" else opposite
            probe = i in catch or i in channel
            plans.append(TrialPlan(len(plans), b, block.name, t, angles[t] % 360.0, positions[t],
                                   max(1, round(delay / dt)), perturbation, i in catch, i in channel,  # type: ignore[arg-type]
                                   block_home, block_q,  # type: ignore[arg-type]
                                   block.probes_feedback if probe else block.feedback))
    return tuple(plans)


def _mixed(rng: random.Random, block: Block, order: list[int], probes: set[int]) -> dict[int, str]:
    """A mixed block's ordinary trials' kinds: for each target (in the order of first appearance), its trials
    take shuffled cycles of the block's ``mix``, so each direction has each kind as often as its trials allow
    (within one), and the sequence of kinds seen from trial to trial is random."""
    out: dict[int, str] = {}
    for t in dict.fromkeys(order[i] for i in range(len(order)) if i not in probes):
        mine = [i for i in range(block.trials) if order[i] == t and i not in probes]
        kinds: list[str] = []
        while len(kinds) < len(mine):
            cycle = list(block.mix)
            rng.shuffle(cycle)
            kinds += cycle
        out.update(zip(mine, kinds, strict=False))
    return out


def _cycles(rng: random.Random, targets: tuple[int, ...], n: int) -> list[int]:
    order: list[int] = []
    while len(order) < n:
        cycle = list(targets)
        rng.shuffle(cycle)
        order += cycle
    return order


def balanced_probes(rng: random.Random, block: Block, targets: tuple[int, ...], probe_targets: tuple[int, ...],
                    consecutive: bool = False) -> tuple[list[int], set[int], set[int]]:
    """A block's targets, catch trials and channel trials with its probes placed evenly (issue 29).

    * When: the trials after the block's first cycle are cut into as many equal runs as there are probes
      (catch plus channel trials), and each probe falls on a trial drawn within its run, never right after
      the previous probe unless ``consecutive`` (the protocol's checks leave room: each run is two trials or
      more). So probes are spread through the block, one a run.
    * Which kind: catch and channel trials alternate as evenly as their counts allow (the j-th probe is a
      channel trial when ``floor((j + 1) h / p)`` steps past ``floor(j h / p)``, with h channel trials of p).
    * Where to: each probe, in order, goes to the probe direction with the fewest probes of its kind so far,
      then the fewest of either kind, ties drawn from the seed. So each kind's probes differ by at most one
      between directions, and every direction is probed before any twice.
    * The other trials keep the block's shuffled cycles of its own targets, the first cycle whole before any
      probe."""
    n, k, p = block.trials, len(targets), block.probes
    ordinary = iter(_cycles(rng, targets, n - p))
    span = n - k
    slots: list[int] = []
    for j in range(p):
        low, high = k + j * span // p, k + (j + 1) * span // p
        if slots and not consecutive:
            low = max(low, slots[-1] + 2)
        slots.append(rng.randrange(low, high))
    kinds = ["channel" if (j + 1) * block.channel_trials // p > j * block.channel_trials // p else "catch"
             for j in range(p)]
    counts = {kind: dict.fromkeys(probe_targets, 0) for kind in ("catch", "channel")}
    total = dict.fromkeys(probe_targets, 0)
    where: dict[int, int] = {}
    for slot, kind in zip(slots, kinds, strict=True):
        best = min((counts[kind][t], total[t]) for t in probe_targets)
        tied = [t for t in probe_targets if (counts[kind][t], total[t]) == best]
        chosen = tied[rng.randrange(len(tied))]
        counts[kind][chosen] += 1
        total[chosen] += 1
        where[slot] = chosen
    order = [where[i] if i in where else next(ordinary) for i in range(n)]
    catch = {s for s, kind in zip(slots, kinds, strict=True) if kind == "catch"}
    channel = {s for s, kind in zip(slots, kinds, strict=True) if kind == "channel"}
    return order, catch, channel


def lab_config(protocol: Protocol, seed: int, muscles: tuple[MuscleSpec, ...] = DEFAULT_MUSCLES,
               person: bool = False, **options: object) -> GameConfig:
    """The ``GameConfig`` a lab run plays on: the game's arm and muscles, home as the start posture,
    and a clock long enough for every trial (a run that fidgets at home past it ends there).

    ``person``: a person at the keys gets three times the time every trial could take, and two minutes
    more (``lesson``: 408 s, 6.8 minutes, of reaching, cards and paths not counted; a program 204 s), where
    a program gets one and a half times and one minute: a volunteer slow to bring the hand home, or talking to
    the class, must not lose the run on the clock. Only a run that idles costs more to replay; a finished one
    ends at its last trial."""
    worst = protocol.trials * (protocol.delay[1] + protocol.timeout)
    program = math.ceil(1.5 * worst + 60.0)
    person_limit = max(program, min(math.ceil(3.0 * worst + 120.0), MAX_GAME_SECONDS))
    time_limit = float(min(MAX_CONFIG_SECONDS, person_limit) if person else program)
    home = tuple(math.radians(a) for a in protocol.start_posture_deg)
    return GameConfig(start_posture=home, time_limit=time_limit, seed=seed, muscles=muscles,  # type: ignore[arg-type]
                      target_radius=protocol.target_radius, scene=LAB_SCENE, **options)  # type: ignore[arg-type]


class LabSession(GameSession):
    """A centre-out experiment on the game's session: see the module's docstring."""

    def __init__(self, config: GameConfig, protocol: Protocol, hold_at_home: bool = True, *,
                 compiled: bool = True, sine: str = "library", speed_limit: float = math.inf) -> None:
        super().__init__(config, compiled=compiled)
        #: A force field's or a channel's joint speed past this (rad/s) stops the run where it is, as the Reach envs'
        #: games stop (``armgame.game.variant.guarded``): the envs set it to the speed bound they declare, since a
        #: field that feeds the arm energy can break any bound. Infinite (the lab's own runs): no guard.
        self.speed_limit = float(speed_limit)
        #: Why the guard stopped the run (one line), or None.
        if sine not in SINES:
            raise UserError(f"a lab run's sine is one of {', '.join(SINES)}, got {sine!r}")
        self.sine = sine
        self.stopped: str | None = None
        self._arm_sine = sine == "arm"
        self._hand_xy = hand_xy_arm_sine if self._arm_sine else hand_xy
        #: True (the lab's rule): the go cue waits for the cursor to stay in home for the trial's delay.
        #: False (for agents, ``armgame/CenterOut-v1``): it comes that delay after the trial began, wherever
        #: the cursor is, so a policy that cannot yet hold still still starts trials.
        self.hold_at_home = bool(hold_at_home)
        if config.scene != LAB_SCENE:
            raise UserError(f"a lab run's scene is {LAB_SCENE!r}, got {config.scene!r}")
        if tuple(config.start_posture) != tuple(math.radians(a) for a in protocol.start_posture_deg):
            raise UserError("the run's start posture differs from its protocol's home posture")
        self.protocol = protocol
        self.home_q = config.start_posture
        self.home = self.hand()
        self.home_target = Target(*self.home, protocol.home_radius)
        #: Each posture's (home, posture in rad), by the posture in degrees (one for most protocols).
        self.homes = {deg: self._home_at(deg) for deg in protocol.postures_deg}
        for home, _q in self.homes.values():
            for x, y in protocol.target_positions(home):
                self.model.inverse_kinematics((x, y))  # UnreachableError (one line) for a target out of reach
        self.plans = schedule(protocol, config.seed, config.dt, self.home,
                              self.homes if len(self.homes) > 1 else None)
        self._still = 0
        self.hold_steps = max(1, round(protocol.hold_time / config.dt))
        self.timeout_steps = max(1, round(protocol.timeout / config.dt))
        if protocol.has_channels:
            self._check_channel()
        self._physics: dict[tuple[Perturbation, tuple[float, float]], tuple[object, Display | None]] = {}
        self._channels: dict[tuple[int, tuple[float, float]], tuple[object, ChannelField]] = {}
        self._channel: ChannelField | None = None
        self._fs: list[float] = []
        self._vxs: list[float] = []
        self._vys: list[float] = []
        self._q1s: list[float] = []
        self._q2s: list[float] = []
        self.outcomes: list[TrialOutcome] = []
        self.trial_index = 0
        self.finished = False
        self.phase = HOLD
        self.cursor = self.home
        self._counter = 0
        self._go_step = 0
        self._xs: list[float] = []
        self._ys: list[float] = []
        self._home_at: int | None = None
        self.rules.target = self.home_target
        self._enter_trial()

    def _home_at(self, posture_deg: tuple[float, float]) -> tuple[tuple[float, float], tuple[float, float]]:
        """(the hand at that posture, the posture in rad), as ``hand()`` computes the hand."""
        q1, q2 = (math.radians(a) for a in posture_deg)
        if (q1, q2) == tuple(self.home_q):
            return self.home, self.home_q
        p = self.config.arm
        return self._hand_xy(p.l1, p.l2, q1, q2), (q1, q2)

    # ------------------------------------------------------------------ queries
    def hand(self) -> tuple[float, float]:
        p = self.config.arm
        return self._hand_xy(p.l1, p.l2, self.state[0], self.state[1])

    @property
    def cursor_visible(self) -> bool:
        """Whether the player sees the cursor now: always at home, and in a reach unless the trial hides it."""
        plan = self.plan
        return self.phase == HOLD or plan is None or plan.feedback == "full"

    @property
    def over(self) -> bool:
        return self.finished or self.steps >= self.total_steps

    @property
    def out_of_time(self) -> bool:
        """The run's clock ran out before its last trial ended (``lab_config``)."""
        return not self.finished and self.steps >= self.total_steps

    @property
    def ending(self) -> str:
        """How the run ended, as its summary line adds it: nothing for a whole run."""
        return "" if self.finished else " (its time ran out)" if self.out_of_time else " (stopped before the end)"

    @property
    def plan(self) -> TrialPlan | None:
        return self.plans[self.trial_index] if self.trial_index < len(self.plans) else None

    @property
    def phase_start_step(self) -> int:
        """The physics step at which the current phase began: the go cue in a reach, the previous trial's
        end (or the run's start) in a hold."""
        if self.phase == REACH:
            return self._go_step
        return self.outcomes[-1].end_step if self.outcomes else 0

    @property
    def stayed(self) -> int:
        """Physics steps in a row the cursor has stayed in the target (a reach: a hit at ``hold_steps``), or counted
        toward the go cue (a hold), so far: what a controller that plans the stay in the target starts from."""
        return self._counter

    @property
    def block(self):
        plan = self.plan or self.plans[-1]
        return self.protocol.blocks[plan.block]

    def steps_before_an_end(self) -> int:
        """The fewest physics steps after which the current trial could end (at least 1; 0 once over).

        A window that never advances further than this in one go stops exactly at a trial's end, to show
        it before the next trial begins, without changing a single step: in a hold, the go cue comes a
        step away at the soonest and a hit then needs a full hold; in a reach, the hold left or the
        time-out, whichever is nearer.
        """
        if self.over:
            return 0
        if self.phase == HOLD:
            return self.hold_steps
        return max(1, min(self.hold_steps - self._counter, self.timeout_steps - (self.steps - self._go_step)))

    def result(self) -> GameResult:
        b, c = self.rules.board, self.config
        return GameResult(b.score, b.hits, b.resets, c.seed, c.time_limit, self.steps, c.scene, c.integrator, c.dt,
                          __version__)

    def trial_records(self) -> list[list[object]]:
        """Each finished trial as [target, go_step, end_step, hit]: what a replay records and verify checks."""
        return [[o.plan.target, o.go_step, o.end_step, o.hit] for o in self.outcomes]

    # ----------------------------------------------------------------- physics
    def physics_for(self, perturbation: Perturbation) -> tuple[object, Display | None]:
        """(step function, shown-hand transform) of a perturbation, built once per run."""
        key = (perturbation, self.home)
        if key not in self._physics:
            loads = perturbation.loads(self.home)
            step = self.unloaded_step() if loads is None else \
                self._guarded(Integrator(self.config.integrator,
                                         loaded_arm(self.model, loads, self._arm_sine)).step_components)
            self._physics[key] = (step, perturbation.display(self.home, self.home_q))
        return self._physics[key]

    def channel_for(self, target: int) -> tuple[object, ChannelField]:
        """(step function, channel) of an error-clamp trial to ``target``, built once per target."""
        key = (target, self.home)
        if key not in self._channels:
            hx, hy = self.home
            tx, ty = self.protocol.target_positions(self.home)[target]
            length = math.hypot(tx - hx, ty - hy)
            channel = ChannelField(self.protocol.channel_stiffness, self.protocol.channel_damping, self.home,
                                   ((tx - hx) / length, (ty - hy) / length))
            arm = loaded_arm(self.model, Loads(hand=channel), self._arm_sine)
            step = self._guarded(Integrator(self.config.integrator, arm).step_components)
            self._channels[key] = (step, channel)
        return self._channels[key]

    def _guarded(self, step: object) -> object:
        """A loaded step under the run's speed guard, if it has one. The arm's own step needs none: every hold starts
        at rest, and from rest the muscles cannot pass the game's speed bound (``env.reach.speed_bound``)."""
        return guarded(step, self.speed_limit) if math.isfinite(self.speed_limit) else step  # type: ignore[arg-type]

    def _check_channel(self) -> None:
        """Refuse a channel too stiff for the fixed physics step (as MotorNet checks delays against dt).

        Across the line the hand is a mass ``m`` on the channel's spring ``k`` and damper ``c``: the modes
        ``m s^2 + c s + k = 0``. ``m`` is taken as the arm's lightest endpoint mass (the smallest eigenvalue
        of ``(J M^-1 J^T)^-1``) at home and at every target, the worst direction a channel can lie in. RK4 is
        stable to |s| dt of 2.65 to 2.83 by the mode's direction; the limit ``MAX_CHANNEL_LAMBDA_DT`` keeps a
        margin and the step's error small.
        """
        import numpy as np

        p, dt = self.protocol, self.config.dt
        postures = [q for home, q in self.homes.values()]
        postures += [tuple(self.model.inverse_kinematics(xy)) for home, _q in self.homes.values()
                     for xy in p.target_positions(home)]
        lightest = math.inf
        for q in postures:
            jac = self.model.jacobian(np.asarray(q, dtype=float))
            inverse = jac @ np.linalg.inv(self.model.mass_matrix(np.asarray(q, dtype=float))) @ jac.T
            lightest = min(lightest, 1.0 / float(np.max(np.linalg.eigvalsh(inverse))))
        fastest = float(np.max(np.abs(np.roots([lightest, p.channel_damping, p.channel_stiffness]))))
        if fastest * dt > MAX_CHANNEL_LAMBDA_DT:
            raise UserError(
                f"the force channel (channel_stiffness {p.channel_stiffness:g} N/m, channel_damping "
                f"{p.channel_damping:g} N s/m) is too stiff for the physics step of {dt:g} s: on the arm's lightest "
                f"endpoint mass ({lightest:.3g} kg) its fastest mode is {fastest:.4g}/s, and |s| dt must be at most "
                f"{MAX_CHANNEL_LAMBDA_DT:g}")

    def _record_channel(self, q1: float, q2: float, w1: float, w2: float) -> None:
        """The force the arm presses into the channel at this state (minus the channel's on the hand)."""
        channel = self._channel
        assert channel is not None
        l1, l2 = self.config.arm.l1, self.config.arm.l2
        if self._arm_sine:
            (s1, c1), (s12, c12) = sin_cos(q1), sin_cos(q1 + q2)
        else:
            s1, c1, s12, c12 = math.sin(q1), math.cos(q1), math.sin(q1 + q2), math.cos(q1 + q2)
        x, y = hand_from_trig(l1, l2, c1, s1, c12, s12)
        vx = (-l1 * s1 - l2 * s12) * w1 - l2 * s12 * w2
        vy = (l1 * c1 + l2 * c12) * w1 + l2 * c12 * w2
        self._fs.append(-channel.lateral(x, y, vx, vy))
        self._vxs.append(vx)
        self._vys.append(vy)
        self._q1s.append(q1)
        self._q2s.append(q2)

    def _enter_trial(self) -> None:
        self._channel = None
        plan = self.plan
        if plan is None:
            self.finished = True
            return
        if plan.home_q != self.home_q and plan.home_q != (0.0, 0.0):  # a block at another posture: home moves
            self.home, self.home_q = plan.home, plan.home_q
            self.home_target = Target(*self.home, self.protocol.home_radius)
        self._step, self._show = self.physics_for(NONE)
        self.phase = HOLD
        self._counter = 0
        self.rules.target = self.home_target

    def shown_hand(self) -> tuple[float, float]:
        x, y = self.hand()
        if self._show is None:
            return x, y
        return self._show(x, y, self.state[0], self.state[1])

    def _advance(self, n: int) -> int:
        """The task's hot loop: ``GameSession.advance`` runs it and stops a state gone non-finite."""
        n = min(n, self.total_steps - self.steps)
        if n <= 0 or self.finished:
            return 0
        dt = self.config.dt
        arm = self.config.arm
        l1, l2 = arm.l1, arm.l2
        muscles = self.muscles
        a0, a1, a2, a3 = muscles.activation
        g0, g1, g2, g3 = muscles.goal
        r0, r1, r2, r3 = muscles.rate
        (s0, e0), (s1, e1), (s2, e2), (s3, e3) = muscles.moments
        q1, q2, w1, w2 = self.state
        previous = self.state
        step, show = self._step, self._show
        channel = self._channel
        hand_at = self._hand_xy
        ran = 0
        try:
            while ran < n:
                t1 = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3
                t2 = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3
                a0 += (g0 - a0) * r0
                a1 += (g1 - a1) * r1
                a2 += (g2 - a2) * r2
                a3 += (g3 - a3) * r3
                previous = (q1, q2, w1, w2)
                q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
                self.steps += 1
                ran += 1
                hx, hy = hand_at(l1, l2, q1, q2)
                if show is not None:
                    hx, hy = show(hx, hy, q1, q2)
                if channel is not None:
                    self._record_channel(q1, q2, w1, w2)
                event = self._task_step(hx, hy)
                if event:
                    step, show = self._step, self._show  # the go cue switched the perturbation on, or the end off
                    channel = self._channel
                    if channel is not None:  # a channel trial's go cue: its first sample
                        self._record_channel(q1, q2, w1, w2)
                    if event == _ENDED:
                        # The arm goes home at rest and the muscles relax.
                        q1, q2 = self.home_q
                        w1 = w2 = 0.0
                        previous = (q1, q2, w1, w2)
                        a0 = a1 = a2 = a3 = 0.0
                        self.cursor = self.home
                        if self.finished:
                            break
        except RunawayError as exc:
            # The guard refused the step's state: the run keeps the last state it allowed and ends there.
            self.stopped = str(exc)
            self.total_steps = self.steps
            raise
        finally:
            muscles.activation = [a0, a1, a2, a3]
            self.state = (q1, q2, w1, w2)
            self.previous_state = previous
        return ran

    def _task_step(self, x: float, y: float) -> int:
        """The task's rules after a physics step, with the shown hand at (x, y): 0, or _WENT at the go cue,
        or _ENDED at the trial's end."""
        self.cursor = (x, y)
        plan = self.plans[self.trial_index]
        if self.phase == HOLD:
            home = self.home_target
            self._counter = self._counter + 1 if not self.hold_at_home or home.contains(x, y) else 0
            if self._counter >= plan.delay_steps:
                self.phase = REACH
                self._go_step = self.steps
                self._counter = 0
                self._xs, self._ys = [x], [y]
                self._home_at = None
                self.rules.target = Target(*plan.position, self.protocol.target_radius)
                self._still = 0
                if plan.channel:
                    self._step, self._channel = self.channel_for(plan.target)
                    self._show = None
                    self._fs, self._vxs, self._vys, self._q1s, self._q2s = [], [], [], [], []
                else:
                    self._step, self._show = self.physics_for(plan.active)
                return _WENT
            return 0
        self._xs.append(x)
        self._ys.append(y)
        self._counter = self._counter + 1 if self.rules.target.contains(x, y) else 0
        hit = self._counter >= self.hold_steps
        if not hit and plan.feedback != "full" and self._stopped(x, y):
            hit = self.rules.target.contains(x, y)  # without a cursor the reach ends where the hand stopped
        elif not hit and self.steps - self._go_step < self.timeout_steps:
            return 0
        outcome = TrialOutcome(plan, self._go_step, self.steps, hit, self._xs, self._ys, home_at=self._home_at)
        if plan.channel:
            outcome.channel_force, outcome.vxs, outcome.vys = self._fs, self._vxs, self._vys
            outcome.q1s, outcome.q2s = self._q1s, self._q2s
        self.outcomes.append(outcome)
        if hit:
            self.rules.board.hits += 1
            self.rules.board.score += 1
        self.trial_index += 1
        self._enter_trial()
        return _ENDED

    def _stopped(self, x: float, y: float) -> bool:
        """A trial without a cursor: whether the hand, more than half the target distance from home, has moved
        slower than ``STILL_SPEED`` for the hold time (counted in ``_still``)."""
        xs, ys = self._xs, self._ys
        hx, hy = self.home
        away = (x - hx) * (x - hx) + (y - hy) * (y - hy) > 0.25 * self.protocol.distance * self.protocol.distance
        if away and len(xs) >= 2:
            dx, dy = x - xs[-2], y - ys[-2]
            limit = STILL_SPEED * self.config.dt
            self._still = self._still + 1 if dx * dx + dy * dy < limit * limit else 0
        else:
            self._still = 0
        return self._still >= self.hold_steps or self.steps - self._go_step >= self.timeout_steps

    def _reset_arm(self) -> None:
        super()._reset_arm()  # the reset key: home, at rest, counted; the trial's clock runs on
        if tuple(self.config.start_posture) != tuple(self.home_q):  # a block at another posture: its home
            q1, q2 = self.home_q
            self.state = self.previous_state = (q1, q2, 0.0, 0.0)
        self.cursor = self.shown_hand()
        if self.phase == REACH and self._home_at is None and not self.over:
            # The reach ends here for its measures: every sample so far was taken before the jump (keys act
            # between physics steps), every later one after it.
            self._home_at = len(self._xs)
