"""A learner's workspace always starts: damaged records are rebuilt, a file/folder clash keeps the learner's version
beside it, links are never written through, backups never overwrite each other, and ``singleuser`` turns every
problem into one line of the server's log."""

from __future__ import annotations

import gzip
import io
import json
import os
import stat
import subprocess
import sys
import tarfile
import time
from datetime import datetime
from pathlib import Path

import pytest
from workspace_helpers import contents, make_course, no_hang, notebook, tree

from rrbot_workshop import cli
from rrbot_workshop.classroom import commands as classroom_commands
from rrbot_workshop.classroom import launcher
from rrbot_workshop.classroom.launcher import refresh_notebook_copies, unique_folder, write_atomically
from rrbot_workshop.classroom.workspace import MARKER, init_workspace
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import course as grading_course
from rrbot_workshop.course.grading.course import read_pristine_archive, reset_exercise
from rrbot_workshop.exceptions import CourseError

ARCHIVE = ".pristine/exercises.tar.gz"


@pytest.fixture
def installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A course installed for a room, and the environment naming it as the course installed now."""
    course = make_course(tmp_path / "opt" / "course")
    for name in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv(tracks.ROOT_ENV, str(course))
    tracks.set_track(None)
    return course


@pytest.fixture
def ws(installed: Path, tmp_path: Path) -> Path:
    """A workspace made from it, in a home of its own (``outside/`` beside it holds files no command may touch)."""
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "mine.py").write_text("kept = True\n")
    return init_workspace(tmp_path / "home" / "rrbot_workshop", installed).workspace


def _course_update(installed: Path) -> None:
    (installed / "exercises/task01_fake/a.py").write_text("x = None  # TODO, reworded\n")
    (installed / "exercises/task01_fake/b.py").write_text("y = 2\n")


# ------------------------------------------------------------------------------------------ damaged records
def _truncated(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: len(path.read_bytes()) // 2])


DAMAGES = {
    "truncated": _truncated,
    "empty": lambda p: p.write_bytes(b""),
    "not gzip": lambda p: p.write_bytes(b"PK\x03\x04 not a tar.gz"),
    "gzip but not tar": lambda p: p.write_bytes(gzip.compress(b"hello " * 100)),
    "a folder": lambda p: (p.unlink(), p.mkdir()),
    "a link to /dev/zero": lambda p: (p.unlink(), p.symlink_to("/dev/zero")),
    "a FIFO": lambda p: (p.unlink(), os.mkfifo(p)),
}


@pytest.mark.parametrize("damage", DAMAGES, ids=str)
def test_a_damaged_archive_is_rebuilt_with_one_line_and_every_learners_file_kept(
        damage: str, ws: Path, installed: Path, tmp_path: Path) -> None:
    (ws / "exercises/task01_fake/a.py").write_text("x = 41  # mine\n")
    DAMAGES[damage](ws / ARCHIVE)
    _course_update(installed)
    before = tree(tmp_path / "outside")
    result = no_hang(init_workspace, ws)
    assert [n for n in result.notes if ARCHIVE in n] == result.notes and len(result.notes) == 1, result.notes
    assert "rebuilt from the installed course" in result.notes[0]
    # with no record of what was handed out, every file that differs from the course's is the learner's: kept
    assert (ws / "exercises/task01_fake/a.py").read_text() == "x = 41  # mine\n"
    assert sorted(result.kept) == ["exercises/task01_fake/a.py", "exercises/task01_fake/b.py"]
    assert (ws / "exercises/task01_fake/b.py.course-update").read_text() == "y = 2\n"
    assert set(read_pristine_archive(ws / ARCHIVE)) >= {"exercises/task01_fake/a.py", "exercises/task02_more/d.py"}
    assert tree(tmp_path / "outside") == before
    assert init_workspace(ws).notes == []


def test_an_archive_that_unpacks_beyond_the_bound_is_damaged(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(grading_course, "ARCHIVE_MAX_BYTES", 1000)
    (tmp_path / "a.tar.gz").write_bytes(grading_course.pristine_archive_bytes({"exercises/zeros": bytes(100_000)}))
    assert (tmp_path / "a.tar.gz").stat().st_size < 1000
    with pytest.raises(CourseError, match="unpacks to more than 1000 bytes"):
        read_pristine_archive(tmp_path / "a.tar.gz")


def test_an_archive_with_too_many_members_is_damaged(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(grading_course, "ARCHIVE_MAX_MEMBERS", 3)
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz") as tar:
        for n in range(5):
            tar.addfile(tarfile.TarInfo(f"exercises/f{n}"), io.BytesIO(b""))
    (tmp_path / "a.tar.gz").write_bytes(buffer.getvalue())
    with pytest.raises(CourseError, match="more than 3 members"):
        read_pristine_archive(tmp_path / "a.tar.gz")


def test_reset_with_a_damaged_archive_is_one_clear_error_naming_init(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _truncated(ws / ARCHIVE)
    monkeypatch.setenv(tracks.ROOT_ENV, str(ws))
    with pytest.raises(CourseError, match="rrbot-workshop init` rebuilds it"):
        reset_exercise(1)


@pytest.mark.parametrize("damage", ["truncated", "a folder"])
def test_a_damaged_marker_is_rebuilt_with_one_line(damage: str, ws: Path, installed: Path) -> None:
    DAMAGES[damage](ws / MARKER)
    result = init_workspace(ws)
    assert not result.created and len(result.notes) == 1 + (damage == "a folder"), result.notes
    assert f"{MARKER} was damaged" in result.notes[0]
    assert init_workspace(ws).notes == []


def test_a_damaged_notebook_index_refreshes_the_copies_with_backups(ws: Path) -> None:
    (ws / "my_notebooks/01_fake.ipynb").write_text(notebook("my notes"))
    _truncated(ws / "my_notebooks/.sources.json")
    result = init_workspace(ws, now=0)
    assert [n for n in result.notes if ".sources.json was damaged" in n] == result.notes and result.notes
    assert [p.read_text() for p in (ws / "my_notebooks/backups").rglob("01_fake.ipynb")] == [notebook("my notes")]
    assert init_workspace(ws).notebooks == []


def test_a_first_init_killed_after_its_marker_is_finished_by_the_next(installed: Path, tmp_path: Path,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    def killed(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr("rrbot_workshop.classroom.workspace._fill", killed)
    with pytest.raises(KeyboardInterrupt):
        init_workspace(tmp_path / "ws", installed)
    monkeypatch.undo()
    monkeypatch.setenv(tracks.ROOT_ENV, str(installed))
    result = init_workspace(tmp_path / "ws")
    assert not result.created and (tmp_path / "ws/exercises/task01_fake/a.py").is_file()


# ------------------------------------------------------------------------------------------ file / folder clashes
def _file_to_folder(path: Path) -> None:
    path.unlink()
    path.mkdir()
    (path / "inside.py").write_text("made by the learner\n")


def _folder_to_file(path: Path) -> None:
    import shutil

    shutil.rmtree(path)
    path.write_text("a file now\n")


def test_a_learners_folder_where_the_course_updates_a_file_is_kept_beside_it(ws: Path, installed: Path) -> None:
    _file_to_folder(ws / "exercises/task01_fake/b.py")
    _course_update(installed)
    result = init_workspace(ws)
    assert result.notes == ["exercises/task01_fake/b.py was a folder where the course now has a file: yours is kept "
                            "beside it as b.py.yours"]
    assert (ws / "exercises/task01_fake/b.py.yours/inside.py").read_text() == "made by the learner\n"
    assert (ws / "exercises/task01_fake/b.py").read_text() == "y = 2\n"


def test_a_learners_file_where_the_course_needs_a_folder_is_kept_beside_it(ws: Path, installed: Path) -> None:
    _folder_to_file(ws / "exercises/task01_fake/config")
    (installed / "exercises/task01_fake/config/c.yaml").write_text("c: 2\n")
    result = init_workspace(ws)
    assert result.notes == ["exercises/task01_fake/config was a file where the course now has a folder: yours is kept "
                            "beside it as config.yours"]
    assert (ws / "exercises/task01_fake/config.yours").read_text() == "a file now\n"
    assert (ws / "exercises/task01_fake/config/c.yaml").read_text() == "c: 2\n"


def test_a_clash_the_course_did_not_touch_is_left_as_the_learner_made_it(ws: Path) -> None:
    _folder_to_file(ws / "exercises/task01_fake/config")
    _file_to_folder(ws / "exercises/task01_fake/b.py")
    before = tree(ws / "exercises")
    assert init_workspace(ws).notes == []
    assert tree(ws / "exercises") == before


@pytest.mark.parametrize("change", ["file to folder", "folder to file"])
def test_a_path_the_course_changed_between_file_and_folder_keeps_the_learners_version(
        change: str, ws: Path, installed: Path) -> None:
    import shutil

    if change == "file to folder":
        (installed / "exercises/task01_fake/b.py").unlink()
        (installed / "exercises/task01_fake/b.py").mkdir()
        (installed / "exercises/task01_fake/b.py/__init__.py").write_text("y = 1\n")
        (ws / "exercises/task01_fake/b.py").write_text("y = 1  # mine\n")
    else:
        shutil.rmtree(installed / "exercises/task01_fake/config")
        (installed / "exercises/task01_fake/config").write_text("c: 1\n")
        (ws / "exercises/task01_fake/config/c.yaml").write_text("c: 1  # mine\n")
    result = init_workspace(ws)
    assert len(result.notes) == 1 and ".yours" in result.notes[0]
    assert b"y = 1  # mine\n" in contents(ws) or b"c: 1  # mine\n" in contents(ws)
    assert init_workspace(ws).notes == []


@pytest.mark.parametrize("rel", ["descriptions", "tests", "my_notebooks", ".pristine", "notebooks", "README.md"])
def test_a_learners_file_or_folder_at_a_course_place_is_kept_beside_it_and_the_start_goes_on(
        rel: str, ws: Path) -> None:
    import shutil

    path = ws / rel
    if path.is_dir():
        shutil.rmtree(path)
        path.write_text("the learner's\n")
    else:
        path.unlink()
        path.mkdir()
        (path / "x").write_text("the learner's\n")
    result = init_workspace(ws)
    assert len(result.notes) == 1 and result.notes[0].startswith(f"{rel} was a "), result.notes
    assert b"the learner's\n" in contents(ws)
    assert (ws / "exercises/task01_fake/a.py").is_file() and (ws / "my_notebooks/01_fake.ipynb").is_file()


# ------------------------------------------------------------------------------------------ links and special files
def test_init_never_writes_through_a_learners_link(ws: Path, installed: Path, tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    (outside / "task").mkdir()
    (outside / "task" / "b.py").write_text("y = 1\n")
    import shutil

    shutil.rmtree(ws / "exercises/task01_fake")
    (ws / "exercises/task01_fake").symlink_to(outside / "task")
    shutil.rmtree(ws / "my_notebooks")
    (ws / "my_notebooks").symlink_to(outside)
    (ws / "exercises/task02_more/d.py").unlink()
    (ws / "exercises/task02_more/d.py").symlink_to(outside / "mine.py")
    (installed / "exercises/task02_more/d.py").write_text("z = 0\n")
    (installed / "notebooks/01_fake.ipynb").write_text(notebook("one, updated"))
    _course_update(installed)
    before = tree(outside)
    result = init_workspace(ws)
    assert tree(outside) == before
    assert sorted(n.split(" was a ")[0] for n in result.notes) == [
        "exercises/task01_fake", "exercises/task02_more/d.py", "my_notebooks"]
    assert os.readlink(ws / "exercises/task01_fake.yours") == str(outside / "task")
    assert (ws / "exercises/task01_fake/b.py").read_text() == "y = 2\n"
    assert (ws / "exercises/task02_more/d.py").read_text() == "z = 0\n"


def test_a_fifo_in_the_learners_exercises_never_blocks_init(ws: Path, installed: Path) -> None:
    fifo = ws / "exercises/task01_fake/b.py"
    fifo.unlink()
    os.mkfifo(fifo)
    _course_update(installed)

    def release() -> None:
        fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        os.close(fd)

    result = no_hang(init_workspace, ws, release=release)
    assert "b.py was a special file" in result.notes[0] and stat.S_ISFIFO(os.lstat(f"{fifo}.yours").st_mode)


# ------------------------------------------------------------------------------------------ backups and writes
def test_two_notebook_backups_in_the_same_second_are_both_kept(ws: Path, installed: Path) -> None:
    for version in ("v2", "v3"):
        (ws / "my_notebooks/01_fake.ipynb").write_text(notebook(f"my notes before {version}"))
        (installed / "notebooks/01_fake.ipynb").write_text(notebook(version))
        init_workspace(ws, now=0)
    stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(0))
    backups = sorted(p.parent.name for p in (ws / "my_notebooks/backups").rglob("01_fake.ipynb"))
    assert backups == [stamp, f"{stamp}_2"]
    assert {p.read_text() for p in (ws / "my_notebooks/backups").rglob("01_fake.ipynb")} == {
        notebook("my notes before v2"), notebook("my notes before v3")}


def test_two_resets_in_the_same_second_keep_both_backups(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(tracks.ROOT_ENV, str(ws))
    moment = datetime(2026, 1, 2, 3, 4, 5)
    for text in ("x = 1\n", "x = 2\n"):
        (ws / "exercises/task01_fake/a.py").write_text(text)
        reset_exercise(1, now=moment)
    kept = sorted((p.parent.name, p.read_text()) for p in (ws / "backups").rglob("a.py"))
    assert kept == [("task01_20260102-030405", "x = 1\n"), ("task01_20260102-030405_2", "x = 2\n")]


def test_unique_folder_never_takes_an_existing_name_even_a_file(tmp_path: Path) -> None:
    (tmp_path / "20260101-000000").write_text("")
    (tmp_path / "20260101-000000_2").mkdir()
    assert unique_folder(tmp_path / "20260101-000000").name == "20260101-000000_3"


def test_a_write_killed_half_way_leaves_the_old_content_whole(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "f.txt"
    target.write_bytes(b"old")
    real_write = os.write

    def half(fd: int, data: object) -> int:
        real_write(fd, bytes(data)[:2])  # type: ignore[call-overload]
        raise KeyboardInterrupt

    monkeypatch.setattr(launcher.os, "write", half)
    with pytest.raises(KeyboardInterrupt):
        write_atomically(target, b"new content")
    monkeypatch.undo()
    assert target.read_bytes() == b"old"
    write_atomically(target, b"new content")
    assert target.read_bytes() == b"new content" and sorted(p.name for p in tmp_path.iterdir()) == ["f.txt"]


def test_write_atomically_replaces_a_link_and_leaves_its_target(tmp_path: Path) -> None:
    (tmp_path / "target").write_text("theirs")
    (tmp_path / "link").symlink_to(tmp_path / "target")
    (tmp_path / ".link.rrbot-partial").symlink_to(tmp_path / "target")  # a planted link at the partial name
    write_atomically(tmp_path / "link", b"ours")
    assert (tmp_path / "target").read_text() == "theirs" and not (tmp_path / "link").is_symlink()
    assert (tmp_path / "link").read_bytes() == b"ours"


def test_refresh_on_a_laptop_keeps_a_file_named_my_notebooks(tmp_path: Path) -> None:
    (tmp_path / "notebooks").mkdir()
    (tmp_path / "notebooks/01_x.ipynb").write_text("v1")
    (tmp_path / "my_notebooks").write_text("notes")
    lines = refresh_notebook_copies(tmp_path)
    assert lines[0].startswith("my_notebooks was a file") and (tmp_path / "my_notebooks.yours").read_text() == "notes"


# ------------------------------------------------------------------------------------------ singleuser
class Home(type(Path())):  # type: ignore[misc]
    """A learner's home folder, with the server commands started from it."""

    started: list[list[str]]


@pytest.fixture
def home(tmp_path: Path, installed: Path, monkeypatch: pytest.MonkeyPatch) -> Home:
    """A learner's home, as the spawner gives it; ``os.execvp`` records the server's command instead of running it."""
    home = Home(tmp_path / "home" / "ana")
    home.mkdir(parents=True)
    monkeypatch.setenv("HOME", str(home))
    home.started = []
    monkeypatch.setattr(classroom_commands.os, "execvp", lambda file, argv: home.started.append(list(argv)))
    return home


def _one_line_each(err: str) -> list[str]:
    lines = err.strip().splitlines()
    assert lines and all(line.startswith("rrbot-workshop singleuser: ") for line in lines), err
    assert "Traceback" not in err
    return lines


def test_singleuser_makes_the_workspace_and_starts_the_server_there(home: Home, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["singleuser", "--port=9999"]) == 0
    (command,) = home.started
    assert command[:3] == [sys.executable, "-m", "rrbot_workshop.classroom.server"]
    assert f"--ServerApp.root_dir={home / 'rrbot_workshop'}" in command
    assert command[-1] == "--port=9999"
    assert "workspace made" in _one_line_each(capsys.readouterr().err)[0]


def test_singleuser_starts_the_server_after_a_damaged_archive_with_one_line(
        home: Home, installed: Path, capsys: pytest.CaptureFixture[str]) -> None:
    init_workspace(home / "rrbot_workshop", installed)
    _truncated(home / "rrbot_workshop" / ARCHIVE)
    assert cli.main(["singleuser"]) == 0 and len(home.started) == 1
    lines = _one_line_each(capsys.readouterr().err)
    assert sum(ARCHIVE in line for line in lines) == 1


def test_singleuser_starts_the_server_when_the_update_fails_but_the_workspace_is_usable(
        home: Home, installed: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    init_workspace(home / "rrbot_workshop", installed)

    def broken(*args: object, **kwargs: object) -> None:
        raise ValueError("something nobody foresaw")

    monkeypatch.setattr("rrbot_workshop.classroom.workspace.init_workspace", broken)
    assert cli.main(["singleuser"]) == 0 and len(home.started) == 1
    (line,) = _one_line_each(capsys.readouterr().err)
    assert "ValueError: something nobody foresaw" in line


def test_singleuser_says_what_to_do_when_the_workspace_is_not_usable(
        home: Home, capsys: pytest.CaptureFixture[str]) -> None:
    (home / "rrbot_workshop").mkdir()
    (home / "rrbot_workshop" / "thesis.tex").write_text("...")
    assert cli.main(["singleuser"]) == classroom_commands.WORKSPACE_UNUSABLE
    assert home.started == []
    lines = _one_line_each(capsys.readouterr().err)
    assert len(lines) == 2 and "is not a workspace made by" in lines[0] and "mv " in lines[1]
    assert (home / "rrbot_workshop" / "thesis.tex").read_text() == "..."


def test_singleuser_without_jupyterhub_is_one_line(home: Home, capsys: pytest.CaptureFixture[str],
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    def missing(file: str, argv: list[str]) -> None:
        raise FileNotFoundError(2, "No such file or directory")

    monkeypatch.setattr(classroom_commands.os, "execvp", missing)
    assert cli.main(["singleuser"]) == classroom_commands.SERVER_MISSING
    assert "could not be started" in _one_line_each(capsys.readouterr().err)[-1]


def test_singleuser_as_the_spawner_runs_it_logs_one_line_each_and_execs_the_server(
        installed: Path, tmp_path: Path) -> None:
    """A real process: the spawner's command, with the hub's real single-user server asked for its version (so it
    exits at once, having been started with the learner's workspace set up first)."""
    import jupyterhub

    home = tmp_path / "home" / "ana"
    home.mkdir(parents=True)
    env = {**os.environ, "HOME": str(home), tracks.ROOT_ENV: str(installed)}
    init_workspace(home / "rrbot_workshop", installed)
    _truncated(home / "rrbot_workshop" / ARCHIVE)
    proc = subprocess.run([sys.executable, "-m", "rrbot_workshop.cli", "singleuser", "--version"], env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    lines = _one_line_each(proc.stderr)
    assert sum(ARCHIVE in line for line in lines) == 1
    assert proc.stdout.split() == [jupyterhub.__version__]
    assert (home / "rrbot_workshop" / ARCHIVE).stat().st_size > 0


# ------------------------------------------------------------------------------------------ the course's own copies
def test_a_learners_edit_of_a_course_file_is_kept_beside_the_courses(ws: Path, installed: Path) -> None:
    (ws / "descriptions/robot/r.urdf").write_text("<robot name='mine'/>")
    (ws / "descriptions/robot/notes.txt").write_text("my notes\n")
    (ws / "README.md").write_text("# my readme\n")
    (installed / "descriptions/robot/r.urdf").write_text("<robot name='r2'/>")
    result = init_workspace(ws)
    assert sorted(result.notes) == [
        "README.md: you changed this file of the course's; the course's is in its place and yours is kept beside it "
        "as README.md.yours",
        "descriptions/robot/r.urdf: you changed this file of the course's; the course's is in its place and yours is "
        "kept beside it as r.urdf.yours"]
    assert (ws / "descriptions/robot/r.urdf").read_text() == "<robot name='r2'/>"
    assert (ws / "descriptions/robot/r.urdf.yours").read_text() == "<robot name='mine'/>"
    assert (ws / "descriptions/robot/notes.txt").read_text() == "my notes\n"  # the learner's own file stays in place
    assert (ws / "README.md.yours").read_text() == "# my readme\n"
    before = tree(ws)
    assert init_workspace(ws).notes == [] and tree(ws).keys() == before.keys()


def test_a_course_update_of_its_own_files_replaces_them_without_a_line(ws: Path, installed: Path) -> None:
    (installed / "descriptions/robot/r.urdf").write_text("<robot name='r2'/>")
    (installed / "notebooks/01_fake.ipynb").write_text(notebook("one, updated"))
    (installed / "descriptions/robot/r.urdf").rename(installed / "descriptions/robot/renamed.urdf")
    result = init_workspace(ws)
    assert result.notes == [] and not (ws / "descriptions/robot/r.urdf").exists()
    assert (ws / "descriptions/robot/renamed.urdf").read_text() == "<robot name='r2'/>"


def test_a_workspace_without_a_record_of_the_course_files_has_them_replaced_whole(ws: Path) -> None:
    """Made by an earlier version: its marker has no record, and its course copies are replaced as they always were."""
    marker = json.loads((ws / MARKER).read_text())
    del marker["course_files"]
    (ws / MARKER).write_text(json.dumps(marker))
    (ws / "descriptions/robot/r.urdf").write_text("<robot name='mine'/>")
    assert init_workspace(ws).notes == []
    assert (ws / "descriptions/robot/r.urdf").read_text() == "<robot name='r'/>"
    assert "course_files" in json.loads((ws / MARKER).read_text())
