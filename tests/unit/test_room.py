"""A workshop room on this machine: JupyterHub on 127.0.0.1, three learners, notebook 02 and task 2's grade.

Each learner logs in through the hub's REST API, gets a server of their own (their workspace is made on first
start, by ``rrbot-workshop singleuser``), runs notebook 02's cells through the kernel protocol and grades task 2;
two of them have solved it. Then the instructor's class report reads the room. Nothing is left running.
"""

from __future__ import annotations

import json
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from rrbot_workshop.classroom.class_report import build_report, write_report
from rrbot_workshop.classroom.room import LearnerRun, Room
from rrbot_workshop.classroom.task_status import NOT_STARTED, PASSED
from rrbot_workshop.cli import main

ROOT = Path(__file__).resolve().parents[2]
SOLUTION = ROOT / "solutions" / "task02_mock_hardware"

# JupyterHub and its proxy come with the course's dev extras, which the test command installs: no skip without them
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not SOLUTION.is_dir(), reason="this copy of the course has no solutions/")]

LEARNERS = {"ana": True, "ben": False, "cleo": True}  # name -> has solved task 2


def _solve(workspace: Path) -> None:
    target = workspace / "exercises" / "task02_mock_hardware"
    shutil.rmtree(target)
    shutil.copytree(SOLUTION, target, ignore=shutil.ignore_patterns("__pycache__"))


@pytest.fixture(scope="module")
def room(tmp_path_factory: pytest.TempPathFactory) -> tuple[Room, dict[str, LearnerRun], list[str]]:
    room = Room(tmp_path_factory.mktemp("room"), timeout=180.0)
    try:
        room.start()
        with ThreadPoolExecutor(max_workers=len(LEARNERS)) as pool:
            futures = {name: pool.submit(room.learner_session, name, prepare=_solve if solved else None)
                       for name, solved in LEARNERS.items()}
            runs = {name: future.result() for name, future in futures.items()}
        room.login("dan")  # a learner who never started a server: no workspace yet
        # the instructor asks the hub who is in the room
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("JUPYTERHUB_API_TOKEN", room.token)
            code = main(["class-report", "--hub", room.url, "--home-template", f"{room.homes}/{{username}}",
                         "--out", str(room.folder / "hub_report")])
        assert code == 0
    finally:
        left = room.stop()
    return room, runs, left


def test_every_learner_runs_notebook_02_and_gets_the_right_grade(room) -> None:
    _, runs, _ = room
    max_score = None
    for name, solved in LEARNERS.items():
        run = runs[name]
        assert run.errors == [], f"{name}: cells raised {run.errors}"
        assert len(run.cell_s) > 10
        score, maximum = run.score
        max_score = max_score or maximum
        assert maximum > 0 and maximum == max_score
        assert score == (maximum if solved else 0.0), f"{name} (solved: {solved}) got {score}/{maximum}"


def test_each_learner_has_their_own_workspace_from_the_shared_course(room) -> None:
    hub, _, _ = room
    for name in LEARNERS:
        workspace = hub.homes / name / "rrbot_workshop"
        assert (workspace / "my_notebooks" / "02_mock_hardware.ipynb").is_file()
        assert not (workspace / "solutions").exists() and not (workspace / "rrbot_workshop").exists()
        log = json.loads((workspace / "exercises" / ".progress" / "task02.json").read_text())
        assert len(log["attempts"]) == 1


def test_the_class_report_shows_the_room(room, tmp_path: Path) -> None:
    hub, _, _ = room
    report = build_report([str(hub.homes / "*")])
    assert [lr.name for lr in report.learners] == sorted(LEARNERS)
    for learner in report.learners:
        # ben graded task 2 as handed out: a self-check of untouched files is not a start
        expected = PASSED if LEARNERS[learner.name] else NOT_STARTED
        assert learner.state(2).status == expected and learner.state(2).attempts == 1
        assert learner.last_activity is not None and learner.notes == []
    assert report.stuck() == []  # nobody who started task 2 fails a check
    paths = write_report(report, tmp_path / "report")
    assert "ben" in paths[2].read_text()


def test_the_class_report_can_take_the_learners_from_the_hubs_user_list(room) -> None:
    hub, _, _ = room
    data = json.loads((hub.folder / "hub_report" / "report.json").read_text())
    assert [lr["name"] for lr in data["learners"]] == sorted(LEARNERS)
    assert any("dan" in note and "no workspace yet" in note for note in data["notes"])


def test_nothing_of_the_room_is_left_running(room) -> None:
    hub, _, left = room
    assert left == [], f"still running after stop: {left}"
    assert hub.process is not None and hub.process.poll() is not None
