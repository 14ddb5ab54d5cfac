"""The live class: the teacher's machine serves a class, students' games arrive by themselves.

The teacher runs ``armgame class serve``; students run ``armgame play --join HOST:PORT --code CODE``
and every game they finish is handed in, verified by re-simulation and entered in the class's table,
which the projector's page shows live, one row per student. What each module owns:

* ``roster``: the class's own record (``class.json``): its join code, the teacher's secret, the seed
  it ranks, each student's name and the hash of the token that proves it, what the teacher hid.
* ``intake``: the ``Clerk``, the class's one writer: a join, the lab runs, the teacher's changes and
  rounds, and the facade of ``handins``, the hand-in pipeline: hand-ins from arrival to answer
  (checked, verified, entered once by its content, durably on disk before it is acknowledged).
  ``board``: the two lists' rows, kept as games are entered; ``labruns``: the lab
  runs' files, written and read again.
* ``views``: what the pages show, read from the clerk's state: the standings, the class curve, the
  teacher's roster and CSVs.
* ``worker``: the clerk's one thread, its work typed (a ``Job``, a ``HandIn``), hand-ins that wait
  together checked and entered as one batch.
* ``app``: the ASGI application (Starlette): module-level endpoints, the routes table, the lifespan
  that runs the clerk's thread. ``state``: what the endpoints
  share (``ClassState``: the bounded queue in front of the clerk's thread, guesses and joins counted
  per machine, the pages' data); ``middleware``: the security headers, the same-site check, the
  refusals' exception handlers, a bug's one line; ``errors``: ``RefusedError``, the refusal any of
  them raises.
* ``bounds``: every bound of the class, each with its reason (what a connection, a request, the
  clerk's queue and a student's machine may cost), with no imports.
* ``guard``: what a connection may cost before it is a request (deadlines, a share per address),
  under uvicorn's own HTTP parsing.
* ``rounds``: a round ("everyone play now"): which games count, its clock, its winners.
* ``page``: the projector's, the lab's and the teacher's pages (static HTML; the data arrives as JSON
  and is only ever set as text).
* ``serve``: starting the server (uvicorn) on the address the students can reach, and stopping it.
* ``client``: the student's side: joining, handing in, the token and the outbox kept in the user's
  folder, so a game played while the server was unreachable is handed in at the next join.
  ``memberships``: the names this machine joined under. ``wire``: what both sides hold to (the join
  code's letters, the busy class's line), with no imports: the student's side imports none of the server's
  modules but ``bounds`` (the largest hand-in), and this package's ``__init__`` imports nothing
  (``tests/test_thin_client.py``).

Above ``records``, ``lab`` and ``game``; below ``commands``; ``records`` never imports it and it
imports pygame only through ``ui`` (``armgame class show``). Headless clients never load pygame.
"""
