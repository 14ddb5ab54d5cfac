"""armgame bench: speed against error for the integrators and their peers, and the defaults it supports."""

from __future__ import annotations

import argparse
import sys

from ..errors import UserError
from ..words import unknown_name

CASE_NAMES = ("passive", "propeller", "upright", "stiff", "game")
INTEGRATOR_NAMES = ("euler", "symplectic-euler", "rk4", "midpoint", "gauss4")


def _names(allowed: tuple[str, ...], what: str):
    def parse(text: str) -> tuple[str, ...]:
        names = tuple(n.strip() for n in text.split(",") if n.strip())
        unknown = [n for n in names if n not in allowed]
        if not names:
            raise argparse.ArgumentTypeError(f"no {what} given: choose from {', '.join(allowed)}")
        if unknown:
            raise argparse.ArgumentTypeError(unknown_name(what, unknown[0], allowed))
        return names

    return parse


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "bench",
        help="measure speed against error of the integrators and their peers",
        description="Work-precision benchmark: each integrator at steps from 1/30 s to 1/4000 s on the hard cases "
        "(passive, propeller, upright, stiff, game), against a DOP853 reference, beside the tutorial's odeint, "
        "scipy's solve_ivp and MuJoCo. Prints a table, the speed ratios, the defaults the data choose, and the "
        "machine and package versions.",
    )
    p.add_argument("--quick", action="store_true", help="fewer steps, tolerances and repeats (under 30 s)")
    p.add_argument("--cases", type=_names(CASE_NAMES, "case"), default=CASE_NAMES, metavar="A,B",
                   help=f"comma-separated cases (default: all: {','.join(CASE_NAMES)})")
    p.add_argument("--integrators", type=_names(INTEGRATOR_NAMES, "integrator"), default=INTEGRATOR_NAMES,
                   metavar="A,B", help="comma-separated integrators of ours (default: all)")
    p.add_argument("--no-peers", action="store_true", help="skip odeint, solve_ivp and MuJoCo")
    p.add_argument("--no-bars", action="store_true", help="skip the speed-bar measurements")
    p.add_argument("--json", action="store_true", help="print the rows, ratios and defaults as JSON instead")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="also write bench.csv, work_precision.png and convergence.png into DIR (needs matplotlib)")
    from .outputs import add_force_option

    add_force_option(p, "those files in --out")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..bench import report
    from ..bench.run import Options, run_bench
    from .outputs import fresh_outputs

    out = None
    if args.out is not None:
        from ..records.storage import user_path

        out = user_path(args.out, "--out")
        if out.exists() and not out.is_dir():
            raise UserError(f"--out {out} exists and is not a folder")
        from ..bench import figures

        figures.require()  # fail now, in one line, not after minutes of measuring
    files = [] if out is None else [out / "bench.csv", out / "work_precision.png", out / "convergence.png"]
    with fresh_outputs(files, args.force, folder=out):  # an existing one is refused now, not after minutes
        options = Options(quick=args.quick, cases=args.cases, integrators=args.integrators, peers=not args.no_peers,
                          bars=not args.no_bars)
        progress = (lambda m: None) if args.json else (lambda m: print(f"... {m}", file=sys.stderr, flush=True))
        result = run_bench(options, progress)
        if out is not None:
            from ..bench import figures

            try:
                out.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise UserError(f"cannot create --out folder {out}: {exc.strerror or exc}") from None
            report.write_csv(result.rows, out / "bench.csv")
            figures.work_precision(result.rows, out / "work_precision.png")
            figures.convergence(result.rows, out / "convergence.png")
            result.notes.append(f"wrote {out / 'bench.csv'}, {out / 'work_precision.png'}, {out / 'convergence.png'}")
    print(report.json_report(result) if args.json else report.text_report(result))
    return 0
