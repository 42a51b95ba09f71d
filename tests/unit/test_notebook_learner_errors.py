"""A notebook cell that runs the learner's code names the learner's file, line, function and exception when that code
raises, whether the library caught the exception (an ``on_configure``, a ``write``) or it came through.

The learner's files are a copy of the exercises with one method made to raise; the notebooks' own cells run in a
kernel, as a learner runs them (only the cells the checked one needs).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

from rrbot_workshop.course import learner, tracks
from rrbot_workshop.course.tracebacks import LearnerErrors

REPO = Path(__file__).resolve().parents[2]


def _line_of(path: Path, text: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), start=1) if text in line)


def _exercises(tmp_path: Path, task: str) -> Path:
    folder = tmp_path / "exercises"
    shutil.copytree(REPO / "exercises" / task, folder / task)
    return folder


def _run_cells(notebook: str, wanted: list[str], exercises: Path, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Run the cells of ``notebook`` whose source holds each of ``wanted`` (in the notebook's order), in a kernel of this
    environment, on ``exercises``; the text output of each."""
    nb = nbformat.read(REPO / "notebooks" / notebook, as_version=4)
    cells = [c for c in nb.cells if c.cell_type == "code" and any(w in c.source for w in wanted)]
    assert len(cells) == len(wanted), f"{notebook}: {len(cells)} cells for {wanted}"
    nb.cells = cells
    monkeypatch.setenv(tracks.EXERCISES_ENV, str(exercises))
    monkeypatch.setenv(tracks.TRACK_ENV, "exercises")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(REPO / "notebooks")}},
                   allow_errors=False).execute(env=dict(os.environ))
    return ["".join(o.get("text", "") for o in c.outputs if o.get("output_type") == "stream") for c in cells]


def test_notebook_08_names_the_line_of_an_on_configure_that_raises(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    exercises = _exercises(tmp_path, "task08_write_a_controller")
    path = exercises / "task08_write_a_controller" / "displacement_controller.py"
    path.write_text(path.read_text().replace('raise NotImplementedError("TODO(task 8.2): on_configure")',
                                             'raise KeyError("interface_name")'))
    line = _line_of(path, 'raise KeyError("interface_name")')
    outputs = _run_cells("08_write_a_controller.ipynb", ['mine = rw.course.load_module(8', "step = rw.course.step",
                                                          'step("configure", h.configure)'], exercises, monkeypatch)
    assert (f"Your code raised: your displacement_controller.py, line {line}, in on_configure: KeyError: "
            "'interface_name'") in outputs[-1], outputs[-1]


def test_notebook_15_names_the_line_of_a_write_that_raises(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    exercises = _exercises(tmp_path, "task15_your_own_robot")
    path = exercises / "task15_your_own_robot" / "my_robot_hardware.py"
    text = path.read_text()
    text = text.replace('raise NotImplementedError("TODO(task 15.1): check the joints\' interfaces in on_init")',
                        'self.joints, self.modes = ["joint1", "joint2", "joint3"], ["effort", "effort", "position"]')
    text = text.replace('raise NotImplementedError("TODO(task 15.3): enforce the limits and write to the device")',
                        'raise ValueError("no limiter for joint3")')
    path.write_text(text)
    line = _line_of(path, 'raise ValueError("no limiter for joint3")')
    outputs = _run_cells("15_your_own_robot.ipynb", [
        "PACKAGE = rw.description.descriptions_root()", "params = jl.load_joint_limits_yaml(LIMITS)", "SPAWN = [",
        "JOINTS = {", "def plot_limits(", 'name="yours"'], exercises, monkeypatch)
    assert (f"Your code raised: your my_robot_hardware.py, line {line}, in write: ValueError: no limiter for joint3"
            in outputs[-1]), outputs[-1]
    assert "after 5 s" not in outputs[-1], "no plot of a component that stopped at its error"


# ------------------------------------------------------------------------------------------- the helpers alone


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """exercises/task09_demo of a course in tmp_path, the learner's files' folder."""
    (tmp_path / "tests" / "tasks").mkdir(parents=True)
    task = tmp_path / "exercises" / "task09_demo"
    task.mkdir(parents=True)
    monkeypatch.setenv(tracks.ROOT_ENV, str(tmp_path))
    for env in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(env, raising=False)
    return task


_CODE = '''import logging


def fine():
    return [1, 2]


def todo():
    raise NotImplementedError("TODO(task 9.1): todo")


def broken():
    return {}["joint3"]


def caught():
    try:
        broken()
    except KeyError:
        logging.getLogger("rrbot_workshop.demo").error("the library caught it", exc_info=True)
    return "went on"
'''


def test_step_says_the_result_or_where_the_learners_code_raised(folder: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    (folder / "code.py").write_text(_CODE)
    module = learner.load_module(9, "code.py")
    assert learner.step("fine", module.fine) == [1, 2]
    assert learner.step("todo", module.todo) is None
    assert learner.step("broken", module.broken) is None
    assert learner.step("caught", module.caught) == "went on"
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "fine: [1, 2]"
    assert out[1] == "todo: not written yet (TODO(task 9.1)): your code.py, line 9, in todo"
    assert out[2] == "broken: raised KeyError"
    assert out[3] == "Your code raised: your code.py, line 13, in broken: KeyError: 'joint3'"
    assert out[4] == "caught: went on (the library caught it)"
    assert out[5] == "Your code raised: your code.py, line 13, in broken: KeyError: 'joint3'"


def test_learner_errors_keeps_the_librarys_log_out_of_the_cell_and_restores_it(
        folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import logging

    (folder / "code.py").write_text(_CODE)
    module = learner.load_module(9, "code.py")
    logger = logging.getLogger("rrbot_workshop")
    before = (logger.level, logger.propagate)
    with LearnerErrors() as errors:
        module.caught()
    assert (logger.level, logger.propagate) == before
    assert errors.found == ["your code.py, line 13, in broken: KeyError: 'joint3'"]
    assert "the library caught it" not in capsys.readouterr().err
    assert errors.report() is True


def test_ask_names_the_learners_function_when_it_raises(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (folder / "code.py").write_text(_CODE)
    module = learner.load_module(9, "code.py")
    assert learner.ask(module, "broken") is None
    assert capsys.readouterr().out == "broken: your code.py, line 13, in broken: KeyError: 'joint3'\n"
