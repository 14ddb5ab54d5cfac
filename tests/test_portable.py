"""Saving works where POSIX's locking and open flags do not exist (Windows): the records tests run
again in a subprocess where armgame's own modules cannot import ``fcntl`` and find no ``O_NOFOLLOW``,
``O_NONBLOCK``, ``O_NOCTTY`` in ``os`` (``tests/no_posix.py``), and must pass there too."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
SIMULATED = os.environ.get("ARMGAME_TEST_NO_POSIX") == "1"

#: The records tests that touch locking, opening and writing: cheap ones, each a promise kept. Not
#: test_hostile's FIFO test: it runs the real program in subprocesses, which never see the simulation
#: (conftest.py only changes this pytest process), so here it only repeated the suite's own run of it.
SELECTION = [
    "tests/test_portable.py",
    "tests/test_scores.py::test_add_saves_the_replay_beside_the_table_and_checks_out",
    "tests/test_scores.py::test_concurrent_writers_all_keep_their_entries",
    "tests/test_class_flood.py::test_the_journal_is_durable_without_rewriting_the_table",
    "tests/test_scores.py::test_a_truncated_table_is_kept_aside_and_its_valid_entries_recovered",
    "tests/test_hostile.py::test_symlinked_replays_folder_or_lock_is_refused",
    "tests/test_hostile.py::test_a_replay_planted_as_a_symlink_is_not_followed",
    "tests/test_hostile.py::test_a_planted_temporary_symlink_is_never_written_through",
    "tests/test_hostile.py::test_read_limited_refuses_special_files_without_blocking",
    "tests/test_hostile.py::test_a_busy_table_keeps_the_game_and_says_how_to_enter_it",
    "tests/test_hostile.py::test_slow_lock_holder_does_not_lose_entries",
    "tests/test_table_identity.py::test_the_same_game_enters_once_however_it_is_copied",
    "tests/test_teacher_record.py::test_a_planted_copy_never_pushes_out_a_game_the_teacher_entered",
    "tests/test_teacher_record.py::test_a_hostile_counter_is_repaired_once_and_every_game_kept",
]


@pytest.mark.slow  # a second pytest over the records' tests (5 s): CI's slow tier runs it after the suite
@pytest.mark.skipif(SIMULATED, reason="runs the others; not itself again")
def test_records_tests_pass_without_posix_locks_or_flags():
    env = {**os.environ, "ARMGAME_TEST_NO_POSIX": "1"}
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider", "-x", *SELECTION],
                          cwd=REPO, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert " passed" in proc.stdout and "failed" not in proc.stdout


@pytest.mark.skipif(not SIMULATED, reason="only where POSIX is simulated away")
def test_the_simulated_platform_really_lacks_them():
    import armgame.files as files
    import armgame.records.locking as locking
    import armgame.records.storage as storage

    assert files._NOFOLLOW == files._NONBLOCK == files._NOCTTY == storage._NOFOLLOW == 0
    assert not hasattr(locking.os, "O_NOFOLLOW") and not hasattr(files.os, "O_NONBLOCK")
    # Only armgame is fooled: the standard library and pytest keep the platform's own (Python 3.13's
    # shutil.rmtree opens folders with os.O_NONBLOCK).
    assert hasattr(os, "O_NONBLOCK") == hasattr(shutil.os, "O_NONBLOCK") == (sys.platform != "win32")


#: What armgame's records once did, POSIX-only: each line must fail under the simulation as on Windows.
OLD_POSIX_ONLY_CODE = [
    "import fcntl",
    "import os\nflags = os.O_RDONLY | os.O_NOFOLLOW",
    "from os import O_NONBLOCK",
    "import os.path\nos.O_NOCTTY",
]


@pytest.mark.skipif(SIMULATED, reason="starts its own simulated interpreters")
@pytest.mark.parametrize("code", OLD_POSIX_ONLY_CODE)
def test_posix_only_code_in_armgame_fails_under_the_simulation(code):
    """Run in a fresh interpreter, as a module of armgame: fails with the simulation, works without it."""
    probe = ("import sys; sys.path.insert(0, 'tests'); import no_posix; no_posix.install_if_asked()\n"
             f"exec({code!r}, {{'__name__': 'armgame.records.old'}})\n"
             "import os, shutil, tempfile; shutil.rmtree(tempfile.mkdtemp())  # the rest of the process is untouched")
    for simulated in (True, False):
        env = {**os.environ, "ARMGAME_TEST_NO_POSIX": "1" if simulated else "0"}
        proc = subprocess.run([sys.executable, "-c", probe], cwd=REPO, env=env, capture_output=True, text=True,
                              timeout=60)
        if simulated:
            assert proc.returncode == 1 and ("ImportError" in proc.stderr or "AttributeError" in proc.stderr)
        elif sys.platform != "win32":
            assert proc.returncode == 0, proc.stderr


@pytest.mark.skipif(not SIMULATED, reason="only where POSIX is simulated away")
def test_a_symlink_swapped_in_after_the_check_is_refused(tmp_path, monkeypatch):
    from armgame.records.storage import DataFileError, read_limited

    (tmp_path / "real.json").write_text("{}")
    (tmp_path / "other").write_text("secret")
    real_open = os.open

    def swap_then_open(path, *args, **kwargs):  # the race: a symlink replaces the file between lstat and open
        if str(path).endswith("real.json"):
            os.replace(tmp_path / "other", tmp_path / "real.json")
        return real_open(path, *args, **kwargs)

    monkeypatch.setattr(os, "open", swap_then_open)
    with pytest.raises(DataFileError, match="changed while it was opened"):
        read_limited(tmp_path / "real.json", 100, "replay file", follow=False)


@pytest.mark.skipif(SIMULATED, reason="needs flock")
def test_a_lock_file_another_user_made_read_only_is_still_locked(tmp_path, monkeypatch):
    """Older armgames created scores.lock 0644: a classmate cannot open it for writing, only for reading."""
    import fcntl

    import filelock

    from armgame.records.locking import LockBusyError, file_lock

    def denied(self, *args, **kwargs):  # what opening another user's 0644 file for writing gives
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(filelock.FileLock, "acquire", denied)
    lock = tmp_path / "scores.lock"
    lock.write_text("")
    with file_lock(lock, 0.2):
        fd = os.open(lock, os.O_RDONLY)
        try:
            with pytest.raises(BlockingIOError):
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # it is held
        finally:
            os.close(fd)
    fd = os.open(lock, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        with pytest.raises(LockBusyError), file_lock(lock, 0.2):
            pass
    finally:
        os.close(fd)


@pytest.mark.skipif(SIMULATED, reason="nothing of the platform in it")
def test_the_supported_pythons_are_said_alike_everywhere():
    """requires-python, the classifiers, CI's oldest and the README agree on the oldest supported Python,
    and the classifiers name every minor version from it to the newest CI tests, none missing."""
    import re
    import tomllib

    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    oldest = re.fullmatch(r">=3\.(\d+)", project["requires-python"]).group(1)
    minors = sorted(int(c.rsplit(".", 1)[1]) for c in project["classifiers"]
                    if re.fullmatch(r"Programming Language :: Python :: 3\.\d+", c))
    assert minors == list(range(int(oldest), minors[-1] + 1)) and minors[0] == int(oldest)
    ci = (REPO / ".ci" / "run").read_text()
    assert re.search(r"^OLDEST=3\.(\d+)\b", ci, re.M).group(1) == oldest
    readme = (REPO / "README.md").read_text()
    tested = re.search(r"Python 3\.(\d+) or newer \([^)]*CI tests 3\.(\d+) and 3\.(\d+)\)", readme.replace("\n", " "))
    assert tested.group(1) == tested.group(2) == oldest and int(tested.group(3)) == minors[-1]
    assert sys.version_info[:2] >= (3, int(oldest))


def test_the_run_writes_nothing_into_the_checkout(pytestconfig):
    """Tests write only to temporary folders: Hypothesis's examples and caches go to the run's private folder
    (tests/conftest.py), not ./.hypothesis, and pytest's own cache (./.pytest_cache) is off."""
    import tempfile
    from pathlib import Path

    from hypothesis.configuration import storage_directory

    home = Path(storage_directory("examples", intent_to_write=False).path).resolve()
    assert home.is_relative_to(Path(tempfile.gettempdir()).resolve()), home
    assert not home.is_relative_to(Path(__file__).resolve().parent.parent)
    assert os.environ["HYPOTHESIS_STORAGE_DIRECTORY"] and not pytestconfig.pluginmanager.has_plugin("cacheprovider")
