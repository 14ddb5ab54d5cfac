"""armgame class: a live class served from the teacher's machine (serve), games handed in by hand
(submit), and the standings in a window for a room without a browser (show)."""

from __future__ import annotations

import argparse
from pathlib import Path

DEFAULT_PORT = 8765


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be from 0 to 65535, got {text!r}")
    return value


def add_join_options(p: argparse.ArgumentParser) -> None:
    """``--join HOST:PORT --code CODE``: shared by play, lab and class submit."""
    p.add_argument("--join", metavar="HOST:PORT", help="hand every finished game in to the live class at HOST:PORT "
                   "(the projector shows it; needs --code)")
    p.add_argument("--code", metavar="CODE", help="with --join: the class's code, as the projector shows it")


def register(subparsers: argparse._SubParsersAction) -> None:
    from . import seed_argument as _seed

    p = subparsers.add_parser(
        "class",
        help="a live class: serve it from the teacher's machine, hand games in, show the standings",
        description="A live class. The teacher runs 'armgame class serve'; it prints what students type "
        "(armgame play --join HOST:PORT --code CODE --name NAME), the projector's page and a secret for the "
        "teacher's page. Every game a student finishes is handed in by itself, verified by replaying it, and "
        "ranked on the projector, one row per student.",
    )
    sub = p.add_subparsers(dest="action", metavar="ACTION")
    serve = sub.add_parser("serve", help="serve the class from this machine (Ctrl-C stops it)",
                           description="Serve a class: the table lives in --folder (default: a new folder per class "
                           "under the per-user data folder); the same --folder again goes on with the same class, "
                           "code and secret. It listens only on --host (default: this machine's address on the "
                           "network with the default route).")
    serve.add_argument("--folder", metavar="DIR", help="the class's folder (default: a new one per class)")
    serve.add_argument("--host", metavar="HOST", help="the address to listen on (default: this machine's LAN "
                       "address; 127.0.0.1 for a trial on one machine)")
    serve.add_argument("--port", type=_port, default=DEFAULT_PORT, help=f"the port (default: {DEFAULT_PORT})")
    serve.add_argument("--seed", type=_seed, default=None, help="the seed the class ranks (a new class: default 10)")
    serve.add_argument("--lab", metavar="PRESET", help="the lab preset the class curve shows (a new class: lesson; "
                       "the teacher's page can change it)")
    serve.add_argument("--lab-b", metavar="PRESET", help="a classroom experiment: the second condition (a preset or a "
                       "protocol's .toml file) beside --lab's; each student is assigned one of the two at their first "
                       "join for the lab, at random in blocks of two (the groups stay within one of equal size), "
                       "and their lab is handed its protocol to run. Fixed for the class's life: only a new class "
                       "starts an experiment")
    serve.add_argument("--proxy", metavar="ADDRESS", help="a reverse proxy in front of the class connects from this "
                       "IP address: a request from it is the last address its X-Forwarded-For names, never the "
                       "teacher's machine (default: none, a client's address is its socket's)")
    serve.add_argument("--teacher-secret-always", action="store_true", help="the teacher's page asks for the secret "
                       "on this machine too (a shared lab PC: otherwise anyone using it is the teacher)")
    serve.add_argument("--rehearse", action="store_true", help="a rehearsal of the lesson: 15 s games and 30 s "
                       "rounds, in a temporary folder removed at Ctrl-C (nothing is kept; not with --folder)")
    serve.set_defaults(run=run_serve)
    submit = sub.add_parser("submit", help="hand replay files in to a class (games or lab runs)",
                            description="Hand replays in by hand: games kept while the class could not be reached, "
                            "games recorded with --record, lab runs. This machine joins under --name (or the name "
                            "it joined under before).")
    submit.add_argument("address", metavar="HOST:PORT")
    submit.add_argument("files", metavar="FILE", nargs="+")
    submit.add_argument("--code", required=True, help="the class's code")
    submit.add_argument("--name", help="the name to hand in under (default: the one this machine joined with)")
    submit.set_defaults(run=run_submit)
    show = sub.add_parser("show", help="the class's standings in a window (for a room without a browser)")
    show.add_argument("address", metavar="HOST:PORT")
    show.add_argument("--key", metavar="KEY", help="the projector link's key (after ?key= in the link the class "
                      "prints): shows the join code; not needed on the teacher's own machine")
    from ..ui.options import add_window_options

    add_window_options(show)
    show.set_defaults(run=run_show)
    p.set_defaults(run=lambda args: (p.print_help(), 0)[1])


def run_serve(args: argparse.Namespace) -> int:
    from ..classroom.serve import REHEARSE_NO_FOLDER, default_folder, lan_address, serve
    from ..errors import UserError
    from ..records.storage import user_path

    if args.rehearse and args.folder:
        raise UserError(REHEARSE_NO_FOLDER)
    folder = None if args.rehearse else user_path(args.folder, "--folder") if args.folder else default_folder()
    if folder is not None and folder.exists() and not folder.is_dir():
        raise UserError(f"--folder {folder}: not a folder")
    host = args.host or lan_address()
    if args.lab_b is not None and args.lab is None:
        raise UserError("--lab-b is the experiment's second condition: name the first with --lab")
    return serve(folder, host, args.port, args.seed, say=lambda line: print(line, flush=True), lab=args.lab,
                 proxy=args.proxy, rehearse=args.rehearse, lab_b=args.lab_b,
                 secret_always=args.teacher_secret_always)


def run_submit(args: argparse.Namespace) -> int:
    from ..classroom import client
    from ..errors import UserError
    from ..limits import MAX_REPLAY_BYTES
    from ..records.storage import read_limited, user_path
    from . import read_lab_replays

    read_lab_replays()
    address = client.ClassAddress.parse(args.address, "HOST:PORT")
    files: list[tuple[Path, bytes | None]] = []
    failed = 0
    for text in args.files:
        path = user_path(text, "FILE")
        try:
            files.append((path, read_limited(path, MAX_REPLAY_BYTES, "replay file")))
        except UserError as exc:
            print(f"{path}: {exc}")
            failed += 1
    # Lab runs alone join for the lab, which a closed class still takes (the lesson's volunteers hand theirs in
    # after the class closed to games); the class reads every file again, so a file's word is not trusted here.
    lab = bool(files) and all(_is_lab_run(data) for _, data in files)
    membership = client.join(address, args.code, args.name, lab=lab)
    if not membership.closed:  # a kept game would be refused in a closed class, and a refusal is final
        for line in client.send_outbox(membership):
            print(line)
    for path, data in files:
        result = client.hand_in(membership, data, keep=False)
        failed += result.refused
        print(f"{path}: {result.message}")
    return 1 if failed else 0


def _is_lab_run(data: bytes) -> bool:
    from ..files import DataFileError
    from ..records.replay import Replay

    try:
        return Replay.from_bytes(data, "the replay").task is not None
    except DataFileError:
        return False


def run_show(args: argparse.Namespace) -> int:
    from ..classroom.client import ClassAddress
    from ..ui.class_window import show_class
    from ..ui.options import window_settings

    address = ClassAddress.parse(args.address, "HOST:PORT")
    settings, _ = window_settings(args)
    if args.key is not None and (len(args.key) > 64 or not args.key.isalnum()):
        from ..errors import UserError

        raise UserError("--key: the letters and digits after ?key= in the projector's link")
    return show_class(address, settings, fullscreen=args.fullscreen, key=args.key)


def join_class(args: argparse.Namespace, lab: bool = False):
    """The class ``--join``/``--code`` name, joined (the outbox handed in first); None without --join.

    Sets ``args.name`` to the name joined under. A class that cannot be reached is played offline when
    this machine joined it before: its games wait in the outbox for the next join. ``lab``: joined for the
    lab, which a closed class takes (its games would be refused, so the outbox waits for it to open)."""
    import sys

    from ..classroom import client
    from ..errors import UserError

    if args.code is not None and args.join is None:
        raise UserError("--code goes with --join HOST:PORT")
    if args.join is None:
        return None
    if args.code is None:
        raise UserError("--join needs --code CODE: the class's code, as the projector shows it")
    address = client.ClassAddress.parse(args.join)
    try:
        membership = client.join(address, args.code, args.name, lab=lab)
    except client.UnreachableError as exc:
        membership = client.offline(address, args.code, args.name)
        if membership is None:
            raise
        print(f"armgame: {exc}; playing on: your games are kept and handed in the next time you join",
              file=sys.stderr)
    else:
        if membership.closed and not lab:  # before a game that could not be handed in, not after it
            raise UserError(f"the class at {address.label} is closed: it takes no more games (the teacher can open "
                            f"it again)")
        what = f"seed {membership.seed}" + (f"; a rehearsal: {membership.duration:g} s games" if membership.rehearsal
                                             else "")
        print(f"joined the class at {address.label} as {membership.name} ({what})", file=sys.stderr)
        if membership.closed:  # a kept game would be refused now, and a refusal is final: it waits for the class
            print("the class is closed to new games: it takes this lab run (games kept on this machine wait until "
                  "it opens)", file=sys.stderr)
        else:
            for line in client.send_outbox(membership):
                print(line, file=sys.stderr)
    args.name = membership.name
    return membership
