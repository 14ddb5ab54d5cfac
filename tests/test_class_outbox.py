"""The browser game's outbox (kept.js, play.js) in a real chromium (issue 54): tabs of one browser finishing games
at the same moment lose none; games kept from last week's class at the same address are never handed in to today's,
and cost today's student no wait; whatever is in the store, the page plays and hands in its next game."""

from __future__ import annotations

import http.client
import json

import pytest
from browser import browser_page
from class_server import free_port, running_class, tapped_games
from play_page import join, open_page, play_keys, to_the_end

OUTBOX = "armgame.play.outbox"  # the one list every kept game was in before
GAME = "armgame.play.game."  # a kept game's own key, with its id

#: Each tab, at one BroadcastChannel message (delivered to every tab at once), keeps a game as a page does at its
#: game's end and, for half of them, drops it a moment later as a page does when the class acknowledges it.
FINISH = """async ([round, tab]) => {
  const kept = await import('/static/kept.js');
  window.acked = window.acked || [];
  const channel = new BroadcastChannel('finish');
  window.done = new Promise((finished) => {
    channel.onmessage = async () => {
      channel.close();
      const id = 'r' + round + 't' + tab;
      kept.keepGame({ id, code: 'ABCD', token: 'token' + tab, class: 'c1a55', body: '{"tab": ' + tab + '}' });
      await new Promise((r) => setTimeout(r, (7 * tab + round) % 4));
      if ((round + tab) % 2 === 0) { kept.dropGame(id); window.acked.push(id); }
      finished(id);
    };
  });
}"""


# In chromium (two tabs about 2 s, four more): the slow tier. The suite keeps kept.js's store of a key a game in
# tests/play_logic.test.mjs (node).
@pytest.mark.slow
@pytest.mark.parametrize("tabs", [2, 4])
def test_tabs_finishing_games_at_the_same_moment_lose_none(tabs):
    """Every kept game was one shared list, read, changed and written back by each tab: a tab that read it just
    before another tab's write wrote back a list without that tab's game (12 of 40 and 36 of 80 games lost here).
    Each game now has a key of its own."""
    rounds = 20
    with running_class(None, rehearse=True) as opened, browser_page(320, 240) as first:
        pages = [first] + [first.context.new_page() for _ in range(tabs - 1)]
        for page in pages:
            page.goto(f"http://127.0.0.1:{opened.port}/play")
        for r in range(rounds):
            for tab, page in enumerate(pages):
                page.evaluate(FINISH, [r, tab])
            first.evaluate("() => new BroadcastChannel('finish').postMessage('now')")
            for page in pages:
                page.evaluate("() => window.done")
        acked = {g for page in pages for g in page.evaluate("() => window.acked")}
        kept = {g["id"] for g in first.evaluate("async () => (await import('/static/kept.js')).outbox()")}
        every = {f"r{r}t{t}" for r in range(rounds) for t in range(tabs)}
        assert every - acked - kept == set()  # each game acknowledged by the class, or still kept
        assert acked & kept == set() and len(acked) == len(every) // 2


def _ask(port: int, path: str, body: bytes, headers: dict[str, str] | None = None) -> tuple[int, dict]:
    """A POST from a student's machine of its own (127.0.0.9, not the teacher's)."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10, source_address=("127.0.0.9", 0))
    try:
        connection.request("POST", path, body, {"Content-Type": "application/json", **(headers or {})})
        answer = connection.getresponse()
        return answer.status, json.loads(answer.read())
    finally:
        connection.close()


def test_a_join_or_a_game_that_names_another_class_is_refused_and_is_no_guess(tmp_path):
    """A request naming another class (last week's, at this address) is refused before its code is looked at: it
    learns nothing of the code, so it is not counted, however many come. The right code is taken at once after."""
    with running_class(tmp_path / "class") as opened:
        roster = opened.clerk.roster
        for n in range(12):
            status, said = _ask(opened.port, "/api/join", json.dumps(
                {"code": "ZZZZ", "name": "Ama", "class": "0123456789abcdef"[: 1 + n]}).encode())
            assert (status, said["ok"]) == (410, False) and "another class" in said["error"]
            status, said = _ask(opened.port, "/api/handin", b"{}", {"Authorization": "Bearer x", "X-Armgame-Code":
                                                                    "ZZZZ", "X-Armgame-Class": "5" * 16})
            assert status == 410 and "another class" in said["error"]
        status, said = _ask(opened.port, "/api/join", json.dumps({"code": roster.code, "name": "Ama"}).encode())
        assert status == 200 and said["class"] == roster.class_id()
        status, said = _ask(opened.port, "/api/join", json.dumps(
            {"code": roster.code, "name": "Ama", "token": said["token"], "class": said["class"]}).encode())
        assert status == 200 and said["name"] == "Ama"


def _member(page) -> dict:
    return json.loads(page.evaluate("() => localStorage.getItem('armgame.play.member')"))


@pytest.mark.slow  # two classes on one port and a browser through both: about 2 s
def test_games_kept_from_last_weeks_class_are_kept_apart_and_todays_code_plays_at_once(tmp_path):
    """Issue 54's browser: 8 games kept from last week's class at this address and port (and 8 more in the old
    outbox, with last week's code). Today's page handed them in with last week's code: 5 wrong codes, then the
    doubling wait; today's game waited behind them and a join with today's right code got 429. Now the page sends
    nothing of another class's, and says so; the join that names last week's class is no guess."""
    port = free_port()
    old = [g.decode() for g in tapped_games(16, ["Ama"])]
    with browser_page(1024, 768) as page:
        with running_class(tmp_path / "last week", port=port, rehearse=False) as last:
            errors = open_page(page, f"http://127.0.0.1:{port}")
            join(page, last.clerk.roster.code, "Ama")
            before = _member(page)
            assert before["class"] == last.clerk.roster.class_id()
        # Last week's class is gone; its games were kept (the class could not be reached as they ended).
        page.evaluate("""([games, member, OUTBOX, GAME]) => {
          games.slice(0, 8).forEach((body, i) => localStorage.setItem(GAME + 'old' + i, JSON.stringify(
            { id: 'old' + i, code: member.code, token: member.token, class: member.class, body, at: i })));
          localStorage.setItem(OUTBOX, JSON.stringify(games.slice(8).map((body, i) =>
            ({ id: 'older' + i, code: member.code, token: member.token, body }))));
        }""", [old, before, OUTBOX, GAME])
        with running_class(None, rehearse=True, port=port) as today:  # today's: a rehearsal's short game
            assert today.clerk.roster.code != before["code"]
            answers: list[tuple[int, str | None, str]] = []
            page.on("response", lambda r: answers.append((r.status, r.request.headers.get("x-armgame-code"), r.url)))
            page.reload()  # today's page: last week's name is no use here, and its code is not guessed with
            page.wait_for_selector("#join-error:has-text('joined another class at this address')")
            assert page.input_value("#code") == ""
            join(page, today.clerk.roster.code, "Ama")
            play_keys(page)
            to_the_end(page)
            page.wait_for_selector("#end-answer:has-text('handed in: 1st of 1 in the class')")
            assert [e.name for e in today.clerk.entries] == ["Ama"]
            page.wait_for_selector("#status:has-text('16 games kept from another class, not handed in here')")
            assert not [a for a in answers if a[0] in (403, 429)], answers  # no wrong code sent, no wait
            assert all(code in (None, today.clerk.roster.code) for _, code, _ in answers), answers
            # An honest join again with today's code is taken at once.
            page.keyboard.press("Enter")
            page.click("#not-me")
            join(page, today.clerk.roster.code, "Ama")
            assert not [a for a in answers if a[0] in (403, 429)], answers
            # The student may let last week's games go: two clicks.
            page.click("#discard")
            page.click("#discard:has-text('discard 16 games for good?')")
            page.wait_for_selector("#status:not(:has-text('another class'))")
            assert page.evaluate("() => Object.keys(localStorage).filter((k) => k.startsWith('armgame.play.game.') "
                                 "|| k === 'armgame.play.outbox')") == []
        assert [e for e in errors if "status of 410" not in e] == []  # the class's "another class": no fault


#: What another page, a damaged store or an old version may have left where the outbox is read: every JSON shape,
#: games with fields missing or of the wrong type, huge values, and text that is not JSON.
def _shapes(game: dict) -> list[str]:
    wrong = [{**game, field: value} for field in ("id", "code", "token", "body", "class")
             for value in (5, 1.5, [], {}, True, *([None] if field != "class" else []),
                           *(["x" * 300] if field != "body" else []))]
    missing = [{k: v for k, v in game.items() if k != field} for field in ("id", "code", "token", "body")]
    shapes = [None, 0, -1, 1e308, 5, "games", "", True, False, {}, [], [None], [5], [[]], [{}], ["x"], [True],
              {"0": game}, {"id": game["id"]}, [game, None, 5], wrong, missing, [[game]], {"games": [game]}]
    return ([json.dumps(s) for s in shapes] + [json.dumps(w) for w in wrong] + [json.dumps(m) for m in missing] +
            ["{", "[", "nul", "undefined", "NaN", "[1,]", "x" * 2_200_000,
             json.dumps({**game, "body": "x" * ((1 << 20) + 1)})])


def _holds(text: str, game: dict) -> bool:
    try:
        value = json.loads(text)
    except ValueError:
        return False
    return isinstance(value, list) and game in value


@pytest.mark.slow  # in chromium: two games, and every shape written and read
def test_whatever_is_in_the_store_the_page_plays_shows_its_end_and_hands_in_the_next_game(tmp_path):
    """Issue 54: an outbox that was valid JSON but not a list of games threw, and the game stopped for good. Every
    shape is written where the old outbox was and under the outbox's own keys (and one shape at a time where the
    old list was, which is read once and moved); the page reads them all without a word in its console, hands in
    nothing of them, and plays, ends and hands in its games."""
    with running_class(None, rehearse=True) as opened, browser_page(1024, 768) as page:
        errors = open_page(page, f"http://127.0.0.1:{opened.port}")
        join(page, opened.clerk.roster.code, "Ama")
        member = _member(page)
        # The one true game among them is another class's: kept, never sent here.
        game = {"id": "g1", "code": member["code"], "token": member["token"], "class": "c1a55", "body": "{}", "at": 1}
        shapes = _shapes(game)
        read, left = page.evaluate("""async ([shapes, OUTBOX, GAME]) => {
          const kept = await import('/static/kept.js');
          const read = [];
          for (const shape of shapes) {  // the old list, one shape at a time: read (and moved) each
            localStorage.setItem(OUTBOX, shape);
            read.push(kept.outbox().map((g) => g.id));
            localStorage.removeItem(GAME + 'g1');
          }
          shapes.forEach((shape, i) => localStorage.setItem(GAME + 'junk' + i, shape));  // under the new keys
          shapes.filter((shape) => shape.length < 1e5).forEach((shape) => localStorage.setItem(GAME + 'g1', shape));
          localStorage.setItem(GAME, JSON.stringify({ id: '' }));
          localStorage.setItem(OUTBOX, '[{"id": 5}, null]');
          return [read, kept.outbox()];
        }""", [shapes, OUTBOX, GAME])
        # Only a list holding the game reads as it; nothing else is a game.
        assert read == [["g1"] if _holds(s, game) else [] for s in shapes]
        assert left == []
        handed: list[str] = []
        page.on("request", lambda r: handed.append(r.post_data) if r.url.endswith("/api/handin") else None)
        for n in (1, 2):
            play_keys(page, rounds=n)  # each game its own (a game counts once)
            to_the_end(page)
            page.wait_for_selector("#end-answer:has-text('handed in: ')")
            assert len(opened.clerk.entries) == n
            page.keyboard.press("Enter")
            page.wait_for_selector("#end", state="hidden")
        assert len(handed) == 2 and errors == []
