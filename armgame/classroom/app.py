"""The class's ASGI application: Starlette routes in front of the clerk thread.

Every request is hostile until checked, and what it can cost is bounded before any work starts
(a connection's own costs, before it is a request, are ``guard``'s):

* only the class's own pages can change anything: a state-changing request must be JSON
  (``Content-Type: application/json``, which a page on another site cannot send without a
  preflight the class never grants), and its ``Origin`` and ``Sec-Fetch-Site``, where sent, must
  be the class's own; every request must name the class by an address, never by a domain name
  (``Host``), so a hostile page cannot rebind its own name to the class;
* wrong join codes, wrong teacher's secrets and wrong tokens are counted apart, per client address
  (``Guesses``): ``FREE_GUESSES`` of each, then a wait that doubles with every further wrong one,
  so a four-letter code (160,000 of them) is beyond guessing (about a dozen tries an hour from an
  address) while a student who mistyped it waits a minute; a right answer clears the count, and
  the teacher's own machine is never locked out of the teacher's routes;
* new names are limited per address (``JOINS_PER_MINUTE``) and for the whole class
  (``CLASS_JOINS_PER_MINUTE``); the teacher sees which names came from one address, removes them
  at once, and can lock the roster;
* a body over its limit is refused from its declared length, or cut off as it arrives (413);
  a body slower than ``BODY_SECONDS`` is cut off (408); at most ``UPLOADS`` bodies are read at
  once and, apart, ``SMALL_UPLOADS`` declared no longer than ``SMALL_UPLOAD_BYTES`` (a student's
  game: a few machines trickling bodies cannot hold every place), ``UPLOADS_PER_ADDRESS`` from one
  address, and a hand-in's code and token are checked from its headers before its body is read, so
  memory stays under ``UPLOADS * MAX_HANDIN_BYTES + SMALL_UPLOADS * SMALL_UPLOAD_BYTES`` (and the
  queued bodies under ``QUEUE_BYTES``) whatever arrives;
* changes go to one worker thread (the ``Clerk``'s, ``worker``), never the event loop; at most ``QUEUE_LIMIT``
  jobs and ``HANDIN_QUEUE`` hand-ins wait for it, one hand-in a player (``TOKEN_SHARE``, checked
  before the body is read, with the token), and past that a client is told to
  come back (503 with Retry-After): its replay stays on its machine, and the client hands it in again;
* a hand-in is answered only after the clerk has written it durably (fsynced file and folder);
* the projector's event stream sends the latest standings, never a backlog, to at most
  ``MAX_STREAMS`` pages, ``STREAMS_PER_ADDRESS`` from one address; the projector's own page
  (its link's key, or the teacher's machine) always gets its stream;
* the join code is in no answer a stranger can fetch: the standings carry it only to the projector's
  link (``?key=``, printed in the teacher's terminal) and to the teacher's machine.

Every bound named here is in ``bounds``, with its reason.

Responses are JSON (``{"ok": false, "error": "one line"}`` when refused) or the static pages,
served with a content security policy that allows no inline script: names reach a page only as
data that its script sets as text.

The app is Starlette's own shape: an endpoint is a module-level ``async def name(request)`` reading
the class from ``request.app.state.armgame`` (``state.ClassState``, where the queue's bounds and the
counts per address live); ``ROUTES`` is the table of them; a refusal anywhere is raised as
``RefusedError`` and answered by the exception handlers, and the security headers, the same-site
check and a bug's one line are middleware (``middleware``); ``lifespan`` runs the clerk's thread
(``worker``); ``build_app`` puts them together. What the pages show is built by ``views``.
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import json
import math
from collections import Counter
from collections.abc import AsyncIterator, Awaitable, Callable, Iterator
from contextlib import asynccontextmanager
from typing import Any

from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.requests import ClientDisconnect, Request
from starlette.responses import Response, StreamingResponse
from starlette.routing import Route

from ..errors import UserError
from . import page, views
from .bounds import (
    BODY_SECONDS,
    HEARTBEAT_SECONDS,
    JOINS_PER_MINUTE,
    MAX_HANDIN_BYTES,
    MAX_JSON_BYTES,
    MAX_STREAMS,
    SMALL_UPLOAD_BYTES,
    STREAMS_PER_ADDRESS,
    UPLOAD_WAIT,
    UPLOADS_PER_ADDRESS,
)
from .errors import RefusedError
from .guard import Guard
from .intake import NOT_JOINED, Clerk
from .middleware import EXCEPTION_HANDLERS, ForwardedFor, OneLineErrors, SameSite, SecurityHeaders, json_answer
from .state import ClassState, Guesses, client_address
from .wire import BUSY
from .worker import ClerkThread


# ---------------------------------------------------------------------- what the endpoints check
def _state(request: Request) -> ClassState:
    return request.app.state.armgame


def _bearer(request: Request) -> str | None:
    value = request.headers.get("authorization", "")
    scheme, _, token = value.partition(" ")
    return token.strip() or None if scheme.lower() == "bearer" and len(token) <= 200 else None


def _waiting(guesses: Guesses, address: str, what: str) -> None:
    wait = guesses.blocked_for(address)
    if wait > 0:
        raise RefusedError(429, f"too many wrong {what} from this machine: wait {math.ceil(wait)} s, then check it "
                                f"again", retry_after=math.ceil(wait))


async def _body(request: Request, limit: int) -> bytes:
    """The request's body, at most ``limit`` bytes, within ``BODY_SECONDS``; else RefusedError."""
    declared = request.headers.get("content-length")
    if declared is not None and (not declared.isdigit() or int(declared) > limit):
        raise RefusedError(413, f"the body is larger than a class takes ({limit:,} bytes)")
    chunks, size = [], 0
    try:
        async with asyncio.timeout(BODY_SECONDS):
            async for chunk in request.stream():
                size += len(chunk)
                if size > limit:
                    raise RefusedError(413, f"the body is larger than a class takes ({limit:,} bytes)")
                chunks.append(chunk)
    except TimeoutError:
        raise RefusedError(408, f"the body took longer than {BODY_SECONDS:g} s to arrive") from None
    except ClientDisconnect:
        raise RefusedError(400, "the client went away before its body arrived") from None
    return b"".join(chunks)


async def _json_body(request: Request) -> dict[str, Any]:
    data = await _body(request, MAX_JSON_BYTES)
    try:
        value = json.loads(data)
    except (ValueError, RecursionError):
        raise RefusedError(400, "the body is not JSON") from None
    if not isinstance(value, dict):
        raise RefusedError(400, "the body must be a JSON object")
    return value


def _check_code(state: ClassState, request: Request, typed: object) -> None:
    address = client_address(request)
    _waiting(state.codes, address, "codes")
    if not isinstance(typed, str) or len(typed) > 20 or not state.clerk.roster.code_matches(typed):
        state.codes.failed(address)
        raise RefusedError(403, "wrong class code: check the code on the projector")
    state.codes.succeeded(address)


#: A join or a hand-in that names another class (a browser's game kept from last week's class at this address):
#: refused before its code is looked at, so it is no guess and not counted as one (it learns nothing of the code).
OTHER_CLASS = 410


def _check_class(state: ClassState, named: object, what: str) -> None:
    if named is not None and not (isinstance(named, str) and hmac.compare_digest(
            named.encode("utf-8", "surrogatepass"), state.clerk.roster.class_id().encode())):
        raise RefusedError(OTHER_CLASS, what)


def _check_secret(state: ClassState, request: Request) -> None:
    """The teacher's routes: the teacher's own machine is the teacher (no secret to type, so none is ever shown
    where the room can read it; never made to wait); any other machine needs the secret, from the Authorization
    header, its wrong guesses counted apart."""
    if state.teachers_machine(request):
        return
    address = client_address(request)
    _waiting(state.secrets, address, "secrets")
    secret = _bearer(request)
    if secret is None or not state.clerk.roster.secret_matches(secret):
        state.secrets.failed(address)
        raise RefusedError(403, "the teacher's secret is needed for this on another machine than the teacher's (it "
                                "is in the file teacher.secret in the class's folder)")
    state.secrets.succeeded(address)


def _check_token(state: ClassState, request: Request) -> str:
    """The hand-in's token, a joined player's, from its headers (before any body is read)."""
    address = client_address(request)
    _waiting(state.tokens, address, "tokens")
    token = _bearer(request)
    if token is None or state.clerk.roster.player_of(token) is None:
        state.tokens.failed(address)
        raise RefusedError(401, NOT_JOINED)
    state.tokens.succeeded(address)
    return token


@contextlib.contextmanager
def _share(counter: Counter[str], address: str, limit: int, own: bool, what: str) -> Iterator[None]:
    """One of ``address``'s ``limit`` places in ``counter`` for the block (the teacher's machine: no limit)."""
    if not own and counter[address] >= limit:
        raise RefusedError(503, what)
    counter[address] += 1
    try:
        yield
    finally:
        counter[address] -= 1
        if counter[address] <= 0:
            del counter[address]


# ---------------------------------------------------------------------- the endpoints
async def home(request: Request) -> Response:
    return page.response("standings.html")


async def lab_page(request: Request) -> Response:
    return page.response("lab.html")


async def teacher_page(request: Request) -> Response:
    return page.response("teacher.html")


async def play_page(request: Request) -> Response:
    return page.response("play.html")


async def play_qr(request: Request) -> Response:
    play_url = _state(request).play_url
    if not play_url:
        raise RefusedError(404, "no such page")
    return Response(page.qr_svg(play_url), 200, media_type="image/svg+xml")


async def asset(request: Request) -> Response:
    return page.response(request.path_params["name"])


async def standings(request: Request) -> Response:
    state = _state(request)
    data = state.projector_snapshot if state.projector(request) else state.snapshot
    return Response(data, 200, media_type="application/json")


async def lab(request: Request) -> Response:
    return Response(_state(request).lab, 200, media_type="application/json")


async def lab_plan(request: Request) -> Response:
    """The lab a browser runs (``lab.plan``), every trial resolved for the class's seed. With a joined student's code
    and token (the headers ``/api/handin`` takes, checked as it checks them), their protocol: in a classroom
    experiment their condition's, assigned at this request if it is their first for the lab, exactly as a lab join
    assigns it (``Clerk.lab_protocol``); without them, or in a class of one protocol, the teacher's (the lesson's
    until one is chosen). The answer is the plan alone: nothing says which condition it is. Each plan is made once a
    protocol (off the event loop) and kept (``class_plan_json``'s bounded cache)."""
    from ..lab.plan import class_plan_json

    state = _state(request)
    clerk = state.clerk
    if "authorization" in request.headers or "x-armgame-code" in request.headers:
        _check_code(state, request, request.headers.get("x-armgame-code"))
        name = clerk.player(_check_token(state, request)).name
        # An assignment is a write to the class's record: the clerk's thread makes it, as it makes a join's.
        protocol = clerk.lab_protocol(name) if clerk.roster.experiment is None else \
            await state.run(lambda: clerk.lab_protocol(name))
    else:
        protocol = clerk.lab_protocol(None)
    try:
        data = await asyncio.to_thread(class_plan_json, protocol, clerk.roster.seed)
    except UserError as exc:
        raise RefusedError(409, str(exc)) from None
    return Response(data, 200, media_type="application/json")


async def events(request: Request) -> Response:
    """The projector's live page: the latest standings and class curve at every change, never a backlog."""
    state = _state(request)
    address = client_address(request)
    projector = state.projector(request)
    own = state.teachers_machine(request)
    if state.streams >= MAX_STREAMS and not projector:
        raise RefusedError(503, "too many pages are open on this class")
    if not own and state.streaming[address] >= STREAMS_PER_ADDRESS:
        raise RefusedError(503, "too many pages of this class are open on this machine: close one")
    state.streams += 1
    state.streaming[address] += 1

    async def stream() -> AsyncIterator[bytes]:
        try:
            sent = None
            while not state.stopping.is_set():
                current = state.projector_snapshot if projector else state.snapshot
                if current is not sent:
                    sent = current
                    yield b"event: standings\ndata: " + sent + b"\n\n"
                    yield b"event: lab\ndata: " + state.lab + b"\n\n"
                changed = state.changed
                try:
                    await asyncio.wait_for(changed.wait(), HEARTBEAT_SECONDS)
                except TimeoutError:
                    yield b": still here\n\n"
        finally:
            state.streams -= 1
            state.streaming[address] -= 1
            if state.streaming[address] <= 0:
                del state.streaming[address]

    return StreamingResponse(stream(), headers={"X-Accel-Buffering": "no"}, media_type="text/event-stream")


async def join(request: Request) -> Response:
    state = _state(request)
    clerk = state.clerk
    address = client_address(request)
    body = await _json_body(request)
    _check_class(state, body.get("class"), "this browser joined another class at this address before: type the code "
                                           "on the projector")
    _check_code(state, request, body.get("code"))
    token = body.get("token")
    if token is not None and (not isinstance(token, str) or len(token) > 200):
        raise RefusedError(400, "token must be a string")
    own = state.teachers_machine(request)
    # Only a join again under a name the token already holds is free: any other is a new name, whatever token it
    # carries (a joined name's token once let one machine join as many names as it liked).
    known = clerk.roster.rejoins(body.get("name"), token) is not None
    if not known and not own:
        if state.joins.full(address):
            raise RefusedError(429, f"this machine has joined {JOINS_PER_MINUTE} names in the last minute: one "
                                    f"name a student; ask the teacher if you need another")
        if state.class_joins.full("class"):
            raise RefusedError(503, "many names are joining at once: try again in a moment")
    # A join for the lab says so (``armgame lab --join``): a closed class still takes it (``Clerk.join``).
    lab = body.get("for") == "lab"
    def joined() -> tuple[Any, str | None, Any]:
        player, new_token = clerk.join(body.get("name"), token, address, lab=lab)
        # In a classroom experiment, the lab's client is handed the protocol of the student's condition to run (as
        # plain data: the client checks it as any protocol file); never the condition's name or its group.
        protocol = clerk.assign(player.name) if lab else None
        return player, new_token, protocol

    player, new_token, protocol = await state.run(joined)
    if new_token is not None and not own:
        state.joins.add(address)
        state.class_joins.add("class")
    # The class's game: its seed, its rules and their clock (a rehearsal's games are 15 s), which the student's
    # machine plays; a game of other rules is refused at hand-in.
    return json_answer({"ok": True, "name": player.name, "token": new_token or token, "seed": clerk.roster.seed,
                        "class": clerk.roster.class_id(),
                        "rules": clerk.game.name, "duration": clerk.game.config.time_limit,
                        "rehearsal": clerk.rehearsal, "closed": clerk.roster.closed,
                        **({} if protocol is None else {"lab": lab_as_data(protocol)}),
                        "message": f"joined the class as {player.name}" if new_token is None
                        else f"joined the class as {player.name} (the name is now this machine's)"})


def lab_as_data(protocol: str | dict) -> dict:
    """A class's protocol choice (a preset's name, or a protocol as data) as the data a lab client runs."""
    from ..lab.analysis import curve_protocol
    from ..lab.protocol_file import protocol_as_dict

    return protocol if isinstance(protocol, dict) else protocol_as_dict(curve_protocol(protocol))


async def start(request: Request) -> Response:
    """A game begins on a joined student's machine: its start ticket (``Clerk.start_ticket``), which its hand-in
    sends back (``X-Armgame-Start``) so a round knows the game was played during it. The code and token are
    checked as a hand-in's; the class keeps a few tickets a player, so asking often costs nothing."""
    state = _state(request)
    _check_code(state, request, request.headers.get("x-armgame-code"))
    token = _check_token(state, request)
    return json_answer({"ok": True, "ticket": state.clerk.start_ticket(token)})


def _ticket(request: Request) -> str | None:
    """The hand-in's start ticket, as ``start`` gave it (anything else is no ticket: the game is not in a round)."""
    ticket = request.headers.get("x-armgame-start", "")
    return ticket if 0 < len(ticket) <= 64 and ticket.isascii() else None


async def hand_in(request: Request) -> Response:
    """A game or a lab run handed in: the code, the token and the player's place checked from the headers, then
    the body read (bounded), then checked and entered by the clerk; answered once it is durably written."""
    state = _state(request)
    address = client_address(request)
    _check_class(state, request.headers.get("x-armgame-class"), "this game was played in another class: it is kept "
                                                                 "on your machine, not handed in to this one")
    _check_code(state, request, request.headers.get("x-armgame-code"))
    token = _check_token(state, request)
    with state.hand_in_share(token), _share(state.uploading, address, UPLOADS_PER_ADDRESS,
                                             state.teachers_machine(request), BUSY):
        # the token's and the machine's places taken before the body is read: a flooder's next costs nothing
        declared = request.headers.get("content-length", "")
        small = declared.isdigit() and int(declared) <= SMALL_UPLOAD_BYTES  # a student's game: its own slots
        slots = state.small_uploads if small else state.uploads
        try:
            async with asyncio.timeout(UPLOAD_WAIT):
                await slots.acquire()
        except TimeoutError:
            raise RefusedError(503, BUSY) from None
        try:
            data = await _body(request, SMALL_UPLOAD_BYTES if small else MAX_HANDIN_BYTES)
        finally:
            slots.release()
        return json_answer(await state.hand_in(token, data, _ticket(request)))


Endpoint = Callable[[Request], Awaitable[Response]]


def teacher_action(act: Callable[[Clerk, dict[str, Any]], str]) -> Endpoint:
    """A teacher's change: the secret (or the teacher's machine), the JSON body, ``act(clerk, body)`` on the
    clerk's thread, its one line back."""
    async def endpoint(request: Request) -> Response:
        state = _state(request)
        _check_secret(state, request)
        body = await _json_body(request)
        return json_answer({"ok": True, "message": await state.run(lambda: act(state.clerk, body))})
    return endpoint


def _start_or_stop_round(clerk: Clerk, body: dict[str, Any]) -> str:
    return clerk.stop_round() if body.get("stop") is True else clerk.start_round(body.get("minutes"))


teacher_hide = teacher_action(lambda clerk, b: clerk.hide(b.get("name"), bool(b.get("hidden", True))))
teacher_release = teacher_action(lambda clerk, b: clerk.release(b.get("name")))
teacher_rename = teacher_action(lambda clerk, b: clerk.rename(b.get("name"), b.get("to")))
teacher_remove = teacher_action(lambda clerk, b: clerk.remove(b.get("names")))
teacher_close = teacher_action(lambda clerk, b: clerk.close(bool(b.get("closed", True))))
teacher_lock = teacher_action(lambda clerk, b: clerk.lock(bool(b.get("locked", True))))
teacher_lab = teacher_action(lambda clerk, b: clerk.choose_lab(b.get("protocol")))
teacher_browser_lab = teacher_action(lambda clerk, b: clerk.browser_lab(b.get("on") is True))
teacher_round = teacher_action(_start_or_stop_round)


async def teacher_standings(request: Request) -> Response:
    state = _state(request)
    _check_secret(state, request)
    return json_answer(await state.run(lambda: views.standings(state.clerk, teacher=True)))


async def teacher_roster(request: Request) -> Response:
    state = _state(request)
    _check_secret(state, request)
    return json_answer(await state.run(lambda: views.roster_view(state.clerk)))


def csv_download(make: Callable[[Clerk], str], filename: str) -> Endpoint:
    """A teacher's CSV: the secret (or the teacher's machine), ``make(clerk)`` on the clerk's thread, as a file."""
    async def endpoint(request: Request) -> Response:
        state = _state(request)
        _check_secret(state, request)
        text = await state.run(lambda: make(state.clerk))
        return Response(text.encode("utf-8"), 200, {"Content-Disposition": f'attachment; filename="{filename}"'},
                        media_type="text/csv; charset=utf-8")
    return endpoint


teacher_games_csv = csv_download(views.games_csv, "class-games.csv")
teacher_lab_csv = csv_download(views.lab_csv, "class-lab-reaches.csv")
teacher_students_csv = csv_download(views.students_table, "class-lab-students.csv")


async def teacher_lab_png(request: Request) -> Response:
    """The class curve as the lab's figure draws it (a PNG for a report), where matplotlib is installed."""
    state = _state(request)
    _check_secret(state, request)
    from ..lab.figures import class_figure_png, require_matplotlib

    try:
        require_matplotlib()
    except UserError:
        raise RefusedError(503, "the lab curve's picture needs matplotlib on the teacher's machine: pip install "
                                "'armgame[plot]' (the lab's CSV needs nothing)") from None

    def draw() -> bytes | None:  # on the clerk's thread: the curve as it is now, and one drawing at a time
        curve = views.class_curve(state.clerk)
        return class_figure_png(curve.trials, metric=curve.metric) if curve.students else None
    png = await state.run(draw)
    if png is None:
        raise RefusedError(404, "no class curve yet: no volunteer's run of the class's protocol")
    return Response(png, 200, {"Content-Disposition": 'attachment; filename="class-lab-curve.png"'},
                    media_type="image/png")


# ---------------------------------------------------------------------- the app
#: Each of the class's routes is behind the same-site check (``middleware.SameSite``), run once the router has
#: found it: a path or a method the class does not serve is the router's own 404 or 405.
SAME_SITE = [Middleware(SameSite)]
POST = ["POST"]
ROUTES = [
    Route("/", home, middleware=SAME_SITE),
    Route("/lab", lab_page, middleware=SAME_SITE),
    Route("/teacher", teacher_page, middleware=SAME_SITE),
    Route("/play", play_page, middleware=SAME_SITE),
    Route("/play.svg", play_qr, middleware=SAME_SITE),
    Route("/static/{name}", asset, middleware=SAME_SITE),
    Route("/api/standings", standings, middleware=SAME_SITE),
    Route("/api/lab", lab, middleware=SAME_SITE),
    Route("/api/labplan", lab_plan, middleware=SAME_SITE),
    Route("/events", events, middleware=SAME_SITE),
    Route("/api/join", join, methods=POST, middleware=SAME_SITE),
    Route("/api/handin", hand_in, methods=POST, middleware=SAME_SITE),
    Route("/api/start", start, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/hide", teacher_hide, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/release", teacher_release, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/remove", teacher_remove, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/rename", teacher_rename, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/close", teacher_close, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/lock", teacher_lock, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/lab", teacher_lab, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/browserlab", teacher_browser_lab, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/round", teacher_round, methods=POST, middleware=SAME_SITE),
    Route("/api/teacher/standings", teacher_standings, middleware=SAME_SITE),
    Route("/api/teacher/roster", teacher_roster, middleware=SAME_SITE),
    Route("/api/teacher/games.csv", teacher_games_csv, middleware=SAME_SITE),
    Route("/api/teacher/lab.csv", teacher_lab_csv, middleware=SAME_SITE),
    Route("/api/teacher/students.csv", teacher_students_csv, middleware=SAME_SITE),
    Route("/api/teacher/lab.png", teacher_lab_png, middleware=SAME_SITE),
]

#: Around the router, outermost first: every answer's security headers, then a bug's one line (the refusals are
#: ``middleware.EXCEPTION_HANDLERS``, inside both).
MIDDLEWARE = [Middleware(SecurityHeaders), Middleware(OneLineErrors)]


async def _load_lab(state: ClassState) -> None:
    for problem in await state.run(state.clerk.load_lab):
        state.say(f"left out of the class curve: {problem}")


async def _round_clock(state: ClassState) -> None:
    """A round's end is a change no request makes: looked for every second while a round is on, and at the
    moment it closes (``Round.closes``), so the projector shows its winners as its clock and grace run out."""
    while not state.stopping.is_set():
        rnd = None if state.clerk.roster.round is None or state.clerk.round_over else state.clerk.current_round()
        left = 1.0 if rnd is None else (rnd.closes - state.clerk.clock()).total_seconds()
        await asyncio.sleep(min(1.0, max(0.0, left)))
        if state.clerk.roster.round is not None and not state.clerk.round_over:
            with contextlib.suppress(RefusedError):
                await state.run(state.clerk.round_ended)


@asynccontextmanager
async def lifespan(app: Starlette) -> AsyncIterator[None]:
    """The clerk's thread for the server's life: started before the first request, and stopped after the last
    (a hand-in being written is finished, never cut)."""
    state: ClassState = app.state.armgame
    state.worker = ClerkThread(state.clerk, state.publish)
    await state.run(lambda: None)  # the first snapshot
    if state.on_ready is not None:
        state.on_ready()
    # The lab runs already in the folder are checked again in the background: the page is up at once.
    loading = asyncio.ensure_future(_load_lab(state))
    ticking = asyncio.ensure_future(_round_clock(state))
    try:
        yield
    finally:
        state.stopping.set()
        state.changed.set()
        loading.cancel()
        ticking.cancel()
        state.worker.stop()


def build_app(clerk: Clerk, join_line: str, on_ready: Callable[[], None] | None = None,
              say: Callable[[str], None] = lambda line: None, guard: Guard | None = None,
              play_url: str = "", proxy: str | None = None, secret_always: bool = False) -> Starlette:
    """The class's app over ``clerk`` (already open on its folder); ``join_line`` is what students type;
    ``on_ready`` is called once the server takes requests; ``say`` gets one-line notices for the teacher;
    ``guard`` knows the teacher's own machine's addresses (``guard.Guard``); ``play_url`` is the browser
    game's address (``/play``) as students reach it, for the projector's QR code; ``proxy``: the address of the
    reverse proxy whose ``X-Forwarded-For`` names its clients (``middleware.ForwardedFor``); ``secret_always``: even
    this machine types the teacher's secret (``ClassState.secret_always``)."""
    middleware = [MIDDLEWARE[0], Middleware(ForwardedFor, proxy=proxy, say=say), *MIDDLEWARE[1:]]
    app = Starlette(routes=ROUTES, middleware=middleware, exception_handlers=EXCEPTION_HANDLERS, lifespan=lifespan)
    app.state.armgame = ClassState(clerk, join_line, guard or Guard(), play_url, secret_always=secret_always,
                                   on_ready=on_ready, say=say)
    return app
