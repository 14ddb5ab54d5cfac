"""A name is a person's, in every script (issue 54): what a join takes, what it refuses, and one check for both.

Every client is another machine than the teacher's: a loopback address from 127.0.0.2 up (Linux routes the whole of
127.0.0.0/8 to this machine), while 127.0.0.1 is the teacher's own.
"""

from __future__ import annotations

import http.client
import json
import sys
from pathlib import Path

import pytest
from class_server import running_class, tapped_game

from armgame.classroom import state as class_state
from armgame.classroom.errors import RefusedError
from armgame.classroom.intake import Clerk
from armgame.classroom.roster import Roster
from armgame.records.lookalikes import name_problem, skeletons

ROOT = Path(__file__).resolve().parent.parent
SCAN = ROOT / "benchmarks" / "results" / "name_scan.json"
on_loopback = pytest.mark.skipif(sys.platform != "linux", reason="other machines are other loopback addresses on Linux")
ANN, OTHER, LAPTOP = "127.0.0.3", "127.0.0.4", "127.0.0.5"
SINHALA = "\u0dc1\u0dca\u200d\u0dbb\u0dd3\u0db8\u0dcf\u0dbd\u0dd2"  # Shrimali: a ZWJ after the virama (්)
PERSIAN = "\u0646\u06cc\u06a9\u200c\u0646\u0627\u0645"  # Niknam: a ZWNJ between two joining letters


def call(served, method: str, path: str, body: dict | bytes | None = None, headers: dict | None = None,
         source: str = ANN) -> tuple[int, dict]:
    conn = http.client.HTTPConnection("127.0.0.1", served.port, timeout=10, source_address=(source, 0))
    try:
        data = body if body is None or isinstance(body, bytes) else json.dumps(body).encode()
        conn.request(method, path, body=data, headers={"Content-Type": "application/json", **(headers or {})})
        response = conn.getresponse()
        return response.status, json.loads(response.read())
    finally:
        conn.close()


def join(served, name: str, source: str, token: str | None = None) -> tuple[int, dict]:
    return call(served, "POST", "/api/join", {"code": served.clerk.roster.code, "name": name,
                                               **({"token": token} if token else {})}, source=source)


def hand_in(served, token: str, game: bytes, source: str) -> tuple[int, dict]:
    return call(served, "POST", "/api/handin", game, {"Authorization": f"Bearer {token}",
                                                      "X-Armgame-Code": served.clerk.roster.code}, source)


def teacher(served, path: str, body: dict) -> tuple[int, dict]:
    return call(served, "POST", path, body, {"Authorization": f"Bearer {served.clerk.roster.secret}"}, "127.0.0.1")


def games_of(served, name: str) -> int:
    students = call(served, "GET", "/api/standings", source="127.0.0.1")[1]["students"]
    return next(s["games"] for s in students if s["name"] == name)


@on_loopback
def test_an_old_name_never_credits_another_machine_to_the_renamed_student(tmp_path):
    with running_class(tmp_path / "class") as served:
        status, ann = join(served, "Ann B", ANN)
        assert status == 200
        assert hand_in(served, ann["token"], tapped_game(1, player="Ann B").to_bytes(), ANN)[0] == 200
        assert teacher(served, "/api/teacher/rename", {"name": "Ann B", "to": "Anna Bell"})[0] == 200
        assert games_of(served, "Anna Bell") == 1
        for i, name in enumerate(("Ann B", "ann  b", "Ann \u0299")):  # the old name, and names that read like it
            machine = f"127.0.3.{i + 1}"
            status, answer = join(served, name, machine)
            assert status == 409 and "Anna Bell" in answer["error"], (name, answer)
            game = tapped_game(2 + i, player=name).to_bytes()
            assert hand_in(served, answer.get("token") or "none", game, machine)[0] == 401
        assert games_of(served, "Anna Bell") == 1
        assert set(served.clerk.roster.players) == {"anna bell"}
        # The renamed student's own machine, joining again under the old name, is Anna Bell (a redirect).
        status, again = join(served, "Ann B", ANN, ann["token"])
        assert status == 200 and again["name"] == "Anna Bell" and again["token"] == ann["token"]


@on_loopback
def test_the_join_limit_holds_whatever_token_is_sent(tmp_path):
    with running_class(tmp_path / "class") as served:
        status, ann = join(served, "Ann", LAPTOP)
        assert status == 200
        answers = [join(served, f"Bot {letter}", LAPTOP, ann["token"])[0] for letter in "ABCDEFGH"]
        assert answers == [200] * (class_state.JOINS_PER_MINUTE - 1) + [429] * (9 - class_state.JOINS_PER_MINUTE)
        assert join(served, "Ann", LAPTOP, ann["token"])[0] == 200  # joining again under one's own name is free


def test_joiners_are_allowed_where_a_script_needs_them_and_nowhere_else():
    assert name_problem(SINHALA) is None and name_problem(PERSIAN) is None
    for hidden in ("Ann\u200dB", "Ann\u200cB", "Ann B\u200d", "\u200dAnn", PERSIAN + "\u200c",
                   "\u0646\u06cc\u06a9\u200c\u200c\u0646\u0627\u0645", "\u0dc1\u0dca\u200d\u200d\u0dbb"):
        assert name_problem(hidden) is not None, ascii(hidden)
    assert "joiner (U+200D)" in name_problem("Ann\u200dB")
    # A joiner is drawn as nothing: two names that differ only by one read alike.
    assert skeletons(PERSIAN) == skeletons(PERSIAN.replace("\u200c", ""))
    assert skeletons(SINHALA) == skeletons(SINHALA.replace("\u200d", ""))


def clerk_of(folder: Path, *names: str) -> Clerk:
    folder.mkdir()
    roster = Roster.open(folder, None)[0]
    clerk = Clerk(folder, roster)
    for name in names:
        clerk.join(name, None, "127.0.0.2")
    return clerk


def refusal(call, *args: object) -> tuple[int, str] | None:
    try:
        call(*args)
    except RefusedError as exc:
        return exc.status, exc.message
    return None


def test_names_in_their_scripts_join_and_a_joiner_makes_no_second_name(tmp_path):
    clerk = clerk_of(tmp_path / "class", SINHALA, PERSIAN)
    assert len(clerk.roster.players) == 2
    for alike in (PERSIAN.replace("\u200c", ""), SINHALA.replace("\u200d", "")):
        assert refusal(clerk.join, alike, None, "127.0.0.9")[0] == 409, ascii(alike)


def test_join_and_rename_refuse_a_name_alike_with_one_check(tmp_path):
    """One function checks a name for a join and for the teacher's rename: the same name is refused by both, in the
    same words."""
    clerk = clerk_of(tmp_path / "class", "Ann B", "Ian", "Carl")
    assert clerk.rename("Ann B", "Anna Bell").startswith("Ann B is shown as Anna Bell")
    for name in ("Ann B", "ANN B", "Lan", "lan", "Ann B\ufffc", "Ann\u200dB", "NAME", "", "x" * 41,
                 "Ahmed \u0639", "\u0410nn"):
        joined = refusal(clerk.join, name, None, "127.0.0.9")
        renamed = refusal(clerk.rename, "Carl", name)
        assert joined is not None and joined == (renamed[0], renamed[1].replace("the new name", "player name")), \
            (ascii(name), joined, renamed)
    assert "surname" in refusal(clerk.join, "Lan", None, "127.0.0.9")[1]  # what to do, not only why
    assert refusal(clerk.join, "Lan K", None, "127.0.0.9") is None
    assert clerk.rename("Anna Bell", "Ann B").startswith("Anna Bell is shown as Ann B")  # her own old name: hers


def test_the_object_replacement_character_is_refused():
    assert name_problem("Ann B\ufffc") == "it holds an invisible character (U+FFFC)"
    assert skeletons("Ann B\ufffc") == skeletons("Ann B")


def test_every_character_the_scan_saw_drawn_as_nothing_is_refused():
    """``benchmarks/name_scan.py`` drew every code point a join took after "Ann B" in Chromium: each one drawn as
    nothing is refused now (and read as nothing beside the name it imitates)."""
    scan = json.loads(SCAN.read_text(encoding="utf-8"))
    nothing = [int(code, 16) for code in scan["drawn_as_nothing"]]
    assert scan["scanned"] > 100_000 and 0xFFFC in nothing
    for code in nothing:
        assert name_problem("Ann B" + chr(code)) is not None, f"U+{code:04X}"


SCRIPTS = {"LATIN": "A", "CYRILLIC": "\u0414", "GREEK": "\u03a9", "ARMENIAN": "\u0531", "CHEROKEE": "\u13aa",
           "ARABIC": "\u0639", "HEBREW": "\u05e9", "DEVANAGARI": "\u0915", "THAI": "\u0e01", "HAN": "\u674e",
           "HIRAGANA": "\u3042", "KATAKANA": "\u30ab", "BOPOMOFO": "\u3105", "HANGUL": "\ud55c"}
MIXING = ("LATIN", "HAN", "HIRAGANA", "KATAKANA", "BOPOMOFO", "HANGUL")


def test_the_guide_lists_every_refused_mix_of_scripts_as_the_check_refuses_them():
    """docs/teaching.md lists the refused mixes script by script, each line derived here from the check's own rule
    (``ALLOWED_MIXES``), and a name of each two scripts is refused exactly when the list says so."""
    from armgame.records.lookalikes import mix_partners

    guide = " ".join((ROOT / "docs" / "teaching.md").read_text(encoding="utf-8").split())
    section = guide.split("**A name is a person's.**", 1)[1].split("\n## ", 1)[0]

    def words(scripts) -> str:
        names = [s.title() for s in sorted(scripts, key=MIXING.index)]
        return ", ".join(names[:-1]) + " and " + names[-1]

    for script in MIXING:
        assert f"- {script.title()} with any script but {words(mix_partners(script))}" in section, script
    assert "- every other script with any script but its own" in section
    assert all(not mix_partners(s) for s in SCRIPTS if s not in MIXING)
    for a, first in SCRIPTS.items():
        for b, second in SCRIPTS.items():
            refused = name_problem(f"{first}x {second}".replace("x", first)) is not None
            assert refused == (a != b and b not in mix_partners(a)), (a, b)
    assert name_problem("Ahmed \u0639") == "it mixes letters of Arabic and Latin" and '"Ahmed \u0639"' in section
    # Why "Lan" cannot join beside "Ian", and what to do, in the guide's words.
    assert "a capital I and a small l are drawn alike" in section and '("Lan K" joins)' in section


@pytest.mark.slow  # about 15 s: a sixteenth of the Basic Multilingual Plane drawn in chromium
def test_a_sample_of_the_plane_drawn_in_chromium_shows_nothing_the_check_takes():
    """The scan's reduced run: every 16th code point of the BMP a join takes after "Ann B", and the characters the
    whole scan found, drawn in chromium: U+FFFC is seen drawn as nothing, and everything drawn as nothing is
    refused by today's check."""
    from browser import chromium_path

    chromium_path()  # skips without chromium (fails in CI, which requires it)
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import name_scan

    from armgame.records.lookalikes import DRAWN_AS_NOTHING

    codes = name_scan.accepted(sorted(set(range(0, 0x10000, 16)) | {ord(c) for c in DRAWN_AS_NOTHING}))
    nothing, _ = name_scan.drawn_as_nothing(codes)
    assert 0xFFFC in nothing
    assert all(name_problem("Ann B" + chr(code)) is not None for code in nothing), [f"{c:04X}" for c in nothing]
