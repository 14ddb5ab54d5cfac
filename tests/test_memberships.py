"""A machine keeps every name it joined a class under, each with its token (memberships.json): a bot's name never
costs a student theirs. The file is bounded, read as hostile, private, and its older one-name format still reads."""

from __future__ import annotations

import json
import os
import stat

import pytest
from class_server import keyboard_game, running_class

from armgame.classroom import client, memberships
from armgame.classroom.bounds import MAX_MEMBERSHIP_CLASSES as MAX_CLASSES
from armgame.classroom.bounds import MAX_MEMBERSHIP_NAMES as MAX_NAMES
from armgame.classroom.bounds import MAX_MEMBERSHIPS_BYTES as MAX_BYTES
from armgame.classroom.roster import CODE_ALPHABET
from armgame.cli import main
from armgame.files import DataFileError


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """This machine's client folder."""
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    return tmp_path / "machine"


def test_a_bots_name_never_costs_a_student_theirs(tmp_path, folder, capsys):
    """docs/teaching.md's bot join, from the student's own machine, between two of their own joins."""
    with running_class(tmp_path / "class") as opened:
        where, code = f"127.0.0.1:{opened.port}", opened.clerk.roster.code
        address = client.ClassAddress.parse(where)
        kofi = client.join(address, code, "Kofi A")
        assert main(["play", "--headless", "--bot", "model", "--join", where, "--code", code,
                     "--name", "Kofi's robot"]) == 0
        again = client.join(address, code, "kofi a")  # the same name, however it is typed: the same token
        assert (again.name, again.token) == ("Kofi A", kofi.token)
        assert client.hand_in(again, keyboard_game(8, player="Kofi A").to_bytes()).answer["ok"]
        robot = client.join(address, code, "Kofi's robot")  # and the bot's name is still the machine's too
        assert client.join(address, code, None).name == "Kofi's robot"  # no --name: the name joined under last
        assert len(opened.clerk.roster.players) == 2
    assert client.offline(address, code, "Kofi A").token == kofi.token  # played on while the class is away
    assert client.offline(address, code, None).token == robot.token
    assert client.offline(address, code, "Someone else") is None
    assert stat.S_IMODE(os.stat(folder / "memberships.json").st_mode) == 0o600


def test_the_one_name_format_of_before_reads_and_is_written_as_the_new_one(tmp_path, folder, capsys):
    with running_class(tmp_path / "class") as opened:
        address, code = client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code
        ann = client.join(address, code, "Ann")
        old = {code: {"name": "Ann", "token": ann.token, "seed": str(ann.seed), "address": address.label,
                      "at": "1764400000.125"}}
        (folder / "memberships.json").write_text(json.dumps(old))  # as armgame 0.4 wrote it
        assert client.last_class() == (address.label, code, "Ann")
        assert client.join(address, code, None).token == ann.token  # its name and token, read
        bo = client.join(address, code, "Bo")
    data = json.loads((folder / "memberships.json").read_text())
    assert data["format"] == 2 and [n["name"] for n in data["classes"][code]["names"]] == ["Bo", "Ann"]
    assert data["classes"][code]["names"][1]["token"] == ann.token and bo.token != ann.token
    assert stat.S_IMODE(os.stat(folder / "memberships.json").st_mode) == 0o600


BAD = {
    "not JSON": b"{",
    "not an object": b"[]",
    "a newer format": json.dumps({"format": 3, "classes": {}}).encode(),
    "a header in a token": json.dumps({"format": 2, "classes": {"ACDE": {
        "address": "10.0.0.5:8765", "seed": 10, "at": 1.0,
        "names": [{"name": "Ann", "token": "x" * 20 + "\r\nX-Evil: 1", "at": 1.0}]}}}).encode(),
    "a control character in a name": json.dumps({"ACDE": {"name": "Ann\x1b[2J", "token": "t" * 32, "seed": "10",
                                                          "address": "10.0.0.5:8765"}}).encode(),
    "a code no class has": json.dumps({"format": 2, "classes": {"BOB8": {
        "address": "", "seed": 10, "at": 1.0, "names": [{"name": "Ann", "token": "t" * 32, "at": 1.0}]}}}).encode(),
    "nested too deeply": b"[" * 100_000,
    "too large": b" " * (MAX_BYTES + 1),
}


@pytest.mark.parametrize("kind", [*BAD, "a symbolic link"])
def test_a_damaged_file_is_one_line_naming_it_and_is_never_written_over(tmp_path, folder, capsys, kind):
    folder.mkdir()
    path = folder / "memberships.json"
    if kind == "a symbolic link":
        (tmp_path / "elsewhere.json").write_text("{}")
        path.symlink_to(tmp_path / "elsewhere.json")
    else:
        path.write_bytes(BAD[kind])
    before = path.read_bytes()
    game = tmp_path / "game.json"
    keyboard_game(3, player="Ann").save(game)
    assert main(["class", "submit", "127.0.0.1:1", "--code", "ACDE", "--name", "Ann", str(game)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and str(path) in err and "Traceback" not in err, err
    assert path.read_bytes() == before and client.last_class() is None  # the menu offers nothing, quietly


def test_the_names_and_classes_kept_are_bounded_the_oldest_dropped_first(tmp_path):
    path = tmp_path / "memberships.json"
    codes = ["".join(CODE_ALPHABET[(i // 20**k) % 20] for k in range(4)) for i in range(MAX_CLASSES + 1)]
    classes: dict = {}
    # Each class under MAX_NAMES + 1 names of the longest (40 characters of 4 bytes), and tokens as long as a
    # class takes: the file still fits its bound, and reads back as written.
    now = 1.0
    for code in codes:
        for n in range(MAX_NAMES + 1):
            now += 1
            name = f"{n:02d}" + "\U0001f600" * 38
            classes = memberships.joined(classes, code, "[fe80::1]:8765" + "x" * 280, 2**63 - 1, name, "T" * 200, now)
    memberships.write(path, classes)
    assert path.stat().st_size < MAX_BYTES
    back = memberships.read(path)
    assert back == classes and len(back) == MAX_CLASSES and codes[0] not in back  # the class joined longest ago
    kept = back[codes[-1]]
    assert [n.name[:2] for n in kept.names] == [f"{n:02d}" for n in range(MAX_NAMES, 0, -1)]  # name 00 dropped
    # A name joined again moves to the front; nothing else is lost.
    again = memberships.joined(back, codes[-1], "10.0.0.5:8765", 10, kept.names[-1].name, "U" * 32, now + 1)
    assert [n.name[:2] for n in again[codes[-1]].names] == ["01", *[f"{n:02d}" for n in range(MAX_NAMES, 1, -1)]]
    with pytest.raises(DataFileError):  # a planted file past the caps is read no further than its bound
        path.write_bytes(b"{" + b" " * MAX_BYTES + b"}")
        memberships.read(path)


def test_the_guide_states_the_bounds():
    from pathlib import Path

    guide = " ".join((Path(__file__).resolve().parent.parent / "docs" / "teaching.md").read_text().split())
    assert f"It keeps {MAX_NAMES} names a class and {MAX_CLASSES} classes, those joined longest ago dropped" in guide
    assert f"at most {MAX_BYTES // 1024} KiB, every field checked" in guide


@pytest.mark.slow  # in chromium: CI's slow tier runs every page after the suite
def test_a_browser_keeps_every_name_it_joined_under(tmp_path):
    """/play: "not Zoë?", a join as her robot, "not Zoë's robot?", and Zoë again: the same player, her token
    kept. The browser's store of before (one name) is read too."""
    from browser import browser_page
    from play_page import join, open_page

    with running_class(tmp_path / "class") as opened, browser_page(1024, 768) as page:
        code = opened.clerk.roster.code
        errors = open_page(page, f"http://127.0.0.1:{opened.port}")
        join(page, code.lower(), "Zoë")
        page.evaluate("localStorage.removeItem('armgame.play.names')")  # as an older page left it: one name
        page.reload()
        page.wait_for_selector("#status:has-text('playing as Zoë')")
        page.click("#not-me")
        join(page, code, "Zoë's robot")
        page.click("#not-me")
        join(page, code, "zoë")  # typed another way: the class's one Zoë, by the token this browser kept
        page.wait_for_selector("#status:has-text('playing as Zoë')")
        assert sorted(p.name for p in opened.clerk.roster.players.values()) == ["Zoë", "Zoë's robot"]
        kept = page.evaluate("JSON.parse(localStorage.getItem('armgame.play.names'))")
        assert [n["name"] for n in kept[code]] == ["Zoë", "Zoë's robot"] and errors == []
        # A damaged store is read as far as it is sound: it proves no name (Zoë's is refused, as a stranger's).
        page.evaluate("code => localStorage.setItem('armgame.play.names', JSON.stringify({[code]: [{name: 5}], x: 1}))",
                      code)
        page.click("#not-me")
        page.fill("#code", code)
        page.fill("#name", "Zoë")
        page.click("#join-button")
        page.wait_for_selector("#join-error:has-text('taken in this class by another machine')")
        assert errors == ["Failed to load resource: the server responded with a status of 409 (Conflict)"]
