"""``rrbot-workshop class-report``: the instructor's view of a room, read from the learners' own attempt logs."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from rrbot_workshop.classroom.class_report import WORKSPACE_NAME, build_report, find_workspaces, write_report
from rrbot_workshop.cli import main
from rrbot_workshop.exceptions import CourseError

T0 = 1_800_000_000.0


def _log(workspace: Path, task: int, attempts: list[dict]) -> Path:
    path = workspace / "exercises" / ".progress" / f"task{task:02d}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"attempts": attempts}))
    return path


def _attempt(minute: float, score: float, max_score: float, reasons: dict[str, str] | None = None) -> dict:
    reasons = reasons or {}
    return {"time": T0 + 60 * minute, "score": score, "max_score": max_score, "failed": sorted(reasons),
            "version": f"v{minute}", "reasons": reasons}


@pytest.fixture
def room(tmp_path: Path) -> Path:
    """Three homes: ana passed task 1 after two checks, is stuck on task 2; ben is stuck on task 1 like ana was;
    cleo has a workspace but never checked; a fourth home has no workspace."""
    homes = tmp_path / "home"
    ana = homes / "ana" / WORKSPACE_NAME
    ben = homes / "ben" / WORKSPACE_NAME
    cleo = homes / "cleo" / WORKSPACE_NAME
    (cleo / "exercises").mkdir(parents=True)
    (homes / "dan").mkdir(parents=True)
    link = "link1 is 0.4 m long; the task states 0.5 m"
    _log(ana, 1, [_attempt(0, 20, 32, {"link1_shape": link}), _attempt(9, 32, 32)])
    _log(ana, 2, [_attempt(15, 10, 23, {"forward_reaches_goal": "joint2 at 0.0 rad"})])
    _log(ben, 1, [_attempt(2, 20, 32, {"link1_shape": link, "joint_limits": "joint1 from -3.14"}),
                  _attempt(5, 20, 32, {"link1_shape": link})])
    return homes


def test_the_report_has_each_learner_by_task_and_where_the_room_is_stuck(room: Path) -> None:
    report = build_report([str(room / "*")])
    assert [lr.name for lr in report.learners] == ["ana", "ben", "cleo"]
    ana, ben, cleo = report.learners
    assert ana.tasks[1].passed and ana.tasks[1].attempts == 2 and ana.tasks[1].time_to_pass_s == 540.0
    assert (ana.tasks[1].points, ana.tasks[1].max_points) == (32, 32)
    assert not ben.tasks[1].passed and ben.tasks[1].time_to_pass_s is None and ben.tasks[1].failing == {
        "link1_shape": "link1 is 0.4 m long; the task states 0.5 m"}
    assert cleo.tasks == {}
    stuck = report.stuck()
    # ana's task-1 failure is in the past: only ben fails link1_shape now; joint_limits was fixed in ben's last check
    assert {(r["task"], r["check"], r["learners_failing"]) for r in stuck} == {(1, "link1_shape", 1),
                                                                               (2, "forward_reaches_goal", 1)}
    assert next(r for r in stuck if r["check"] == "link1_shape")["most_common_reason"].startswith("link1 is 0.4 m")


def test_json_csv_and_html_are_written_and_no_learner_file_changes(room: Path, tmp_path: Path) -> None:
    before = {p: p.read_bytes() for p in room.rglob("*") if p.is_file()}
    out = tmp_path / "report"
    paths = write_report(build_report([str(room / "*")]), out)
    assert [p.name for p in paths] == ["report.json", "report.csv", "report.html"]
    data = json.loads(paths[0].read_text())
    assert data["learners"][0]["tasks"]["1"] == {"attempts": 2, "passed": True, "points": 32.0, "max_points": 32.0,
                                                  "time_to_pass_s": 540.0, "failing": []}
    rows = list(csv.DictReader(paths[1].open()))
    assert [(r["learner"], r["task"], r["passed"]) for r in rows] == [("ana", "1", "True"), ("ana", "2", "False"),
                                                                       ("ben", "1", "False")]
    page = paths[2].read_text()
    assert "<h1>The room: 3 learners</h1>" in page and "data:image/png;base64," in page and "link1_shape" in page
    assert {p: p.read_bytes() for p in room.rglob("*") if p.is_file()} == before


def test_half_written_and_unreadable_logs_become_notes(room: Path) -> None:
    ben = room / "ben" / WORKSPACE_NAME / "exercises" / ".progress"
    (ben / "task02.json").write_text('{"attempts": [{"time": 1800000000.0, "sco')
    (ben / "task03.json").write_text('{"attempts": {"not": "a list"}}')
    (ben / "task04.json").write_bytes(b"\xff\xfe\x00")
    report = build_report([str(room / "ben")])
    assert set(report.learners[0].tasks) == {1}
    assert [n.split(" could not be read ")[1] for n in report.notes] == [
        "(half-written or not JSON); left out", "(not an attempt log: no list of attempts); left out",
        "(not UTF-8 text); left out"]
    assert all(n.startswith(f"ben: task {t}'s log task0{t}.json") for n, t in zip(report.notes, (2, 3, 4), strict=True))


def test_a_course_folder_is_a_workspace_too_and_bad_arguments_are_refused(room: Path, tmp_path: Path) -> None:
    workspace = room / "ana" / WORKSPACE_NAME
    assert find_workspaces([str(workspace)]) == [(WORKSPACE_NAME, workspace.resolve())]
    with pytest.raises(CourseError, match="matches no folder"):
        find_workspaces([str(tmp_path / "nobody*")])
    with pytest.raises(CourseError, match="no learner's workspace"):
        find_workspaces([str(room / "dan")])
    (tmp_path / "afile").write_text("x")
    with pytest.raises(CourseError, match="is a file"):
        write_report(build_report([str(room / "*")]), tmp_path / "afile")


def test_the_command_prints_where_the_room_is_stuck(room: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["class-report", str(room / "*"), "--out", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("3 learner(s); wrote ") and "Most learners stuck on: task 1 link1_shape" in out
    assert main(["class-report", str(tmp_path / "none*"), "--out", str(tmp_path / "r")]) == 2


def test_hub_homes_needs_a_template_with_the_user_and_an_answering_hub() -> None:
    from rrbot_workshop.classroom.class_report import hub_homes

    with pytest.raises(CourseError, match="must contain"):
        hub_homes("http://127.0.0.1:9", "t", "/home/nobody")
    with pytest.raises(CourseError, match="did not list its users"):
        hub_homes("http://127.0.0.1:9", "t", "/home/{username}")


def test_class_report_without_workspaces_or_a_hub_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["class-report", "--out", str(tmp_path / "r")]) == 2
    assert "--hub" in capsys.readouterr().err
