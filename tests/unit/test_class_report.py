"""``rrbot-workshop class-report``: the instructor's view of a room, read from the learners' own attempt logs."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from types import SimpleNamespace

import pytest
from workspace_helpers import tree

from rrbot_workshop.classroom import class_report
from rrbot_workshop.classroom.class_report import (
    WORKSPACE_NAME,
    Workspace,
    build_report,
    find_workspaces,
    untouched_versions,
)
from rrbot_workshop.classroom.class_report_page import write_report
from rrbot_workshop.classroom.task_status import NOT_STARTED, PASSED, STUCK, WORKING, local_time
from rrbot_workshop.cli import main
from rrbot_workshop.course.grading.attempts import files_version
from rrbot_workshop.exceptions import CourseError

T0 = 1_800_000_000.0
NOW = T0 + 60 * 30  # the report is made 30 minutes into the workshop


def _log(workspace: Path, task: int, attempts: list[dict]) -> Path:
    path = workspace / "exercises" / ".progress" / f"task{task:02d}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"attempts": attempts}))
    return path


def _attempt(minute: float, score: float, max_score: float, reasons: dict[str, str] | None = None,
             version: str = "") -> dict:
    reasons = reasons or {}
    return {"time": T0 + 60 * minute, "score": score, "max_score": max_score, "failed": sorted(reasons),
            "version": version or f"v{minute}", "reasons": reasons}


@pytest.fixture
def course(tmp_path: Path) -> Path:
    """A course whose exercises (as handed out) are task 1 and task 2."""
    root = tmp_path / "course"
    for task in ("task01_description", "task02_mock_hardware"):
        (root / "exercises" / task).mkdir(parents=True)
        (root / "exercises" / task / "file.py").write_text(f"# TODO: {task}\n")
    return root


@pytest.fixture
def room(tmp_path: Path, course: Path) -> Path:
    """Homes: ana passed task 1 after two checks and is stuck on task 2 since minute 15; ben has failed task 1's
    link1_shape since minute 2 (stuck) and only ran task 2's self-check on the untouched exercise; cleo has a
    workspace but never checked; dan has no workspace; eve passed task 1 at her first check."""
    homes = tmp_path / "home"
    ana, ben, cleo, eve = (homes / n / WORKSPACE_NAME for n in ("ana", "ben", "cleo", "eve"))
    (cleo / "exercises").mkdir(parents=True)
    (homes / "dan").mkdir(parents=True)
    handed_out = files_version(course / "exercises" / "task02_mock_hardware")
    link = "link1 is 0.4 m long; the task states 0.5 m"
    todo = {f"check_{i:02d}": "TODO" for i in range(19)}
    _log(ana, 1, [_attempt(0, 20, 32, {"link1_shape": link}), _attempt(9, 32, 32)])
    _log(ana, 2, [_attempt(15, 10, 23, {"forward_reaches_goal": "joint2 at 0.0 rad"}),
                  _attempt(25, 12, 23, {"forward_reaches_goal": "joint2 at 0.1 rad"})])
    _log(ben, 1, [_attempt(2, 20, 32, {"link1_shape": link, "joint_limits": "joint1 from -3.14"}),
                  _attempt(27, 20, 32, {"link1_shape": link})])
    _log(ben, 2, [_attempt(20, 0, 23, todo, version=handed_out)])
    _log(eve, 1, [_attempt(14, 32, 32)])
    return homes


def _report(room: Path, course: Path, **kwargs: object):
    return build_report([str(room / "*")], now=NOW, course=course, **kwargs)


def test_each_learner_by_task_is_not_started_working_stuck_or_passed(room: Path, course: Path) -> None:
    report = _report(room, course)
    assert [lr.name for lr in report.learners] == ["ana", "ben", "cleo", "eve"]
    status = {(lr.name, t): lr.state(t).status for lr in report.learners for t in report.tasks()}
    assert status == {("ana", 1): PASSED, ("ana", 2): STUCK, ("ben", 1): STUCK, ("ben", 2): NOT_STARTED,
                      ("cleo", 1): NOT_STARTED, ("cleo", 2): NOT_STARTED, ("eve", 1): PASSED, ("eve", 2): NOT_STARTED}
    assert report.counts()[2] == {NOT_STARTED: 3, WORKING: 0, STUCK: 1, PASSED: 0}


def test_a_longer_stuck_after_makes_the_same_learners_working(room: Path, course: Path) -> None:
    report = _report(room, course, stuck_after=3600.0)
    assert {lr.name: lr.state(2).status for lr in report.learners}["ana"] == WORKING
    assert all(r["learners_stuck"] == 0 for r in report.stuck())


def test_the_stuck_table_holds_only_learners_who_started_the_task(room: Path, course: Path) -> None:
    """ben's 19 failing checks of the untouched task 2 are not in it; the table says who is stuck and why."""
    rows = _report(room, course).stuck()
    assert [(r["task"], r["check"], r["learners_stuck"], r["learners_failing"]) for r in rows] == [
        (1, "link1_shape", 1, 1), (2, "forward_reaches_goal", 1, 1)]
    assert rows[0]["most_common_reason"].startswith("link1 is 0.4 m")


def test_time_to_pass_is_given_only_when_it_means_something(room: Path, course: Path) -> None:
    learners = {lr.name: lr for lr in _report(room, course).learners}
    assert learners["ana"].state(1).time_to_pass_s == 540.0 and not learners["ana"].state(1).first_try
    assert learners["eve"].state(1).time_to_pass_s is None and learners["eve"].state(1).first_try


def test_the_report_says_when_it_was_made_and_each_learners_last_self_check(room: Path, course: Path,
                                                                             tmp_path: Path) -> None:
    report = _report(room, course)
    assert report.made_at == NOW
    assert {lr.name: lr.last_activity for lr in report.learners} == {
        "ana": T0 + 60 * 25, "ben": T0 + 60 * 27, "cleo": None, "eve": T0 + 60 * 14}
    data = json.loads(write_report(report, tmp_path / "r")[0].read_text())
    assert data["made_at"] == NOW and data["made_at_local"] == local_time(NOW) and data["stuck_after_s"] == 600.0
    assert data["learners"][1]["last_activity"] == T0 + 60 * 27


def test_json_csv_and_html_are_written_and_no_learner_file_changes(room: Path, course: Path, tmp_path: Path) -> None:
    before = tree(room)
    paths = write_report(_report(room, course), tmp_path / "report")
    assert [p.name for p in paths] == ["report.json", "report.csv", "report.html"]
    data = json.loads(paths[0].read_text())
    assert data["learners"][0]["tasks"]["1"]["status"] == PASSED
    assert data["learners"][0]["tasks"]["1"]["time_to_pass_s"] == 540.0
    rows = list(csv.DictReader(paths[1].open(newline="")))
    assert len(rows) == 4 * 2  # every learner x every task anyone checked
    assert [(r["learner"], r["task"], r["status"]) for r in rows[:4]] == [
        ("ana", "1", PASSED), ("ana", "2", STUCK), ("ben", "1", STUCK), ("ben", "2", NOT_STARTED)]
    assert rows[6]["time_to_pass_s"] == "" and rows[6]["first_try"] == "True"  # eve, task 1
    page = paths[2].read_text()
    assert "<h1>The room: 4 learners</h1>" in page and '<polyline class="line"' in page
    assert f"Made {local_time(NOW)}" in page and "first try" in page and "in 9 min" in page
    assert tree(room) == before


def test_the_progress_plot_steps_up_once_per_task_passed(room: Path, course: Path) -> None:
    """ana passed task 1 at minute 9 and eve at minute 14: two steps, flat to the report's minute 30."""
    import re

    from rrbot_workshop.classroom.class_report_page import progress_svg

    svg = progress_svg(_report(room, course))
    points = [tuple(map(float, p.split(","))) for p in re.search(r'points="([^"]+)"', svg).group(1).split()]
    assert len(points) == 2 + 2 * 2
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    assert xs == sorted(xs) and ys[0] == ys[1] > ys[2] == ys[3] > ys[4] == ys[5]  # y grows downwards in SVG
    assert (xs[2] - xs[0]) / (xs[-1] - xs[0]) == pytest.approx(9 / 30, abs=0.01)


def test_half_written_and_unreadable_logs_become_one_note_each(room: Path, course: Path) -> None:
    ben = room / "ben" / WORKSPACE_NAME / "exercises" / ".progress"
    (ben / "task03.json").write_text('{"attempts": [{"time": 1800000000.0, "sco')
    (ben / "task04.json").write_text('{"attempts": {"not": "a list"}}')
    (ben / "task05.json").write_bytes(b"\xff\xfe\x00")
    (ben / "task06.json").write_text(json.dumps({"attempts": [_attempt(1, 0, 3), {"score": 2}, "x"]}))
    report = build_report([str(room / "ben")], now=NOW, course=course)
    assert set(report.learners[0].tasks) == {1, 2, 6}
    assert report.notes == [
        "ben: task 3's log task03.json could not be read (half-written or not JSON); left out",
        "ben: task 4's log task04.json could not be read (not an attempt log: no list of attempts); left out",
        "ben: task 5's log task05.json could not be read (not UTF-8 text); left out",
        "ben: task 6's log task06.json 2 of its 3 entries are not attempts (the first: 'time' must be a number, not "
        "NoneType); they are left out"]


def test_a_course_folder_is_a_workspace_too_and_bad_arguments_are_refused(room: Path, course: Path,
                                                                          tmp_path: Path) -> None:
    workspace = room / "ana" / WORKSPACE_NAME
    assert find_workspaces([str(workspace)]) == [Workspace("ana", workspace)]
    with pytest.raises(CourseError, match="matches no folder"):
        find_workspaces([str(tmp_path / "nobody*")])
    with pytest.raises(CourseError, match="no learner's workspace"):
        find_workspaces([str(room / "dan")])
    (tmp_path / "afile").write_text("x")
    with pytest.raises(CourseError, match="is a file"):
        write_report(_report(room, course), tmp_path / "afile")
    with pytest.raises(CourseError, match="cannot be written"):
        write_report(_report(room, course), tmp_path / "afile" / "below")


def test_a_link_among_a_globs_matches_is_left_out_with_a_note(room: Path, course: Path) -> None:
    os.symlink(room / "ana", room / "zed")
    report = _report(room, course)
    assert "zed" not in [lr.name for lr in report.learners]
    assert any(n.endswith("zed: a link (or in one) among the folders '" + str(room / "*") + "' matches; left out (a learner may "
                          "have made it; name the folder itself to include it)") for n in report.notes)


def test_a_folder_a_glob_reaches_through_a_link_is_left_out(room: Path, course: Path) -> None:
    os.symlink(room / "ana", room / "zed")
    report = build_report([str(room / "*" / WORKSPACE_NAME)], now=NOW, course=course)
    assert [lr.name for lr in report.learners] == ["ana", "ben", "cleo", "eve"]
    assert any(n.startswith(f"{room}/zed/{WORKSPACE_NAME}: a link (or in one)") for n in report.notes)


def test_a_folder_named_explicitly_is_followed_even_as_a_link(room: Path, course: Path, tmp_path: Path) -> None:
    os.symlink(room / "ana", tmp_path / "ana_upload")
    report = build_report([str(tmp_path / "ana_upload")], now=NOW, course=course)
    assert report.learners[0].name == "ana_upload" and report.learners[0].state(1).status == PASSED


def test_untouched_versions_are_the_course_exercises_as_handed_out(course: Path) -> None:
    versions = untouched_versions(course)
    assert versions == {1: {files_version(course / "exercises" / "task01_description")},
                        2: {files_version(course / "exercises" / "task02_mock_hardware")}}
    assert untouched_versions(None) == {} and untouched_versions(course / "nowhere") == {}


def test_without_the_course_a_note_says_that_untouched_checks_count_as_a_start(room: Path, tmp_path: Path) -> None:
    report = build_report([str(room / "*")], now=NOW, course=tmp_path / "elsewhere")
    assert report.notes[0] == (f"the course's exercises as handed out were not found (in {tmp_path}/elsewhere/"
                               "exercises); a self-check of an untouched exercise counts as a start (give the course "
                               "with --course)")
    assert {lr.name: lr.state(2).status for lr in report.learners}["ben"] == STUCK


def test_the_command_takes_the_course_the_workspaces_were_made_from(room: Path, course: Path, tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(class_report, "time", SimpleNamespace(time=lambda: NOW))
    assert main(["class-report", str(room / "*"), "--course", str(course), "--out", str(tmp_path / "r")]) == 0
    data = json.loads((tmp_path / "r" / "report.json").read_text())
    assert data["learners"][1]["tasks"]["2"]["status"] == NOT_STARTED and not data["notes"]


def test_the_command_prints_where_the_room_is_stuck(room: Path, course: Path, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("RRBOT_WORKSHOP_ROOT", str(course))  # the installed course
    monkeypatch.setattr(class_report, "time", SimpleNamespace(time=lambda: NOW))
    assert main(["class-report", str(room / "*"), "--out", str(tmp_path / "r"), "--stuck-after", "1"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("4 learner(s); wrote ")
    assert "Most learners stuck on: task 1 link1_shape (1 learner(s) for 1 min or more)" in out
    assert main(["class-report", str(tmp_path / "none*"), "--out", str(tmp_path / "r")]) == 2


@pytest.mark.parametrize("minutes", ["-1", "nan", "20000"])
def test_the_command_refuses_a_stuck_after_out_of_range(room: Path, tmp_path: Path, minutes: str,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["class-report", str(room / "*"), "--out", str(tmp_path / "r"), "--stuck-after", minutes]) == 2
    assert "--stuck-after" in capsys.readouterr().err


def test_build_report_raises_course_error_for_a_stuck_after_that_is_not_seconds(room: Path, course: Path) -> None:
    with pytest.raises(CourseError, match="stuck_after"):
        _report(room, course, stuck_after=-1.0)


def test_class_report_without_workspaces_or_a_hub_is_refused(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["class-report", "--out", str(tmp_path / "r")]) == 2
    assert "--hub" in capsys.readouterr().err
