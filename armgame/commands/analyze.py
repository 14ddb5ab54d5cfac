"""armgame analyze: per-reach measures of lab replays, verified first; a class's mean learning curve."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import UserError
from ..records.storage import user_path
from ..words import plural
from . import read_lab_replays

#: A class folder is read up to this many replays: the work is bounded before it starts.
MAX_CLASS_FILES = 500


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "analyze",
        help="per-reach measures of lab replays (verified first), or a class's mean learning curve",
        description="Re-simulate each lab replay from its input timeline, check that it reproduces its recorded "
        "trials, and measure every reach: one row per reach (block, trial, target_deg, perturbation, "
        "reaction_time_s, movement_time_s, peak_speed_m_per_s, initial_direction_error_deg, max_perpendicular_error_m, "
        "path_length_ratio, hit, and on error-clamp trials channel_force_peak_n, channel_force_at_peak_speed_n, "
        "adaptation_index; hand_sent_home is 1 on a reach that space ended, measured only up to then). --fit "
        "two-rate (or one-rate) fits a learner's rates to each run by maximum likelihood, "
        "with profile-likelihood intervals, AIC and BIC; --fit both fits the two and says which the data support. A "
        "replay that does not verify is reported and left out. With --class DIR: "
        "every lab replay in DIR (one per student, the same protocol) into one class curve, the mean and s.e.m. "
        "per trial of --metric: class_curve.csv and, where matplotlib is installed, class_curve.png in --out. The "
        "class's protocol is the one most replays share (or the one --protocol names); each game counts once, "
        "however many copies of it there are; what is left out is named, with why. A live class's folder (with its "
        "class.json), or its lab/, gives the class's own curve, the one its /lab page drew: the teacher's protocol, "
        "each person's first run of it, programs' runs and hidden names apart. Exit status: 0 if every replay "
        "was analysed, 1 if some were left out, 2 on bad arguments or when nothing could be analysed.",
    )
    p.add_argument("replays", nargs="*", metavar="REPLAY", help="lab replays (armgame lab --record FILE)")
    p.add_argument("--out", metavar="PATH",
                   help="a .csv file (all reaches in one table, each row led by its player and replay), or a folder "
                   "(one REPLAY.trials.csv each); "
                   "with --class, the folder for class_curve.csv and class_curve.png; with --fit it may be left out: "
                   "the fit is printed and nothing written")
    p.add_argument("--class", dest="class_dir", metavar="DIR", help="a folder of students' lab replays")
    p.add_argument("--metric", default=None,
                   help="the class curve's measure (default: max_perpendicular_error_m for force fields, "
                   "initial_direction_error_deg for visual transforms)")
    p.add_argument("--no-figures", action="store_true",
                   help="with --class or --fit: no figures (--class draws its figure only where matplotlib is "
                   "installed, and says so otherwise)")
    p.add_argument("--fit", choices=("two-rate", "one-rate", "both", "trial-by-trial", "state-space"),
                   help="fit a learner to each replay's per-trial errors by maximum likelihood (Gaussian noise): "
                   "two-rate (A_f, A_s, B_f, B_s), one-rate (A, B), or both, compared by AIC, BIC and the likelihood "
                   "ratio; the values with 95%% profile-likelihood intervals, the residual, the log-likelihood, and "
                   "NAME.fit.json and NAME.fit.png (the fit over the data) next to --out, if given; trial-by-trial: "
                   "the generalization function over direction from trial-to-trial changes (Donchin et al. 2003); "
                   "state-space: one state with process and output noise, by EM (Cheng & Sabes 2006)")
    p.add_argument("--fit-on", choices=("error", "index"), default="error",
                   help="with --fit: the errors of the reaches that are not channel trials (default; the measure "
                   "the learning figure plots), or the adaptation index of the channel trials")
    p.add_argument("--subtract-baseline", action="store_true",
                   help="each channel trial's adaptation_index less its direction's baseline: the mean index of the "
                   "channel trials to that direction before the run's first perturbed block (for a direction with "
                   "none, the nearest probed direction's, the mean of two as near); in the tables and with --fit-on "
                   "index")
    p.add_argument("--channel-traces", action="store_true",
                   help="also write each run's channel trials' force over time, one row per physics step: "
                   "REPLAY.channel_traces.csv beside the tables (trial, block, target_deg, time_s, channel_force_n, "
                   "cancelling_force_n, hand_speed_m_per_s)")
    p.add_argument("--students", metavar="FILE.csv", default=None,
                   help="with --class: also write the class's students, one row each (name, early and late exposure "
                   "error, late - early, late baseline, after-effect, in cm or deg as the column says, and the "
                   "two-rate learner's rates where a fit converges): the table the live class's teacher's page "
                   "downloads")
    p.add_argument("--protocol", metavar="NAME", default=None,
                   help="with --class: the protocol (its name) whose replays make the curve (default: the one most "
                   "replays share)")
    from .outputs import add_force_option

    add_force_option(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    with _fresh_outputs(args):  # what --out would replace is refused before anything is replayed
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    read_lab_replays()
    if args.class_dir is not None:
        if args.replays:
            raise UserError("give replays or --class DIR, not both")
        if args.subtract_baseline or args.channel_traces:
            raise UserError("--subtract-baseline and --channel-traces apply to replays, not --class")
        if args.out is None:
            raise UserError("--class needs --out DIR: the folder for class_curve.csv and class_curve.png")
        if args.students is not None and not args.students.lower().endswith(".csv"):
            raise UserError(f"--students {args.students}: give a .csv file for the students' table")
        return _class(args)
    if args.students is not None:
        raise UserError("--students applies with --class only")
    if not args.replays:
        raise UserError("no replay given: armgame analyze REPLAY... --out trials.csv (or --class DIR)")
    if args.out is None and not args.fit:  # a fit alone is printed; the table has nowhere else to go
        raise UserError("--out is needed: a .csv file or a folder for the reaches' table (only --fit prints "
                        "without it)")
    if args.metric:
        raise UserError("--metric applies with --class only")
    if args.no_figures and not args.fit:
        raise UserError("--no-figures applies with --class or --fit only")
    if args.fit_on != "error" and not args.fit:
        raise UserError("--fit-on applies with --fit only")
    if args.channel_traces and args.out is None:
        raise UserError("--channel-traces needs --out: the traces are written beside the tables")
    if args.fit and not args.no_figures and args.out is not None:  # without --out no figure is drawn
        from ..lab.figures import require_matplotlib

        try:
            require_matplotlib()
        except UserError:
            raise UserError("the fit's figure needs matplotlib: pip install 'armgame[plot]', or add --no-figures "
                            "to print the fit only") from None
    return _replays(args)


def lab_replay(path: Path):
    """The lab run in ``path`` (read and checked, not yet replayed); raises UserError otherwise."""
    from ..records.replay import Replay

    if path.is_symlink() or not path.is_file():
        raise UserError(f"{path}: not a regular file")
    replay = Replay.load(path)
    if replay.task is None:
        raise UserError(f"{path}: a game, not a lab run: nothing to analyse")
    return replay


def verified_run(path: Path, replay):
    """(rows, session) of ``replay`` (read from ``path``) if it reproduces its trials; else UserError."""
    from ..lab.analysis import trial_rows
    from ..records.replay import same_outcome

    ok, recomputed, session = replay.task.verify(replay.config, replay.timeline, replay.result)
    if not ok:
        same = same_outcome(recomputed, replay.result)
        why = "its trials differ" if same else f"its result differs ({recomputed.hits} hits, not {replay.result.hits})"
        raise UserError(f"{path}: DIFFERS: the replay does not reproduce its recording ({why}): not analysed")
    return trial_rows(session), session


def class_members(runs: list, wanted: str | None) -> tuple[list, object, list[tuple[Path, str]]]:
    """The class: ``(path, rows)`` of each run of the class's protocol, once per game; the protocol; and
    ``(path, why)`` of each run left out.

    The protocol is the one most runs share (ties: the one whose first file sorts first), or the one
    named ``wanted``: one planted file sorting first cannot set it. ``runs`` are ``(path, rows, session,
    digest)``, each game once: ``_class`` leaves copies out (``records.identity.FirstEntries``), so five
    copies of one replay are one student.
    """
    groups: list[tuple[object, list]] = []  # (protocol, its runs), protocols compared whole
    for run in runs:
        group = next((g for g in groups if g[0] == run[2].protocol), None)
        if group is None:
            groups.append((run[2].protocol, [run]))
        else:
            group[1].append(run)
    if wanted is not None:
        named = [g for g in groups if g[0].name == wanted]
        if not named:
            found = ", ".join(sorted({repr(g[0].name) for g in groups})) or "none"
            raise UserError(f"--protocol {wanted!r}: no verified replay in the class has it (found: {found})")
        groups_to_pick = named
    else:
        groups_to_pick = groups
    if not groups_to_pick:
        return [], None, []
    protocol, chosen = max(groups_to_pick, key=lambda g: len({r[3] for r in g[1]}))  # max keeps the first of ties
    shared = f"{protocol.name!r}, shared by {len(chosen)} replays"
    left_out: list[tuple[Path, str]] = []
    for other, members in groups:
        if other is protocol:
            continue
        why = (f"its protocol is also named {other.name!r} but differs from the class's ({shared})"
               if other.name == protocol.name else f"its protocol {other.name!r} differs from the class's ({shared})")
        left_out += [(r[0], why) for r in members]
    students = [(path, rows) for path, rows, _, _ in chosen]
    return students, protocol, sorted(left_out, key=lambda item: str(item[0]))


def _replays(args: argparse.Namespace) -> int:
    from ..lab.metrics import LABEL_COLUMNS, write_trials_csv

    # No --out (a fit only): the fit is printed, nothing written.
    out = None if args.out is None else user_path(args.out, "--out")
    one_table = out is not None and out.suffix.lower() == ".csv"
    if one_table and not out.resolve().parent.is_dir():
        raise UserError(f"--out {args.out}: its folder does not exist")
    if out is not None and not one_table and out.exists() and not out.is_dir():
        raise UserError(f"--out {args.out}: not a folder (give a .csv file for one table)")
    table: list[dict[str, object]] = []
    skipped = 0
    written = []
    for name in args.replays:
        path = Path(name)
        try:
            path = user_path(name, "REPLAY")
            replay = lab_replay(path)
            rows, session = verified_run(path, replay)
        except UserError as exc:
            print(f"armgame analyze: {exc}", file=sys.stderr)
            skipped += 1
            continue
        print(f"{path}: verified: {session.protocol.name}, seed {session.config.seed}, {len(rows)} reaches")
        if replay.driven == "bot":  # a person brings their own noise; a bot's is what its replay recorded
            from ..lab.record import motor_noise_words

            print(f"  {replay.driver} bot, {motor_noise_words(replay.task.motor_noise)}")
        if args.subtract_baseline:
            from ..lab.analysis import baseline_offsets, subtract_baseline

            offsets = baseline_offsets(session, rows)
            try:
                rows = subtract_baseline(session, rows)
            except ValueError as exc:
                print(f"armgame analyze: {path}: --subtract-baseline: {exc}", file=sys.stderr)
                skipped += 1
                continue
            print("  adaptation index less each direction's baseline, which was: "
                  + ", ".join(f"{deg:g} deg {value:+.2f}" for deg, value in offsets.items()))
            from ..lab.analysis import baseline_for

            borrowed = sorted({float(r["target_deg"]) for r in rows if r["perturbation"] == "channel"}  # type: ignore[arg-type]
                              - set(offsets))
            if borrowed:  # directions the baseline never probed: the nearest probed direction's stands in
                print("  no baseline channel trial to " + "; ".join(
                    f"{deg:g} deg: the nearest probed ({' and '.join(f'{d:g}' for d in baseline_for(offsets, deg)[1])}"
                    " deg) stands in" for deg in borrowed))
        if args.channel_traces:
            from ..lab.analysis import write_channel_traces

            traces = (out.parent if one_table else out) / f"{path.stem}.channel_traces.csv"
            traces.parent.mkdir(parents=True, exist_ok=True)
            write_channel_traces(traces, session)
            written.append(traces)
        if args.fit:
            beside = None if out is None else (out.parent if one_table else out)  # the fit's files: by the table
            try:
                written += _fit(session, rows, args.fit_on, beside, path, replay.player, not args.no_figures, args.fit)
            except UserError as exc:
                print(f"armgame analyze: {path}: {exc}", file=sys.stderr)
                skipped += 1
                continue
        if one_table:  # whose each row is: several runs' trials restart at 1
            who = {"player": replay.player or "", "replay": str(path)}  # the file verified, not read again
            table += [{**who, **row} for row in rows]
        elif out is not None:
            out.mkdir(parents=True, exist_ok=True)
            target = out / f"{path.stem}.trials.csv"
            write_trials_csv(target, rows)
            written.append(target)
    if skipped == len(args.replays):
        raise UserError("no replay could be analysed")
    if one_table:
        write_trials_csv(out, table, labels=LABEL_COLUMNS)
        written.append(out)
    for path in written:
        print(f"wrote {path}")
    return 1 if skipped else 0


def _fit(session, rows, on: str, beside: Path | None, path: Path, player: str | None, figures: bool,
         model: str = "two-rate") -> list[Path]:
    """Fit ``model`` (``both``: the one-rate and two-rate models, compared) to one verified run and print it;
    with ``beside`` (a folder), keep the fit there as ``NAME.fit.json`` (and draw ``NAME.fit.png``)."""
    from ..lab.analysis import figure_metric, fit_schedule
    from ..lab.fit import compare, fit_learner

    metric = figure_metric(session.protocol) if on == "error" else "adaptation_index"
    if model in ("trial-by-trial", "state-space"):
        return _design_fit(session, rows, on, beside, path, player, figures, model, metric)
    comparison = None
    try:
        disturbance, clamped = fit_schedule(session)
        observed = [float(r[metric]) for r in rows]
        if model == "both":
            comparison = compare(disturbance, clamped, observed, on)
            fits = [comparison.simple, comparison.full]
        else:
            fits = [fit_learner(model, disturbance, clamped, observed, on)]
    except ValueError as exc:
        raise UserError(f"cannot fit the {'learners' if model == 'both' else model + ' model'} to its {metric}: "
                        f"{exc}") from None
    unit = metric.rsplit("_", 1)[1] if metric != "adaptation_index" else ""
    shown, scale = ("cm", 100.0) if unit == "m" else (unit, 1.0)  # a student reads cm; the file keeps metres
    for fit in fits:
        print(f"  {fit.model} fit to {metric} ({fit.n} trials), 95% intervals by profile likelihood:")
        for line in fit.lines(shown, scale):
            print(line)
    if comparison is not None:
        for line in comparison.lines():
            print(line)
    fit = fits[-1]  # the file's and the figure's: the two-rate model when both were fitted
    if beside is None:
        return []
    extra = {} if comparison is None else {"compared_with": comparison.simple.as_dict(unit),
                                           "comparison": comparison.as_dict()}
    written = [_keep_fit(beside, path, {"replay": str(path), "player": player or "",
                                        "protocol": session.protocol.name, "seed": session.config.seed,
                                        "measure": metric, **fit.as_dict(unit), **extra})]
    if figures:
        from ..lab.figures import fit_figure

        figure = beside / f"{path.stem}.fit.png"
        fit_figure(rows, fit, figure, metric, None if comparison is None else comparison.simple)
        written.append(figure)
    return written


def class_of(folder: Path):
    """(the class's folder, its lab runs' folder) when ``folder`` is a live class's folder (``class.json`` in it)
    or its ``lab/``; else (None, ``folder``)."""
    from ..classroom.labruns import LAB_DIR
    from ..classroom.roster import ROSTER_NAME

    if (folder / ROSTER_NAME).is_file():
        return folder, folder / LAB_DIR
    if folder.name == LAB_DIR and (folder.parent / ROSTER_NAME).is_file():
        return folder.parent, folder
    return None, folder


def _keep_fit(beside: Path, path: Path, record: dict[str, object]) -> Path:
    """A fit's record kept beside its replay as ``NAME.fit.json`` (the folder made if need be); UserError in one
    line if it cannot be."""
    import json

    from ..lab.metrics import check_regular_target
    from ..records.storage import atomic_write_bytes

    try:
        beside.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create the output folder {beside}: {exc.strerror or exc}") from None
    kept = beside / f"{path.stem}.fit.json"
    check_regular_target(kept)
    try:
        atomic_write_bytes(kept, (json.dumps(record, indent=2, allow_nan=False) + "\n").encode())
    except (OSError, ValueError) as exc:
        raise UserError(f"cannot write {kept}: {exc}") from None
    return kept


def _design_fit(session, rows, on: str, beside: Path | None, path: Path, player: str | None, figures: bool,
                model: str, metric: str) -> list[Path]:
    """Issue 41's fits (``armgame.lab.trialfit``) of one verified run, printed and, with ``beside``, kept as
    ``NAME.fit.json`` (and ``NAME.fit.png``: the generalization function, or the fit over the data)."""
    from ..lab.analysis import fit_schedule
    from ..lab.trialfit import fit_generalization, fit_state_space

    if model == "trial-by-trial" and on != "error":
        raise UserError("--fit trial-by-trial fits the reaches' errors (--fit-on error)")
    try:
        disturbance, clamped = fit_schedule(session)
        observed = [float(r[metric]) for r in rows]
        if model == "trial-by-trial":
            fit = fit_generalization([o.plan.target for o in session.outcomes], session.protocol.targets,
                                     disturbance, observed, clamped)
        else:
            fit = fit_state_space(disturbance, clamped, observed, on)
    except ValueError as exc:
        raise UserError(f"cannot fit the {model} model to its {metric}: {exc}") from None
    unit = metric.rsplit("_", 1)[1] if metric != "adaptation_index" else ""
    shown, scale = ("cm", 100.0) if unit == "m" else (unit, 1.0)
    how = "profile likelihood" if model == "trial-by-trial" else "Wald, observed information"
    print(f"  {model} fit to {metric} ({fit.n} trials), 95% intervals by {how}:")
    for line in fit.lines(shown, scale):
        print(line)
    if beside is None:
        return []
    written = [_keep_fit(beside, path, {"replay": str(path), "player": player or "",
                                        "protocol": session.protocol.name, "seed": session.config.seed,
                                        "measure": metric, **fit.as_dict(unit)})]
    if figures:
        from ..lab.figures_designs import generalization_fit_figure, state_space_figure

        figure = beside / f"{path.stem}.fit.png"
        if model == "trial-by-trial":
            generalization_fit_figure(fit, figure, shown, scale)
        else:
            state_space_figure(rows, fit, figure, metric)
        written.append(figure)
    return written


def _class(args: argparse.Namespace) -> int:
    from ..lab.analysis import ClassRun, class_curve_of, curve_protocol
    from ..lab.metrics import write_class_csv

    folder = user_path(args.class_dir, "--class")
    if not folder.is_dir():
        raise UserError(f"--class {args.class_dir}: not a folder")
    out = user_path(args.out, "--out")
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {args.out}: not a folder")
    figures = not args.no_figures
    if figures:  # the curve's CSV needs no matplotlib: the figure is drawn only where it is installed
        from ..lab.figures import require_matplotlib

        try:
            require_matplotlib()
        except UserError:
            figures = False
    classroom, folder = class_of(folder)
    roster = None
    if classroom is not None:  # a live class's folder: its own rules, as its /lab page drew the curve
        from ..classroom.roster import Roster
        from ..records.storage import DataFileError

        try:
            roster = Roster.open(classroom, None)[0]
        except DataFileError as exc:
            raise UserError(str(exc)) from None
        if not folder.is_dir():
            raise UserError(f"{classroom}: a class with no lab runs ({folder.name}/ is missing)")
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() == ".json")
    if not files:
        raise UserError(f"{folder}: no replays (*.json) there")
    if len(files) > MAX_CLASS_FILES:
        raise UserError(f"{folder}: {len(files)} replays, more than a class curve reads ({MAX_CLASS_FILES})")
    from ..records.identity import FirstEntries, game_digest

    runs, skipped, copies, replays = [], 0, [], []
    first: FirstEntries[Path] = FirstEntries()  # in file order: the first verified run of a game counts
    for path in files:
        try:
            replay = lab_replay(path)
            digest = game_digest(replay)
            twin = first.counted(digest)
            if twin is not None:  # a copy of a game already verified: counted once, never replayed again
                copies.append((path, f"the same game as {twin.name} (a copy counts once)"))
                continue
            rows, session = verified_run(path, replay)
        except UserError as exc:
            print(f"armgame analyze: {exc}", file=sys.stderr)
            skipped += 1
            continue
        first.copy_of(path, None, digest, ok=True)  # verified: it counts from now on
        runs.append((path, rows, session, digest))
        replays.append(replay)
    left_out: list[tuple[Path, str]] = []
    if roster is not None:
        # Hidden names are never in the class's curve; a program's run is counted apart (class_curve_of).
        keep = [i for i, r in enumerate(replays) if not (r.player and roster.is_hidden(r.player))
                or r.driven != "keyboard"]
        left_out += [(runs[i][0], "a name the teacher hid") for i in range(len(runs)) if i not in keep]
        runs, replays = [runs[i] for i in keep], [replays[i] for i in keep]
    people = [run for run, r in zip(runs, replays, strict=True) if roster is None or r.driven == "keyboard"]
    if args.protocol is None and roster is not None and roster.lab:
        protocol = curve_protocol(roster.lab)  # the teacher's choice, as the class's /lab page showed it
        print(f"the class's protocol: {protocol.name} (the teacher's choice, {classroom / 'class.json'})")
    else:
        protocol = class_members(people, args.protocol)[1]
    curve = class_curve_of([ClassRun(r.player, r.driven != "keyboard", run[2].protocol, run[1])
                            for run, r in zip(runs, replays, strict=True)], protocol, args.metric,
                           people_only=roster is not None)
    shared = None if protocol is None else \
        f"{protocol.name!r}, shared by {sum(run[2].protocol == protocol for run in runs)} replays"
    second = None
    if roster is not None and roster.experiment is not None:
        second = curve_protocol(roster.experiment.b)  # the experiment's group B: its own curve, never left out
    for i, why in curve.left_out:
        other = runs[i][2].protocol
        if second is not None and other == second and why.startswith("another protocol"):
            continue
        if why.startswith("another protocol") and protocol is not None:
            why = (f"its protocol is also named {other.name!r} but differs from the class's ({shared})"
                   if other.name == protocol.name
                   else f"its protocol {other.name!r} differs from the class's ({shared})")
        left_out.append((runs[i][0], why))
    left_out = sorted(left_out + copies, key=lambda item: str(item[0]))
    for path, reason in left_out:
        print(f"armgame analyze: {path}: {reason}: not in the curve", file=sys.stderr)
    skipped += len(left_out)
    for i in curve.members:
        print(f"{runs[i][0].name}: verified: {len(runs[i][1])} reaches")
    if not curve.students:
        if protocol is not None and roster is not None and roster.lab:
            raise UserError(f"{folder}: no person's verified run of the class's protocol {protocol.name!r}")
        raise UserError(f"{folder}: no replay could be analysed")
    metric = curve.metric
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create the output folder {out}: {exc.strerror or exc}") from None
    csv_path = out / "class_curve.csv"
    write_class_csv(csv_path, curve.trials, metric)  # type: ignore[arg-type]
    written = [csv_path]
    if figures:
        from ..lab.figures import class_figure

        class_figure(curve.trials, out / "class_curve.png", metric=metric)  # type: ignore[arg-type]
        written.append(out / "class_curve.png")
    from ..lab.analysis import display_unit
    from ..lab.classstats import answer_line, class_stats

    members = [(replays[i].player or runs[i][0].stem, runs[i][1]) for i in curve.members]
    scale, unit = display_unit(metric)  # type: ignore[arg-type]
    if args.students is not None:
        from ..classroom.views import students_csv
        from ..lab.metrics import _write_text

        table = user_path(args.students, "--students")
        _write_text(table, students_csv(curve.protocol, metric, members))
        written.append(table)
    print(f"class curve of {plural(curve.students, 'student')} ({skipped} left out), "
          f"{plural(len(curve.trials), 'trial')}, {metric}")
    print(f"  the class's answer: {answer_line(class_stats(curve.protocol, members, metric), scale, unit)}")
    if roster is not None and roster.experiment is not None:  # the projector's two groups, from the same runs
        from ..lab.analysis import curve_protocol
        from ..lab.classstats import difference_words, two_groups

        experiment = roster.experiment
        groups = two_groups([ClassRun(r.player, r.driven != "keyboard", run[2].protocol, run[1])
                             for run, r in zip(runs, replays, strict=True)],
                            (curve_protocol(experiment.a), curve_protocol(experiment.b)),
                            lambda name: experiment.condition_of(name, roster.renamed))
        g_scale, g_unit = display_unit(groups.metric)
        for c, g_curve, g_stats in zip("AB", groups.curves, groups.stats, strict=True):
            said = "no run" if g_stats is None else answer_line(g_stats, g_scale, g_unit)
            print(f"  group {c} ({g_curve.protocol.name}, {plural(g_curve.students, 'student')}): {said}")
        print(f"  the experiment's answer: {difference_words(groups, g_scale, g_unit)}")
    if curve.programs:
        print(f"  {plural(curve.programs, 'run')} of programs kept apart (never in a class's curve, as on its /lab "
              "page)")
    for path in written:
        print(f"wrote {path}")
    if not figures and not args.no_figures:
        print("class_curve.png not drawn: the figure needs matplotlib (pip install 'armgame[plot]'); the CSV is "
              "complete")
    return 1 if skipped else 0


def _fresh_outputs(args: argparse.Namespace):
    """``outputs.fresh_outputs`` for every file --out would get: the class curve's, one table, or each
    replay's table and fit (two replays of one name would write one file: refused)."""
    from .outputs import fresh_outputs

    if args.out is None:
        return fresh_outputs([], args.force)
    out = user_path(args.out, "--out")
    figures = not args.no_figures
    if args.class_dir is not None:
        students = [] if args.students is None else [user_path(args.students, "--students")]
        return fresh_outputs([out / "class_curve.csv", *([out / "class_curve.png"] if figures else []), *students],
                             args.force, folder=out)
    one_table = out.suffix.lower() == ".csv"
    folder = out.parent if one_table else out
    files = [out] if one_table else []
    stems: dict[str, str] = {}
    for name in args.replays:
        stem = Path(name).stem
        if stem in stems and (args.fit or args.channel_traces or not one_table):
            raise UserError(f"{stems[stem]} and {name} would both write {stem}.* in {folder}: give --out a .csv "
                            "file for one table, or rename one")
        stems[stem] = name
        files += [] if one_table else [out / f"{stem}.trials.csv"]
        files += [folder / f"{stem}.fit.json"] if args.fit else []
        files += [folder / f"{stem}.channel_traces.csv"] if args.channel_traces else []
        files += [folder / f"{stem}.fit.png"] if args.fit and figures else []
    return fresh_outputs(files, args.force, folder=folder)
