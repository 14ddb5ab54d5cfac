"""``analyze --class`` cannot be hijacked (issue 16, class 7): one planted file sorting first does not
set the class's protocol, copies of one replay count once, and what is left out is named with why."""

import shutil

import pytest

from armgame.cli import main

#: A class's protocol, and a planted one-trial protocol under the same name or another: cheap to run.
CLASS = 'name = "short"\ntargets = 2\ntimeout = 1.5\n[[blocks]]\nname = "b"\ntrials = 2\n'
PLANTED = 'name = "{name}"\ntargets = 1\ntimeout = 1.5\n[[blocks]]\nname = "x"\ntrials = 1\n'


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """Two students' runs of the short protocol, and two planted one-trial runs (recorded once)."""
    folder = tmp_path_factory.mktemp("recorded")
    runs = {"student1": (CLASS, 1), "student2": (CLASS, 2), "planted-short": (PLANTED.format(name="short"), 9),
            "planted-tiny": (PLANTED.format(name="tiny"), 9)}  # "short": the class's name on another protocol
    for name, (text, seed) in runs.items():
        protocol = folder / f"{name}.toml"
        protocol.write_text(text)
        assert main(["lab", str(protocol), "--bot", "adaptive", "--headless", "--seed", str(seed),
                     "--record", str(folder / f"{name}.json"), "--name", name]) == 0
    return folder


def _class(tmp_path, recorded, files):
    folder = tmp_path / "class"
    folder.mkdir()
    for source, target in files.items():
        shutil.copy(recorded / source, folder / target)
    return folder


def test_a_planted_file_sorting_first_and_copies_do_not_take_the_class(tmp_path, recorded, capsys):
    folder = _class(tmp_path, recorded, {"planted-short.json": "000-planted.json", "student1.json": "student1.json",
                                         "student2.json": "student2.json"})
    for i in range(4):
        shutil.copy(folder / "student1.json", folder / f"copy{i}.json")
    capsys.readouterr()
    assert main(["analyze", "--class", str(folder), "--out", str(tmp_path / "curve"), "--no-figures"]) == 1
    captured = capsys.readouterr()
    assert "class curve of 2 students (5 left out), 2 trials" in captured.out
    assert "000-planted.json: its protocol is also named 'short' but differs from the class's ('short', shared " \
           "by 2 replays)" in captured.err
    assert captured.err.count("the same game as copy0.json (a copy counts once)") == 4
    assert "student1.json: the same game as copy0.json" in captured.err
    lines = (tmp_path / "curve" / "class_curve.csv").read_text().splitlines()
    assert len(lines) == 3 and all(line.endswith(",2") for line in lines[1:])


def test_protocol_names_the_class_and_an_unknown_name_is_one_line(tmp_path, recorded, capsys):
    folder = _class(tmp_path, recorded, {"student1.json": "student1.json", "planted-tiny.json": "tiny.json"})
    out = ["--out", str(tmp_path / "curve"), "--no-figures"]
    assert main(["analyze", "--class", str(folder), "--protocol", "tiny", *out]) == 1
    captured = capsys.readouterr()
    assert "class curve of 1 student (1 left out), 1 trial" in captured.out
    assert "student1.json: its protocol 'short' differs from the class's ('tiny', shared by 1 replays)" \
        in captured.err
    assert main(["analyze", "--class", str(folder), "--protocol", "nope", *out, "--force"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "'short', 'tiny'" in err
