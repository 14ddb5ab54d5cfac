"""The envs' one error for a bad argument, below every env module (``base`` and ``features`` both raise it,
and neither imports the other for it)."""

from __future__ import annotations

from ..errors import UserError


class EnvArgumentError(UserError, ValueError):
    """A bad argument to an env: one line naming it (a ``ValueError`` too, as Gymnasium users expect)."""
