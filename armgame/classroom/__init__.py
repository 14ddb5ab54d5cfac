"""The live class: the teacher's machine serves a class, students' games arrive by themselves.

The teacher runs ``armgame class serve``; students run ``armgame play --join HOST:PORT --code CODE``
and every game they finish is handed in, verified by re-simulation and entered in the class's table,
which the projector's page shows live, one row per student. What each module owns:

* ``roster``: the class's own record (``class.json``): its join code, the teacher's secret, the seed
  it ranks, each student's name and the hash of the token that proves it, what the teacher hid.
* ``intake``: one hand-in from arrival to answer: checked, verified, entered once by its content,
  durably on disk before it is acknowledged; the class's standings built from what was entered.
* ``app``: the ASGI application (Starlette): the routes, the bounded queue in front of the clerk
  thread, rate limits and body limits per machine, the projector's event stream.
* ``guard``: what a connection may cost before it is a request (deadlines, a share per address),
  under uvicorn's own HTTP parsing.
* ``rounds``: a round ("everyone play now"): which games count, its clock, its winners.
* ``page``: the projector's, the lab's and the teacher's pages (static HTML; the data arrives as JSON
  and is only ever set as text).
* ``serve``: starting the server (uvicorn) on the address the students can reach, and stopping it.
* ``client``: the student's side: joining, handing in, the token and the outbox kept in the user's
  folder, so a game played while the server was unreachable is handed in at the next join.

Above ``records``, ``lab`` and ``game``; below ``commands``; ``records`` never imports it and it
imports pygame only through ``ui`` (``armgame class show``). Headless clients never load pygame.
"""
