"""One module per subcommand. Each defines ``register(subparsers)``.

These modules import only the standard library at the top: ``armgame --help`` and the
parsing of every command must not pay for numpy, scipy or pygame. Heavy imports go inside
each command's ``run``. A command that opens a window sets ``without_window``: the command line
that does the same without one, which the CLI prints when no display can be opened.
"""

from __future__ import annotations

import shlex
from collections.abc import Sequence


def command_line(typed: Sequence[str], *added: str) -> str:
    """``armgame`` with the arguments the user typed and ``added``, quoted to paste into a shell."""
    return shlex.join(["armgame", *typed, *added])


def read_lab_replays() -> None:
    """Make a lab run's replay readable here: its task section's reader is the lab's, which it
    registers with records (a lower layer, which never imports the lab). Every command that reads
    replays calls this before it reads one, so none depends on what happened to be imported first."""
    from ..lab.record import register

    register()
