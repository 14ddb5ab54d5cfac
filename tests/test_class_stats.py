"""The class's statistics (issue 50, item 2) held to an independent computation from the run files.

Every number ``lab/classstats.py`` gives (the curve's t interval per trial, each student's early and late exposure
error and after-effect, the class's answer, the generalization by direction, the fitted rates) is computed here
again from the ``trials.csv`` files ``armgame analyze`` writes for each run, with plain numpy and the t quantiles
of a printed table; the live class's ``/api/lab`` and teacher's CSV, and ``armgame analyze --class --students``,
carry the same numbers. The students are the adapting bot's runs relabelled as people's, with different seeds and
learning rates for a spread.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import urllib.request

import numpy as np
import pytest
from class_server import running_class

from armgame.classroom import client
from armgame.cli import main
from armgame.lab.classstats import estimate, welch
from armgame.records.replay import Replay

#: Baseline, a curl field, washout: k = 3 at each end of the field's 8 trials, the after-effect on the washout's first.
#: Go cues after 0.1 to 0.2 s (both protocols): the statistics need the trials, not the waits between them.
LESSON = ('name = "mini"\ntargets = 2\ntimeout = 1.5\ndelay_min = 0.1\ndelay_max = 0.2\n'
          '[[blocks]]\nname = "baseline"\ntrials = 4\n'
          '[[blocks]]\nname = "field"\ntrials = 8\nperturbation = "curl"\nb = 10.0\n'
          '[[blocks]]\nname = "washout"\ntrials = 3\n')
#: Train to 90 deg, probe four directions with channel trials (a channel-trial baseline to each first).
GENERAL = ('name = "minigen"\ntargets = 4\ntimeout = 1.5\ndelay_min = 0.1\ndelay_max = 0.2\n'
           '[[blocks]]\nname = "baseline"\ntrials = 4\n'
           'channel_trials = 4\n[[blocks]]\nname = "exposure"\ntrials = 4\nperturbation = "curl"\nb = 10.0\n'
           'directions_deg = [90]\n[[blocks]]\nname = "test"\ntrials = 10\nperturbation = "curl"\nb = 10.0\n'
           'channel_trials = 4\ndirections_deg = [90]\nprobe_directions_deg = [0, 90, 180, 270]\n')
#: Each student: a seed and the adaptive bot's learning rates (B_f, B_s).
STUDENTS = {"Ann": (1, "0.21", "0.02"), "Bo": (2, "0.4", "0.05"), "Cy": (3, "0.1", "0.01"), "Dee": (4, "0.3", "0.0"),
            "Eve": (5, "0.08", "0.04")}
#: Student's t, 0.975 quantile, by degrees of freedom (a printed table: not computed by the code under test).
T975 = {1: 12.7062, 2: 4.3027, 3: 3.1824, 4: 2.7764, 5: 2.5706}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Each student's run of both protocols, and each run's trials.csv as ``armgame analyze`` writes it."""
    folder = tmp_path_factory.mktemp("runs")
    for name, text in (("mini", LESSON), ("minigen", GENERAL)):
        (folder / f"{name}.toml").write_text(text)
        for student, (seed, fast, slow) in STUDENTS.items():
            path = folder / f"{name}-{student}.json"
            assert main(["lab", str(folder / f"{name}.toml"), "--bot", "adaptive", "--headless", "--seed", str(seed),
                         "--learning", fast, slow, "--record", str(path)]) == 0
            path.write_bytes(as_person(path, student))
        assert main(["analyze", *(str(folder / f"{name}-{s}.json") for s in STUDENTS), "--out",
                     str(folder / name)]) == 0
    return folder


def as_person(path, name: str) -> bytes:
    return dataclasses.replace(Replay.load(path), driven="keyboard", driver=None, player=name).to_bytes()


def table(runs, protocol: str, student: str) -> list[dict[str, str]]:
    with (runs / protocol / f"{protocol}-{student}.trials.csv").open() as f:
        return list(csv.DictReader(f))


def value(row: dict[str, str], column: str) -> float:
    return math.nan if row["hand_sent_home"] in ("1", "True") or row[column] == "" else float(row[column])


def t_interval(values: list[float]) -> tuple[float, float, float]:
    x = np.array([v for v in values if math.isfinite(v)])
    half = T975[len(x) - 1] * x.std(ddof=1) / math.sqrt(len(x))
    return float(x.mean()), float(x.mean() - half), float(x.mean() + half)


def by_hand(rows: list[dict[str, str]]) -> dict[str, float]:
    """One student's numbers from their trials.csv: the ordinary trials (the block's own perturbation) of each
    block, the field's first and last 3, the baseline's last 3, the washout's first."""
    def block(name: str, kind: str) -> list[float]:
        return [v for r in rows if r["block"] == name and r["perturbation"] == kind
                for v in [value(r, "max_perpendicular_error_m")] if math.isfinite(v)]

    field, base, wash = block("field", "curl"), block("baseline", "none"), block("washout", "none")
    early, late = float(np.mean(field[:3])), float(np.mean(field[-3:]))
    return {"early": early, "late": late, "learning": late - early,
            "after_effect": wash[0] - float(np.mean(base[-3:]))}


def test_estimate_and_welch_are_the_textbooks():
    values = [1.0, 2.0, 4.0, 7.0]
    mean, low, high = t_interval(values)
    e = estimate(values)
    assert (e.n, e.mean) == (4, mean)
    assert e.low == pytest.approx(low, abs=1e-3) and e.high == pytest.approx(high, abs=1e-3)
    assert math.isnan(estimate([1.0, 2.0]).low)  # two students: no interval
    a, b = [1.0, 2.0, 4.0, 7.0], [0.0, 0.5, 0.7]
    va, vb = np.var(a, ddof=1) / 4, np.var(b, ddof=1) / 3
    df = (va + vb) ** 2 / (va ** 2 / 3 + vb ** 2 / 2)
    d = welch(a, b)
    assert d.df == pytest.approx(df) and d.difference == pytest.approx(np.mean(a) - np.mean(b))
    # df = 3.38: between the table's 3 and 4, so the half-width between theirs
    half = (d.high - d.low) / 2
    assert T975[4] * math.sqrt(va + vb) < half < T975[3] * math.sqrt(va + vb)


def test_every_statistic_is_the_one_computed_from_the_trials_files(runs):
    from armgame.lab.classstats import class_stats, student_fit
    from armgame.lab.protocol_file import load_protocol

    protocol = load_protocol(runs / "mini.toml")
    tables = {s: table(runs, "mini", s) for s in STUDENTS}
    rows = {s: [{**r, "trial": int(r["trial"]), "hand_sent_home": r["hand_sent_home"] in ("1", "True")}
                for r in t] for s, t in tables.items()}
    stats = class_stats(protocol, list(rows.items()))
    # Each student.
    for m in stats.students:
        mine = by_hand(tables[m.player])
        for key, v in mine.items():
            assert getattr(m, key) == pytest.approx(v, abs=1e-12), (m.player, key)
    # The class's answer.
    for key in ("early", "late", "learning", "after_effect"):
        mean, low, high = t_interval([by_hand(t)[key] for t in tables.values()])
        e = getattr(stats, key)
        assert (e.n, e.mean) == (5, pytest.approx(mean)) and (e.low, e.high) == (pytest.approx(low, abs=1e-4),
                                                                                 pytest.approx(high, abs=1e-4))
    assert stats.after_effect.low > 0  # the class's after-effect: positive, its interval clear of 0
    # The curve: per trial, the mean and interval across the five.
    for point in stats.curve:
        values = [value(t[point["trial"] - 1], "max_perpendicular_error_m") for t in tables.values()]
        mean, low, high = t_interval(values)
        assert point["n"] == 5 and point["mean"] == pytest.approx(mean) and point["low"] == pytest.approx(low, abs=1e-4)
    # Two students: their own curves, no interval.
    two = class_stats(protocol, list(rows.items())[:2])
    assert len(two.own) == 2 and all(math.isnan(p["low"]) for p in two.curve)
    # The fitted rates: the two-rate fit analyze --fit prints for the same run.
    fit = student_fit(rows["Bo"], "max_perpendicular_error_m")
    from armgame.lab.fit import fit_learner

    disturbance = [float(r["disturbance"]) for r in tables["Bo"]]
    clamped = [r["perturbation"] == "channel" for r in tables["Bo"]]
    observed = [float(r["max_perpendicular_error_m"]) for r in tables["Bo"]]
    direct = fit_learner("two-rate", disturbance, clamped, observed)
    assert fit == pytest.approx({"A_f": direct.values["retention_fast"], "A_s": direct.values["retention_slow"],
                                 "B_f": direct.values["rate_fast"], "B_s": direct.values["rate_slow"]})
    assert student_fit(rows["Bo"][:5], "max_perpendicular_error_m") == {}  # too few trials: empty, no traceback


def test_generalization_by_direction_is_the_probes_less_their_baseline(runs):
    from armgame.lab.classstats import class_stats
    from armgame.lab.protocol_file import load_protocol

    protocol = load_protocol(runs / "minigen.toml")
    tables = {s: table(runs, "minigen", s) for s in STUDENTS}
    rows = {s: [{**r, "trial": int(r["trial"]), "hand_sent_home": r["hand_sent_home"] in ("1", "True")}
                for r in t] for s, t in tables.items()}
    stats = class_stats(protocol, list(rows.items()))
    expected: dict[float, list[float]] = {}
    for t in tables.values():
        base = {float(r["target_deg"]): float(r["adaptation_index"]) for r in t if r["block"] == "baseline"}
        for r in t:
            if r["block"] == "test" and r["perturbation"] == "channel":
                angle = (float(r["target_deg"]) - 90.0 + 180.0) % 360.0 - 180.0
                angle = 180.0 if angle == -180.0 else angle
                expected.setdefault(angle, []).append(float(r["adaptation_index"]) - base[float(r["target_deg"])])
    got = {g["angle_deg"]: g["estimate"] for g in stats.generalization}
    assert sorted(got) == sorted(expected) == [-90.0, 0.0, 90.0, 180.0]
    for angle, values in expected.items():
        mean, low, _ = t_interval(values)
        assert got[angle].mean == pytest.approx(mean) and got[angle].low == pytest.approx(low, abs=1e-4)
        assert got[angle].n == 5


def get(opened, path: str, secret: str | None = None) -> bytes:
    headers = {"Authorization": f"Bearer {secret}"} if secret else {}
    req = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}", headers=headers)
    with urllib.request.urlopen(req, timeout=30) as r:
        return r.read()


@pytest.mark.slow  # a class served and analyze run (2.6 s): one function builds the three, CI runs it after the suite
def test_the_projector_the_teachers_table_and_analyze_say_the_same(tmp_path, runs, monkeypatch, capsys):
    folder = tmp_path / "class"
    with running_class(folder, lab=str(runs / "mini.toml")) as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        for name in STUDENTS:
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            member = client.join(address, opened.clerk.roster.code, name)
            assert "in the class curve" in client.hand_in(member, (runs / f"mini-{name}.json").read_bytes()).message
        lab = json.loads(get(opened, "/api/lab"))
        teacher = get(opened, "/api/teacher/students.csv", opened.clerk.roster.secret).decode("utf-8-sig")
    stats = lab["stats"]
    mean, low, high = t_interval([by_hand(table(runs, "mini", s))["after_effect"] * 100 for s in STUDENTS])
    assert stats["after_effect"] == {"mean": pytest.approx(mean, abs=1e-5), "low": pytest.approx(low, abs=1e-3),
                                     "high": pytest.approx(high, abs=1e-3), "n": 5}
    assert stats["answer"].startswith(f"after-effect: {mean:+.2f} cm (95 % CI ") and "n = 5" in stats["answer"]
    assert [p["n"] for p in stats["curve"]] == [5] * 15 and stats["own"] == [] and stats["generalization"] == []
    rows = list(csv.DictReader(io.StringIO(teacher)))
    assert [r["name"] for r in rows] == list(STUDENTS)
    for r in rows:
        mine = by_hand(table(runs, "mini", r["name"]))
        assert float(r["after_effect_cm"]) == pytest.approx(mine["after_effect"] * 100)
        assert float(r["early_cm"]) == pytest.approx(mine["early"] * 100)
        assert r["A_f"] == "" or 0 <= float(r["A_f"]) <= 1
    # After class, from the folder: the same table, the same answer.
    capsys.readouterr()
    assert main(["analyze", "--class", str(folder), "--out", str(tmp_path / "out"), "--no-figures",
                 "--students", str(tmp_path / "students.csv")]) == 0
    assert f"the class's answer: {stats['answer']}" in capsys.readouterr().out
    assert (tmp_path / "students.csv").read_text(encoding="utf-8-sig") == teacher


def inside(page, selector: str) -> bool:
    """Whether every element ``selector`` finds lies inside the viewport (CSS laid it out; nothing spills)."""
    return page.evaluate("""(sel) => [...document.querySelectorAll(sel)].every((e) => {
        const r = e.getBoundingClientRect();
        return r.width > 0 && r.left >= 0 && r.top >= 0 && r.right <= innerWidth + 0.5 && r.bottom <= innerHeight + 0.5;
    })""", selector)


@pytest.mark.slow  # in chromium
@pytest.mark.parametrize("protocol", ["mini", "minigen"])
def test_the_projectors_lab_page_draws_the_band_the_answer_n_and_the_generalization(tmp_path, runs, monkeypatch,
                                                                                       protocol):
    from browser import browser_page

    with running_class(tmp_path / "class", lab=str(runs / f"{protocol}.toml")) as opened, \
            browser_page(1024, 768) as page:
        page.goto(f"http://127.0.0.1:{opened.port}/lab")
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        for i, name in enumerate(STUDENTS):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            member = client.join(address, opened.clerk.roster.code, name)
            client.hand_in(member, (runs / f"{protocol}-{name}.json").read_bytes())
            if i == 1:  # two students: their own curves, no band
                page.wait_for_selector("body[data-students='2']", state="attached", timeout=10_000)
                assert page.locator("#curve path.own").count() == 2 and page.locator("#curve polygon.band").count() == 0
                assert "too few for an interval" in page.text_content("#facts")
        page.wait_for_selector("body[data-students='5']", state="attached", timeout=10_000)
        lab = json.loads(get(opened, "/api/lab"))
        assert page.locator("#curve polygon.band").count() == 1 and page.locator("#curve path.mean").count() == 1
        assert "n = 5 per trial" in page.text_content("#facts")
        assert page.text_content("#answer") == "The class's answer: " + lab["stats"]["answer"]
        general = page.locator("#general")
        if protocol == "minigen":
            assert general.is_visible() and page.locator("#general-plot circle.dot").count() == 4
            assert page.locator("#general-plot line.bar").count() == 4  # an interval per direction
            assert inside(page, "#general-plot")
        else:
            assert not general.is_visible()
        assert inside(page, "#curve") and inside(page, "#answer") and page.dialogs == []
        page.screenshot(path=str(tmp_path.parent / f"lab-{protocol}.png"))
