"""armgame scores: the high-score table, best first, each entry checked against its replay.

What a listing replays, counts and flags is ``records.listing``'s to decide; this command parses, prints
and adds a replay to the table.
"""

from __future__ import annotations

import argparse

from ..limits import DEFAULT_SEED
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
        help="the high-score table, best first, one row a player",
        description="Print the high-score table, best first (equal scores: the earlier entry first), one row a "
        "player: their best game and how many games they played (--all-games: every game). The ranked "
        "table holds keyboard games of the standard rules (the default 60 s game) and the table's seed "
        f"({DEFAULT_SEED} unless the table was started with --new --seed N); games of another seed are listed "
        "apart as practice, games a program played (bots, scripts) apart as programs, games of other rules apart "
        "as custom games. A game "
        "enters once, whatever name or date its copy carries. Each entry's replay is played again (once: "
        "verdicts, failures too, are cached per user): an entry whose replay is missing, changed or does not "
        "reproduce its score is flagged and not ranked; one that would cost more than a listing spends is listed "
        "apart, not ranked until armgame verify checks it.",
    )
    add_scores_option(p)
    p.add_argument("--top", type=int, default=10, metavar="N",
                   help="how many rows of each list: players, or games with --all-games (default: 10)")
    p.add_argument("--all", action="store_true", help="every row, every entry checked")
    p.add_argument("--all-games", action="store_true",
                   help="a row for every game, not one a player (a player's games each ranked)")
    p.add_argument("--no-check", action="store_true", help="do not replay the games (faster, nothing flagged)")
    p.add_argument("--add", metavar="REPLAY", help="enter the game of a replay file (a game the table was too busy "
                   "to take, or one recorded with play --record); it is verified first")
    p.add_argument("--name", help="with --add: the player's name, if the replay has none")
    p.add_argument("--new", action="store_true", help="start an empty table in the --scores folder (with --seed: "
                   "the seed it ranks); this account then keeps its own record of the table's seed and of the order "
                   "of the games it enters, which its listings follow wherever the shared file says otherwise")
    p.add_argument("--seed", type=_seed_arg, metavar="N", help="with --new: the seed the table ranks "
                   f"(default: {DEFAULT_SEED}, the default game's)")
    p.add_argument("--cache", metavar="DIR", help="folder of the verification cache (default: $ARMGAME_CACHE, "
                   "else the per-user cache folder, ~/.cache/armgame on Linux)")
    p.set_defaults(run=run)


def _seed_arg(text: str) -> int:
    from . import seed_argument as _seed

    return _seed(text)


def verification_cache(args: argparse.Namespace, warn=None):
    from ..records.cache import VerificationCache
    from ..records.storage import user_path

    folder = user_path(args.cache, "--cache") if getattr(args, "cache", None) is not None else None
    return VerificationCache(folder, warn=warn)


def run(args: argparse.Namespace) -> int:
    import sys

    from ..errors import UserError
    from ..records.scores import ScoreTable
    from ..records.storage import user_path

    if args.top < 1:
        raise UserError(f"--top must be 1 or more, got {args.top}")
    if args.name is not None and args.add is None:
        raise UserError("--name goes with --add")
    if args.seed is not None and not args.new:
        raise UserError("--seed goes with --new (a table ranks one seed, set when it is started)")
    if args.new and args.add is not None:
        raise UserError("--new starts an empty table: give --add in a second command")

    def warn(message: str) -> None:
        print(f"armgame scores: {message}", file=sys.stderr)

    cache = None if args.no_check or args.new else verification_cache(args, warn)
    read_lab_replays()
    records = user_path(args.cache, "--cache") if args.cache is not None else None  # the teacher's record's folder
    table = ScoreTable(scores_dir(args), warn=warn, cache=cache, records=records)
    if args.new:

        seed = DEFAULT_SEED if args.seed is None else args.seed
        table.new(seed)
        print(f"started an empty table in {table.folder}: it ranks standard games of seed {seed}")
        return 0
    if args.add is not None:
        return _add(table, args)
    entries = table.all_entries()
    if not entries:
        print(f"no scores yet in {table.path}")
        return 0
    hidden = _hidden_by_the_teacher(table.folder, warn)
    if hidden:  # a live class's folder: the names its teacher hid stay off every list of it
        from ..records.standings import player_key

        entries = [e for e in entries if player_key(e.name) not in hidden]
        print(f"{plural(len(hidden), 'name')} hidden by the class's teacher (armgame class serve): not listed")
    limit = None if args.all else args.top
    per_player = not args.all_games
    from ..records.listing import listing

    lists, flagged = listing(table, entries, limit, check=not args.no_check, per_player=per_player)
    if cache is not None:
        cache.save()
    _print_listing(table, len(entries), lists, flagged, args.no_check, _games_note(per_player, limit, args.no_check))
    return 0


def _hidden_by_the_teacher(folder, warn) -> set[str]:
    """The names the teacher hid in the live class kept in ``folder`` (its ``class.json``), by player key; none
    where the folder is not a class's. A class record that cannot be read is said once, and hides nothing."""
    from ..classroom.roster import ROSTER_NAME, Roster
    from ..errors import UserError

    if not (folder / ROSTER_NAME).exists():
        return set()
    try:
        roster, _ = Roster.open(folder, None)
    except UserError as exc:
        warn(f"{exc} (the names its teacher hid are listed)")
        return set()
    return set(roster.hidden)


def _games_note(per_player: bool, limit: int | None, no_check: bool) -> str | None:
    """What the "games" column counts (``records.listing.listing``'s docstring), or None without one."""
    if not per_player:
        return None
    if no_check:
        return "One row a player, at their best game; games: their entries in the list (no replay checked)"
    if limit is None:
        return "One row a player, at their best game; games: their games in the list that check out"
    return ("One row a player, at their best game (its replay checked); games: their entries in the list, "
            "flagged ones not counted (--all checks every game)")


def _print_listing(table, count: int, lists, flagged, no_check: bool, note: str | None = None) -> None:
    """Print ``records.listing.listing``'s lists and flagged entries."""
    from ..records.listing import COSTLY
    from ..records.scores import LIST_TITLES, RANKED

    checked = "" if no_check else ", replays checked"
    print(f"High scores in {table.path} ({plural(count, 'entry')}{checked})")
    print(f"Ranked: keyboard games of the standard rules, seed {table.seed}")
    _print_rows(lists[RANKED], note is not None)
    if not lists[RANKED]:
        print("  no ranked games yet")
    for name, title in LIST_TITLES.items():
        if name != RANKED and lists[name]:
            print(title[0].upper() + title[1:])
            _print_rows(lists[name], note is not None)
    if note is not None and any(lists[name] for name in LIST_TITLES):
        print(note)
    if lists.get(COSTLY):
        print(f"{len(lists[COSTLY])} not checked yet (costly replay: armgame verify checks it; not ranked until then)")
        for row in lists[COSTLY]:
            e, c = row.best
            print(f"  {e.name} ({e.score}, {e.date[:16].replace('T', ' ')}): {c.label}: {c.detail}")
    if flagged:
        print(f"{len(flagged)} flagged: the replay does not back the score (not ranked)")
        for e, c in flagged:
            print(f"  {e.name} ({e.score}, {e.date[:16].replace('T', ' ')}): {c.label}: {c.detail}")


def _print_rows(rows_in, games: bool) -> None:
    """The rows of one list (``records.listing.listing``'s), ranked (equal scores share a place:
    ``standings.places``); ``games``: with the column of each player's games."""
    from ..records.standings import places

    rows = [("#", "name", "score", *(("games",) if games else ()), "hits", "resets", "driven", "seed", "length",
             "date", "version", "replay")]
    for rank, row in zip(places(row.best[0].score for row in rows_in), rows_in, strict=True):
        e, c = row.best
        when = e.when.astimezone().strftime("%Y-%m-%d %H:%M")
        rows.append((str(rank), e.name, str(e.score), *((str(row.games),) if games else ()), str(e.hits),
                     str(e.resets), e.how, str(e.seed), f"{e.duration:g} s" if e.complete is not False else "stopped",
                     when, e.version, "-" if c is None else c.label))
    if len(rows) == 1:
        return
    right = {0, 2, 3, 4, 6, 7} if not games else {0, 2, 3, 4, 5, 7, 8}
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        cells = [c.rjust(w) if i in right else c.ljust(w) for i, (c, w) in enumerate(zip(r, widths, strict=True))]
        print("  ".join(cells).rstrip())


def _add(table, args: argparse.Namespace) -> int:
    from ..errors import UserError
    from ..records.replay import Replay
    from ..records.storage import user_path
    from ..valid import check_name

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
    twin = _already_in(table, replay)
    if twin is not None:  # the collecting loop run again: nothing to do, and nothing wrong
        print(f"already in: {twin.name}'s game (score {twin.score}, entry #{twin.entered})")
        return 0
    from ..records.replay import VerifyCostError

    try:
        ok, got = replay.verify()
    except VerifyCostError as exc:  # a hit storm: one line naming the file, after a bounded try
        raise UserError(f"{path}: {exc}: not entered") from None
    if not ok:
        raise UserError(f"{path}: the replay does not reproduce its score (recorded {replay.result.score}, "
                        f"replayed {got.score}): not entered")
    same_file = path.parent.resolve() == table.replays.resolve() and args.name is None
    try:
        entry = table.add(replay, path if same_file else None)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    print(f"entered {entry.name}'s game (score {entry.score}): {where_it_went(table, entry)}")
    return 0


def _already_in(table, replay):
    """The entry that holds ``replay``'s game, as it claims it, under its own player's name; or None (another
    name's copy, or other claims for the same game, go on to the checks that refuse them)."""
    from ..records.identity import game_digests
    from ..records.standings import player_key

    digests = set(game_digests(replay))
    r = replay.result
    return next((e for e in table.all_entries() if e.game_sha256 in digests
                 and player_key(e.name) == player_key(replay.player)
                 and (e.score, e.hits, e.resets) == (r.score, r.hits, r.resets)), None)


def where_it_went(table, entry) -> str:
    """One line: the place of the entry's player (one row a player: ``ScoreTable.rank``) and the list it
    went to (``armgame scores`` and ``play`` say it)."""
    from ..records.scores import LIST_TITLES

    return f"#{table.rank(entry)} in {LIST_TITLES[table.list_of(entry)]} ({table.path})"
