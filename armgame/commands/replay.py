"""armgame replay: play a recorded game back, in a window or headless."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    from .play import _size

    p = subparsers.add_parser(
        "replay",
        help="play back a recorded game (a window, or --headless --json)",
        description="Play back a replay file (from play --record, or the replays/ folder beside the score "
        "table) at real-time speed in a window; the keyboard only pauses (p) and quits (Esc). With "
        "--headless the game is recomputed at once; --json prints the same object as play --headless --json.",
    )
    p.add_argument("file", metavar="FILE", help="the replay file (JSON)")
    p.add_argument("--headless", action="store_true", help="no window: recompute the game at once")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--fullscreen", action="store_true", help="fill the screen")
    p.add_argument("--size", type=_size, default=(800, 800), help="window size (default: 800x800)")
    p.add_argument("--fps", type=int, default=60, help="frame-rate cap of the window (default: 60)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import json

    from ..errors import UserError
    from ..game.session import GameSession
    from ..records.replay import Replay
    from ..records.storage import user_path

    replay = Replay.load(user_path(args.file, "FILE"))
    if args.headless:
        result = replay.replay()
        played = result.steps
    else:
        if not 1 <= args.fps <= 1000:
            raise UserError(f"--fps must be from 1 to 1000, got {args.fps}")
        session = GameSession(replay.config)
        _watch(session, replay, args)
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
            else f"recorded {r.score} ({r.hits} hits, {r.resets} resets): DIFFERS"
        print(f"replay of {who} ({replay.driven}, seed {r.seed}): score {result.score} "
              f"({result.hits} hits, {result.resets} resets), {verdict}")
    return 0


def _watch(session, replay, args: argparse.Namespace) -> None:
    from ..errors import UserError

    try:
        import pygame

        from ..game.timeline import TimelineDriver
        from ..ui.frontend import GameWindow, open_window
    except ImportError as exc:
        raise UserError(f"the window needs pygame-ce: {exc}") from None
    try:
        screen = open_window(args.size, args.fullscreen)
    except pygame.error as exc:
        raise UserError(f"cannot open a window ({exc}); use --headless where there is no display") from None
    try:
        pygame.display.set_caption(f"armgame replay - {replay.player or 'a game'}, seed {replay.config.seed}")
        driver = TimelineDriver(session, replay.timeline, replay.steps)
        GameWindow(session, screen, fps=args.fps, driver=driver).run()
    finally:
        pygame.display.quit()
