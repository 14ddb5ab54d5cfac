"""One module per subcommand. Each defines ``register(subparsers)``.

These modules import only the standard library at the top: ``armgame --help`` and the
parsing of every command must not pay for numpy, scipy or pygame. Heavy imports go inside
each command's ``run``.
"""
