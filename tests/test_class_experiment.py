"""A classroom experiment (issue 50, item 3): the class split at random into two conditions, in permuted blocks of
two, seeded and kept in class.json; each student's lab handed their condition's protocol; the projector's two
groups and their difference (Welch's interval on the after-effect) held to an independent computation from the run
files, and ``armgame analyze --class`` saying the same after class."""

from __future__ import annotations

import csv
import dataclasses
import json
import math

import numpy as np
import pytest

from armgame.classroom.experiment import Experiment, condition_at
from armgame.classroom.intake import Clerk
from armgame.classroom.roster import Roster
from armgame.classroom.views import lab_curve
from armgame.cli import main
from armgame.lab.protocol_file import load_protocol, protocol_as_dict
from armgame.records.replay import Replay
from armgame.records.storage import DataFileError

#: Two field strengths: baseline, a curl field, washout (go cues after 0.1 to 0.2 s: the trials matter, not the waits).
STRONG = ('name = "strong"\ntargets = 2\ntimeout = 1.5\ndelay_min = 0.1\ndelay_max = 0.2\n'
          '[[blocks]]\nname = "baseline"\ntrials = 4\n'
          '[[blocks]]\nname = "field"\ntrials = 8\nperturbation = "curl"\nb = 10.0\n'
          '[[blocks]]\nname = "washout"\ntrials = 3\n')
WEAK = STRONG.replace('"strong"', '"weak"').replace("b = 10.0", "b = 4.0")
#: Each condition's runs: a seed and the adaptive bot's learning rates, for a spread.
BOTS = ((1, "0.21", "0.02"), (2, "0.4", "0.05"), (3, "0.1", "0.01"), (4, "0.3", "0.06"))
#: Student's t, 0.975 quantile (a printed table), for Welch's degrees of freedom between its rows.
T975 = {2: 4.3027, 3: 3.1824, 4: 2.7764, 5: 2.5706, 6: 2.4469}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("runs")
    for name, text in (("strong", STRONG), ("weak", WEAK)):
        (folder / f"{name}.toml").write_text(text)
        for seed, fast, slow in BOTS:
            path = folder / f"{name}{seed}.json"
            assert main(["lab", str(folder / f"{name}.toml"), "--bot", "adaptive", "--headless", "--seed", str(seed),
                         "--learning", fast, slow, "--record", str(path)]) == 0
        assert main(["analyze", *(str(folder / f"{name}{s}.json") for s, _, _ in BOTS), "--out",
                     str(folder / name)]) == 0
    return folder


def as_person(path, name: str) -> bytes:
    return dataclasses.replace(Replay.load(path), driven="keyboard", driver=None, player=name).to_bytes()


def experiment_class(folder, seed: int) -> tuple[Roster, Clerk]:
    folder.mkdir(exist_ok=True)
    roster, _ = Roster.open(folder, None)
    for name, text in (("strong", STRONG), ("weak", WEAK)):
        (folder.parent / f"{name}.toml").write_text(text)
    a, b = (protocol_as_dict(load_protocol(folder.parent / f"{n}.toml")) for n in ("strong", "weak"))
    roster.changed(lab=a, experiment=Experiment(a, b, seed))
    return roster, Clerk(folder, roster)


def test_forty_students_split_in_blocks_of_two_balanced_seeded_recorded_and_kept_over_a_restart(tmp_path):
    names = [f"Student {i}" for i in range(40)]
    roster, clerk = experiment_class(tmp_path / "one", seed=2026)
    got = []
    for i, name in enumerate(names):
        if i == 20:  # the server restarted halfway: the class goes on from its record
            roster = Roster.open(tmp_path / "one", None)[0]
            clerk = Clerk(tmp_path / "one", roster)
        clerk.join(name, None, lab=True)
        got.append(roster.experiment.condition_of(name))
        counts = roster.experiment.counts()
        assert abs(counts["a"] - counts["b"]) <= (i + 1) % 2  # within one, and equal after every pair
    assert got.count("a") == got.count("b") == 20
    assert all({got[i], got[i + 1]} == {"a", "b"} for i in range(0, 40, 2))  # each pair: one of each
    assert len({tuple(got[i:i + 2]) for i in range(0, 40, 2)}) == 2  # in random order: both orders occur
    # Recorded: class.json holds the seed and every assignment, in order.
    record = json.loads((tmp_path / "one" / "class.json").read_text())
    assert record["format_version"] >= 3 and record["experiment"]["seed"] == 2026
    assert [c for _, c in record["experiment"]["assigned"]] == got
    # Deterministic given the seed: another class of the same seed splits the same; another seed does not.
    other_roster, other = experiment_class(tmp_path / "two", seed=2026)
    for name in names:
        other.join(name, None, lab=True)
    assert [other_roster.experiment.condition_of(n) for n in names] == got
    assert [condition_at(2027, i) for i in range(40)] != got
    # A join that is not for the lab (a game) assigns nothing; a rejoin keeps the condition.
    token = clerk.join("Gamer", None)[1]
    assert roster.experiment.condition_of("Gamer") is None
    clerk.join("Gamer", token, lab=True)
    assert roster.experiment.condition_of("Gamer") == condition_at(2026, 40)
    # A hand-edited split is refused at the next start, in one line; a class file from before (format 2) reads.
    record["experiment"]["assigned"][0][1] = "b" if got[0] == "a" else "a"
    (tmp_path / "one" / "class.json").write_text(json.dumps(record))
    with pytest.raises(DataFileError, match="not the condition its seed draws"):
        Roster.open(tmp_path / "one", None)
    del record["experiment"]
    record.pop("browser_lab", None)  # format 4's switch: a format 2 file has none
    record["format_version"] = 2
    (tmp_path / "one" / "class.json").write_text(json.dumps(record))
    assert Roster.open(tmp_path / "one", None)[0].experiment is None


def after_effect(rows: list[dict[str, str]]) -> float:
    """From trials.csv: the washout's first ordinary reach less the mean of the baseline's last three."""
    def block(name: str) -> list[float]:
        return [float(r["max_perpendicular_error_m"]) for r in rows if r["block"] == name
                and r["perturbation"] == "none" and r["hand_sent_home"] in ("0", "False")]
    return block("washout")[0] - float(np.mean(block("baseline")[-3:]))


def test_the_two_groups_and_their_difference_are_welchs_from_the_run_files_and_analyze_says_the_same(
        tmp_path, runs, capsys):
    folder = tmp_path / "class"
    roster, clerk = experiment_class(folder, seed=5)
    used = {"a": iter(BOTS), "b": iter(BOTS)}
    effects: dict[str, list[float]] = {"a": [], "b": []}
    for i in range(8):
        name = f"S{i}"
        token = clerk.join(name, None, lab=True)[1]
        c = roster.experiment.condition_of(name)
        seed = next(used[c])[0]
        protocol = "strong" if c == "a" else "weak"
        answer = clerk.hand_in(token, as_person(runs / f"{protocol}{seed}.json", name))
        assert answer["message"] == "lab run handed in: in the class curve"
        with (runs / protocol / f"{protocol}{seed}.trials.csv").open() as f:
            effects[c].append(after_effect(list(csv.DictReader(f))) * 100)
    groups = lab_curve(clerk)["groups"]
    a, b = np.array(effects["a"]), np.array(effects["b"])
    va, vb = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
    df = (va + vb) ** 2 / (va ** 2 / (len(a) - 1) + vb ** 2 / (len(b) - 1))
    assert 3 < df < 6
    d = groups["difference"]
    assert d["difference"] == pytest.approx(a.mean() - b.mean(), abs=1e-5) and d["df"] == pytest.approx(df, rel=1e-5)
    half = (d["high"] - d["low"]) / 2  # between the t table's rows either side of df
    assert T975[math.ceil(df)] * math.sqrt(va + vb) <= half + 1e-4 <= T975[math.floor(df)] * math.sqrt(va + vb) + 2e-4
    assert (groups["a"]["students"], groups["b"]["students"]) == (4, 4)
    assert (groups["a"]["protocol"], groups["b"]["protocol"]) == ("strong", "weak")
    assert groups["a"]["stats"]["after_effect"]["mean"] == pytest.approx(a.mean(), abs=1e-5)
    assert d["difference"] > 0  # the stronger field leaves the larger after-effect
    words = groups["difference_words"]
    assert words.startswith(f"after-effect, group A - group B: {a.mean() - b.mean():+.2f} cm (Welch's 95 % CI ")
    # The same class started again: the same groups.
    again = Clerk(folder, Roster.open(folder, None)[0])
    assert again.load_lab() == []
    assert lab_curve(again)["groups"] == groups
    # After class, from the folder: the same answer.
    capsys.readouterr()
    assert main(["analyze", "--class", str(folder), "--out", str(tmp_path / "out"), "--no-figures"]) == 0
    said = capsys.readouterr().out
    assert f"the experiment's answer: {words}" in said and "group B (weak, 4 students)" in said


def test_the_lab_client_runs_the_protocol_its_class_hands_it_and_nothing_else(tmp_path, runs, monkeypatch, capsys):
    from class_server import running_class

    from armgame.classroom import client

    with running_class(tmp_path / "class", lab=str(runs / "strong.toml"), lab_b=str(runs / "weak.toml"),
                       split_seed=5) as opened:
        code = opened.clerk.roster.code
        for name in ("Ann", "Bo"):  # both type the first protocol; the class hands each their own
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            assert main(["lab", str(runs / "strong.toml"), "--bot", "adaptive", "--headless", "--join",
                         f"127.0.0.1:{opened.port}", "--code", code, "--name", name]) == 0
        experiment = opened.clerk.roster.experiment
        ran = {run.player: run.protocol.name for run in opened.clerk.lab_runs}
    said = capsys.readouterr()
    assert {experiment.condition_of("Ann"), experiment.condition_of("Bo")} == {"a", "b"}
    assert ran == {n: "strong" if experiment.condition_of(n) == "a" else "weak" for n in ("Ann", "Bo")}
    assert "group" not in said.out + said.err and "condition" not in said.out + said.err  # the student is told nothing
    # A class's answer whose protocol is no protocol is refused, never run.
    with pytest.raises(ValueError):
        client._class_protocol({"name": "x", "blocks": "all of them"})
    with pytest.raises(ValueError):
        client._class_protocol(["lesson"])


def _call(port: int, path: str, body: dict | None = None, headers: dict | None = None) -> tuple[int, dict]:
    import urllib.error
    import urllib.request

    req = urllib.request.Request(f"http://127.0.0.1:{port}{path}", headers={**(headers or {}), **(
        {"Content-Type": "application/json"} if body is not None else {})},
        data=None if body is None else json.dumps(body).encode())
    try:
        with urllib.request.urlopen(req, timeout=20) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as exc:
        with exc:
            return exc.code, json.loads(exc.read())


def test_each_browser_is_handed_its_students_conditions_plan_assigned_at_its_first_request(tmp_path):
    """``/api/labplan`` with a student's code and token: their condition's plan, the condition assigned at the first
    request as a lab join assigns it (in the split's order, balanced, in class.json); nothing in the plan names it.
    Without the headers, the class's default plan; a wrong token or code is refused in one line and counted."""
    from class_server import running_class

    from armgame.classroom.state import FREE_GUESSES
    from armgame.lab.plan import lab_plan
    from armgame.lab.session import lab_config
    from armgame.records.standings import player_key

    for name, text in (("strong", STRONG), ("weak", WEAK)):
        (tmp_path / f"{name}.toml").write_text(text)
    protocols = {"a": load_protocol(tmp_path / "strong.toml"), "b": load_protocol(tmp_path / "weak.toml")}
    names = [f"Student {i}" for i in range(6)]
    with running_class(tmp_path / "class", lab=str(tmp_path / "strong.toml"), lab_b=str(tmp_path / "weak.toml"),
                       split_seed=11) as opened:
        port, code, seed = opened.port, opened.clerk.roster.code, opened.clerk.roster.seed
        tokens = {}
        for name in names:  # as the browser joins: for its game, which assigns nobody
            status, answer = _call(port, "/api/join", {"code": code, "name": name})
            assert status == 200 and "lab" not in answer
            tokens[name] = answer["token"]
        assert opened.clerk.roster.experiment.assigned == []
        plans = {}
        for name in names:
            status, plans[name] = _call(port, "/api/labplan", headers={"Authorization": f"Bearer {tokens[name]}",
                                                                       "X-Armgame-Code": code})
            assert status == 200
        # Asked again (a reload), the same plan; a lab join afterwards hands the Python client the same protocol.
        assert _call(port, "/api/labplan", headers={"Authorization": f"Bearer {tokens[names[0]]}",
                                                    "X-Armgame-Code": code})[1] == plans[names[0]]
        joined = _call(port, "/api/join", {"code": code, "name": names[1], "token": tokens[names[1]], "for": "lab"})[1]
        assert joined["lab"] == plans[names[1]]["protocol"]
        status, default = _call(port, "/api/labplan")
        assert status == 200
        status, refused = _call(port, "/api/labplan", headers={"Authorization": f"Bearer {tokens[names[0]]}",
                                                               "X-Armgame-Code": "ZZZZ" if code != "ZZZZ" else "YYYY"})
        assert status == 403 and "\n" not in refused["error"] and "code" in refused["error"]
        wrong = [_call(port, "/api/labplan", headers={"Authorization": "Bearer not-a-token", "X-Armgame-Code": code})
                 for _ in range(FREE_GUESSES + 1)]
        assert [s for s, _ in wrong] == [401] * FREE_GUESSES + [429]  # counted as wrong tokens are everywhere
        assert all("\n" not in answer["error"] for _, answer in wrong)
        record = json.loads((tmp_path / "class" / "class.json").read_text())["experiment"]
    # Assigned in the order the browsers asked, as the split draws (blocks of two): three in each condition.
    assert [key for key, _ in record["assigned"]] == [player_key(n) for n in names]
    assert [c for _, c in record["assigned"]] == [condition_at(11, i) for i in range(6)]
    conditions = dict(record["assigned"])
    assert sorted(conditions.values()) == ["a"] * 3 + ["b"] * 3
    for name, plan in plans.items():
        protocol = protocols[conditions[player_key(name)]]
        assert plan == lab_plan(lab_config(protocol, seed, person=True), protocol)
        assert not {"condition", "group"} & set(plan)
    assert default == lab_plan(lab_config(protocols["a"], seed, person=True), protocols["a"])  # the teacher's --lab


@pytest.mark.slow  # in chromium
def test_the_projector_shows_the_two_groups_side_by_side_and_their_difference(tmp_path, runs, monkeypatch):
    import urllib.request

    from browser import browser_page
    from class_server import running_class

    from armgame.classroom import client

    with running_class(tmp_path / "class", lab=str(runs / "strong.toml"), lab_b=str(runs / "weak.toml"),
                       split_seed=5) as opened, browser_page(1024, 768) as page:
        page.goto(f"http://127.0.0.1:{opened.port}/lab")
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        used = {"a": iter(BOTS), "b": iter(BOTS)}
        for i in range(8):
            name = f"S{i}"
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            member = client.join(address, opened.clerk.roster.code, name, lab=True)
            c = opened.clerk.roster.experiment.condition_of(name)
            run = runs / f"{'strong' if c == 'a' else 'weak'}{next(used[c])[0]}.json"
            assert "in the class curve" in client.hand_in(member, as_person(run, name)).message
        page.wait_for_selector("body[data-students='8']", state="attached", timeout=10_000)
        with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}/api/lab", timeout=10) as r:
            groups = json.loads(r.read())["groups"]
        assert page.locator("#groups").is_visible() and not page.locator("figure.curve").is_visible()
        assert page.locator("#group-a polygon.band.a").count() == 1
        assert page.locator("#group-b polygon.band.b").count() == 1
        assert page.text_content("#difference") == groups["difference_words"]
        assert "group A: strong" in page.text_content("#group-a-title")
        boxes = page.evaluate("""() => ['#group-a', '#group-b', '#difference'].map((s) => {
            const r = document.querySelector(s).getBoundingClientRect();
            return [r.left, r.top, r.right, r.bottom]; })""")
        assert all(left >= 0 and top >= 0 and right <= 1024.5 and bottom <= 768.5
                   for left, top, right, bottom in boxes), boxes
        assert boxes[0][2] <= boxes[1][0]  # side by side, not overlapping
        page.screenshot(path=str(tmp_path.parent / "lab-groups.png"))


def test_a_renamed_student_keeps_the_condition_their_first_name_drew(tmp_path):
    """The teacher fixes a typo after the split: the student's next lab request, under the new name, is handed the
    same condition (it drew a new one: a second assignment, the split unbalanced), and the groups count them once."""
    roster, clerk = experiment_class(tmp_path / "class", seed=5)
    students = ("Anm", "Bo", "Cy", "Di")
    for name in students:
        clerk.join(name, None, "127.0.0.1")
    drawn = {name: clerk.assign(name) for name in students}
    clerk.rename("Anm", "Ann")
    assert clerk.assign("Ann") == drawn["Anm"] and len(roster.experiment.assigned) == len(students)
    assert roster.experiment.condition_of("Ann", roster.renamed) == roster.experiment.condition_of("Anm")
    assert roster.experiment.counts() == {"a": 2, "b": 2}
    again = Roster.open(tmp_path / "class", None)[0]  # the record as a restart, or analyze after class, reads it
    assert again.experiment.condition_of("Ann", again.renamed) == roster.experiment.condition_of("Anm")
