"""What the class's pages show, built from the clerk's state: read-only, it never changes the class.

* ``standings``: the projector's lists (hidden names left out, the top ``STANDINGS_ROWS`` of each), its
  round and the game just entered; or every row, hidden ones marked, for the teacher;
* ``lab_curve`` and ``class_curve``: the class curve of the protocol the teacher chose, as ``/lab``
  draws it and as the teacher's PNG (``lab.analysis.class_curve_of``, the function ``armgame analyze
  --class`` builds it with afterwards);
* ``roster_view``: the teacher's list of names, grouped by the machine each joined from;
* ``games_csv`` and ``lab_csv``: the teacher's exports, every cell a spreadsheet shows as text
  (``csv_cell``).

Each reads the state the clerk (``intake.Clerk``) changes, so each runs where the clerk runs: on its
thread (``worker.ClerkThread``), as the app's ``ClassState.publish`` and the teacher's routes call them.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Sequence
from datetime import datetime
from typing import Any

from ..records.standings import player_key, shared_rank
from .bounds import STANDINGS_ROWS
from .intake import Clerk
from .rounds import round_view


def standings(clerk: Clerk, teacher: bool = False) -> dict[str, object]:
    """The class as the projector shows it (hidden names left out), or as the teacher sees it."""
    roster = clerk.roster

    def rows(programs: bool) -> list[dict[str, object]]:
        out: list[dict[str, object]] = []
        for row in clerk.boards[programs].each():
            hidden = roster.is_hidden(row.name)
            if hidden and not teacher:
                continue
            e = row.best
            out.append({"rank": shared_rank(out, e.score), "name": row.name, "score": e.score, "hits": e.hits,
                        "games": row.games, "driver": e.how if programs else None,
                        **({"hidden": hidden} if teacher else {})})
            if len(out) >= STANDINGS_ROWS and not teacher:
                break
        return out

    arrival = clerk.arrival
    if arrival is not None and roster.is_hidden(arrival.name):
        arrival = None
    return {"version": clerk.version, "seed": roster.seed, "closed": roster.closed, "rehearsal": clerk.rehearsal,
            "browser_lab": roster.browser_lab and clerk.lab_protocol_name(),
            "joined": len(roster.players), "people": who_joined(clerk), "games": len(clerk.entries),
            "round": None if teacher else round_shown(clerk),
            "students": rows(False), "programs": rows(True),
            "arrival": None if arrival is None else {"seq": arrival.seq, "name": arrival.name, "score": arrival.score,
                                                     "note": arrival.note, "program": arrival.program}}


def who_joined(clerk: Clerk) -> dict[str, int]:
    """The joined names (``Roster.players``) as the pages count them, so a class of thirty reads as thirty:
    ``programs``, the names whose every game and lab run says a program played it (``ScoreEntry.program``,
    docs/scores.md); ``lab_only``, a person's lab run and no person's game (the lesson's volunteers); and
    ``students``, the rest: a person's game, or nothing handed in yet (a student about to play)."""
    played = {player_key(row.name) for row in clerk.boards[False].each()}
    programs = {player_key(row.name) for row in clerk.boards[True].each()}
    lab_people: set[str] = set()
    for run in clerk.lab_runs:
        key = player_key(clerk.shown_name(run.player))
        (programs if run.program else lab_people).add(key)
    counts = {"students": 0, "lab_only": 0, "programs": 0}
    for key in clerk.roster.players:
        kind = ("students" if key in played else "lab_only" if key in lab_people
                else "programs" if key in programs else "students")
        counts[kind] += 1
    return counts


def lab_runs_by_name(clerk: Clerk) -> dict[str, list[str]]:
    """Each name's lab runs (its ``player_key``), as the protocol each ran, in the order they came."""
    runs: dict[str, list[str]] = {}
    for run in clerk.lab_runs:
        runs.setdefault(player_key(clerk.shown_name(run.player)), []).append(str(run.protocol.name))
    return runs


def round_shown(clerk: Clerk, now: datetime | None = None) -> dict[str, object] | None:
    """The round on the projector (``rounds.round_view``): its clock, and its winners once it is over (by the
    clerk's clock, the one that takes games into it)."""
    return round_view(clerk.current_round(), clerk.entries, clerk.roster.hidden, now or clerk.clock(),
                      STANDINGS_ROWS, name_of=clerk.shown_name, counted=clerk.round_games)


def class_curve(clerk: Clerk) -> Any:
    """``lab.analysis.class_curve_of`` the teacher's protocol over the class's runs (in SI units): hidden
    names left out, programs' runs counted apart."""
    return curve_and_members(clerk)[0]


def curve_and_members(clerk: Clerk) -> tuple[Any, list[Any]]:
    """``class_curve`` and the runs in it (``classroom.labruns.LabRun``), in the curve's order."""
    from ..lab.analysis import ClassRun, class_curve_of

    runs = [run for run in clerk.lab_runs if run.program or (run.first and not clerk.roster.is_hidden(run.player))]
    curve = class_curve_of([ClassRun(run.player, run.program, run.protocol, run.rows) for run in runs],
                           clerk.curve_protocol())
    return curve, [runs[i] for i in curve.members]


def lab_curve(clerk: Clerk) -> dict[str, object]:
    """The class curve of the protocol the teacher chose: each person's first run of it (programs' runs
    and hidden names never in it; the programs counted apart). Built by ``lab.analysis.class_curve_of``,
    as ``armgame analyze --class`` builds it from the folder afterwards."""
    from ..lab.analysis import display_unit
    from ..lab.classstats import answer_line, class_stats

    protocol = clerk.curve_protocol()
    curve, members = curve_and_members(clerk)
    if not curve.students:
        return {"protocol": None if protocol is None else protocol.name, "students": 0, "programs": curve.programs,
                "metric": None, "trials": [], "stats": None, "groups": groups_view(clerk)}
    scale, unit = display_unit(curve.metric)  # type: ignore[arg-type]
    trials = [{"trial": int(row["trial"]), "block": str(row["block"]), "perturbation": str(row["perturbation"]),
               "mean": _finite(row["mean"], scale), "sem": _finite(row["sem"], scale), "n": int(row["n"])}
              for row in curve.trials]
    stats = class_stats(curve.protocol, [(clerk.shown_name(run.player), run.rows) for run in members], curve.metric)
    return {"protocol": protocol.name, "students": curve.students, "programs": curve.programs,
            "metric": curve.metric, "unit": unit, "trials": trials, "groups": groups_view(clerk),
            "stats": {**stats.as_dict(scale, probe_scale(curve.protocol, curve.metric)),
                      "probe_unit": probe_unit(curve.protocol, curve.metric),
                      "answer": answer_line(stats, scale, unit)}}


def experiment_groups(clerk: Clerk) -> Any:
    """A classroom experiment's two groups (``lab.classstats.two_groups``) over the class's runs, or None."""
    from ..lab.analysis import ClassRun, curve_protocol
    from ..lab.classstats import two_groups

    experiment = clerk.roster.experiment
    if experiment is None:
        return None
    runs = [run for run in clerk.lab_runs if run.program or (run.first and not clerk.roster.is_hidden(run.player))]
    # By the name each run was handed in under: the split keeps the condition a student drew, renamed or not.
    return two_groups([ClassRun(run.player, run.program, run.protocol, run.rows) for run in runs],
                      (curve_protocol(experiment.a), curve_protocol(experiment.b)),
                      lambda name: experiment.condition_of(name, clerk.roster.renamed))


def groups_view(clerk: Clerk) -> dict[str, object] | None:
    """The two groups as ``/lab`` draws them side by side, and their difference in one line."""
    from ..lab.analysis import display_unit
    from ..lab.classstats import difference_words

    groups = experiment_groups(clerk)
    if groups is None:
        return None
    scale, unit = display_unit(groups.metric)
    counts = clerk.roster.experiment.counts()  # type: ignore[union-attr]
    out: dict[str, object] = {}
    for c, curve, stats in zip(("a", "b"), groups.curves, groups.stats, strict=True):
        out[c] = {"name": f"group {c.upper()}", "protocol": curve.protocol.name, "assigned": counts[c],  # type: ignore[attr-defined]
                  "students": curve.students, "stats": None if stats is None else stats.as_dict(scale)}  # type: ignore[attr-defined]
    return {**out, "metric": groups.metric, "unit": unit,
            "difference": None if groups.difference is None else groups.difference.as_dict(scale),
            "difference_words": difference_words(groups, scale, unit)}


def probe_scale(protocol: Any, metric: str) -> float:
    """The factor the generalization panel shows probes in: an adaptation index as it is, a probe's error in the
    curve's unit."""
    from ..lab.analysis import display_unit

    return 1.0 if probe_unit(protocol, metric) == "" else display_unit(metric)[0]


def probe_unit(protocol: Any, metric: str) -> str:
    """The generalization panel's unit: "" for the channel trials' adaptation index, else the curve's."""
    from ..lab.analysis import display_unit
    from ..lab.classstats import generalization_blocks

    blocks = generalization_blocks(protocol)
    channels = any(protocol.blocks[b].channel_trials for b in blocks)
    return "" if channels else display_unit(metric)[1]


#: Each run's two-rate fit, made once (a fit costs a tenth of a second; a run's rows never change), by its file.
_FITS: dict[tuple[str, str], dict[str, float]] = {}


def students_table(clerk: Clerk) -> str:
    """The teacher's table of the class curve's students, one row each (``lab.classstats.student_table``), as
    ``armgame analyze --class --students`` writes it from the folder (``students_csv``)."""
    curve, members = curve_and_members(clerk)
    if not curve.students:
        return students_csv(None, None, [], [])
    fits = []
    from ..lab.classstats import student_fit

    for run in members:
        key = (str(run.path), curve.metric)
        if key not in _FITS:
            if len(_FITS) > 10_000:  # a server that ran many classes: the cache is a cache, not a record
                _FITS.clear()
            _FITS[key] = student_fit(run.rows, curve.metric)
        fits.append(_FITS[key])
    return students_csv(curve.protocol, curve.metric, [(clerk.shown_name(run.player), run.rows) for run in members],
                        fits)


def students_csv(protocol: Any, metric: str | None, students: Sequence[tuple[str, Any]],
                 fits: Sequence[Any] | None = None) -> str:
    """The students' table as CSV text (the teacher's download and ``armgame analyze --class --students``): a
    student a row, each measure in the unit the page shows it (cm or deg: the column names it), the fitted rates
    as they are; an empty cell where a measure is undefined or the fit did not converge."""
    from ..lab.analysis import display_unit
    from ..lab.classstats import FIT_NAMES, STUDENT_COLUMNS, student_table

    if protocol is None or metric is None:
        return _csv(STUDENT_COLUMNS, [])
    scale, unit = display_unit(metric)
    table = student_table(protocol, students, metric, fits)
    columns = [c if c == "name" or c in FIT_NAMES else f"{c}_{unit}" for c in STUDENT_COLUMNS]
    return _csv(columns, ([row["name"], *(float(row[c]) * (1.0 if c in FIT_NAMES else scale)  # type: ignore[arg-type]
                                           for c in STUDENT_COLUMNS[1:])] for row in table))


def roster_view(clerk: Clerk) -> dict[str, object]:
    """For the teacher's page: every joined name with the machine (address) it joined from, its games (0: joined,
    not played yet) and its lab runs (the protocol of each), grouped by address, most names first; who joined
    (``who_joined``); whether the list is locked, and the class curve's protocol."""
    from ..lab.presets import PRESETS

    roster = clerk.roster
    played: dict[str, int] = {}
    for entry in clerk.entries:
        key = player_key(clerk.shown_name(entry.name))
        played[key] = played.get(key, 0) + 1
    lab = lab_runs_by_name(clerk)
    machines: dict[str, list[dict[str, object]]] = {}
    for key, p in roster.players.items():
        machines.setdefault(p.address or "unknown", []).append(
            {"name": p.name, "joined": p.joined, "games": played.get(key, 0), "lab": lab.get(key, []),
             "hidden": key in roster.hidden})
    groups = [{"address": address, "names": sorted(names, key=lambda n: str(n["joined"]))}
              for address, names in machines.items()]
    groups.sort(key=lambda g: (-len(g["names"]), g["address"]))  # type: ignore[arg-type]
    chosen = roster.lab
    return {"machines": groups, "joined": len(roster.players), "people": who_joined(clerk),
            "waiting": sum(1 for k in roster.players if not played.get(k) and not lab.get(k)),
            "locked": roster.locked, "closed": roster.closed, "browser_lab": roster.browser_lab,
            "lab": chosen.get("name") if isinstance(chosen, dict) else chosen, "presets": list(PRESETS)}


def games_csv(clerk: Clerk) -> str:
    """Every game entered, in order; ``entered_local`` is the teacher's clock (what a teacher compares with
    the lesson), ``entered_at`` the same moment in UTC as the table keeps it."""
    columns = ("entered", "name", "list", "driven", "driver", "score", "hits", "resets", "seed", "entered_local",
               "entered_at", "hidden", "replay")
    ordered = sorted(clerk.entries, key=lambda e: e.entered or 0)
    return _csv(columns, ([e.entered, e.name, "programs" if e.program else "students", e.driven, e.driver or "",
                           e.score, e.hits, e.resets, e.seed, local_time(e.entered_at), e.entered_at or "",
                           clerk.roster.is_hidden(e.name), e.replay] for e in ordered))


def lab_csv(clerk: Clerk) -> str:
    """Every reach of the runs the class curve could read (people's first runs, programs' runs), a row each."""
    from ..lab.metrics import TRIAL_COLUMNS

    columns = ("player", "program", "protocol", "replay", *TRIAL_COLUMNS)
    return _csv(columns, ([run.player, run.program, run.protocol.name, run.path.name,
                           *(row[c] for c in TRIAL_COLUMNS)] for run in clerk.lab_runs for row in run.rows
                          if run.first or run.program))


def _finite(value: object, scale: float) -> float | None:
    value = float(value)  # type: ignore[arg-type]
    return round(value * scale, 6) if math.isfinite(value) else None


_FORMULA = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value: object) -> str:
    """A cell a spreadsheet shows as text: a leading = + - @ would make it a formula (OWASP's advice:
    prefix a quote). Numbers are written as they are, so they stay numbers."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int | float) and not isinstance(value, bool):
        return "" if isinstance(value, float) and not math.isfinite(value) else repr(value)
    text = str(value)
    return "'" + text if text.startswith(_FORMULA) else text


def local_time(utc: str | None) -> str:
    """An ISO time with its zone as this machine's local time, to the second (the teacher's clock)."""
    if not utc:
        return ""
    try:
        return datetime.fromisoformat(utc).astimezone().strftime("%Y-%m-%d %H:%M:%S")
    except (ValueError, OverflowError, OSError):
        return ""


def _csv(columns: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """The CSV text, with a byte-order mark first: the one sign a spreadsheet (Excel) reads to take the file as
    UTF-8, so an accented name is not garbled."""
    out = io.StringIO()
    out.write("\ufeff")
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([csv_cell(v) for v in row])
    return out.getvalue()
