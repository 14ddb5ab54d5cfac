"""armgame scores: the high-score table, best first, each entry checked against its replay."""

from __future__ import annotations

import argparse

from ..words import plural

SCORES_HELP = ("folder of the high-score table (default: $ARMGAME_SCORES, else scores/ in a checkout, "
               "else ~/.local/share/armgame/scores)")


def add_scores_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scores", metavar="DIR", help=SCORES_HELP)


def scores_dir(args: argparse.Namespace):
    from pathlib import Path

    from ..records.scores import default_scores_dir

    return Path(args.scores).expanduser() if getattr(args, "scores", None) else default_scores_dir()


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "scores",
        help="the high-score table, best first",
        description="Print the high-score table, best first (equal scores: the earlier game first), with how "
        "each game was driven. Each entry's replay is played again: an entry whose replay is missing, "
        "changed or does not reproduce its score is flagged.",
    )
    add_scores_option(p)
    p.add_argument("--top", type=int, default=10, metavar="N", help="how many entries (default: 10)")
    p.add_argument("--all", action="store_true", help="every entry")
    p.add_argument("--no-check", action="store_true", help="do not replay the games (faster, nothing flagged)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import sys

    from ..errors import UserError
    from ..records.scores import ScoreTable

    if args.top < 1:
        raise UserError(f"--top must be 1 or more, got {args.top}")
    table = ScoreTable(scores_dir(args), warn=lambda m: print(f"armgame scores: {m}", file=sys.stderr))
    entries = table.entries()
    if not entries:
        print(f"no scores yet in {table.path}")
        return 0
    shown = entries if args.all else entries[: args.top]
    checks = [None if args.no_check else table.check(e) for e in shown]
    rows = [("#", "name", "score", "hits", "resets", "driven", "seed", "length", "date", "version", "replay")]
    for rank, (e, c) in enumerate(zip(shown, checks, strict=True), 1):
        when = e.when.astimezone().strftime("%Y-%m-%d %H:%M")
        rows.append((str(rank), e.name, str(e.score), str(e.hits), str(e.resets), e.how, str(e.seed),
                     f"{e.duration:g} s", when, e.version, "-" if c is None else c.label))
    right = {0, 2, 3, 4, 6, 7}
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    more = f", the top {len(shown)} shown" if len(shown) < len(entries) else ""
    print(f"High scores in {table.path} ({plural(len(entries), 'entry')}{more})")
    for r in rows:
        cells = [c.rjust(w) if i in right else c.ljust(w) for i, (c, w) in enumerate(zip(r, widths, strict=True))]
        print("  ".join(cells).rstrip())
    flagged = [(rank, e, c) for rank, (e, c) in enumerate(zip(shown, checks, strict=True), 1) if c and not c.ok]
    if flagged:
        print(f"{len(flagged)} flagged: the replay does not back the score")
        for rank, e, c in flagged:
            print(f"  #{rank} {e.name}: {c.label}: {c.detail}")
    return 0
