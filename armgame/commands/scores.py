"""armgame scores: the high-score table, best first, each entry checked against its replay."""

from __future__ import annotations

import argparse

from ..words import plural
from . import read_lab_replays

SCORES_HELP = ("folder of the high-score table (default: $ARMGAME_SCORES, else scores/ in a checkout, "
               "else ~/.local/share/armgame/scores)")


def add_scores_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scores", metavar="DIR", help=SCORES_HELP)


def scores_dir(args: argparse.Namespace):
    from ..records.scores import default_scores_dir
    from ..records.storage import user_path

    return user_path(args.scores, "--scores") if getattr(args, "scores", None) is not None else default_scores_dir()


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "scores",
        help="the high-score table, best first",
        description="Print the high-score table, best first (equal scores: the earlier game first), with how "
        "each game was driven. Only games of a ranked ruleset (standard: the default 60 s game, any seed) are "
        "ranked; custom games are listed apart. Each entry's replay is played again (once: verdicts are cached "
        "per user, by the replay's SHA-256 and the armgame version): an entry whose replay is missing, changed "
        "or does not reproduce its score is flagged and not ranked.",
    )
    add_scores_option(p)
    p.add_argument("--top", type=int, default=10, metavar="N", help="how many entries of each kind (default: 10)")
    p.add_argument("--all", action="store_true", help="every entry")
    p.add_argument("--no-check", action="store_true", help="do not replay the games (faster, nothing flagged)")
    p.add_argument("--add", metavar="REPLAY", help="enter the game of a replay file (a game the table was too busy "
                   "to take, or one recorded with play --record); it is verified first")
    p.add_argument("--name", help="with --add: the player's name, if the replay has none")
    p.add_argument("--cache", metavar="DIR", help="folder of the verification cache (default: $ARMGAME_CACHE, "
                   "else ~/.cache/armgame)")
    p.set_defaults(run=run)


def verification_cache(args: argparse.Namespace):
    from ..records.scores import VerificationCache
    from ..records.storage import user_path

    return VerificationCache(user_path(args.cache, "--cache") if getattr(args, "cache", None) is not None else None)


def run(args: argparse.Namespace) -> int:
    import sys

    from ..errors import UserError
    from ..records.rulesets import RULESETS
    from ..records.scores import ScoreTable

    if args.top < 1:
        raise UserError(f"--top must be 1 or more, got {args.top}")
    if args.name is not None and args.add is None:
        raise UserError("--name goes with --add")
    cache = None if args.no_check else verification_cache(args)
    read_lab_replays()
    table = ScoreTable(scores_dir(args), warn=lambda m: print(f"armgame scores: {m}", file=sys.stderr), cache=cache)
    if args.add is not None:
        return _add(table, args)
    entries = table.all_entries()
    if not entries:
        print(f"no scores yet in {table.path}")
        return 0
    limit = None if args.all else args.top
    seen: set[str] = set()
    ranked, custom, flagged = [], [], []
    custom_checked = 0
    # Best first. Ranked games: checked until --top of them pass (each costs exactly its ruleset,
    # 15,000 steps, once per user thanks to the cache). Custom games cost up to MAX_GAME_STEPS each, so
    # at most --top of them are checked, flagged ones included: planted entries cannot keep it busy.
    for e in entries:
        is_ranked = table.ruleset(e) in RULESETS
        kind = ranked if is_ranked else custom
        if limit is not None and (len(ranked) if is_ranked else custom_checked) >= limit:
            continue
        custom_checked += not is_ranked
        if e.replay_sha256 in seen:
            flagged.append((e, _check("DUPLICATE", "the same replay is entered more than once")))
            continue
        seen.add(e.replay_sha256)
        c = None if args.no_check else table.check(e)
        if c is not None and not c.ok:
            flagged.append((e, c))
        else:
            kind.append((e, c))
    if cache is not None:
        cache.save()
    count = plural(len(entries), "entry")
    names = ", ".join(RULESETS)
    print(f"High scores in {table.path} ({count}; ranked: {names} games{'' if args.no_check else ', replays checked'})")
    _print_rows(ranked, args.no_check)
    if not ranked:
        print("  no ranked games yet")
    if custom:
        print(f"Custom games (their own rules: not ranked, not comparable with {names} games)")
        _print_rows(custom, args.no_check)
    if flagged:
        print(f"{len(flagged)} flagged: the replay does not back the score (not ranked)")
        for e, c in flagged:
            print(f"  {e.name} ({e.score}, {e.date[:16].replace('T', ' ')}): {c.label}: {c.detail}")
    return 0


def _check(label: str, detail: str):
    from ..records.scores import Check

    return Check(False, label, detail)


def _print_rows(rows_in, no_check: bool) -> None:
    rows = [("#", "name", "score", "hits", "resets", "driven", "seed", "length", "date", "version", "replay")]
    for rank, (e, c) in enumerate(rows_in, 1):
        when = e.when.astimezone().strftime("%Y-%m-%d %H:%M")
        rows.append((str(rank), e.name, str(e.score), str(e.hits), str(e.resets), e.how, str(e.seed),
                     f"{e.duration:g} s", when, e.version, "-" if c is None else c.label))
    if len(rows) == 1:
        return
    right = {0, 2, 3, 4, 6, 7}
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        cells = [c.rjust(w) if i in right else c.ljust(w) for i, (c, w) in enumerate(zip(r, widths, strict=True))]
        print("  ".join(cells).rstrip())


def _add(table, args: argparse.Namespace) -> int:
    from ..errors import UserError
    from ..records.replay import Replay, check_name
    from ..records.storage import user_path

    path = user_path(args.add, "--add")
    replay = Replay.load(path)
    if args.name is not None:
        try:
            name = check_name(args.name, "--name")
        except ValueError as exc:
            raise UserError(str(exc)) from None
        if replay.player is not None and replay.player != name:
            raise UserError(f"{path}: the replay is {replay.player}'s game, not {name}'s")
        replay = replay.with_player(name)
    if replay.player is None:
        raise UserError(f"{path}: the replay has no player's name: give --name")
    if not replay.complete:
        raise UserError(f"{path}: the game was stopped before its end: only a whole game enters the table")
    ok, got = replay.verify()
    if not ok:
        raise UserError(f"{path}: the replay does not reproduce its score (recorded {replay.result.score}, "
                        f"replayed {got.score}): not entered")
    same_file = path.parent.resolve() == table.replays.resolve() and args.name is None
    try:
        entry = table.add(replay, path if same_file else None)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    kind = "ranked" if table.ruleset(entry) != "custom" else "custom game, not ranked"
    print(f"entered {entry.name}'s game (score {entry.score}, {kind}): #{table.rank(entry)} in {table.path}")
    return 0
