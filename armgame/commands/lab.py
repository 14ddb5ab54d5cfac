"""armgame lab: centre-out adaptation experiments, played in a window or by a bot headless."""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

from ..errors import UserError
from ..words import unknown_name
from .outputs import RecordTarget, fresh_outputs
from .play import DEFAULT_SEED, _seed, check_recordable


def _rate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number from 0 to 1, got {text!r}") from None
    if not (math.isfinite(value) and 0.0 <= value <= 1.0):
        raise argparse.ArgumentTypeError(f"must be from 0 to 1, got {text!r}")
    return value


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 0 <= value <= 1000:
        raise argparse.ArgumentTypeError(f"must be from 0 to 1000, got {text!r}")
    return value


def register(subparsers: argparse._SubParsersAction) -> None:
    from ..lab.presets import HUMAN_NOISE, PRESETS

    p = subparsers.add_parser(
        "lab",
        help="adaptation experiments: centre-out reaches in a force field or a changed display",
        description="Reach from home to targets around it, in blocks: baseline (nothing changed), exposure "
        "(a force field or a changed display), washout (the perturbation removed). PROTOCOL is a preset ("
        + ", ".join(PRESETS) + ") or a TOML protocol file. In a window you play with the muscle keys (d f j k); "
        "--bot lets a bot play (model, naive, or adaptive: the model bot learning the perturbation trial by "
        "trial with a two-rate learner). --out DIR writes trials.csv (one row per reach), learning.png and "
        "paths.png; --record FILE saves the run as a replay that 'armgame verify' and 'armgame analyze' check. "
        "A run in a window is always kept: without --out or --record, in a new folder of the per-user data "
        "folder (~/.local/share/armgame/lab), which the window's last screen names.",
    )
    p.add_argument("protocol", metavar="PROTOCOL", help=f"a preset ({', '.join(PRESETS)}) or a .toml file")
    p.add_argument("--seed", type=_seed, default=DEFAULT_SEED,
                   help=f"target order and go-cue delays (default: {DEFAULT_SEED})")
    p.add_argument("--bot", metavar="NAME", help="a bot plays: model, naive or adaptive")
    p.add_argument("--headless", action="store_true", help="no window (needs --bot): run as fast as possible")
    p.add_argument("--out", metavar="DIR", help="write trials.csv, learning.png and paths.png to DIR")
    p.add_argument("--no-figures", action="store_true", help="with --out, or in a window: trials.csv only (no figures)")
    p.add_argument("--record", metavar="FILE|FOLDER",
                   help="save the run's replay to FILE (JSON), or into FOLDER as NAME-labN.json (the player's name "
                   "and the next number there)")
    from .outputs import add_force_option

    add_force_option(p, "an existing --record FILE and --out's files")
    p.add_argument("--name", help="the player's name, kept in the replay (never in the high-score table)")
    from .classroom import add_join_options

    add_join_options(p)
    p.add_argument("--catch", type=_count, default=None, metavar="N",
                   help="N catch trials (the perturbation off, unannounced) in each perturbed block")
    p.add_argument("--keys", default="dfjk",
                   help="keys for pectoralis, posterior deltoid, biceps, triceps (default: dfjk)")
    p.add_argument("--retention", type=_rate, nargs=2, metavar=("FAST", "SLOW"), default=None,
                   help="adaptive bot: the learner's retention rates A_f A_s (default: 0.59 0.992)")
    p.add_argument("--learning", type=_rate, nargs=2, metavar=("FAST", "SLOW"), default=None,
                   help="adaptive bot: the learner's learning rates B_f B_s (default: 0.21 0.02; 0 0 learns nothing)")
    p.add_argument("--representation", choices=("global", "local"), default=None,
                   help="adaptive bot: its internal model of the field, one estimate for every direction (global, "
                   "the default but on the generalization preset) or Gaussian tuning over movement direction (local, "
                   "the generalization preset's default: what it learns falls off with the angle from where it "
                   "learned it)")
    p.add_argument("--frame", choices=("hand", "joint"), default=None,
                   help="adaptive bot: the coordinates its internal model holds a force field in: at the hand (force "
                   "B^ v, the default) or at the joints (torque W^ qdot); they differ at a posture other than the one "
                   "it was learned at (the frames preset)")
    p.add_argument("--tuning-width", type=float, default=None, metavar="DEG",
                   help="with --representation local: the tuning's width, s.d. in degrees (5 to 180; default 30)")
    p.add_argument("--motor-noise", type=_noise_level, default=None, metavar="LEVEL",
                   help="a bot's signal-dependent motor noise: the s.d. of its command as a fraction of it (0 to 1), "
                   f"or 'human' ({HUMAN_NOISE:g}, the level chosen to vary as people do); drawn from --seed, carried "
                   "by the keys it presses (default: human for every preset but lesson, none for lesson and for a "
                   "protocol file; 0 turns it off)")
    from ..ui.options import add_window_options

    add_window_options(p, sound=False)
    p.add_argument("--fps", type=int, default=60, help="frame-rate cap of the window (default: 60)")
    p.add_argument("--speed", type=_speed, default=1.0, metavar="X",
                   help=f"a bot's run in the window starts at this speed ({_speeds()}; - and + change it as it "
                   "runs; default 1)")
    p.set_defaults(run=run, without_window=without_window)


def _noise_level(text: str) -> float:
    from ..lab.presets import HUMAN_NOISE

    if text == "human":
        return HUMAN_NOISE
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 <= value <= 1.0:  # also refuses NaN
        raise argparse.ArgumentTypeError(f"must be from 0 to 1, or human, got {text!r}")
    return value


def _resolve_motor_noise(args: argparse.Namespace) -> None:
    """``args.motor_noise`` as the run uses it: as given, else the preset's (``PRESET_MOTOR_NOISE``) for a bot,
    else none; ``args.motor_noise_given`` says which, for the run's output."""
    from ..lab.presets import PRESET_MOTOR_NOISE

    args.motor_noise_given = args.motor_noise is not None
    if args.motor_noise is None:
        args.motor_noise = PRESET_MOTOR_NOISE.get(args.protocol, 0.0) if args.bot else 0.0


def _noise_line(args: argparse.Namespace) -> str:
    """The motor noise a bot's run used and where its level came from, for the run's output."""
    from ..lab.presets import PRESETS
    from ..lab.record import motor_noise_words

    words = motor_noise_words(_motor_noise(args))
    preset = args.protocol if args.protocol in PRESETS else None
    if args.motor_noise_given:
        return f"{words}, as --motor-noise asked"
    if preset is None:
        return f"{words}, a protocol file's default (--motor-noise human adds a person's)"
    if args.motor_noise:
        return f"{words}, the {preset} preset's default (--motor-noise 0 turns it off)"
    return f"{words}, the {preset} preset's default (reproducible to the digit; --motor-noise human adds a person's)"


def _motor_noise(args: argparse.Namespace):
    """The bot's ``MotorNoise`` (its stream seeded by the run's seed), or None for none."""
    if not args.motor_noise:
        return None
    from ..game.bots import MotorNoise

    return MotorNoise(args.motor_noise, args.seed)


def _speeds() -> str:
    from ..ui.playback import REPLAY_SPEEDS

    return ", ".join(f"{s:g}" for s in REPLAY_SPEEDS)


def _speed(text: str) -> float:
    from ..ui.playback import REPLAY_SPEEDS

    try:
        value = float(text.rstrip("xX"))
    except ValueError:
        value = math.nan
    if value not in REPLAY_SPEEDS:
        raise argparse.ArgumentTypeError(f"must be one of {_speeds()}, got {text!r}")
    return value


def load_protocol_argument(text: str):
    from ..lab.presets import PRESETS, preset
    from ..lab.protocol_file import load_protocol

    if text in PRESETS:
        return preset(text)
    from ..records.storage import user_path

    path = user_path(text, "PROTOCOL")  # a path the file system cannot name is one line, not OSError
    if text.endswith(".toml") or path.exists():
        return load_protocol(path)
    raise UserError(unknown_name("lab protocol", text, PRESETS, "or give a .toml file"))


def run(args: argparse.Namespace) -> int:
    from ..game.muscles import DEFAULT_MUSCLES, remap_keys
    from ..lab.bots import LAB_BOT_NAMES, LearningRates
    from ..lab.protocol import with_catch_trials
    from ..lab.session import LabSession, lab_config

    protocol = load_protocol_argument(args.protocol)
    if args.catch is not None:
        if all(b.perturbation.kind == "none" for b in protocol.blocks):
            raise UserError(f"--catch: protocol {protocol.name!r} has no perturbed block to put catch trials in")
        try:
            protocol = with_catch_trials(protocol, args.catch)
        except ValueError as exc:
            raise UserError(f"--catch {args.catch}: {exc}") from None
    if args.headless and not args.bot:
        raise UserError("--headless needs a --bot to play (model, naive or adaptive); people play in the window")
    if args.bot and args.bot not in LAB_BOT_NAMES:
        raise UserError(unknown_name("lab bot", args.bot, LAB_BOT_NAMES))
    if args.motor_noise and not args.bot:
        raise UserError("--motor-noise sets a bot's motor noise: add --bot (a person brings their own)")
    _resolve_motor_noise(args)
    if (args.retention or args.learning or args.representation or args.frame) and args.bot != "adaptive":
        raise UserError("--retention, --learning, --representation and --frame set the adaptive bot's learner: add "
                        "--bot adaptive")
    from ..lab.presets import PRESET_REPRESENTATION

    if args.bot == "adaptive" and args.representation is None:  # the preset's own learner (generalization: local)
        args.representation = PRESET_REPRESENTATION.get(args.protocol, "global")
    if args.tuning_width is not None and args.representation != "local":
        raise UserError("--tuning-width sets the local learner's tuning: add --representation local")
    if args.no_figures and not args.out and args.headless:
        raise UserError("--no-figures applies with --out only (or to the run a window keeps)")
    if args.speed != 1.0 and not (args.bot and not args.headless):
        raise UserError("--speed sets a bot's run in the window (--bot, no --headless): a person plays at real "
                        "speed, and --headless runs as fast as it can")
    _check_outputs(args)
    from .classroom import join_class

    args.membership = join_class(args, lab=True)  # before the run: a wrong code is said now, not after ten minutes
    args.refused = False
    if args.membership is not None and args.membership.protocol is not None:
        protocol = args.membership.protocol  # a classroom experiment: the class says which protocol this student runs
    config = check_recordable(lab_config(protocol, args.seed, remap_keys(DEFAULT_MUSCLES, args.keys),
                                         person=not args.bot), str(args.protocol))
    session = LabSession(config, protocol)
    bot, rates = None, None
    if args.bot:
        defaults = LearningRates()
        rates = LearningRates(*(args.retention or (defaults.retention_fast, defaults.retention_slow)),
                              *(args.learning or (defaults.rate_fast, defaults.rate_slow)))
        bot = _bot(args, rates)
        args.learner_words = bot.describe()
        args.frame_words = bot.frame_words()
    if args.headless:
        from ..game.bots import Autopilot

        Autopilot(session, bot).play()  # type: ignore[arg-type]
        _report(session, args)
        _keep(session, args)
        if args.membership is not None:
            line = _hand_in(session, args)
            print(f"armgame lab: {line}" if args.refused else line, file=sys.stderr if args.refused else sys.stdout)
        return 1 if args.refused else 0
    if not 1 <= args.fps <= 1000:
        raise UserError(f"--fps must be from 1 to 1000, got {args.fps}")

    def new_run(number: int):
        """Run ``number`` of this window (r on the last screen starts the next): the same protocol, seed,
        player and bot, kept apart from the one before."""
        fresh = session if number == 1 else LabSession(config, protocol)
        player = bot if number == 1 else _bot(args, rates) if args.bot else None
        return fresh, player, RunKeeper(args, number)

    def end_run(done, keeper: RunKeeper) -> None:
        _report(done, args)
        played = done.steps > 0 and (args.bot is not None or bool(done.timeline))
        if not keeper.kept and played and (done.outcomes or args.record or args.out):
            keeper(done)  # quit before the end: what was done is kept all the same
        elif not keeper.kept and not played:  # Esc at the first card: no empty run to mistake for a volunteer's
            print("nothing was played: nothing kept")
        for line in keeper.lines:
            print(line)
        if keeper.error is not None:
            raise keeper.error

    _play_in_window(args, new_run, end_run)
    return 1 if args.refused else 0


def _bot(args: argparse.Namespace, rates):
    from ..lab.bots import make_lab_bot
    from ..lab.learner import TUNING_WIDTH_DEG

    if args.bot != "adaptive":
        return make_lab_bot(args.bot, noise=_motor_noise(args))
    width = TUNING_WIDTH_DEG if args.tuning_width is None else args.tuning_width
    return make_lab_bot(args.bot, rates, args.representation or "global", width, noise=_motor_noise(args),
                        frame=args.frame or "hand")


def default_runs_dir() -> Path:
    """Where a window run is kept unless --out or --record say otherwise: ``lab`` in the per-user data
    folder, beside the high-score table's (``~/.local/share/armgame/lab`` or ``$XDG_DATA_HOME/armgame/lab``
    on Linux, ``~/Library/Application Support/armgame/lab`` on macOS, ``%LOCALAPPDATA%\\armgame\\lab`` on
    Windows). The one place that chooses it."""
    from ..records.scores import user_data_dir

    return user_data_dir() / "lab"


def _new_run_folder(session) -> Path:
    """A folder of its own for this run in ``default_runs_dir``: the date, time and protocol name."""
    import re
    import time as _time

    name = re.sub(r"[^A-Za-z0-9_-]+", "-", session.protocol.name)[:40].strip("-") or "run"
    base = default_runs_dir() / f"{_time.strftime('%Y-%m-%d_%H%M%S')}_{name}"
    folder, n = base, 1
    while folder.exists():
        n += 1
        folder = base.with_name(f"{base.name}_{n}")
    return folder


class RunKeeper:
    """Keeps a window run (the replay, trials.csv and, with matplotlib, the figures), once; the window calls
    it at the end to name where on its last screen, the command after the window when quit early."""

    def __init__(self, args: argparse.Namespace, run: int = 1) -> None:
        self.args = args
        #: The window's run again (r) makes run 2, 3, ...: its --record and --out get that number, so no run
        #: overwrites the one before.
        self.run = run
        self.kept = False
        self.lines: list[str] = []
        self.error: UserError | None = None

    def __call__(self, session) -> list[str]:
        self.kept = True
        args = self.args
        try:
            folder = None
            if not (args.record and args.out):
                folder = _new_run_folder(session)
                try:
                    folder.mkdir(parents=True)
                except OSError as exc:
                    raise UserError(f"cannot create {folder}: {exc.strerror or exc}") from None
            # A second run (r) goes beside the first: --record numbers its replays itself, --out is numbered here.
            record = args.record or RecordTarget(folder / "replay.json", folder=False)
            out = _numbered(args.out, self.run) or folder
            figures = not args.no_figures
            if figures and not args.out:
                try:
                    import matplotlib  # noqa: F401
                except ImportError:
                    figures = False
            written = _save(session, args, record, out if session.outcomes or args.out else None, figures)
        except UserError as exc:
            self.error = exc
            self.lines = [f"not kept: {exc}"]
            return self.lines
        self.lines = [f"replay saved to {path}" if path.suffix == ".json" else f"wrote {path}" for path in written]
        if args.membership is not None:
            self.lines.append(_hand_in(session, args))
        shown = kept_lines(written)
        if folder is not None and not figures and not args.no_figures:
            shown.append("   (figures need matplotlib: pip install 'armgame[plot]')")
        if args.membership is not None:
            shown.append(self.lines[-1][:1].upper() + self.lines[-1][1:])
        return shown


#: What a run writes in --out (adaptation.png only with channel trials): refused before the run if there.
OUT_FILES = ("trials.csv", "learning.png", "paths.png", "adaptation.png", "frames.png", "generalization.png")


def _numbered(path: Path | None, run: int) -> Path | None:
    """``path`` for the window's run number ``run``: itself for the first, ``DIR-2`` (the first such name not
    yet taken, as --record numbers a window's replays) for the next."""
    if path is None or run == 1:
        return path
    n = run
    while True:
        numbered = path.with_name(f"{path.name}-{n}")
        if not numbered.exists():
            return numbered
        n += 1


def kept_lines(written: list[Path]) -> list[str]:
    """Where a run was kept, as its last screen says it: each folder once (absolute, home as ~), then the
    files kept in it on one line, so a replay --record put elsewhere is never listed in the run's folder."""
    folders: dict[Path, list[str]] = {}
    for path in written:
        path = Path(os.path.abspath(path))
        folders.setdefault(path.parent, []).append(path.name)
    lines: list[str] = []
    for folder, names in folders.items():
        lines += [f"Kept in {_home(folder)}:", "   " + "   ".join(names)]
    return lines


def _check_outputs(args: argparse.Namespace) -> None:
    """Refuse a bad --record, --name or missing matplotlib before the run, not after it."""
    if args.name is not None:
        from ..valid import check_name

        try:
            args.name = check_name(args.name, "--name")
        except ValueError as exc:
            raise UserError(str(exc)) from None
    from ..records.storage import user_path
    from .outputs import refuse_existing

    if args.record:
        record = user_path(args.record, "--record")
        if not record.resolve().parent.is_dir():
            raise UserError(f"--record {args.record}: its folder does not exist")
        # A device, FIFO, or a file there already (without --force): refused before the run.
        args.record = RecordTarget.parse(args.record, args.force, "lab")
    if args.out and not args.no_figures:
        from ..lab.figures import require_matplotlib

        require_matplotlib()
    if args.out:
        args.out = user_path(args.out, "--out")
        if args.out.exists() and not args.out.is_dir():
            raise UserError(f"--out {args.out}: not a folder")
        refuse_existing([args.out / name for name in OUT_FILES], args.force)


def _report(session, args: argparse.Namespace) -> None:
    from ..lab.analysis import block_summary, channel_summary, trial_rows

    done, total = len(session.outcomes), len(session.plans)
    print(f"lab {session.protocol.name}: {done} of {total} trials, {session.result().hits} hits, seed "
          f"{session.config.seed}{session.ending}")
    if getattr(args, "learner_words", ""):
        print(f"  the adaptive bot's {args.learner_words}")
    if getattr(args, "frame_words", ""):
        print(f"  its {args.frame_words}")
    if getattr(args, "bot", None):
        print(f"  {_noise_line(args)}")
    if session.outcomes:
        rows = trial_rows(session)
        cycle = session.protocol.targets  # a cycle of targets: each direction's own offset averages out
        for b in block_summary(rows, first=cycle):
            where = (f"mean {_cm(b['early'])}" if b["trials"] <= cycle else
                     f"first {cycle} {_cm(b['early'])}, last {cycle} {_cm(b['late'])}")
            print(f"  {b['block']}: {b['trials']} trials, {b['hits']} hits; max perpendicular error {where}")
        for b in channel_summary(rows):
            print(f"  {b['block']}: {b['channels']} channel trials; adaptation index {b['first']:+.2f} on the first, "
                  f"mean of {b['cycle']}: first {b['early']:+.2f}, last {b['late']:+.2f}, largest {b['largest']:+.2f} "
                  f"(from channel trial {b['at']})")
        from ..lab.analysis import generalization

        table = generalization(session, rows)
        for name in dict.fromkeys(str(g["block"]) for g in table):
            mine = [g for g in table if g["block"] == name]
            subtracted = all(math.isfinite(float(g["index_less_baseline"])) for g in mine)  # type: ignore[arg-type]
            key, how = ("index_less_baseline", "less each direction's baseline") if subtracted else ("index", "raw")
            print(f"  {name}: adaptation index by angle from the trained {mine[0]['trained_deg']:g} deg ({how}): "
                  + ", ".join(f"{g['angle_deg']:+g} {g[key]:+.2f}" for g in mine))
        _report_designs(session, rows)


def _report_designs(session, rows) -> None:
    """Issue 41's designs in the run's output: the frames test and generalization probed without vision."""
    from ..lab.designs import frames_summary, probe_generalization

    for f in frames_summary(session, rows):
        how = "less each direction's baseline there" if f["less_baseline"] else "raw"
        print(f"  {f['block']} (posture {f['posture_deg'][0]:g}, {f['posture_deg'][1]:g} deg): mean adaptation index "
              f"of its first {f['trials']} channel trials ({how}): the field held at the hand {f['hand']:+.2f}, held "
              f"at the joints {f['joint']:+.2f}: it reads as learned in {f['reads_as']} coordinates")
    table = probe_generalization(session, rows)
    for name in dict.fromkeys(str(g["block"]) for g in table):
        mine = [g for g in table if g["block"] == name]
        print(f"  {name}: generalization of the rotation by angle from the trained {mine[0]['trained_deg']:g} deg "
              f"(probes with feedback {mine[0]['feedback']}, fraction of the rotation, less each direction's "
              "baseline): " + ", ".join(f"{g['angle_deg']:+g} {g['generalization']:+.2f}" for g in mine))


def _home(path: Path) -> str:
    """A path as a student would type it: the home folder as ~."""
    try:
        return "~/" + str(path.relative_to(Path.home()))
    except ValueError:
        return str(path)


def _keep(session, args: argparse.Namespace) -> None:
    """A headless run keeps what --record and --out ask for, and says where."""
    for path in _save(session, args, args.record, args.out, not args.no_figures):
        print(f"replay saved to {path}" if path.suffix == ".json" else f"wrote {path}")


def _save(session, args: argparse.Namespace, record: RecordTarget | None, out: Path | None,
          figures: bool) -> list[Path]:
    """The replay to ``record`` and trials.csv (and the figures) to ``out``, each when given; what was written."""
    from ..lab.analysis import write_run_outputs

    written: list[Path] = []
    if record:
        written.append(record.save(_replay(session, args)))
    if out:
        if not session.outcomes:
            raise UserError("no trial was finished: nothing to write to --out")
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise UserError(f"cannot create the output folder {out}: {exc.strerror or exc}") from None
        with fresh_outputs([], args.force, folder=out):  # a file that appeared during the run stays
            written += write_run_outputs(session, out, figures=figures)
    return written


def _hand_in(session, args: argparse.Namespace) -> str:
    """Hand a finished run in to the class; the line saying what became of it. A refusal sets ``args.refused``:
    the command then exits 1, as ``armgame play --join`` and ``class submit`` do (a run kept to hand in later
    is not refused)."""
    from ..classroom.client import hand_in

    if not session.finished:
        how = "ran out of time" if session.out_of_time else "stopped"
        return f"the run {how} before its last trial: not handed in to the class"
    result = hand_in(args.membership, _replay(session, args).to_bytes())
    args.refused = args.refused or result.refused
    return result.message


def _replay(session, args: argparse.Namespace):
    from ..lab.record import LabTask
    from ..records.replay import Replay, now_iso

    driven = "bot" if args.bot else "keyboard"
    return Replay(session.config, tuple(session.timeline), session.result(), driven, args.bot, args.name, now_iso(),
                  task=LabTask.of(session, _motor_noise(args)))


def _cm(value: object) -> str:
    v = float(value)  # type: ignore[arg-type]
    return "n/a" if not math.isfinite(v) else f"{100.0 * v:+.2f} cm"


def _play_in_window(args: argparse.Namespace, new_run, end_run) -> None:
    """Runs in one window until its last screen is closed with Esc: ``new_run(n)`` gives run n's session, bot
    and keeper; ``end_run`` reports and keeps each, between runs, the window staying open (a projector's
    full screen is not lost to r)."""
    from ..errors import NoDisplayError

    try:
        import pygame

        from ..ui.frontend import open_window
        from ..ui.lab_window import LabWindow
    except ImportError as exc:
        raise UserError(f"the window needs pygame-ce: {exc}") from None
    try:
        from ..ui.options import window_settings

        settings, _ = window_settings(args)
        screen = open_window(settings.size, args.fullscreen, "armgame lab - reach from home to each target")
    except pygame.error as exc:
        raise NoDisplayError(f"cannot open a window ({exc})") from None
    try:
        number = 1
        while True:
            session, bot, keeper = new_run(number)
            driver = None
            if bot is not None:
                from ..game.bots import Autopilot
                from ..game.session import RealTimeDriver

                driver = RealTimeDriver(Autopilot(session, bot))  # type: ignore[arg-type]
            window = LabWindow(session, screen, fps=args.fps, driver=driver,
                               mode="LAB" if bot is None else f"AUTOPILOT: {args.bot}", on_finish=keeper,
                               palette=settings.palette, text_scale=settings.text_scale,
                               bot=None if bot is None else args.bot)
            window.speed = args.speed
            window.run()
            end_run(window.session, keeper)
            if not window.play_again:
                return
            screen = pygame.display.get_surface() or window.screen
            number += 1
    finally:
        pygame.display.quit()


def without_window(args: argparse.Namespace, typed: list[str]) -> str:
    """The run headless: a bot plays it (the adapting one, unless the user chose one)."""
    from . import command_line

    return command_line(typed, "--headless", *([] if args.bot else ["--bot", "adaptive"]))
