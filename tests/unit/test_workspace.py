"""``rrbot-workshop init``: a learner's workspace from a course installed once for a room, updated without conflicts."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest

from rrbot_workshop.classroom.workspace import MARKER, init_workspace, singleuser_command
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import check
from rrbot_workshop.course.grading.attempts import log_path
from rrbot_workshop.course.grading.course import reset_exercise
from rrbot_workshop.exceptions import CourseError

_GRADER = '''
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded


@graded(points=1, hint=("idea", "api", "code"))
def test_answer():
    assert (tracks.task_dir(1) / "a.py").read_text().strip() == "x = 42", "a.py must say x = 42"
'''


def _notebook(text: str) -> str:
    return json.dumps({"cells": [{"cell_type": "markdown", "metadata": {}, "source": [text]}], "metadata": {},
                       "nbformat": 4, "nbformat_minor": 5})


@pytest.fixture
def installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A course installed for a room: one task, one notebook, a grader; no solutions in sight of the workspace."""
    course = tmp_path / "opt" / "course"
    (course / "exercises" / "task01_fake").mkdir(parents=True)
    (course / "exercises" / "task01_fake" / "a.py").write_text("x = None  # TODO\n")
    (course / "exercises" / "task01_fake" / "b.py").write_text("y = 1\n")
    (course / "exercises" / "README.md").write_text("# Exercises\n")
    (course / "solutions" / "task01_fake").mkdir(parents=True)
    (course / "solutions" / "task01_fake" / "a.py").write_text("x = 42\n")
    (course / "notebooks").mkdir()
    (course / "notebooks" / "01_fake.ipynb").write_text(_notebook("one"))
    (course / "descriptions" / "robot").mkdir(parents=True)
    (course / "descriptions" / "robot" / "r.urdf").write_text("<robot name='r'/>")
    (course / "tests" / "tasks").mkdir(parents=True)
    (course / "tests" / "tasks" / "test_task01_fake.py").write_text(_GRADER)
    (course / "README.md").write_text("# Course\n")
    for name in (tracks.ROOT_ENV, tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(name, raising=False)
    tracks.set_track(None)
    return course


def test_init_makes_a_workspace_with_the_learners_files_and_not_the_solutions(installed: Path, tmp_path: Path) -> None:
    home = tmp_path / "home" / "ana"
    result = init_workspace(home / "rrbot_workshop", installed)
    ws = result.workspace
    assert result.created and sorted(result.added) == ["exercises/task01_fake/a.py", "exercises/task01_fake/b.py"]
    assert (ws / "exercises" / "task01_fake" / "a.py").read_text() == "x = None  # TODO\n"
    assert (ws / "my_notebooks" / "01_fake.ipynb").is_file() and (ws / "tests" / "tasks" / "test_task01_fake.py").is_file()
    assert (ws / "descriptions" / "robot" / "r.urdf").is_file() and (ws / "exercises" / "README.md").is_file()
    assert not (ws / "solutions").exists() and json.loads((ws / MARKER).read_text())["source"] == str(installed)
    assert result.notebooks == ["01_fake.ipynb: copied to my_notebooks/"]


def test_inside_the_workspace_the_course_grades_and_logs_the_learners_files(
    installed: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    ws = init_workspace(tmp_path / "ws", installed).workspace
    monkeypatch.chdir(ws / "my_notebooks")  # where a notebook's kernel runs
    assert tracks.course_root() == ws
    (ws / "exercises" / "task01_fake" / "a.py").write_text("x = 42\n")
    assert check(1, check_timeout=5.0).score == 1
    assert log_path(1).is_relative_to(ws) and log_path(1).is_file()
    assert not (installed / "exercises" / ".progress").exists()
    result = reset_exercise(1)
    assert result.source == "archive" and (ws / "exercises" / "task01_fake" / "a.py").read_text().startswith("x = None")


def test_init_again_updates_the_course_and_never_the_learners_work(
    installed: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    ws = init_workspace(tmp_path / "ws", installed).workspace
    monkeypatch.setenv(tracks.ROOT_ENV, str(installed))  # the course installed now
    (ws / "exercises" / "task01_fake" / "a.py").write_text("x = 41  # mine\n")
    (ws / "my_notebooks" / "01_fake.ipynb").write_text(_notebook("one, with my notes"))
    # the course is updated: both exercise files, the notebook, a new task
    (installed / "exercises" / "task01_fake" / "a.py").write_text("x = None  # TODO(task 1.1): 42\n")
    (installed / "exercises" / "task01_fake" / "b.py").write_text("y = 2\n")
    (installed / "exercises" / "task02_more").mkdir()
    (installed / "exercises" / "task02_more" / "c.py").write_text("z = None\n")
    (installed / "notebooks" / "01_fake.ipynb").write_text(_notebook("one, updated"))
    result = init_workspace(ws, now=0.0)
    assert not result.created
    assert result.updated == ["exercises/task01_fake/b.py"] and (ws / "exercises/task01_fake/b.py").read_text() == "y = 2\n"
    assert result.kept == ["exercises/task01_fake/a.py"]
    assert (ws / "exercises/task01_fake/a.py").read_text() == "x = 41  # mine\n"
    assert (ws / "exercises/task01_fake/a.py.course-update").read_text().startswith("x = None  # TODO(task 1.1)")
    assert result.added == ["exercises/task02_more/c.py"]
    backups = list((ws / "my_notebooks" / "backups").rglob("01_fake.ipynb"))
    assert len(backups) == 1 and "with my notes" in backups[0].read_text()
    assert "updated" in (ws / "my_notebooks" / "01_fake.ipynb").read_text()
    again = init_workspace(ws)  # nothing new: nothing moves
    assert (again.added, again.updated, again.notebooks, again.notes) == ([], [], [], [])


def test_the_workspace_follows_the_course_installed_now_and_says_it_moved(
    installed: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    ws = init_workspace(tmp_path / "ws", installed).workspace
    moved = tmp_path / "srv" / "course"
    shutil.copytree(installed, moved)
    shutil.rmtree(installed)
    (moved / "exercises" / "task01_fake" / "b.py").write_text("y = 3\n")
    monkeypatch.setenv(tracks.ROOT_ENV, str(moved))
    result = init_workspace(ws)
    assert result.source == moved and result.updated == ["exercises/task01_fake/b.py"]
    assert result.notes == [f"this workspace was made from the course at {installed}, which is no longer there: it "
                            f"now follows the course at {moved}"]
    assert json.loads((ws / MARKER).read_text())["source"] == str(moved)
    assert init_workspace(ws).notes == []  # said once


def test_init_refuses_what_is_not_a_course_or_would_overwrite_someone(installed: Path, tmp_path: Path) -> None:
    with pytest.raises(CourseError, match="is not an installed course"):
        init_workspace(tmp_path / "ws", tmp_path)
    with pytest.raises(CourseError, match="must be outside the installed course"):
        init_workspace(installed / "ws", installed)
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "thesis.tex").write_text("...")
    with pytest.raises(CourseError, match="not a workspace made by"):
        init_workspace(tmp_path / "busy", installed)
    assert (tmp_path / "busy" / "thesis.tex").read_text() == "..."
    (tmp_path / "afile").write_text("")
    with pytest.raises(CourseError, match="is a file"):
        init_workspace(tmp_path / "afile", installed)


def test_the_single_user_server_opens_the_learners_workspace_without_solutions(tmp_path: Path) -> None:
    command = singleuser_command(tmp_path, ["--port=9999"])
    assert command[:3] == [sys.executable, "-m", "rrbot_workshop.classroom.server"] and command[-1] == "--port=9999"
    assert f"--ServerApp.root_dir={tmp_path}" in command
    hidden = next(a for a in command if a.startswith("--ContentsManager.hide_globs="))
    assert "'solutions'" in hidden and "'notebooks'" in hidden


def test_a_workspace_that_cannot_be_written_is_one_clear_error(installed: Path, tmp_path: Path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        if (locked / "probe").parent.exists() and not _writable(locked):
            with pytest.raises(CourseError, match="cannot be written"):
                init_workspace(locked / "ws", installed)
        with pytest.raises(CourseError):
            init_workspace("/proc/rrbot_workshop_ws", installed)
    finally:
        locked.chmod(0o700)


def _writable(folder: Path) -> bool:
    try:
        (folder / ".probe").write_text("")
    except OSError:
        return False
    (folder / ".probe").unlink()
    return True
