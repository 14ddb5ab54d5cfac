"""The class's refusal: a request turned down, with the status and the one line its client is sent.

Its own module, as Starlette keeps ``HTTPException`` in ``starlette/exceptions.py``: whoever refuses (an endpoint,
a check in the app, the clerk on its thread, the middleware, a page that is not there) raises it without importing
the clerk, and ``middleware.EXCEPTION_HANDLERS`` answers it. The student's client has its own (``client.RefusalError``,
a refusal as the client heard it).
"""

from __future__ import annotations


class RefusedError(Exception):
    """A request the class turns down: an HTTP status and one line saying why (sent as it is); for 429 and 503,
    the seconds after which to ask again (``Retry-After``)."""

    def __init__(self, status: int, message: str, retry_after: int = 2) -> None:
        super().__init__(message)
        self.status = status
        self.message = message
        self.retry_after = retry_after
