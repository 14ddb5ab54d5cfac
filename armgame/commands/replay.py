"""armgame replay: play a recorded game back, in a window or headless."""

from __future__ import annotations

import argparse

from ..words import plural
from . import read_env_games, read_lab_replays
from .verify import work_arg


def register(subparsers: argparse._SubParsersAction) -> None:
    from ..ui.options import add_window_options

    p = subparsers.add_parser(
        "replay",
        help="play back a recorded game (a window, or --headless --json)",
        description="Play back a replay file (from play --record, or the replays/ folder beside the score "
        "table) at real-time speed in a window: p pauses, - and + set the speed (0.25x to 8x), 1 back to real "
        "speed, the left and right arrows skip 5 s back and forth, Enter at the end watches again, Esc quits; "
        "the game keys do nothing. With "
        "--headless the game is recomputed at once; --json prints the same object as play --headless --json.",
    )
    p.add_argument("file", metavar="FILE", help="the replay file (JSON)")
    p.add_argument("--headless", action="store_true", help="no window: recompute the game at once")
    p.add_argument("--max-work", type=work_arg, metavar="N",
                   help="with --headless: recompute no game whose replay counts more than N steps of work "
                        "(default: the budget armgame verify spends; a hit storm of a stranger's stops there)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    add_window_options(p, sound=True, trail=True)
    p.add_argument("--fps", type=int, default=60, help="frame-rate cap of the window (default: 60)")
    p.set_defaults(run=run, without_window=without_window)


def run(args: argparse.Namespace) -> int:
    import json

    from ..errors import UserError
    from ..records.replay import Replay
    from ..records.storage import user_path

    read_lab_replays()
    read_env_games()
    replay = Replay.load(user_path(args.file, "FILE"))
    if args.headless:
        from .. import limits  # read now: the budget is the one verify spends
        from ..records.replay import VerifyCostError

        limit = limits.MAX_VERIFY_WORK if args.max_work is None else args.max_work
        try:
            result = replay.replay(max_work=limit)
        except VerifyCostError as exc:
            raise UserError(f"{args.file}: not replayed: {exc} (--max-work N spends up to N)") from None
        played = result.steps
    else:
        if not 1 <= args.fps <= 1000:
            raise UserError(f"--fps must be from 1 to 1000, got {args.fps}")
        session = _watch(replay, args)
        result, played = session.result(), session.steps
    if args.json:
        print(json.dumps(result.as_dict(), sort_keys=True))
        return 0
    who = f"{replay.player}'s game" if replay.player else "the game"
    if played < replay.steps:
        print(f"replay of {who} stopped at {played * replay.config.dt:.1f} s of "
              f"{replay.steps * replay.config.dt:.1f} s: score so far {result.score}")
    else:
        r = replay.result
        verdict = "as recorded" if (result.score, result.hits, result.resets) == (r.score, r.hits, r.resets) \
            else f"recorded {r.score} ({plural(r.hits, 'hit')}, {plural(r.resets, 'reset')}): DIFFERS"
        print(f"replay of {who} ({replay.driven}, seed {r.seed}): score {result.score} "
              f"({plural(result.hits, 'hit')}, {plural(result.resets, 'reset')}), {verdict}")
    return 0


def _watch(replay, args: argparse.Namespace):
    """The replay in a window; returns the session as the window left it (skips back replay it afresh)."""
    from ..errors import UserError

    try:
        from ..ui.frontend import ReplaySource, play_window
        from ..ui.options import window_settings
    except ImportError as exc:
        raise UserError(f"the window needs pygame-ce: {exc}") from None
    settings, path = window_settings(args)
    if replay.task is not None and hasattr(replay.task, "about"):
        raise UserError(f"{args.file}: a Gymnasium env's game ({replay.task.about()}): the window plays the game "
                        f"itself, not its variant; --headless replays it, armgame verify checks it")
    if replay.task is not None:  # a lab run is watched on its own task's session and window
        return _watch_lab(replay, args, settings)
    when = replay.date[:16].replace("T", " ") if replay.date else "date unknown"
    source = ReplaySource(replay.config, replay.timeline, replay.steps, replay.player)
    session, _ = source.start()
    window = play_window(session, settings, path, fullscreen=args.fullscreen, fps=args.fps, replay=source,
                         trail=args.trail, driven_by="REPLAY",
                         details=(replay.player or "no name", when),
                         caption=f"armgame replay - {replay.player or 'a game'}, seed {replay.config.seed}")
    return window.session


def _watch_lab(replay, args: argparse.Namespace, settings):
    import pygame

    from ..ui.frontend import open_window
    from ..ui.lab_window import LabReplay, LabWindow

    player = replay.player or "no name"
    source = LabReplay(replay.config, replay.task.new_session, replay.timeline, replay.steps, player)
    screen = open_window(settings.size, args.fullscreen,
                         f"armgame replay - {replay.player or 'a lab run'}, seed {replay.config.seed}")
    try:
        window = LabWindow(source.new_session(source.config), screen, fps=args.fps, mode=f"REPLAY   {player}",
                           replay=source, palette=settings.palette, text_scale=settings.text_scale)
        window.run()
    finally:
        pygame.display.quit()
    return window.session


def without_window(args: argparse.Namespace, typed: list[str]) -> str:
    """The replay recomputed at once."""
    from . import command_line

    return command_line(typed, "--headless")
