"""armgame play: the game, in a window or headless from a script."""

from __future__ import annotations

import argparse
import math

from ..errors import UserError
from ..limits import DEFAULT_SEED
from ..words import plural
from . import read_lab_replays
from . import seed_argument as _seed


def add_game_options(p: argparse.ArgumentParser) -> None:
    """Options that define a game: shared by every command that plays one."""
    p.add_argument("--seed", type=_seed, default=DEFAULT_SEED,
                   help=f"target sequence (default: {DEFAULT_SEED}, the same targets every game)")
    p.add_argument("--duration", type=float, default=60.0, help="game length in seconds (default: 60)")
    p.add_argument("--keys", default=None,
                   help="keys for pectoralis, posterior deltoid, biceps, triceps (default: dfjk; a window: the "
                   "settings file's)")


def register(subparsers: argparse._SubParsersAction) -> None:
    from ..ui.options import add_window_options

    p = subparsers.add_parser(
        "play",
        help="play the game (a window, or --headless from a script)",
        description="Hit the targets (rings) with the hand (a solid disc). d/f drive the shoulder flexor and "
        "extensor, j/k the elbow flexor and extensor; space resets the arm (costs a point), tab hides the arm, "
        "p pauses, m mutes, F11 toggles fullscreen, Esc quits. A 3-2-1 countdown (any key skips it) starts the "
        "clock. The end screen shows your score, rank and the table at once: Enter saves your name, then Enter "
        "plays again with the same options; Esc quits, keeping the game's replay.",
    )
    add_game_options(p)
    p.add_argument("--headless", action="store_true", help="no window: run as fast as possible")
    p.add_argument("--script", metavar="FILE", nargs="+", action="extend",
                   help="input timeline, one 'TIME KEY ACTION' a line (headless); several files or a folder of "
                   "*.txt scripts play a whole class in one batch, one result a line")
    p.add_argument("--bot", metavar="NAME", help="an autopilot at the muscle keys: model (knows the interaction "
                   "torques) or naive (drives each joint as if the other did not move)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    add_window_options(p, sound=True, trail=True)
    p.add_argument("--fps", type=int, default=60, help="frame-rate cap of the window (default: 60)")
    _add_score_options(p)
    p.set_defaults(run=run, without_window=without_window)


def _add_score_options(p: argparse.ArgumentParser) -> None:
    from .outputs import add_force_option
    from .scores import add_scores_option

    p.add_argument("--name", help="the player's name for the high-score table (the window asks at the end "
                   "otherwise; a headless game enters the table only with --name)")
    p.add_argument("--record", metavar="FILE|FOLDER", nargs="?", const=".",
                   help="save each game's replay: to FILE (JSON; a window's later games beside it, FILE-2.json and "
                   "on), or into FOLDER (alone: the current folder) as NAME-gameN.json, the player's name and the "
                   "next number there (ann-b-game3.json). A file that exists is never replaced: refused before "
                   "the game unless --force")
    add_force_option(p, "the --record FILE")
    add_scores_option(p)
    from .classroom import add_join_options

    add_join_options(p)


def game_config(args: argparse.Namespace):
    from ..game.muscles import DEFAULT_MUSCLES, remap_keys
    from ..game.rules import GameConfig
    from ..limits import MAX_GAME_SECONDS, MAX_GAME_STEPS

    if not (math.isfinite(args.duration) and 0 < args.duration <= MAX_GAME_SECONDS):
        raise UserError(f"--duration must be a positive number of seconds up to {MAX_GAME_SECONDS:g} (the longest "
                        f"game a replay may hold), got {args.duration!r}")
    config = GameConfig(seed=args.seed, time_limit=args.duration,
                        muscles=remap_keys(DEFAULT_MUSCLES, args.keys or "dfjk"))
    if config.total_steps > MAX_GAME_STEPS:
        raise UserError(f"--duration {args.duration:g} is {config.total_steps} physics steps, more than a replay may "
                        f"hold ({MAX_GAME_STEPS})")
    return check_recordable(config, "--keys")


def check_recordable(config, what: str):
    """``config``, if its replay would be read back; else one line before the game is played.

    The replay reader's own checks on the configuration (``config_from_dict``), run on it now: a
    key name with a control character or over 20 characters, or a clock past the longest game, is
    refused here rather than saved and refused by ``verify`` and ``analyze`` later.
    """
    from ..records.replay import config_from_dict, config_to_dict

    try:
        config_from_dict(config_to_dict(config))
    except (ValueError, UserError) as exc:
        raise UserError(f"{what}: {exc} (its replay could not be read back): nothing was played") from None
    return config


def run(args: argparse.Namespace) -> int:
    from ..game.script import load_script
    from ..game.session import GameSession
    from ..records.storage import user_path

    if args.script and (len(args.script) > 1 or user_path(args.script[0], "--script").is_dir()):
        return _play_class(args)
    if args.script:
        args.script = args.script[0]  # before the join, which checks the score options (--script among them)
    args.membership = _join(args)
    window = None if args.headless else _window_settings(args)  # before the game: its keys may come from there
    session = GameSession(game_config(args))
    _check_score_options(args)
    if args.script and not args.headless:
        raise UserError("--script drives a headless game: add --headless")
    if args.bot and args.script:
        raise UserError("--bot and --script both drive the game: give one of them")
    if args.headless and args.bot:
        from ..game.bots import Autopilot, make_bot

        result = Autopilot(session, make_bot(args.bot)).play()
    elif args.headless:
        events = load_script(args.script_path, session.keys, session.config.dt, session.total_steps) \
            if args.script else []
        result = session.play(events)
    else:
        if not 1 <= args.fps <= 1000:
            raise UserError(f"--fps must be from 1 to 1000, got {args.fps}")
        session = _play_in_window(session, args, window)  # the last game, when Enter played again
        result = session.result()
    _report(session, result, args)
    _wait_for_hand_ins(args)
    # A game the class refused is the command's failure, as a refused file is armgame class submit's (exit 1);
    # a game kept in the outbox is not: it goes in at the next join (exit 0).
    return 1 if getattr(args, "refused", False) else 0


def _join(args: argparse.Namespace):
    """With --join: the class joined, and the game set to the class's (its seed and its clock: the standard 60 s,
    or a rehearsal's 15 s)."""
    from .classroom import join_class

    if args.join is not None:
        if args.duration != 60.0:
            raise UserError("a class plays its own game (the standard 60 s game, a rehearsal's 15 s one): leave out "
                            "--duration")
        if args.name is not None:
            _check_score_options(args)  # the name is checked before it is sent
    membership = join_class(args)
    if membership is not None:
        if args.seed not in (DEFAULT_SEED, membership.seed):
            raise UserError(f"the class plays seed {membership.seed}: leave out --seed")
        args.seed = membership.seed
        args.duration = membership.duration
    return membership


def _hand_in(replay, membership, args: argparse.Namespace, out=None, ticket: str | None = None) -> object:
    """Hand a finished game in to the class; one line on what became of it (kept in the outbox if the
    class could not be reached), on ``out`` (stdout), or for a refusal on stderr (and ``args.refused``
    set: the command exits 1). The window's games are handed in on a thread, and say so here too: the
    terminal's scrollback keeps the record of every game. ``ticket``: the game's start ticket, for a round."""
    import sys

    from ..classroom.client import hand_in

    result = hand_in(membership, replay.to_bytes(), ticket=ticket)
    if result.refused:
        args.refused = True
        print(f"armgame play: {result.message}", file=sys.stderr, flush=True)
    else:
        print(result.message, file=out or sys.stdout, flush=True)
    return result


def _wait_for_hand_ins(args: argparse.Namespace) -> None:
    """The window closed with a game still on its way to the class: wait for its answer (bounded by the
    client's patience with a busy class), so the game is not cut off with the process and its line is
    printed."""
    waiting = [t for t in getattr(args, "handing_in", ()) if t.is_alive()]
    if waiting:
        print("handing your last game in to the class...", flush=True)
    for thread in waiting:
        thread.join()


def _report(session, result, args: argparse.Namespace) -> None:
    """Print one game's result and keep it (the window's end screen may have kept it already)."""
    import json
    import sys

    if args.json:
        print(json.dumps(result.as_dict(), sort_keys=True))
    else:
        print(f"your score is: {result.score}  ({plural(result.hits, 'hit')}, {plural(result.resets, 'reset')}, "
              f"{session.time:.1f} s of {result.duration:g} s)")
    if session.event_limit_reached:
        print(f"the game was stopped at {session.time:.1f} s: it reached {len(session.timeline)} input events, the "
              f"most a replay holds", file=sys.stderr)
    if not getattr(args, "kept", False):  # the window's end screen may have kept it already
        _keep(session, args)


def _play_class(args: argparse.Namespace) -> int:
    """Many scripts, one batch: one line per script, in order, each naming its script."""
    import json

    from ..game.batch import play_scripts, script_paths

    if not args.headless:
        raise UserError("--script drives a headless game: add --headless")
    if args.bot:
        raise UserError("--bot and --script both drive the game: give one of them")
    if args.name is not None or args.record or args.join is not None:
        raise UserError("--name, --record and --join are for one game: give one script, not several")
    paths = script_paths(args.script)
    for path, result in zip(paths, play_scripts(game_config(args), paths), strict=True):
        if args.json:
            print(json.dumps({"script": str(path), **result.as_dict()}, sort_keys=True))
        else:
            print(f"{path}: score {result.score}  ({result.hits} hits, {result.resets} resets)")
    return 0


def _check_score_options(args: argparse.Namespace) -> None:
    """Refuse a bad --name, --record, --script or --scores before the game, not after a minute of play."""
    import sys

    from ..records.storage import check_writable_folder, user_path
    from ..valid import check_name
    from .outputs import RecordTarget
    from .scores import scores_dir

    if args.name is not None:
        try:
            args.name = check_name(args.name, "--name")
        except ValueError as exc:
            raise UserError(str(exc)) from None
    args.script_path = user_path(args.script, "--script") if args.script is not None else None
    if args.record is not None:  # an existing file is refused now, not after a minute of play
        args.record_target = RecordTarget.parse(args.record, args.force, "game")
    if args.name is not None:  # a game that will enter the table
        check_writable_folder(scores_dir(args), "--scores")
    elif not args.headless:  # the window may ask for a name: say now if it could not be saved
        try:
            check_writable_folder(scores_dir(args), "--scores")
        except UserError as exc:
            print(f"armgame play: note: scores cannot be saved: {exc}", file=sys.stderr)


def _keep(session, args: argparse.Namespace):
    """Save the replay where --record asks, and enter a finished game with a name in the table.

    Returns the new table entry, or None when the game was not entered."""
    import sys
    from pathlib import Path

    from ..records.replay import Replay
    from ..records.scores import ScoreTable, VerificationCache
    from .scores import scores_dir, where_it_went

    read_lab_replays()  # the table's other entries are read too
    out = sys.stderr if args.json else sys.stdout
    bot = getattr(args, "bot", None)
    driven = "bot" if bot else "script" if args.headless else "keyboard"
    driver = bot or (driver_name(Path(args.script).name) if args.script else None)
    replay = Replay.from_session(session, driven, driver, args.name)
    args.saved_to = None
    if session.steps == 0:  # Esc at the countdown: nothing to keep, no empty file to hand in by mistake
        print("the game was quit before it started: nothing kept", file=out)
        return None
    if _played(session, args):
        args.saved_to = _record(replay, args, out)
    elif getattr(args, "record_target", None) is not None:  # nobody at the keys: not a game to hand in
        print("no key was pressed in this game: nothing saved for --record", file=out)
    membership = getattr(args, "membership", None)
    if membership is not None and replay.complete:
        _hand_in(replay, membership, args, out)
        return None
    if args.name is None or not replay.complete or membership is not None:
        if membership is not None:
            print("the game was stopped before the end: not handed in to the class", file=out)
        if not args.headless:  # a window's game: nothing is lost (Esc on the end screen)
            _keep_replay(replay, args, out)
        elif args.name is not None:
            print("the game was stopped before the end: not entered in the high-score table", file=out)
        return
    warn = lambda m: print(f"armgame play: {m}", file=sys.stderr)  # noqa: E731
    table = ScoreTable(scores_dir(args), warn=warn,
                       cache=VerificationCache(warn=warn))  # read only here: it knows older entries' rulesets
    try:
        entry = table.add(replay)
    except OSError as exc:
        raise UserError(f"cannot save the score in {table.folder}: {exc.strerror or exc}") from None
    except ValueError as exc:
        raise UserError(f"not entered in the high-score table: {exc}") from None
    print(f"saved to the high-score table as {entry.name}: {where_it_went(table, entry)}", file=out)
    return entry


def _played(session, args: argparse.Namespace) -> bool:
    """Whether a game is worth a --record file: it began, and in a window a key of the game (or a bot) played
    it. A headless game is what its script asked for, even an empty one."""
    if session.steps == 0:
        return False
    return bool(getattr(args, "headless", False) or getattr(args, "bot", None) or session.timeline)


def _record(replay, args: argparse.Namespace, out):
    """The replay where --record asks (``outputs.RecordTarget``), and a line naming the file; its path."""
    target = getattr(args, "record_target", None)
    if target is None:
        return None
    path = target.save(replay)
    print(f"replay saved to {path}", file=out)
    return path


def _keep_replay(replay, args: argparse.Namespace, out) -> None:
    """A window's game not entered in the table: its replay is kept (beside the table's, or where
    --record put it) and the line printed says how to enter it later, or to watch it."""
    import shlex

    from ..records.scores import ScoreTable
    from ..records.storage import DataFileError
    from .scores import scores_dir

    if args.saved_to is not None:
        path = args.saved_to
    else:
        try:
            path = ScoreTable(scores_dir(args)).save_replay(replay)
        except (OSError, DataFileError) as exc:
            print(f"the game's replay could not be kept: {getattr(exc, 'strerror', None) or exc}", file=out)
            return
    scores = ["--scores", str(args.scores)] if getattr(args, "scores", None) else []
    if replay.complete:
        add = shlex.join(["armgame", "scores", "--add", str(path), "--name", "NAME", *scores])
        print(f"not entered in the high-score table; the game's replay is kept: {path}\n"
              f"  to enter it later: {add}", file=out)
    else:
        print(f"the game was stopped at {replay.steps * replay.config.dt:.1f} s (a game stopped early is never "
              f"entered); its replay is kept: {shlex.join(['armgame', 'replay', str(path)])} watches it", file=out)


def driver_name(file_name: str) -> str:
    """A script's file name as the table shows it: printable, at most 60 characters."""
    cleaned = "".join(c if c.isprintable() else "?" for c in file_name).strip() or "script"
    return cleaned if len(cleaned) <= 60 else cleaned[:57] + "..."


def _window_settings(args: argparse.Namespace):
    from ..ui.options import window_settings

    settings, path = window_settings(args)
    args.keys = args.keys or settings.keys
    return settings, path


def list_name(kind: str) -> str:
    """The heading of a list (``records.scores.LIST_TITLES``) as the end screen shows it: "the ranked
    table", "practice", "programs" or "custom games". One place: the scores layer decides the lists."""
    from ..records.scores import LIST_TITLES

    return LIST_TITLES[kind].split(" (")[0]


def _table_of_list(session, args: argparse.Namespace, entry=None):
    """The table, the rows of the list the game goes to (or would go to), one a player at their best game
    (``records.standings``), best first, and that list."""
    import sys

    from ..records.scores import ScoreTable
    from ..records.standings import one_row_per_player
    from .scores import scores_dir

    table = ScoreTable(scores_dir(args), warn=lambda m: print(f"armgame play: {m}", file=sys.stderr))
    everything = table.all_entries()  # read once: it also gives the table's seed, which the lists need
    kind = table.list_of(entry) if entry is not None else _list_it_would_join(session, args, table)
    return table, one_row_per_player(table.of_list(kind, everything)), kind


def _rows(ranked: list[tuple[str, int]], own: int | None) -> tuple[tuple[tuple[int, str, int], ...], int | None]:
    """The top 10 as (place, name, score), equal scores sharing a place (``standings.places``), and the
    player's own row (``own``: its position, 1-based) after them if it is lower; and the index of that row
    among them, the one row the end screen shows as theirs (None: no row is)."""
    from ..records.standings import places

    shown = places(score for _, score in ranked)
    rows = [(shown[i], name, score) for i, (name, score) in enumerate(ranked[:10])]
    if own is None:
        return tuple(rows), None
    if own > 10:
        rows.append((shown[own - 1], *ranked[own - 1]))
        return tuple(rows), len(rows) - 1
    return tuple(rows), own - 1


def _standing(session, args: argparse.Namespace):
    """The end screen's callback: keep the game (under the name typed there) and say where it stands."""
    import sys

    from ..records.standings import rank_of, row_of
    from ..ui.render import Standing

    membership = getattr(args, "membership", None)
    if membership is not None:
        return _class_standing(session, args, membership)

    def standing(name: str | None) -> Standing | None:
        args.name = name or args.name
        try:
            entry = _keep(session, args)
            args.kept = True
            _, rows, kind = _table_of_list(session, args, entry)
        except UserError as exc:
            print(f"armgame play: error: {exc}", file=sys.stderr)
            return None
        # The player's place, at their best game (maybe an earlier one): "#3" is the third place.
        rank = None if entry is None else rank_of(rows, entry.name)
        top, mine = _rows([(r.name, r.best.score) for r in rows], None if entry is None else row_of(rows, entry.name))
        return Standing(rank, len(rows), top, list_name(kind), saved=_saved_line(args), mine=mine)

    return standing


def _saved_line(args: argparse.Namespace) -> str | None:
    """The end screen's line naming the --record file just written (the terminal has its whole path)."""
    path = getattr(args, "saved_to", None)
    return None if path is None else f"Saved as {path.name}"


def _class_standing(session, args: argparse.Namespace, membership):
    """The end screen in a live class: the game is handed in on a thread (the window never waits for
    the network), and the screen shows what became of it, and the class's top, when the answer comes. The game's
    start ticket is asked for as it is set up, on a thread too, and goes with it (a round counts games begun
    during it)."""
    import sys
    import threading

    from ..classroom.bounds import TICKET_TIMEOUT
    from ..classroom.client import start_ticket
    from ..records.replay import Replay
    from ..ui.render import Standing

    ticket: list[str | None] = []
    asking = threading.Thread(target=lambda: ticket.append(start_ticket(membership)), daemon=True)
    asking.start()

    def handed_in(replay) -> object:
        asking.join(TICKET_TIMEOUT)
        return _hand_in(replay, membership, args, ticket=ticket[0] if ticket else None)

    def standing(name: str | None) -> Standing | None:
        args.kept = True
        if not session.over:
            return Standing(None, 0, (), "the class", note="Stopped before the end: not handed in")
        replay = Replay.from_session(session, "bot" if args.bot else "keyboard", args.bot, membership.name)
        args.saved_to = None
        if _played(session, args):
            try:
                args.saved_to = _record(replay, args, sys.stdout)
            except UserError as exc:
                print(f"armgame play: error: {exc}", file=sys.stderr)
        saved = _saved_line(args)
        done: list = []
        thread = threading.Thread(target=lambda: done.append(handed_in(replay)), daemon=True)
        thread.start()
        args.handing_in = [*(t for t in getattr(args, "handing_in", ()) if t.is_alive()), thread]

        def later() -> Standing | None:
            if not done:
                return None
            result = done[0]
            answer = result.answer
            if result.kept is not None:  # the whole reason went to the terminal; the screen says what matters
                return Standing(None, 0, (), "the class", note="Not handed in: the class cannot be reached.\n"
                                "Your game is kept: it goes in the next time you join", saved=saved)
            if answer is None:
                return Standing(None, 0, (), "the class", note=_screen_line(result.message), saved=saved)
            top = tuple((int(r), str(n), int(v)) for r, n, v in answer.get("top", ()))
            where = "the class" if answer.get("list") == "students" else "the programs"
            yours = answer.get("yours")  # which row is the player's: a place may be several rows'
            mine = yours if isinstance(yours, int) and not isinstance(yours, bool) and 0 <= yours < len(top) else None
            return Standing(int(answer["rank"]), int(answer["of"]), top, where,
                            note=_screen_line(result.message), saved=saved, mine=mine)

        return Standing(None, 0, (), "the class", note="Handing your game in...", later=later, saved=saved)

    return standing


def _screen_line(message: str) -> str:
    """A hand-in's message for the end screen: its first clause, then the rest on a line of its own."""
    first, _, rest = message.partition(": ")
    return f"{first[:1].upper()}{first[1:]}:\n{rest}" if rest else message


def _list_it_would_join(session, args: argparse.Namespace, table) -> str:
    """The list a game not entered would have gone to: its end screen shows that list's top."""
    from ..records.rulesets import ruleset_of
    from ..records.scores import CUSTOM_GAMES, PRACTICE, PROGRAMS, RANKED

    if getattr(args, "bot", None):
        return PROGRAMS
    if ruleset_of(session.config) is None:
        return CUSTOM_GAMES
    return PRACTICE if session.config.seed != table.seed else RANKED


def _preview(session, args: argparse.Namespace):
    """The end screen's first look: where the score would rank, before any name is typed, as a new
    player's (nothing is entered: an equal score already in the table shares the place, its row first, as
    the earlier game)."""
    import sys

    from ..records.standings import place_of_new
    from ..records.storage import DataFileError
    from ..ui.render import Standing

    def preview() -> Standing | None:
        try:
            _, rows, kind = _table_of_list(session, args)
        except (UserError, DataFileError, OSError) as exc:
            print(f"armgame play: {exc}", file=sys.stderr)
            return None
        score = session.rules.board.score
        ranked = [(r.name, r.best.score) for r in rows]
        position = 1 + sum(1 for _, s in ranked if s >= score)  # after the equal scores, the earlier games
        ranked.insert(position - 1, ("", score))
        top, mine = _rows(ranked, position)
        return Standing(place_of_new(rows, score), len(ranked), top, list_name(kind), pending=True, mine=mine)

    return preview


def _play_in_window(session, args: argparse.Namespace, window):
    from ..game.session import GameSession

    try:
        from ..ui.frontend import NextGame, play_window
    except ImportError as exc:
        raise UserError(f"the window needs pygame-ce: {exc}") from None
    settings, path = window
    named = args.name  # --name: every game of the window goes under it; else each is asked its own

    def next_game(finished):
        """Enter on the end screen: this game is kept and reported, the next has the same options."""
        args.name = args.name or finished.player_name
        _report(finished.session, finished.session.result(), args)
        args.name, args.kept = named, False  # --record's target numbers the next games' files itself
        new = GameSession(game_config(args))
        return NextGame(new, _bot_driver(new, args), _standing(new, args),
                        None if getattr(args, "membership", None) else _preview(new, args))

    played = play_window(session, settings, path, fullscreen=args.fullscreen, fps=args.fps,
                         driver=_bot_driver(session, args), ask_name=named is None, trail=args.trail,
                         standing=_standing(session, args), next_game=next_game,
                         preview=None if getattr(args, "membership", None) else _preview(session, args),
                         driven_by=f"AUTOPILOT: {args.bot}" if args.bot else None,
                         details=() if args.bot else (f"seed {args.seed}",))
    args.name = args.name or played.player_name  # the name typed on the end screen
    return played.session


def _bot_driver(session, args: argparse.Namespace):
    """A bot at the keys (the same Autopilot as headless; the keyboard only pauses and quits), or None."""
    if not args.bot:
        return None
    from ..game.bots import Autopilot, make_bot
    from ..game.session import RealTimeDriver

    return RealTimeDriver(Autopilot(session, make_bot(args.bot)))  # type: ignore[arg-type]


def without_window(args: argparse.Namespace, typed: list[str]) -> str:
    """The game headless: a bot plays it (the player's keys need a window)."""
    from . import command_line

    return command_line(typed, "--headless", *([] if args.bot else ["--bot", "model"]))
