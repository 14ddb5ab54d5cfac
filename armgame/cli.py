"""The armgame command line. Parsing imports nothing heavy; each command imports what it needs."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from . import __version__
from .errors import UserError

# Commands whose module exists; each module's register() adds its parser.
COMMAND_MODULES = ("play", "simulate", "demo", "derive", "bench", "scores", "replay", "verify", "settings")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, not the whole usage block
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="armgame",
        description="Drive a simulated two-joint arm with four muscle keys, and explore its dynamics.",
    )
    parser.add_argument("--version", action="version", version=f"armgame {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMAND_MODULES:
        importlib.import_module(f"armgame.commands.{name}").register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return 0
    try:
        return int(args.run(args) or 0)
    except UserError as exc:
        print(f"armgame {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("armgame: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
