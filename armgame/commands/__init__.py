"""One module per subcommand. Each defines ``register(subparsers)``.

These modules import only the standard library at the top (and armgame's modules below every
layer, which import nothing else): ``armgame --help`` and the parsing of every command must not
pay for numpy, scipy or pygame. Heavy imports go inside
each command's ``run``. A command that opens a window sets ``without_window``: the command line
that does the same without one, which the CLI prints when no display can be opened.
"""

from __future__ import annotations

import argparse
import contextlib
import shlex
from collections.abc import Sequence

from ..valid import INT64_MAX


def command_line(typed: Sequence[str], *added: str) -> str:
    """``armgame`` with the arguments the user typed and ``added``, quoted to paste into a shell."""
    return shlex.join(["armgame", *typed, *added])


def seed_argument(text: str) -> int:
    """``--seed``'s type: a game's seed, a whole number from 0 to 2^63 - 1. Here, below the commands that
    take one (play, lab, scores --new, class), so that none imports another for it."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 0 <= value <= INT64_MAX:
        raise argparse.ArgumentTypeError(f"must be from 0 to 2^63 - 1, got {text!r}")
    return value


def read_lab_replays() -> None:
    """Make a lab run's replay readable here: its task section's reader is the lab's, which it
    registers with records (a lower layer, which never imports the lab). Every command that reads
    replays calls this before it reads one, so none depends on what happened to be imported first."""
    from ..lab.record import register

    register()


def read_env_games() -> None:
    """Make a Gymnasium env's game readable here (``armgame.records.env_game``: its variant and muscle levels);
    the commands that verify or replay games call it. The class and the table never do: a replay with a task
    section is never a ranked game, and an unregistered kind is refused in one line."""
    from ..records.env_game import register
    from ..records.replay import register_task

    register()
    with contextlib.suppress(ValueError):  # armgame.env.record registered its own, which reads the same class
        register_task("centre-out-env", _read_centre_out)


def _read_centre_out(section: object, config: object, last_step: int) -> object:
    """A CenterOut env's section, read by ``armgame.env.record`` (above the lab): it needs Gymnasium's extra."""
    try:
        from ..env.record import CenterOutEnvTask
    except ImportError as exc:
        raise ValueError(f"a CenterOut env's episode: verifying it needs Gymnasium (pip install 'armgame[gym]'): "
                         f"{exc}") from None
    return CenterOutEnvTask.from_dict(section, config, last_step)  # type: ignore[arg-type]
