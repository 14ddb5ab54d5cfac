"""armgame scores: the high-score table, best first, each entry checked against its replay."""

from __future__ import annotations

import argparse

from ..limits import DEFAULT_SEED
from ..words import plural
from . import read_lab_replays

SCORES_HELP = ("folder of the high-score table (default: $ARMGAME_SCORES, else scores/ in a checkout, "
               "else ~/.local/share/armgame/scores)")


#: The most work ``scores`` spends recomputing one game, in physics steps of the compiled loop
#: (``records.checking.replay_work``: steps, 100 a claimed hit under a ranked ruleset and 6,000 under others,
#: 20 an input event): about 0.13 s. Three times the largest honest game measured: the model bot's standard
#: game of seed 18, 333,900 (15,000 steps, 50 hits, 15,695 events); the naive bot's largest is 64,720 and
#: a keyboard player pressing each of the four keys 20 times a second 214,960 (``python
#: benchmarks/honest_work.py``: both bots on seeds 0 to 41). A game of more (a long clock, a "hit storm"
#: claiming thousands of hits, a replay of 100,000 events) is listed apart, not checked yet and not ranked:
#: ``armgame verify`` checks it, whatever it costs, and the next listing has its verdict.
MAX_CHECK_WORK = 1_000_000
#: The rows of ``listing`` left unchecked for their cost (one a game): listed apart, neither flagged nor ranked.
COSTLY = "costly"
#: The fewest entries ``listing`` checks together (batches recompute many games at once): a list still
#: wanting rows checks at least this many of the entries below, not one game at a time.
MIN_BATCH = 256


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


def listing(table, entries, limit: int | None, check: bool, per_player: bool = True):
    """Each list's rows best first, at most ``limit`` each, and the flagged entries ``(entry, check)``.

    A row is a ``standings.PlayerRow`` whose ``best`` is ``(entry, check)``: with ``per_player``, one a
    player (``standings.one_row_per_player``), their best game that checks out and how many games they
    played in that list; else one a game (``games`` 1), as ``--all-games`` lists them.

    Cost: no replay is read without ``check``. With it, entries are checked best first, in batches
    (``records.batch_verify``), only while a list still wants rows: at most ``limit`` rows (players) of
    each list of standard games (each costs exactly its ruleset's steps, once per user: verdicts,
    failures too, are cached), and at most ``limit`` custom games, flagged ones included (their cost
    is their own). Once a player has a row, their entries below it are not replayed (but for those in
    the batch that found it, checked together). So a row's
    ``games`` is the player's entries in its list less those found flagged (a check failed, or a copy of
    an earlier game): with a limit, their games below the best count as entered; with none (``--all``:
    every entry is checked), only games that check out count. Which of two entries of one game counts,
    and which is the copy, is ``records.identity.FirstEntries``'s to say; the entries flagged are those
    met on the way. A game whose replay costs more than ``MAX_CHECK_WORK`` is a row of ``lists[COSTLY]``
    (one a game): not checked yet, so neither flagged nor ranked.
    """
    from ..records.batch_verify import check_entries
    from ..records.identity import FirstEntries
    from ..records.scores import CUSTOM_GAMES, LIST_TITLES, NOT_CHECKED, sort_key
    from ..records.standings import PlayerRow, one_row_per_player, player_key

    first: FirstEntries = FirstEntries()
    counted: dict[str, list] = {name: [] for name in LIST_TITLES}  # (entry, check) of each list's games
    players: dict[str, set[str]] = {name: set() for name in LIST_TITLES}  # who has a row, by list
    flagged: list = []
    costly: list = []
    custom_checked = 0

    def who(e) -> str:
        return player_key(e.name) if per_player else e.id

    def wants(e, custom_in_batch: int) -> bool:
        twin = first.counted_file(e.replay_sha256)
        if twin is not None:  # a replay file already counted: the copy is flagged unread
            flagged.append((e, _duplicate(twin)))
            return False
        name = table.list_of(e)
        if limit is None:
            return True
        if who(e) in players[name]:  # their row is found: a game below it is counted, not replayed
            counted[name].append((e, None))
            return False
        if name == CUSTOM_GAMES:  # each may cost up to MAX_GAME_STEPS: never more than --top of them
            return custom_checked + custom_in_batch < limit
        return len(players[name]) < limit

    pending = sorted(entries, key=sort_key)
    size = max(2 * limit, MIN_BATCH) if limit else max(1, len(pending))

    def check_batch(batch: list) -> None:
        results = check_entries(table, batch, MAX_CHECK_WORK) if check else ((e, None) for e in batch)
        for e, c in results:
            name = table.list_of(e, c)
            if limit is not None and name != CUSTOM_GAMES and len(players[name]) >= limit \
                    and who(e) not in players[name]:
                continue
            # Unchecked (--no-check), an entry is taken at its word: the earlier of two counts.
            twin = first.copy_of(e, e.replay_sha256, None if c is None else c.game, c is None or c.ok)
            if c is not None and c.label == NOT_CHECKED:
                costly.append(PlayerRow(e.name, (e, c), 1))  # honest or not, nobody knows yet: verify checks it
            elif c is not None and not c.ok:
                flagged.append((e, c))
            elif twin is not None:
                flagged.append((e, _duplicate(twin)))
            else:
                players[name].add(who(e))
                counted[name].append((e, c))

    # One pass, best first: an entry its list no longer wants now is never wanted later (lists only fill).
    batch: list = []
    custom_in_batch = 0
    for e in pending:
        if not wants(e, custom_in_batch):
            continue
        batch.append(e)
        custom_in_batch += table.list_of(e) == CUSTOM_GAMES
        if len(batch) >= size:
            custom_checked += custom_in_batch  # counted as listed before the check: an old entry's may rank it
            check_batch(batch)
            batch, custom_in_batch = [], 0
    if batch:
        check_batch(batch)
    lists = {}
    for name, games in counted.items():
        games.sort(key=lambda game: sort_key(game[0]))
        lists[name] = (one_row_per_player(games, lambda game: game[0].name) if per_player
                       else [PlayerRow(e.name, (e, c), 1) for e, c in games])
    lists[COSTLY] = costly
    return lists, flagged


def _duplicate(twin):
    when = (twin.entered_at or twin.date)[:16].replace("T", " ")
    return _check("DUPLICATE", f"the same game as {twin.name}'s entry of {when}, which counts")


def _games_note(per_player: bool, limit: int | None, no_check: bool) -> str | None:
    """What the "games" column counts (``listing``'s docstring), or None without one."""
    if not per_player:
        return None
    if no_check:
        return "One row a player, at their best game; games: their entries in the list (no replay checked)"
    if limit is None:
        return "One row a player, at their best game; games: their games in the list that check out"
    return ("One row a player, at their best game (its replay checked); games: their entries in the list, "
            "flagged ones not counted (--all checks every game)")


def _print_listing(table, count: int, lists, flagged, no_check: bool, note: str | None = None) -> None:
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


def _check(label: str, detail: str):
    from ..records.scores import Check

    return Check(False, label, detail)


def _print_rows(rows_in, games: bool) -> None:
    """The rows of one list (``listing``'s), ranked; ``games``: with the column of each player's games."""
    rows = [("#", "name", "score", *(("games",) if games else ()), "hits", "resets", "driven", "seed", "length",
             "date", "version", "replay")]
    for rank, row in enumerate(rows_in, 1):
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
