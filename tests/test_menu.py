"""`armgame` alone: the menu window under SDL's dummy driver (keys, mouse, each entry starting its
window and coming back), its layout at every size, and the commands printed where no display is."""

import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"

import json
import subprocess
import sys

import pygame
import pytest

from armgame.commands import menu as menu_command
from armgame.ui.menu import MenuWindow, run_menu
from armgame.ui.render import MIN_TEXT_AT_720, PALETTES

SIZES = [(640, 480), (1024, 768), (1280, 720), (1920, 1080), (720, 1280)]


@pytest.fixture(autouse=True)
def private_files(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "scores"))
    yield
    pygame.display.quit()


def key(name):
    return pygame.event.Event(pygame.KEYDOWN, key=pygame.key.key_code(name))


def scripted(monkeypatch, script):
    """Each frame of the menu first posts the next keys of ``script`` (Esc when it runs out).
    Returns the pages' titles seen, frame by frame."""
    real = MenuWindow.frame
    seen = []

    def frame(self):
        assert pygame.display.get_surface() is not None  # the menu's own window is open
        for name in script.pop(0) if script else ["escape"]:
            pygame.event.post(key(name))
        real(self)
        seen.append(self.page.title)

    monkeypatch.setattr(MenuWindow, "frame", frame)
    return seen


def test_each_entry_starts_its_window_and_the_menu_comes_back(monkeypatch):
    launched = []

    def launch(argv):
        assert pygame.display.get_surface() is None  # the menu's window is closed while the command runs
        launched.append(list(argv))
        return 0 if argv[0] != "lab" else 2

    seen = scripted(monkeypatch, [
        ["return"],  # Play
        ["down", "down", "return"], ["2"],  # Lab, then its second preset
        ["escape"], ["4"], ["6"],  # back; Demos, the sixth
        ["escape"], ["5"], ["escape"], ["6"], ["escape"], ["7"],  # Replays and scores, Settings, Quit
    ])
    menu = run_menu(lambda: menu_command.main_page(launch), fps=0, max_frames=40)
    assert launched == [["play"], ["lab", "curl"], ["demo", "autopilot"]]
    assert not menu.running
    # The page each frame showed: after each window, the menu is back on the page it started it from.
    assert seen[:7] == ["armgame", "Lab", "Lab", "armgame", "Demos", "Demos", "armgame"]
    assert "Replays and scores" in seen and "Settings" in seen


def test_a_failed_entry_says_so_on_the_menu():
    menu = MenuWindow(lambda: menu_command.main_page(lambda argv: 2))
    menu.choose(0)
    assert menu.pending is not None and menu.pending.start() == "armgame play stopped (status 2)"


def test_a_failed_join_shows_its_whole_reason_on_the_menu(capsys):
    """The command's own line, as the terminal has it, on the menu, wrapped, never cut off."""
    import sys

    why = ("cannot reach the class at 10.0.0.9:8765 (Connection refused): is the class started, and is this machine "
           "on the teacher's network? (school Wi-Fi often keeps laptops apart: docs/teaching.md)")

    def failing(argv):
        print(f"armgame play: {why}", file=sys.stderr)
        return 2

    menu = MenuWindow(lambda: menu_command.main_page(failing))
    menu.choose(0)
    menu.status = menu.pending.start()
    assert menu.status == why and why in capsys.readouterr().err  # the terminal has it too
    pygame.display.init()
    pygame.font.init()
    menu.screen = pygame.display.set_mode((1024, 768))
    shown = [label.text for label in sorted(menu.layout((1024, 768)).labels, key=lambda label: label.rect.top)
             if label.role == "status"]
    assert len(shown) > 1 and " ".join(shown) == why


def test_the_mouse_chooses_and_clicks():
    launched = []
    menu = MenuWindow(lambda: menu_command.main_page(lambda argv: launched.append(argv) or 0))
    pygame.display.init()
    menu.screen = pygame.display.set_mode((1024, 768))
    rows = dict(menu.layout((1024, 768)).rows)
    assert sorted(rows) == list(range(7))
    menu.handle(pygame.event.Event(pygame.MOUSEMOTION, pos=rows[3].center, rel=(0, 0), buttons=(0, 0, 0)))
    assert menu.page.selected == 3
    menu.handle(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=rows[3].center, button=1))
    assert menu.page.title == "Demos"
    menu.handle(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=(5, 5), button=3))  # right click: back
    assert menu.page.title == "armgame"


def test_play_from_the_menu_is_the_real_command_and_returns(monkeypatch, tmp_path, capsys):
    """The whole path: the menu, `armgame play` in this process, its end screen's Esc, the menu again."""
    from armgame.cli import main
    from armgame.ui.frontend import GameWindow

    def run(self, max_frames=None):
        self.countdown_left = None
        while not self.ended:
            self.frame(0.25)
        pygame.event.post(key("escape"))
        self.frame(0.0)
        return self.session

    monkeypatch.setattr(GameWindow, "run", run)
    seen = scripted(monkeypatch, [["return"], ["escape"]])
    monkeypatch.setattr(menu_command, "_start", lambda launch, *argv: lambda: main([*argv, "--duration", "1"]) and
                        "failed")
    run_menu(lambda: menu_command.main_page(main), fps=0, max_frames=10)
    out = capsys.readouterr().out
    assert "your score is" in out and "to enter it later" in out
    assert seen == ["armgame", "armgame"]


def test_replays_and_scores_lists_the_table_and_watches_a_replay(tmp_path):
    from armgame.game.bots import play_bot
    from armgame.game.rules import GameConfig
    from armgame.records.replay import Replay
    from armgame.records.scores import ScoreTable

    table = ScoreTable(tmp_path / "scores")
    for name, seconds in (("Ann", 3.0), (None, 2.0)):
        session = play_bot(GameConfig(time_limit=seconds, seed=2), "model")
        table.save_replay(Replay.from_session(session, "bot", "model", name))
    (tmp_path / "scores" / "replays" / "link.json").symlink_to(tmp_path / "elsewhere.json")
    launched = []
    page = menu_command.replays_page(lambda argv: launched.append(argv) or 0)
    assert any("No ranked scores yet" in line for line in page.lines)
    labels = sorted(item.label for item in page.items)
    assert labels[0].startswith("watch Ann: score") and labels[1].startswith("watch no name: score")
    assert len(page.items) == 2  # the symlink is not followed
    page.items[0].start()
    assert launched[0][0] == "replay" and launched[0][1].startswith(str(tmp_path / "scores" / "replays"))


def test_settings_toggle_sound_and_colours_in_the_file(tmp_path):
    from armgame.ui.settings import load

    page = menu_command.settings_page()
    assert page.items[2].label == "Sound: on" and page.items[2].detail == "Enter: mute"
    assert page.items[2].act().startswith("saved to")
    assert load()[0].mute
    page = menu_command.settings_page()
    assert page.items[2].label == "Sound: off" and page.items[2].detail == "Enter: unmute"
    page.items[1].act()
    assert load()[0].palette == menu_command.settings_page().items[1].label.split(": ")[1] != "okabe-ito"
    assert load()[0].mute  # one change leaves the others as they were


def test_the_text_size_goes_up_a_step_at_a_time_and_round_to_the_smallest():
    from armgame.ui.settings import load

    seen = []
    for _ in range(len(menu_command.TEXT_SCALES)):
        page = menu_command.settings_page()
        assert page.items[0].label == f"Text size: {load()[0].text_scale:g}x"
        page.items[0].act()
        seen.append(load()[0].text_scale)
    assert seen == [1.25, 1.5, 2.0, 2.5, 0.75, 1.0]
    assert menu_command.next_text_scale(1.3) == 1.5  # a value typed into the file goes to the next step


def item_height(menu, size=(1024, 768)):
    return next(lab.rect.height for lab in menu.layout(size).labels if lab.role == "item")


def test_the_settings_page_shows_a_new_text_size_and_palette_at_once():
    """Enter on Text size and on Colours: saved to the file, and the menu itself is drawn with them at once."""
    from armgame.ui.settings import load

    pygame.display.init()
    pygame.font.init()
    menu = MenuWindow(menu_command.settings_page, looks=lambda: menu_command.looks("okabe-ito", 1.0))
    before = item_height(menu)
    menu.choose(0)  # 1.0 -> 1.25
    menu.choose(0)  # -> 1.5
    assert load()[0].text_scale == 1.5 and menu.text_scale == 1.5
    assert item_height(menu) >= 1.45 * before
    menu.choose(1)  # okabe-ito -> classic
    menu.choose(1)  # -> high-contrast
    assert load()[0].palette == "high-contrast" and menu.palette is PALETTES["high-contrast"]
    menu.screen = pygame.display.set_mode((1024, 768))
    menu.draw()
    assert menu.screen.get_at((3, 3))[:3] == PALETTES["high-contrast"].window != PALETTES["okabe-ito"].window
    assert menu.status.startswith("saved to")


def test_the_menu_opens_with_the_settings_files_palette_and_text_size(tmp_path, monkeypatch):
    seen = {}
    monkeypatch.setattr("armgame.ui.menu.run_menu", lambda root, **kwargs: seen.update(kwargs))
    folder = tmp_path / "config" / "armgame"
    folder.mkdir(parents=True)
    (folder / "settings.toml").write_text('palette = "high-contrast"\ntext_scale = 1.5\n', encoding="utf-8")
    assert menu_command.run(None, lambda argv: 0) == 0
    assert seen["palette"] == "high-contrast" and seen["text_scale"] == 1.5
    assert seen["looks"]() == ("high-contrast", 1.5)
    (folder / "settings.toml").write_text('palette = "nope"\n', encoding="utf-8")
    assert seen["looks"]() == ("high-contrast", 1.5)  # a file gone bad meanwhile: the looks as they were


@pytest.mark.parametrize("scale", [1.5, 2.5])
def test_large_text_grows_one_and_a_half_times_and_every_page_still_fits(scale):
    pygame.display.init()
    pygame.font.init()
    plain = MenuWindow(lambda: menu_command.main_page(lambda argv: 0))
    large = MenuWindow(lambda: menu_command.main_page(lambda argv: 0), text_scale=scale)
    assert item_height(large) >= (scale - 0.05) * item_height(plain)
    for size in SIZES:
        window = pygame.Rect((0, 0), size)
        for build in (lambda: menu_command.main_page(lambda argv: 0), menu_command.settings_page,
                      lambda: menu_command.demos_page(lambda argv: 0)):
            menu = MenuWindow(build, text_scale=scale)
            menu.status = "saved to /home/teacher/.config/armgame/settings.toml"
            lay = menu.layout(size)
            if build is not menu_command.demos_page and size[1] >= 720 and scale == 1.5:
                assert len(lay.rows) == len(menu.page.items), (size, menu.page.title)  # nothing scrolled away
            boxes = lay.boxes()
            for i, (name, rect) in enumerate(boxes):
                assert window.contains(rect), (size, name, rect)
                for other, r in boxes[i + 1:]:
                    assert not rect.colliderect(r), (size, name, other)


def text(value):
    return pygame.event.Event(pygame.TEXTINPUT, text=value)


@pytest.fixture
def client_folder(tmp_path, monkeypatch):
    from armgame.classroom import client

    folder = tmp_path / "client"
    monkeypatch.setenv(client.CLIENT_ENV, str(folder))
    return folder


def test_join_a_class_asks_checks_and_starts_play_join(monkeypatch, client_folder):
    """Typed once on the menu, each value checked as the command line checks it (its one line on the
    menu), then `armgame play --join` and `armgame class show` started with them."""
    launched = []
    real = MenuWindow.frame
    statuses = []

    def frame(self):
        for step in script.pop(0) if script else ["escape"]:  # a key's name, ("text", typed) or ("number", n)
            if isinstance(step, str):
                pygame.event.post(key(step))
            elif step[0] == "number":
                pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.key.key_code(step[1]), unicode=step[1]))
            else:
                pygame.event.post(text(step[1]))
        real(self)
        statuses.append((self.page.title, self.status, self.typing))

    script = [
        ["2"],  # Join a class
        ["4"],  # Join and play, with nothing typed yet: not started, says what is missing
        # The address, refused. As SDL sends a key that types: its key (that chooses the item), then its text.
        [("number", "1"), ("text", "1"), ("text", "192.168.1.20:99999"), "return"],
        ["backspace"] * 5 + [("text", "8765"), "return"],  # mended, kept
        ["down", "return", "h", ("text", "h"), ("text", "apf"), "return"],  # the code, in the case typed
        ["down", "return", ("text", "x"), "escape"],  # Esc: the name stays as it was (empty)
        ["return", ("text", "<script>alert(1)</script>"), "return"],
        ["4"],  # Join and play
        ["5"],  # Show the class's standings
    ]
    monkeypatch.setattr(MenuWindow, "frame", frame)
    menu = run_menu(lambda: menu_command.main_page(lambda argv: launched.append(argv) or 0), fps=0, max_frames=30)
    assert statuses[1][1].startswith("type the class's address first")
    assert statuses[2][1] == "the class's address '192.168.1.20:99999': the port must be a number from 1 to 65535 " \
        "(HOST:PORT, as the projector shows)" and statuses[2][2] == "192.168.1.20:99999"  # still typing
    assert statuses[3][1:] == ("", None)
    assert statuses[5][2] is None
    join = ["play", "--join", "192.168.1.20:8765", "--code", "HAPF", "--name", "<script>alert(1)</script>"]
    assert launched == [join, ["class", "show", "192.168.1.20:8765"]]
    assert statuses[-1][0] == "armgame" and not menu.running
    assert not client_folder.exists()  # the menu keeps nothing: the join itself remembers the class


def test_join_a_class_offers_the_class_this_machine_joined_last(client_folder):
    client_folder.mkdir()
    (client_folder / "memberships.json").write_text(json.dumps({
        "ACDE": {"name": "Bo", "token": "t1", "seed": "10", "address": "10.0.0.4:8765", "at": "1.0"},
        "HAPF": {"name": "Ann", "token": "t2", "seed": "10", "address": "10.0.0.5:8765", "at": "2.0"}}))
    launched = []
    menu = MenuWindow(lambda: menu_command.class_page(lambda argv: launched.append(argv) or 0))
    assert [item.shown() for item in menu.page.items[:3]] == \
        ["Class address: 10.0.0.5:8765", "Code: HAPF", "Your name: Ann"]
    assert menu.page.items[3].detail == "armgame play --join 10.0.0.5:8765 --code HAPF --name Ann"
    menu.choose(3)
    menu.pending.start()
    assert launched == [["play", "--join", "10.0.0.5:8765", "--code", "HAPF", "--name", "Ann"]]
    # A stale value from the file is checked before it is used.
    (client_folder / "memberships.json").write_text(json.dumps({
        "HAPF": {"name": "Ann", "token": "t2", "seed": "10", "address": "not an address!", "at": "2.0"}}))
    menu = MenuWindow(lambda: menu_command.class_page(lambda argv: 0))
    menu.choose(4)
    assert menu.pending is None and "'not an address!' is not an address" in menu.status


@pytest.mark.parametrize("size", SIZES)
def test_typing_a_long_or_right_to_left_value_fits_every_window(size, client_folder):
    pygame.display.init()
    pygame.font.init()
    window = pygame.Rect((0, 0), size)
    for typed in ("W" * 260, "محمد علي " * 4, "שלום"):
        menu = MenuWindow(lambda: menu_command.class_page(lambda argv: 0))
        menu.choose(2)
        menu.typing = typed
        menu.status = "your name must be at most 40 characters, got 41"
        lay = menu.layout(size)
        item = next(lab for lab in lay.labels if lab.role == "item" and lab.text.startswith("3  Your name: "))
        assert item.text.endswith("|")  # the end of what is typed, where the caret is, in view
        boxes = lay.boxes()
        for i, (name, rect) in enumerate(boxes):
            assert window.contains(rect) and rect.height >= MIN_TEXT_AT_720 * min(size) // 720, (size, name, rect)
            for other, r in boxes[i + 1:]:
                assert not rect.colliderect(r), (size, name, other)


@pytest.mark.parametrize("size", SIZES)
def test_every_page_fits_every_window(size):
    pygame.display.init()
    pygame.font.init()
    min_height = int(MIN_TEXT_AT_720 * min(size) / 720)
    window = pygame.Rect((0, 0), size)
    pages = [lambda: menu_command.main_page(lambda argv: 0), lambda: menu_command.demos_page(lambda argv: 0),
             lambda: menu_command.lab_page(lambda argv: 0), menu_command.settings_page,
             lambda: menu_command.class_page(lambda argv: 0)]
    for build in pages:
        menu = MenuWindow(build)
        menu.status = "armgame play stopped (status 2): the terminal says why"
        lay = menu.layout(size)
        boxes = lay.boxes()
        assert len(lay.rows) == len(menu.page.items), (size, menu.page.title)  # every item reachable by mouse
        if len(menu.page.items) > 3:  # a long page scrolls: the last item chosen is in view
            menu.page.selected = len(menu.page.items) - 1
            assert menu.layout(size).rows[-1][0] == menu.page.selected
        for i, (name, rect) in enumerate(boxes):
            assert window.contains(rect) and rect.height >= min_height, (size, name, rect)
            for other, r in boxes[i + 1:]:
                assert not rect.colliderect(r), (size, name, other)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the no-display check is Linux's here")
def test_no_display_prints_the_commands_and_exits_0(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    code = "import sys\nfrom armgame.cli import main\ncode = main([])\nprint('pygame' in sys.modules)\nsys.exit(code)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=20)
    assert out.returncode == 0 and out.stderr == ""
    lines = out.stdout.splitlines()
    assert lines[0].startswith("armgame: no display here for the menu")
    assert any(line.split()[:2] == ["armgame", "play"] for line in lines)
    assert any(line.split()[:2] == ["armgame", "analyze"] for line in lines)
    assert lines[-1] == "False"  # pygame never loaded
