"""The ``rrbot-workshop`` command: grade, progress, tasks, reset, export, and its exit codes."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tarfile
from datetime import datetime
from pathlib import Path

import pytest

from rrbot_workshop.cli import main
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import export_student_copy, reset_exercise
from rrbot_workshop.exceptions import CourseError

REPO = Path(__file__).resolve().parents[2]
_GIT_ENV = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.invalid", "GIT_COMMITTER_NAME": "t",
            "GIT_COMMITTER_EMAIL": "t@example.invalid"}


@pytest.fixture(autouse=True)
def _clean_env(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in (tracks.TRACK_ENV, tracks.ROOT_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV, "GIT_DIR", "GIT_WORK_TREE"):
        monkeypatch.delenv(name, raising=False)
    tracks.set_track(None)


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A tiny course with two fast graders (tasks 5 and 6) and an exercise for task 5."""
    root = tmp_path / "course"
    (root / "tests" / "tasks").mkdir(parents=True)
    (root / "tests" / "tasks" / "test_task05_fake.py").write_text(
        "from rrbot_workshop.course import tracks\nfrom rrbot_workshop.course.grading import graded\n\n"
        "@graded(points=2, hint='write 42')\ndef test_answer():\n"
        "    assert (tracks.task_dir(5) / 'answer.txt').read_text().strip() == '42'\n"
    )
    (root / "tests" / "tasks" / "test_task06_other.py").write_text("def test_ok():\n    pass\n")
    for track in tracks.TRACKS:
        (root / track / "task05_fake").mkdir(parents=True)
        (root / track / "task05_fake" / "answer.txt").write_text("42\n" if track == "solutions" else "TODO\n")
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    return root


def _git(root: Path, *args: str) -> None:
    subprocess.run(["git", *args], cwd=root, check=True, capture_output=True, env={**os.environ, **_GIT_ENV})


# ------------------------------------------------------------------------------------------- grade, progress


@pytest.mark.skipif(not (REPO / "solutions").is_dir(), reason="this copy of the course has no solutions/")
def test_grade_json_of_the_real_task01_solution(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["grade", "1", "--json", "--track", "solutions"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"task", "score", "max_score", "checks"}
    assert data["task"] == 1 and data["score"] == data["max_score"] > 0
    assert all(set(c) >= {"name", "points", "max_points", "passed", "given", "hint", "reason"} for c in data["checks"])


def test_grade_prints_a_rubric_and_exits_0_on_a_low_score(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["grade", "5"]) == 0
    out = capsys.readouterr().out
    assert "FAIL  0/2  answer" in out and "hint: write 42" in out and "Total: 0/2 points" in out


def test_grade_output_is_identical_between_runs(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """No wall-clock time in the output: notebooks compare it with nbval."""
    main(["grade", "5"])
    first = capsys.readouterr().out
    main(["grade", "5"])
    assert capsys.readouterr().out == first


def test_grade_root_option_grades_a_copy(course: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "upload" / "task05_fake").mkdir(parents=True)
    (tmp_path / "upload" / "task05_fake" / "answer.txt").write_text("42")
    assert main(["grade", "5", "--json", "--root", str(tmp_path / "upload")]) == 0
    assert json.loads(capsys.readouterr().out)["score"] == 2


def test_unknown_task_exits_2_and_lists_tasks(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["grade", "13"]) == 2
    err = capsys.readouterr().err
    assert "task 13" in err and "task05_fake" in err and "task06_other" in err


def test_unknown_track_is_a_usage_error(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["grade", "5", "--track", "answers"]) == 2
    assert "invalid choice" in capsys.readouterr().err


def test_invalid_track_environment_is_a_usage_error(
    course: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv(tracks.TRACK_ENV, "answers")
    assert main(["grade", "5"]) == 2
    assert "valid: 'exercises', 'solutions'" in capsys.readouterr().err


def test_missing_command_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == 2


def test_broken_grader_exits_1(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (course / "tests" / "tasks" / "test_task06_other.py").write_text("import no_such_module_here\n")
    assert main(["grade", "6"]) == 1
    assert "could not be collected" in capsys.readouterr().err


def test_progress_json_grades_every_task_with_a_grader(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["progress", "--json", "--track", "solutions"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [t["task"] for t in data["tasks"]] == [5, 6]
    assert (data["track"], data["score"], data["max_score"]) == ("solutions", 3, 3)


def test_progress_text_has_one_line_per_task(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["progress"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "Progress on the exercises track"
    assert "task05_fake" in out[1] and "0/2" in out[1] and "task06_other" in out[2]
    assert out[-1] == "Total: 1/3 points"


def test_progress_counts_the_learners_checks_not_the_given_ones(course: Path,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    grader = course / "tests" / "tasks" / "test_task05_fake.py"
    grader.write_text(grader.read_text() + "\n\n@graded(given=True, points=1, hint='keep the file')\n"
                      "def test_file_kept():\n    assert (tracks.task_dir(5) / 'answer.txt').is_file()\n")
    assert main(["progress"]) == 0
    line = capsys.readouterr().out.splitlines()[1]
    if "0/2" not in line or "(0 of 1 checks)" not in line:  # the given check passes, yet it is not the learner's
        raise AssertionError(line)
    (course / "exercises" / "task05_fake" / "answer.txt").unlink()
    assert main(["progress"]) == 0
    line = capsys.readouterr().out.splitlines()[1]
    if "(0 of 1 checks; given, failing now: file_kept)" not in line:
        raise AssertionError(line)


def test_tasks_lists_tasks_and_track(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["tasks"]) == 0
    out = capsys.readouterr().out
    assert "Track: exercises" in out and "task05_fake" in out and "exercises, solutions" in out


def test_course_option_selects_the_course(course: Path, monkeypatch: pytest.MonkeyPatch,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.delenv(tracks.ROOT_ENV)
    assert main(["--course", str(course), "tasks"]) == 0
    assert "task05_fake" in capsys.readouterr().out
    assert tracks.ROOT_ENV not in os.environ


# ------------------------------------------------------------------------------------------- reset


@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_reset_restores_from_git_after_a_backup(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _git(course, "init", "-q")
    _git(course, "add", "exercises")
    _git(course, "commit", "-q", "-m", "course")
    exercise = course / "exercises" / "task05_fake"
    (exercise / "answer.txt").write_text("my work\n")
    (exercise / "notes.txt").write_text("extra\n")
    assert main(["reset", "5"]) == 0
    assert (exercise / "answer.txt").read_text() == "TODO\n" and not (exercise / "notes.txt").exists()
    (backup,) = (course / "backups").iterdir()
    assert backup.name.startswith("task05_")
    assert (backup / "answer.txt").read_text() == "my work\n" and (backup / "notes.txt").is_file()
    assert "from git" in capsys.readouterr().out


@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_two_resets_in_the_same_second_keep_both_backups(course: Path) -> None:
    _git(course, "init", "-q")
    _git(course, "add", "exercises")
    _git(course, "commit", "-q", "-m", "course")
    now = datetime(2026, 1, 2, 3, 4, 5)
    first = reset_exercise(5, now=now)
    second = reset_exercise(5, now=now)
    assert first.backup is not None and second.backup is not None
    assert first.backup.name == "task05_20260102-030405" and second.backup.name == "task05_20260102-030405_2"


def _committed(course: Path) -> Path:
    _git(course, "init", "-q")
    _git(course, "add", "exercises")
    _git(course, "commit", "-q", "-m", "course")
    exercise = course / "exercises" / "task05_fake"
    (exercise / "answer.txt").write_text("my work\n")
    return exercise


@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_reset_with_an_unwritable_backup_folder_changes_nothing_and_says_why(
    course: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    exercise = _committed(course)

    def no_space(src: object, dst: str, *args: object, **kwargs: object) -> None:
        Path(dst).mkdir(parents=True, exist_ok=True)  # the backup folder is made first (a name of its own)
        (Path(dst) / "half.txt").write_text("x")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(shutil, "copytree", no_space)
    assert main(["reset", "5"]) == 2
    err = capsys.readouterr().err
    assert "cannot back up your files there (No space left on device); nothing was changed" in err
    assert (exercise / "answer.txt").read_text() == "my work\n"
    assert list((course / "backups").iterdir()) == [], "a half-written backup was left behind"


@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_a_reset_failing_half_way_leaves_the_learners_files_in_place(
    course: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    exercise = _committed(course)
    (exercise / "more.txt").write_text("notes\n")
    real = Path.write_bytes
    broken = [True]

    def failing(self: Path, data: bytes) -> int:
        if broken[0] and ".reset" in str(self):
            raise OSError(13, "Permission denied")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", failing)
    with pytest.raises(CourseError, match="could not be restored \\(Permission denied\\); your files are unchanged"):
        reset_exercise(5)
    assert (exercise / "answer.txt").read_text() == "my work\n" and (exercise / "more.txt").is_file()
    assert sorted(p.name for p in (course / "exercises").iterdir()) == ["task05_fake"], "temporary folders were left"
    broken[0] = False
    result = reset_exercise(5)  # and the next reset works
    assert (exercise / "answer.txt").read_text() == "TODO\n" and not (exercise / "more.txt").exists()
    assert result.backup is not None and (result.backup / "more.txt").is_file()


def test_reset_without_pristine_copy_changes_nothing(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (course / "exercises" / "task05_fake" / "answer.txt").write_text("my work\n")
    assert main(["reset", "5"]) == 2
    assert "no pristine copy" in capsys.readouterr().err
    assert (course / "exercises" / "task05_fake" / "answer.txt").read_text() == "my work\n"
    assert not (course / "backups").exists()


def test_reset_unknown_task_raises_course_error(course: Path) -> None:
    with pytest.raises(CourseError, match="no task 9"):
        reset_exercise(9)


# ------------------------------------------------------------------------------------------- export


def test_export_leaves_out_solutions_and_reset_works_from_its_archive(course: Path, tmp_path: Path) -> None:
    (course / ".git").mkdir()
    (course / ".venv").mkdir()
    (course / "backups").mkdir()
    target = export_student_copy(tmp_path / "student")
    assert not any((target / name).exists() for name in ("solutions", ".git", ".venv", "backups"))
    assert (target / "exercises" / "task05_fake" / "answer.txt").is_file()
    with tarfile.open(target / ".pristine" / "exercises.tar.gz") as tar:
        assert tar.getnames() == ["exercises/task05_fake/answer.txt"]
    (target / "exercises" / "task05_fake" / "answer.txt").write_text("mine")
    assert main(["--course", str(target), "reset", "5"]) == 0
    assert (target / "exercises" / "task05_fake" / "answer.txt").read_text() == "TODO\n"


@pytest.mark.parametrize("from_git", [True, False])
def test_export_leaves_out_the_hidden_wrong_controllers_of_task16(course: Path, tmp_path: Path, from_git: bool) -> None:
    hidden = course / "tests" / "tasks" / "task16_mutants"
    hidden.mkdir()
    (hidden / "update.py").write_text("class StateNotAdded: ...\n")
    (course / "tests" / "tasks" / "task16_public_mutants.py").write_text("class SlowModeIgnored: ...\n")
    if from_git:
        _git(course, "init", "-q")
        _git(course, "add", ".")
        _git(course, "commit", "-q", "-m", "course")
    target = export_student_copy(tmp_path / "student")
    assert not (target / "tests" / "tasks" / "task16_mutants").exists()
    assert (target / "tests" / "tasks" / "task16_public_mutants.py").is_file()
    assert (target / "tests" / "tasks" / "test_task05_fake.py").is_file()


def test_export_refuses_a_non_empty_folder(course: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("")
    assert main(["export", "--student", str(tmp_path / "full")]) == 2
    assert "not an empty folder" in capsys.readouterr().err


def test_export_refuses_a_folder_inside_the_course(course: Path) -> None:
    with pytest.raises(CourseError, match="outside the course folder"):
        export_student_copy(course / "handout")


def test_student_copy_of_the_real_course_still_grades(tmp_path: Path) -> None:
    """Export this repository, then grade task 1 inside the copy, on the exercises track, with the copy's code."""
    target = tmp_path / "student"
    env = {k: v for k, v in os.environ.items() if not k.startswith("RRBOT_WORKSHOP_")}
    subprocess.run([sys.executable, "-m", "rrbot_workshop.cli", "export", "--student", str(target)],
                   cwd=REPO, env=env, check=True, capture_output=True)
    assert not (target / "solutions").exists() and (target / "rrbot_workshop" / "cli.py").is_file()
    result = subprocess.run([sys.executable, "-m", "rrbot_workshop.cli", "grade", "1", "--json"],
                            cwd=target, env=env, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["task"] == 1 and 0 < data["max_score"] and data["score"] < data["max_score"]
    missing = subprocess.run([sys.executable, "-m", "rrbot_workshop.cli", "grade", "1", "--track", "solutions"],
                             cwd=target, env=env, capture_output=True, text=True, check=False)
    assert missing.returncode == 2 and "no 'solutions/' folder" in missing.stderr


# ------------------------------------------------------------------------------------------- lint, export --ros2

_BROKEN_YAML = """controller_manager:
  ros__parameters:
    update_rate: 100
    fwd:
      type: forward_command_controller/ForwardCommandControler
"""


def test_lint_passes_the_course_yaml_with_its_description(capsys: pytest.CaptureFixture[str]) -> None:
    config = REPO / "descriptions" / "rrbot" / "config" / "rrbot_controllers.yaml"
    urdf = REPO / "descriptions" / "rrbot" / "urdf" / "rrbot.urdf.xacro"
    assert main(["lint", str(config), "--description", str(urdf)]) == 0
    assert capsys.readouterr().out.strip().endswith("no problems found")


def test_lint_exits_1_and_names_line_and_closest_type(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(_BROKEN_YAML)
    assert main(["lint", str(bad)]) == 1
    out = capsys.readouterr().out
    assert f"{bad}:5: error: controller_manager.fwd.type" in out
    assert "did you mean 'forward_command_controller/ForwardCommandController'" in out and "1 error(s)" in out


def test_lint_checks_a_description_with_xacro_args(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = REPO / "descriptions" / "rrbot" / "urdf" / "rrbot.urdf.xacro"
    assert main(["lint", str(urdf), "--xacro-arg", "prefix:=left_"]) == 0
    broken = tmp_path / "broken.urdf"
    broken.write_text('<robot name="r"><ros2_control name="s" type="system"><joint name="j"/></ros2_control></robot>')
    assert main(["lint", str(broken)]) == 1
    assert "broken.urdf" in capsys.readouterr().out
    assert main(["lint", str(urdf), "--xacro-arg", "prefix=left_"]) == 2
    assert "NAME:=VALUE" in capsys.readouterr().err


@pytest.mark.skipif(not (REPO / "solutions").is_dir(), reason="this copy of the course has no solutions/")
def test_export_ros2_writes_the_packages_and_refuses_a_full_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tracks.set_track("solutions")
    target = tmp_path / "ws"
    assert main(["--course", str(REPO), "export", "--ros2", str(target)]) == 0
    assert f"Wrote ROS 2 packages to {target}" in capsys.readouterr().out
    assert (target / "controlko_bringup" / "launch" / "rrbot.launch.py").is_file()
    assert (target / "controlko_description" / "package.xml").is_file()
    assert main(["--course", str(REPO), "export", "--ros2", str(target)]) == 2
    assert "is not empty" in capsys.readouterr().err
    assert main(["--course", str(REPO), "export", "--ros2", str(target), "--force"]) == 0


def test_export_needs_exactly_one_target(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["export"]) == 2
    assert main(["export", "--student", "a", "--ros2", "b"]) == 2
