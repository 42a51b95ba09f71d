"""rw.course helpers: a notebook cell loads the learner's files and calls their functions without plumbing."""

from __future__ import annotations

from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import systems
from rrbot_workshop.course import learner


@pytest.fixture
def task_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "exercises" / "task09_demo"
    folder.mkdir(parents=True)
    monkeypatch.setattr(learner, "task_file", lambda task, relpath, track=None: folder / relpath)
    return folder


def test_load_module_of_a_broken_file_says_where_and_returns_none(task_folder: Path, capsys) -> None:  # noqa: ANN001
    (task_folder / "answers.py").write_text("def f(:\n    pass\n")
    assert learner.load_module(9, "answers.py") is None
    out = capsys.readouterr().out
    assert out.startswith("answers.py cannot be imported yet (SyntaxError: ") and "(answers.py, line 1)" in out


def test_load_module_rereads_the_file_each_time(task_folder: Path) -> None:
    path = task_folder / "answers.py"
    path.write_text("X = 1\n")
    assert learner.load_module(9, "answers.py").X == 1
    path.write_text("X = 2\n")
    assert learner.load_module(9, "answers.py").X == 2


def test_ask_reports_not_written_and_errors_in_one_line(task_folder: Path, capsys) -> None:  # noqa: ANN001
    (task_folder / "answers.py").write_text(
        "def todo():\n    raise NotImplementedError('TODO(task 9.1)')\n\ndef bad():\n    return 1 / 0\n\ndef good(x):\n    return x * 2\n"
    )
    module = learner.load_module(9, "answers.py")
    assert learner.ask(module, "todo") is None
    assert learner.ask(module, "bad") is None
    assert learner.ask(module, "good", 21) == 42
    out = capsys.readouterr().out.splitlines()
    assert out == [
        "todo: not written yet (TODO(task 9.1))",
        "bad: raised ZeroDivisionError: division by zero (in answers.py, line 5: return 1 / 0)",
        "good: 42",
    ]


def test_mine_or_reference_uses_the_learners_file_when_the_check_passes(task_folder: Path, capsys) -> None:  # noqa: ANN001
    mine = task_folder / "robot.urdf.xacro"
    mine.write_text("<robot/>")
    chosen = learner.mine_or_reference(9, "robot.urdf.xacro", "rrbot/urdf/rrbot.urdf.xacro", check=lambda p: "",
                                       what="description")
    assert chosen == mine
    assert capsys.readouterr().out.startswith("Using your description: ")


@pytest.mark.parametrize(
    ("content", "check", "expected"),
    [
        (None, None, "robot.urdf.xacro is not in the task folder"),
        ("<robot/>", lambda p: "it has no link 'tool0'", "it has no link 'tool0'"),
        ("<robot", lambda p: rw.description.process_xacro(p) and "", "DescriptionError"),
    ],
)
def test_mine_or_reference_falls_back_and_says_why(task_folder: Path, capsys, content, check, expected) -> None:  # noqa: ANN001
    if content is not None:
        (task_folder / "robot.urdf.xacro").write_text(content)
    chosen = learner.mine_or_reference(9, "robot.urdf.xacro", "rrbot/urdf/rrbot.urdf.xacro", check=check,
                                       what="description")
    assert chosen == rw.description.descriptions_root() / "rrbot/urdf/rrbot.urdf.xacro"
    out = capsys.readouterr().out
    assert out.startswith("Your description is not finished yet (") and expected in out
    assert out.rstrip().endswith("this notebook uses descriptions/rrbot/urdf/rrbot.urdf.xacro instead.")


def _start_then_fail() -> None:
    rw.bringup("rrbot", "rrbot_controllers.yaml", name="half_started")
    raise KeyError("joint_trajectory_controler")


def test_run_shuts_down_what_a_failing_function_started(capsys) -> None:  # noqa: ANN001
    assert learner.run(_start_then_fail, instead="rw.bringup") is None
    assert "half_started" not in systems()
    assert capsys.readouterr().out.startswith("Your _start_then_fail() does not run yet (KeyError: ")


def test_run_checks_the_result_and_returns_it_when_right(capsys) -> None:  # noqa: ANN001
    assert learner.run(lambda: 3, check=lambda r: "" if r == 3 else "wrong", what="three()") == 3
    assert learner.run(lambda: 4, check=lambda r: "" if r == 3 else f"it returned {r}", what="three()") is None
    assert capsys.readouterr().out == "Your three() does not run yet (it returned 4).\n"
    assert learner.run(None) is None
