"""Every bound of the live class, each with its reason: what a connection, a request, the clerk's queue and a
student's machine may cost, in the order a hand-in meets them.

One module, as uvicorn keeps its settings in one ``Config``: a bound is changed here, and every module that holds
to it imports it by name (``from .bounds import BODY_SECONDS``). A test that changes a bound for one module
patches that module's name, which is the one it reads. The bounds lean on each other (the app's body deadline
within the connection's, the largest hand-in within the queue's bytes): tests/test_class_bounds.py holds each
coupling, and docs/development.md's table ("The class's bounds") is checked against this file.

No imports, so the student's client reads the bounds it shares with the class (``MAX_HANDIN_BYTES``) without
loading any of the server. The bounds of games and replays anywhere, in a class or not, are ``armgame.limits``.
"""

from __future__ import annotations

# ---------------------------------------------------------------------- a connection (guard, serve)
#: Seconds for a request's headers to arrive: a browser or the client sends them in one packet.
HEADER_SECONDS = 5.0
#: Seconds for a whole request once its headers are in: room for the largest hand-in over slow school Wi-Fi, and
#: for the wait for an upload's place and the body's own deadline before it (``UPLOAD_WAIT``, ``BODY_SECONDS``).
REQUEST_SECONDS = 15.0
#: Seconds an idle kept-alive connection stays open (uvicorn's ``timeout_keep_alive``).
KEEP_ALIVE_SECONDS = 5
#: Connections one client address may hold at once: a browser opens six per server, the client one.
PER_ADDRESS = 16
#: Requests one connection may have waiting behind the one being answered: no browser pipelines; a script may.
PIPELINE = 8
#: Headers in one request: a browser sends about 15 (Apache's LimitRequestFields is 100).
MAX_HEADERS = 100
#: Bytes of one request's head, its line and headers together (nginx's default is 4 x 8 KiB, Go's 1 MB).
MAX_HEADER_BYTES = 16 * 1024
#: Connections served at once; past it uvicorn answers 503 itself. A lecture hall's round's end is 1,000 students
#: at the same moment: at 400, six in ten were sent away for 2 s, again and again (the clerk's own queue, bounded
#: in bytes and one hand-in a player, is what keeps memory bounded). The process's limit of open files is raised
#: to fit where the system allows (``serve._more_files``).
CONCURRENCY = 2500
#: Connections from other machines than the teacher's at once: ``CONCURRENCY`` less a reserve of 100 for the
#: teacher's machine and the connections on probation.
CONNECTIONS = 2400
#: Connections past ``CONNECTIONS`` that wait to show they are the projector's (its link's key), the oldest closed
#: for a newer: a flood of new connections cannot keep the projector out for longer than its first request takes.
PROBATION = 32
#: Connections the system holds for the server to accept (capped by the system's own, 4,096 on Linux, 128 on
#: macOS unless raised). Past it a new connection's first packet is dropped and its client sends it again a second
#: later, then three: at 128, a round's end of 1,000 students at once cost an honest student seconds.
BACKLOG = 2048
#: Bytes fed to the parser at a time while a request's head is read or requests wait: the head is counted, and
#: reading stops when the queue is full, to within this.
SLICE = 1024
#: Seconds a refused connection's input is still read (and dropped) after its answer, so that the client reads
#: the answer instead of a reset.
LINGER_SECONDS = 1.0
#: Bytes of input held back past which a connection is closed: asyncio reads 256 KiB at a time, so one read is
#: held at most.
HELD_BYTES = 1024 * 1024
#: Seconds requests in flight get to finish at Ctrl-C (uvicorn's ``timeout_graceful_shutdown``); a hand-in being
#: written is finished whatever it takes. Not a round's grace (``rounds.GRACE_SECONDS``).
SHUTDOWN_SECONDS = 3

# ---------------------------------------------------------------------- a request's body (app)
#: Bytes of the largest hand-in a class reads: a 60 s bot game that acts every control period is about 0.55 MB and a lab
#: run on a preset about 0.5 MB; eight times that, and no more, is read at once. The client keeps a bigger replay
#: rather than send what the class would cut off, so both sides read this one number.
MAX_HANDIN_BYTES = 4 * 1024 * 1024
#: Seconds a request's body may take to arrive once the app reads it: the largest hand-in at half a megabyte a
#: second. With ``UPLOAD_WAIT`` before it, within ``REQUEST_SECONDS``, so the app answers 408 before the
#: connection is closed.
BODY_SECONDS = 9.0
#: Bytes of a JSON request (a join, the teacher's changes): a name, a code and a token fit many times over.
MAX_JSON_BYTES = 4096
#: Hand-in bodies of any size (a bot's game, a lab run) read at once.
UPLOADS = 16
#: Hand-in bodies of at most ``SMALL_UPLOAD_BYTES`` read at once, apart from ``UPLOADS``: 40 machines holding both
#: of their places with bodies trickled a byte a second leave most of them free for an honest student's game
#: (tests/test_class_memory.py), and all of them together hold 16 MiB.
SMALL_UPLOADS = 256
#: Bytes of a small hand-in, by its declared length: a student's 60 s game is about 9 KB.
SMALL_UPLOAD_BYTES = 64 * 1024
#: Hand-ins one address uploads at once: a student hands in one game at a time, a flooder's third waits.
UPLOADS_PER_ADDRESS = 2
#: Seconds a hand-in waits for an upload's place before it is told the class is busy (its client comes back).
UPLOAD_WAIT = 5.0

# ---------------------------------------------------------------------- waiting for the clerk (state, worker)
#: Jobs (a join, the teacher's requests) waiting for the clerk at once; past it, 503 and the client comes back. A
#: join rewrites the roster, so a lecture hall's joins are let in a few at a time.
QUEUE_LIMIT = 64
#: Hand-ins waiting for the clerk at once. One checked and entered in a batch costs the clerk 2.5 ms (a bot's game
#: 60 ms): room for a lecture hall's round's end (benchmarks/class_server.py), where a queue of 64 sent nine
#: students in ten away for 2 s, again and again.
HANDIN_QUEUE = 1024
#: Bytes of the bodies those waiting hand-ins hold at the most (a bot's game is 0.5 MB, a student's 9 KB).
QUEUE_BYTES = 64 * 1024 * 1024
#: Hand-ins of one player (one token) waiting at once: a client that floods the class has one in the queue, and
#: its next is told the class is busy before its body is read, so a flooder's backlog never sits in front of an
#: honest student's game.
TOKEN_SHARE = 1
#: Seconds a player's next hand-in is told the class is busy after one of theirs did not reproduce its score (422,
#: found only by re-simulating it): a forger's next game waits its turn behind the honest students' instead of
#: taking the clerk's time at once. A body that is not a class's game (400, 413) is refused cheaply and does not
#: count.
COOL_DOWN = 2.0
#: Hand-ins checked, re-simulated (one batch) and entered (one table write) together at the most.
BATCH = 64

# ---------------------------------------------------------------------- guesses and joins (state)
#: Wrong answers of one kind (codes, secrets, tokens) an address may give before it waits: a student who
#: mistyped the code is not made to wait.
FREE_GUESSES = 5
#: Seconds of the first wait, doubled for every further wrong answer: a four-letter code (160,000 of them) is
#: beyond guessing, about a dozen tries an hour from an address.
GUESS_WAIT = 60.0
#: Seconds of the longest wait: a student locked out by a classmate's guesses from a shared address gets in within
#: the hour.
MAX_GUESS_WAIT = 3600.0
#: Addresses whose guesses and joins are counted (the oldest forgotten first): IPv6 gives a laptop millions.
MAX_TRACKED_ADDRESSES = 10_000
#: New names one address joins in a minute: a student, a bot and a typo; not a flood of names.
JOINS_PER_MINUTE = 3
#: New names the whole class takes in a minute: a lecture hall joins in a few minutes, a flood from many
#: addresses is slowed.
CLASS_JOINS_PER_MINUTE = 120

# ---------------------------------------------------------------------- the clerk's work (handins, intake, roster)
#: The most re-simulation one hand-in may ask for, in physics steps (``records.scores.replay_work``): a standard
#: game costs 15,000 steps and its hits and events, a lab run its protocol's steps. A game claiming more (a "hit
#: storm") is refused before anything is replayed.
MAX_HANDIN_WORK = 1_500_000
#: Forged games whose re-simulated result is kept (by identity), so one sent again is not played again: a result
#: is about 200 bytes.
REMEMBERED_FORGERIES = 4096
#: Names one class holds: a lecture hall of students, each with a program or two, with room.
MAX_PLAYERS = 2000
#: Bytes of the class's record (class.json): ``MAX_PLAYERS`` names, their tokens' hashes and renames fit.
MAX_ROSTER_BYTES = 2 * 1024 * 1024
#: Bytes of the current round's games (``handins.ROUND_GAMES``, read at a restart): a lecture hall's round, each
#: game's entry id, with room.
MAX_ROUND_GAMES_BYTES = 4 * 1024 * 1024

# ---------------------------------------------------------------------- the pages (app, views)
#: Rows of each list the standings carry: the projector shows the top, the CSV has everything.
STANDINGS_ROWS = 60
#: The projector's live pages open at once (its own always gets one).
MAX_STREAMS = 64
#: Live pages open on one machine (the teacher's apart): a student who opened the projector's page in a few tabs.
STREAMS_PER_ADDRESS = 4
#: Seconds between a live page's heartbeats when nothing changed: a page whose machine went away is found.
HEARTBEAT_SECONDS = 15.0

# ---------------------------------------------------------------------- the student's machine (client, memberships)
#: Seconds the client waits for one answer: a hand-in's body and the clerk's durable write under a lecture hall's
#: load.
CLIENT_TIMEOUT = 15.0
#: Seconds a game's start ticket is waited for: the game starts anyway (it is then not in a round).
TICKET_TIMEOUT = 3.0
#: Seconds a hand-in keeps asking a busy class, in all.
BUSY_PATIENCE = 60.0
#: Seconds before asking again when the class took a request but its answer never came.
LOST_ANSWER_PAUSE = 1.0
#: Replays one class's outbox keeps on a student's machine: a term of games the class could not be reached for.
MAX_OUTBOX = 200
#: Names one class keeps on one machine: a student, their bots and a spelling or two, with room.
MAX_MEMBERSHIP_NAMES = 8
#: Classes one machine keeps: a school year of lessons, each its own class.
MAX_MEMBERSHIP_CLASSES = 40
#: Bytes of memberships.json: the caps filled with the longest names (40 characters of 4 bytes each), tokens and
#: addresses take 150 KB of it (tests/test_memberships.py).
MAX_MEMBERSHIPS_BYTES = 1 << 18
