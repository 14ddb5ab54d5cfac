"""The armgame command line. Parsing imports nothing heavy; each command imports what it needs."""

from __future__ import annotations

import argparse
import contextlib
import importlib
import itertools
import os
import re
import signal
import sys
from collections.abc import Sequence
from typing import NoReturn

from . import __version__
from .errors import NoDisplayError, UserError
from .words import closest

# Commands whose module exists; each module's register() adds its parser.
COMMAND_MODULES = ("play", "simulate", "demo", "derive", "bench", "scores", "replay", "verify", "lab", "analyze",
                   "settings", "classroom")


class _Parser(argparse.ArgumentParser):
    """Errors in one line that name the command (``armgame demo: error: ...``), not the usage block."""

    def parse_known_args(self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
                         ) -> tuple[argparse.Namespace, list[str]]:
        self._arg_strings = list(sys.argv[1:] if args is None else args)  # for error()'s hint
        return super().parse_known_args(args, namespace)

    def _check_value(self, action: argparse.Action, value: object) -> None:
        # The closest valid name first. Asked of the parser rather than read back out of argparse's
        # message, whose quoting of the choices changed in Python 3.12.8 and 3.13.1.
        choices = action.choices
        if choices is not None and isinstance(value, str) and value not in choices:
            close = closest(value, [str(c) for c in choices])
            if close is not None:
                raise argparse.ArgumentError(action, f"invalid choice: {value!r}: did you mean {close}? "
                                                     f"(choose from {', '.join(map(str, choices))})")
        super()._check_value(action, value)

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}{_dash_value_hint(message, getattr(self, '_arg_strings', []))}\n")


def _dash_value_hint(message: str, arg_strings: Sequence[str]) -> str:
    """For ``--initial -60,0``: argparse reads a value starting with '-' as an option; say how to pass it."""
    found = re.match(r"argument (\S+): expected one argument", message)
    if not found:
        return ""
    names = found.group(1).split("/")
    for option, value in itertools.pairwise(arg_strings):
        if option in names and value.startswith("-"):
            return f" (for a value starting with '-', join it with '=': {option}={value})"
    return ""


def _spaced_name_hint(argv: Sequence[str] | None, extra: Sequence[str]) -> str:
    """For ``--name Ann B``: the shell split the name at its space; say how to keep it whole."""
    words = list(sys.argv[1:] if argv is None else argv)
    if "--name" not in words[:-2] or not extra:
        return ""
    at = words.index("--name")
    rest = list(itertools.takewhile(lambda w: not w.startswith("-"), words[at + 2:]))
    if not rest or rest[0] != extra[0]:  # the word left over is not the name's second half
        return ""
    return f' (a name with a space goes in quotes: --name "{" ".join([words[at + 1], *rest])}")'


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="armgame",
        description="Drive a simulated two-joint arm with four muscle keys, and explore its dynamics.",
    )
    parser.add_argument("--version", action="version", version=f"armgame {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMAND_MODULES:
        importlib.import_module(f"armgame.commands.{name}").register(subparsers)
    parser.set_defaults(_commands=subparsers.choices)
    return parser


#: The exit status when the reader of the output left early (``armgame scores | head``): a shell's for a
#: process ended by SIGPIPE, 128 + 13; 1 where there is no such signal (Windows).
EXIT_BROKEN_PIPE = 128 + getattr(signal, "SIGPIPE", -127)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command ``argv`` (the command line's arguments if None); returns the exit status."""
    try:
        try:
            return _main(argv)
        finally:
            # Flushed here, so a reader that left early is found inside this try, not at the interpreter's
            # exit (which would print "Exception ignored ... BrokenPipeError").
            sys.stdout.flush()
    except BrokenPipeError:
        # The recipe of Python's signal docs: what is still buffered goes to devnull, not to the closed pipe
        # at exit; nothing is said (the reader is gone, and stderr may be the same pipe).
        with contextlib.suppress(OSError, ValueError):
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE


def _main(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    args, extra = parser.parse_known_args(argv)
    if extra:  # left over by the command's parser: its error, under its name
        parser_of_command = args._commands.get(getattr(args, "command", None), parser)
        parser_of_command.error(f"unrecognized arguments: {' '.join(extra)}{_spaced_name_hint(argv, extra)}")
    command = getattr(args, "command", None)
    if command is None:  # `armgame` alone: the menu, or the commands without a display
        from .commands import menu

        def run() -> object:
            return menu.run(parser, main)
    elif getattr(args, "run", None):
        def run() -> object:
            return args.run(args)
    else:
        parser.print_help()
        return 0
    who = f"armgame {command}" if command else "armgame"
    try:
        return int(run() or 0)
    except NoDisplayError as exc:
        # The same command without a window, as the user can run it: their arguments, and what it needs.
        without = getattr(args, "without_window", None)
        typed = list(sys.argv[1:] if argv is None else argv)
        tail = f"; run it without one: {without(args, typed)}" if without else ""
        print(f"{who}: error: {exc}{tail}", file=sys.stderr)
        return 2
    except UserError as exc:
        print(f"{who}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("armgame: interrupted", file=sys.stderr)
        return 130

if __name__ == "__main__":
    sys.exit(main())
