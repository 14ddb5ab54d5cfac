"""armgame demo: the tutorial's ideas as classroom demonstrations, in a window or headless."""

from __future__ import annotations

import argparse
import math

from ..demos import DEMO_NAMES
from ..errors import UserError

_FIXED_STEP = "euler, symplectic-euler, rk4, midpoint or gauss4"


def register(subparsers: argparse._SubParsersAction) -> None:
    from ..ui.options import add_window_options

    p = subparsers.add_parser(
        "demo",
        help="classroom demos: pendulum, passive, chaos, interaction, planning, autopilot",
        description="Show one of the tutorial's ideas in a window (space pauses, r restarts, the arrow keys or "
        "- and + slow down and speed up, Esc quits), or with --headless --out DIR write NAME.csv and the figure "
        "NAME.png there. Demos: pendulum (the one-joint passive arm from 90 deg), passive (the two-joint passive "
        "arm), chaos (two passive arms 1e-6 rad apart), interaction (a fast minimum-jerk reach and the torques "
        "it needs, split into each joint's own and interaction torques), planning (one reach as minimum jerk beside "
        "minimum torque change, computed on the arm's own dynamics), autopilot (two bots play the game, one "
        "knowing the interaction torques and one not; headless it prints their hits on seeds 0 to 9, and with --out "
        "writes autopilot.csv and autopilot.png). "
        "Figures need matplotlib: "
        "pip install 'armgame[plot]'.",
    )
    names = (*DEMO_NAMES, "autopilot")  # autopilot: the model and naive bots play the game side by side
    p.add_argument("name", choices=names, metavar="NAME", help=", ".join(names))
    p.add_argument("--headless", action="store_true", help="no window: write the CSV and figure to --out")
    p.add_argument("--out", default=None, metavar="DIR", help="folder for NAME.csv and NAME.png (with --headless)")
    p.add_argument("--no-figures", action="store_true", help="headless: write the CSV only (no matplotlib needed)")
    p.add_argument("--duration", type=float, default=None,
                   help="headless: seconds to run (default: the demo's, 10 s for pendulum and passive; "
                   "planning takes none)")
    p.add_argument("--integrator", default="rk4", help=f"fixed-step scheme: {_FIXED_STEP} (default: rk4)")
    p.add_argument("--dt", type=float, default=0.001, help="physics step in seconds (default: 0.001)")
    p.add_argument("--gravity", action="store_true",
                   help="interaction only: the reach in a vertical plane, so gravity adds its torques")
    p.add_argument("--speed", type=float, default=1.0, help="window: initial playback rate (default: 1 = real time)")
    from .outputs import add_force_option

    add_force_option(p, "NAME.csv and NAME.png in --out")
    add_window_options(p, sound=False)
    p.set_defaults(run=run, without_window=without_window)


def run(args: argparse.Namespace) -> int:
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise UserError(f"--duration must be a positive, finite number of seconds, got {args.duration!r}")
    if not (math.isfinite(args.speed) and 0.01 <= args.speed <= 100):
        raise UserError(f"--speed must lie between 0.01 and 100, got {args.speed!r}")
    if args.name == "autopilot":
        from ..demos import autopilot
        from ..records.storage import user_path

        if args.headless:
            out = None if args.out is None else user_path(args.out, "--out")
            with _fresh(out, "autopilot", args):
                print(autopilot.run_headless(out, args.duration, figures=not args.no_figures))
        else:
            from ..ui.autopilot_window import run_window as autopilot_window
            from ..ui.options import window_settings

            settings = window_settings(args)[0]
            autopilot_window(autopilot.WINDOW_SEED, size=settings.size, fullscreen=args.fullscreen,
                             palette=settings.palette, text_scale=settings.text_scale)
        return 0
    if args.headless:
        if args.out is None:
            raise UserError("--headless needs --out DIR, the folder to write the CSV and figure to")
        from ..demos.catalog import run_headless
        from ..records.storage import user_path

        out = user_path(args.out, "--out")
        with _fresh(out, args.name, args):
            result = run_headless(args.name, out, args.duration, args.integrator, args.dt, args.gravity,
                                  figures=not args.no_figures)
        print(f"{args.name}: {result.summary}")
        for path in result.files:
            print(f"wrote {path}")
        return 0
    if args.out is not None or args.no_figures or args.duration is not None:
        raise UserError("--out, --no-figures and --duration apply with --headless only")
    from ..demos.catalog import make_run

    run_ = make_run(args.name, args.integrator, args.dt, args.gravity)
    from ..ui.demo_window import run_window
    from ..ui.options import window_settings

    settings = window_settings(args)[0]
    run_window(args.name, run_, speed=args.speed, size=settings.size, fullscreen=args.fullscreen,
               palette=settings.palette, text_scale=settings.text_scale)
    return 0


def _fresh(out, name: str, args: argparse.Namespace):
    """NAME.csv and NAME.png in ``out`` are new files, or refused before the demo runs (unless --force)."""
    from .outputs import fresh_outputs

    if out is None:
        return fresh_outputs([], args.force)
    return fresh_outputs([out / f"{name}.csv", *([] if args.no_figures else [out / f"{name}.png"])], args.force,
                         folder=out)


def without_window(args: argparse.Namespace, typed: list[str]) -> str:
    """The demo headless, its CSV and figure written to a folder named after it (autopilot: printed)."""
    from . import command_line

    return command_line(typed, "--headless", *([] if args.name == "autopilot" else ["--out", args.name]))
