"""The class's pages: the projector's standings, the lab's class curve and the teacher's controls.

Static files in ``static/``, served only by name from a fixed list (a path from a client is never
used). The HTML holds no data and no inline script: each page's script asks ``/api/...`` and the
event stream for JSON and sets every name and number as text (``textContent``), so a name such as
``<script>`` or one with right-to-left marks shows as the characters it is. The projector's sizes
follow the window (CSS viewport units, 19 px at the least at 1024x768) in the high-contrast palette
of the game's windows (``ui.render.PALETTES["high-contrast"]``): black on white, red for news.
``play.html`` is the game itself for a browser (``/play``): ``engine.js`` plays it, ``play.js`` draws it
(``body.js``: the arm and torso), ``kept.js`` keeps what the browser keeps (names, tokens, games not yet taken).
When the teacher has every browser run the lab, ``labpage.js`` runs it there: ``labengine.js`` plays the server's
plan, ``labmeasure.js`` measures each reach for the student, ``labview.js`` draws the scene and sets the words.
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
    "play.html": "text/html; charset=utf-8",
    "play.css": "text/css; charset=utf-8",
    "play.js": "text/javascript; charset=utf-8",
    "engine.js": "text/javascript; charset=utf-8",
    "body.js": "text/javascript; charset=utf-8",
    "kept.js": "text/javascript; charset=utf-8",
    "labengine.js": "text/javascript; charset=utf-8",
    "labmeasure.js": "text/javascript; charset=utf-8",
    "labview.js": "text/javascript; charset=utf-8",
    "labpage.js": "text/javascript; charset=utf-8",
    "icon.svg": "image/svg+xml",
}


@cache
def _read(name: str) -> bytes:
    return resources.files(__package__).joinpath("static", name).read_bytes()


def response(name: str) -> Response:
    """The static file ``name`` if it is one of ``PAGES``; else 404 (the name is never used as a path). The
    security headers (no inline script) are the app's middleware's, as on every answer."""
    media = PAGES.get(name)
    if media is None:
        raise RefusedError(404, "no such page")
    return Response(_read(name), 200, media_type=media)


@cache
def qr_svg(url: str) -> bytes:
    """``url`` as a QR code in SVG (made once): black on white, sized by the page, a quiet zone of 4 modules
    (what the standard asks, so a phone's camera finds the code on any background)."""
    import io

    import segno

    out = io.BytesIO()
    segno.make(url, error="m").save(out, kind="svg", border=4, omitsize=True, xmldecl=False, dark="#000",
                                    light="#fff")
    return out.getvalue()
