"""The class's pages: the projector's standings, the lab's class curve and the teacher's controls.

Static files in ``static/``, served only by name from a fixed list (a path from a client is never
used). The HTML holds no data and no inline script: each page's script asks ``/api/...`` and the
event stream for JSON and sets every name and number as text (``textContent``), so a name such as
``<script>`` or one with right-to-left marks shows as the characters it is. The projector's sizes
follow the window (CSS viewport units, 19 px at the least at 1024x768) in the high-contrast palette
of the game's windows (``ui.render.PALETTES["high-contrast"]``): black on white, red for news.
"""

from __future__ import annotations

from functools import cache
from importlib import resources

from starlette.responses import Response

from .intake import RefusedError

PAGES = {
    "standings.html": "text/html; charset=utf-8",
    "lab.html": "text/html; charset=utf-8",
    "teacher.html": "text/html; charset=utf-8",
    "class.css": "text/css; charset=utf-8",
    "standings.js": "text/javascript; charset=utf-8",
    "lab.js": "text/javascript; charset=utf-8",
    "teacher.js": "text/javascript; charset=utf-8",
    "engine.js": "text/javascript; charset=utf-8",  # the game's engine, an ES module (the student's page imports it)
}


@cache
def _read(name: str) -> bytes:
    return resources.files(__package__).joinpath("static", name).read_bytes()


def response(name: str, headers: dict[str, str]) -> Response:
    """The static file ``name`` if it is one of ``PAGES``; else 404 (the name is never used as a path)."""
    media = PAGES.get(name)
    if media is None:
        raise RefusedError(404, "no such page")
    return Response(_read(name), 200, headers, media_type=media)
