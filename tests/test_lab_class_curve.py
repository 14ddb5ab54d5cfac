"""The class curve after class is the projector's (issue 39): ``armgame analyze --class`` on a class's folder
and the class's ``/lab`` (``classroom.views.lab_curve``) are built by one function,
``lab.analysis.class_curve_of``, from the teacher's protocol (``class.json``), people's first runs only,
programs counted apart, hidden names left out; and ``analyze --class`` needs no matplotlib."""

from __future__ import annotations

import csv
import dataclasses
import shutil
import sys

import pytest

from armgame.classroom.intake import Clerk
from armgame.classroom.roster import Roster
from armgame.classroom.views import lab_curve
from armgame.cli import main
from armgame.lab.protocol_file import load_protocol, protocol_as_dict
from armgame.records.replay import Replay

#: The teacher's protocol, and another one a student ran too (a longer washout): short to run.
PROTOCOL = ('name = "short"\ntargets = 2\ntimeout = 1.5\n[[blocks]]\nname = "field"\ntrials = 2\n'
            'perturbation = "curl"\nb = 10.0\n[[blocks]]\nname = "washout"\ntrials = 2\n')
OTHER = PROTOCOL.replace('name = "short"', 'name = "other"').replace("trials = 2\n", "trials = 3\n")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Bot runs of both protocols, recorded once: relabelled as people's runs where a test needs that."""
    folder = tmp_path_factory.mktemp("runs")
    (folder / "short.toml").write_text(PROTOCOL)
    (folder / "other.toml").write_text(OTHER)
    for name, seed in (("short", 1), ("short", 2), ("short", 3), ("short", 4), ("short", 6), ("other", 5)):
        assert main(["lab", str(folder / f"{name}.toml"), "--bot", "adaptive", "--headless", "--seed", str(seed),
                     "--record", str(folder / f"{name}{seed}.json")]) == 0
    return folder


def as_person(path, name: str) -> bytes:
    return dataclasses.replace(Replay.load(path), driven="keyboard", driver=None, player=name).to_bytes()


def curve_csv(folder):
    with (folder / "class_curve.csv").open() as f:
        return [(int(r["trial"]), r["block"], r["perturbation"], float(r["mean_max_perpendicular_error_m"]),
                 int(r["n"])) for r in csv.DictReader(f)]


def test_analyze_class_is_the_projectors_curve(tmp_path, runs, monkeypatch, capsys):
    folder = tmp_path / "class"
    folder.mkdir()
    roster, _ = Roster.open(folder, None)
    roster.changed(lab=protocol_as_dict(load_protocol(runs / "short.toml")))  # the teacher's --lab short.toml
    clerk = Clerk(folder, roster)
    tokens = {name: clerk.join(name, None)[1] for name in ("Ann", "Bo", "Cy", "Dee", "Bot")}
    for name, run in (("Ann", "short1"), ("Bo", "short2"), ("Ann", "short3"),  # Ann's second run: kept apart
                      ("Cy", "other5"), ("Dee", "short4")):  # another protocol; a name the teacher will hide
        clerk.hand_in(tokens[name], as_person(runs / f"{run}.json", name))
    program = dataclasses.replace(Replay.load(runs / "short6.json"), player="Bot").to_bytes()
    assert "a program's run" in clerk.hand_in(tokens["Bot"], program)["message"]
    clerk.hide("Dee", True)
    projector = lab_curve(clerk)
    assert (projector["protocol"], projector["students"], projector["programs"]) == ("short", 2, 1)
    # A class from before programs went to lab-more/: the bot's run in lab/ beside the people's. The projector's
    # curve never had it; analyze once counted it as a third student.
    shutil.copy(next((folder / "lab-more").glob("Bot-*.json")), folder / "lab" / "bot-old.json")
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # the README's install: no [plot] extra
    for given, out in ((folder / "lab", tmp_path / "curve"), (folder, tmp_path / "curve2")):
        capsys.readouterr()
        assert main(["analyze", "--class", str(given), "--out", str(out)]) == 1  # others left out, and named
        said = capsys.readouterr()
        assert "the class's protocol: short (the teacher's choice" in said.out
        assert "class curve of 2 students" in said.out and "1 run of programs kept apart" in said.out
        assert "class_curve.png not drawn: the figure needs matplotlib (pip install 'armgame[plot]')" in said.out
        assert not (out / "class_curve.png").exists()
        assert "a name the teacher hid" in said.err and "its protocol 'other' differs" in said.err
        mine = curve_csv(out)
        assert [(t, b, p, n) for t, b, p, _, n in mine] == \
            [(t["trial"], t["block"], t["perturbation"], t["n"]) for t in projector["trials"]]
        assert [round(m * 100, 6) for *_, m, _ in mine] == [t["mean"] for t in projector["trials"]]
    # The same class read again by its server (a restart) draws the same curve.
    again = Clerk(folder, Roster.open(folder, None)[0])
    again.load_lab()
    assert lab_curve(again) == projector


def test_a_folder_that_is_no_class_keeps_its_rules(tmp_path, runs, capsys):
    """A rehearsal's folder (no class.json): bots may stand in for volunteers, and the protocol is the one most
    replays share, as before."""
    folder = tmp_path / "rehearsal"
    folder.mkdir()
    for name in ("short1", "short2", "other5"):
        shutil.copy(runs / f"{name}.json", folder)
    assert main(["analyze", "--class", str(folder), "--out", str(tmp_path / "c"), "--no-figures"]) == 1
    said = capsys.readouterr()
    assert "class curve of 2 students (1 left out)" in said.out and "programs" not in said.out
    assert [n for *_, n in curve_csv(tmp_path / "c")] == [2, 2, 2, 2]


def test_the_teachers_page_downloads_the_class_curve_as_a_png(tmp_path, runs, monkeypatch):
    import json
    import urllib.error
    import urllib.request

    from class_server import running_class

    from armgame.classroom import client

    def get(opened, path):
        request = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}",
                                         headers={"Authorization": f"Bearer {opened.clerk.roster.secret}"})
        try:
            with urllib.request.urlopen(request, timeout=20) as r:
                return r.status, r.headers.get("Content-Type"), r.read()
        except urllib.error.HTTPError as exc:
            return exc.code, exc.headers.get("Content-Type"), exc.read()

    with running_class(tmp_path / "class", lab=str(runs / "short.toml")) as opened:
        status, _, body = get(opened, "/api/teacher/lab.png")
        assert status == 404 and "no class curve yet" in json.loads(body)["error"]
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        for i, name in enumerate(("Ann", "Bo"), 1):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            client.hand_in(client.join(address, opened.clerk.roster.code, name),
                           as_person(runs / f"short{i}.json", name))
        status, kind, png = get(opened, "/api/teacher/lab.png")
        assert (status, kind) == (200, "image/png") and png.startswith(b"\x89PNG\r\n\x1a\n")
        import io

        import matplotlib.image
        assert matplotlib.image.imread(io.BytesIO(png)).shape[:2] == (1080, 1920)  # the lab's figure, projector-sized
        monkeypatch.setitem(sys.modules, "matplotlib", None)  # the README's install: no [plot] extra
        status, _, body = get(opened, "/api/teacher/lab.png")
        message = json.loads(body)["error"]
        assert status == 503 and "pip install 'armgame[plot]'" in message and "\n" not in message
