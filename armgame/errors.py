"""The one base class for errors a user can cause and fix (bad parameters, files, arguments).

The CLI prints these as one line and exits non-zero; anything else is a bug and keeps its traceback.
"""


class UserError(Exception):
    """A problem with what the user asked for, explained in one line."""


class NoDisplayError(UserError):
    """No window can be opened here. The command line adds the command that runs without one."""
