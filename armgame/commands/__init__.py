"""One module per subcommand. Each defines ``register(subparsers)``.

These modules import only the standard library at the top: ``armgame --help`` and the
parsing of every command must not pay for numpy, scipy or pygame. Heavy imports go inside
each command's ``run``.
"""


def read_lab_replays() -> None:
    """Make a lab run's replay readable here: its task section's reader is the lab's, which it
    registers with records (a lower layer, which never imports the lab). Every command that reads
    replays calls this before it reads one, so none depends on what happened to be imported first."""
    from ..lab.record import register

    register()
