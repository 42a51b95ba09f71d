"""Gradings forked from the clean copy a notebook's kernel makes at ``%load_ext rrbot_workshop`` (Linux only).

Each test talks to a real IPython kernel (jupyter_client, as JupyterLab starts one) over Jupyter's protocol.
"""

from __future__ import annotations

import ast
import json
import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade
from rrbot_workshop.course.grading.pytest_process import FORK_ENV

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the kernel's copy for gradings is Linux only")

_GRADER = '''
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded


@graded(points=2, hint="write 42")
def test_answer():
    assert (tracks.task_dir(5) / "answer.txt").read_text().strip() == "42", "the answer is not 42"


@graded(points=1, hint="loops forever")
def test_endless_loop():
    while True:
        try:
            pass
        except Exception:
            pass
'''


def _hypothesis_ci_variables() -> tuple[str, ...]:
    try:
        from hypothesis._settings import _CI_VARS
    except ImportError:  # a later Hypothesis may keep its list elsewhere; "CI" is the one every service sets
        return ("CI",)
    return tuple(_CI_VARS)


def _course(root: Path) -> Path:
    (root / "tests" / "tasks").mkdir(parents=True)
    (root / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER)
    for track in tracks.TRACKS:
        (root / track / "task05_fake").mkdir(parents=True)
        (root / track / "task05_fake" / "answer.txt").write_text("42\n" if track == "solutions" else "?\n")
    return root


class Kernel:
    """A real IPython kernel and a client to run code in it."""

    def __init__(self, root: Path, first_cell: str) -> None:
        from jupyter_client.manager import start_new_kernel

        # a learner's kernel, not a CI job's: Hypothesis turns its example database off when it sees CI's variables
        env = {k: v for k, v in os.environ.items() if k not in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV,
                                                                FORK_ENV, *_hypothesis_ci_variables())}
        env[tracks.ROOT_ENV] = str(root)
        self.folder = root / "my_notebooks"  # a notebook's kernel runs in the notebook's folder
        self.folder.mkdir(exist_ok=True)
        self.manager, self.client = start_new_kernel(kernel_name="python3", cwd=str(self.folder), env=env)
        self.pid = self.manager.provisioner.process.pid  # type: ignore[union-attr]
        self.run(first_cell)

    def run(self, code: str, timeout: float = 300.0) -> str:
        out: list[str] = []
        errors: list[str] = []

        def hook(message: dict[str, Any]) -> None:
            if message["msg_type"] == "stream":
                out.append(message["content"]["text"])
            elif message["msg_type"] == "error":
                errors.append(f"{message['content']['ename']}: {message['content']['evalue']}")

        self.client.execute_interactive(code, timeout=timeout, output_hook=hook)
        if errors:
            raise AssertionError(f"the cell raised {errors}; printed {''.join(out)}")
        return "".join(out)

    def value(self, expression: str, timeout: float = 300.0) -> Any:
        """``expression`` evaluated in the kernel, read from the execute reply (its ``user_expressions``), not from
        printed output: after an interrupt, a print's stream message may reach the client after the reply."""
        for _ in range(50):  # bounded: ipykernel aborts requests that reach it just after an error (an interrupt)
            reply = self.client.execute_interactive("", timeout=timeout, user_expressions={
                "value": f"__import__('json').dumps({expression})"})
            if reply["content"]["status"] != "aborted":
                break
            time.sleep(0.1)
        if "user_expressions" not in reply["content"]:
            raise AssertionError(f"{expression} was not evaluated: {reply['content']}")
        found = reply["content"]["user_expressions"]["value"]
        if found["status"] != "ok":
            raise AssertionError(f"{expression} raised {found.get('ename')}: {found.get('evalue')}")
        return json.loads(ast.literal_eval(found["data"]["text/plain"]))

    def stop(self) -> None:
        self.client.stop_channels()
        self.manager.shutdown_kernel(now=True)


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _course(tmp_path_factory.mktemp("kernel_fork") / "course")


@pytest.fixture(scope="module")
def kernel(root: Path) -> Iterator[Kernel]:
    """A kernel whose first cell loaded the extension, as every notebook's does."""
    k = Kernel(root, "%load_ext rrbot_workshop")
    k.run("from rrbot_workshop.course.grading import grade, kernel_fork")
    try:
        yield k
    finally:
        k.stop()


def _details_with_grader(kernel: Kernel, root: Path, name: str, source: str, call: str) -> list[str]:
    """The checks' details of ``call`` (a grading in the kernel) with the grader ``name`` written for it, then removed."""
    grader = root / "tests" / "tasks" / name
    grader.write_text(source)
    try:
        return list(kernel.value(f"[c.detail for c in {call}.checks]"))
    finally:
        grader.unlink()


def _rubric(kernel: Kernel, call: str) -> dict[str, list[Any]]:
    return dict(kernel.value(
        f"{{c.name: [c.passed, c.points, c.detail] for c in {call}.checks}}"))


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def test_the_first_cells_load_ext_forks_a_copy_and_gradings_fork_from_it(kernel: Kernel) -> None:
    """The grading's process is the copy's child, not the kernel's, and the copy is not the kernel."""
    copy = kernel.value("kernel_fork._COPY[0].pid if kernel_fork.running() else None")
    assert copy is not None and copy != kernel.pid
    assert int(Path(f"/proc/{copy}/stat").read_text().rsplit(")", 1)[1].split()[1]) == kernel.pid
    out = kernel.run("r = grade(5, track='solutions', check_timeout=1.0, record=False)\n"
                     "print([c.detail for c in r.checks])")
    assert "CheckTimeout" in out  # the endless loop was stopped by the per-check limit
    assert kernel.value("kernel_fork.running()") is True


def test_a_grading_in_the_kernel_gives_the_rubric_a_grading_outside_gives(kernel: Kernel, root: Path,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    monkeypatch.delenv(tracks.TASK_ROOT_ENV, raising=False)
    monkeypatch.delenv(tracks.TRACK_ENV, raising=False)
    monkeypatch.delenv(tracks.EXERCISES_ENV, raising=False)
    tracks.set_track(None)
    for track in tracks.TRACKS:
        inside = _rubric(kernel, f"grade(5, track={track!r}, check_timeout=1.0, record=False)")
        outside = {c.name: [c.passed, c.points, c.detail] for c in grade(5, track=track, check_timeout=1.0,
                                                                          record=False).checks}
        assert inside == outside


def test_the_learners_changes_in_the_kernel_do_not_reach_the_grading_but_their_files_do(kernel: Kernel,
                                                                                       root: Path) -> None:
    """A library function the learner replaced in the kernel stays replaced there only; the file as saved now is what
    is graded."""
    kernel.run("import pathlib\nfrom rrbot_workshop.course import tracks\n"
               f"tracks.task_dir = lambda task, track=None: pathlib.Path({str(root / 'solutions' / 'task05_fake')!r})")
    before = _rubric(kernel, "grade(5, track='exercises', check_timeout=1.0, record=False)")
    assert before["answer"][0] is False
    answer = root / "exercises" / "task05_fake" / "answer.txt"
    try:
        answer.write_text("42\n")
        after = _rubric(kernel, "grade(5, track='exercises', check_timeout=1.0, record=False)")
    finally:
        answer.write_text("?\n")
    assert after["answer"][0] is True, after


def test_a_grading_that_hangs_is_stopped_at_the_whole_graders_limit_and_the_copy_grades_on(kernel: Kernel,
                                                                                          root: Path) -> None:
    detail = _details_with_grader(kernel, root, "test_task06_hang.py",
                                  "import time\n\ndef test_first():\n    pass\n\ndef test_hangs():\n    while True:\n"
                                  "        time.sleep(0.05)\n",
                                  "grade(6, check_timeout=0, total_timeout=15.0, record=False)")
    assert "stopped after 15 s" in detail[1]
    assert kernel.value("kernel_fork.running()") is True
    assert _rubric(kernel, "grade(5, track='solutions', check_timeout=1.0, record=False)")["answer"][0] is True


def test_an_interrupted_self_check_stops_its_grading_and_the_copy_grades_on(kernel: Kernel, root: Path) -> None:
    """Interrupting the kernel (JupyterLab's stop button) during a self-check ends that check; the next one is forked
    from the copy as before."""
    grader = root / "tests" / "tasks" / "test_task06_hang.py"
    grader.write_text("import time\n\ndef test_hangs():\n    while True:\n        time.sleep(0.05)\n")
    copy = kernel.value("kernel_fork._COPY[0].pid")
    children = Path(f"/proc/{copy}/task/{copy}/children")
    errors: list[str] = []
    try:
        msg_id = kernel.client.execute("grade(6, check_timeout=0, total_timeout=600.0, record=False)")
        for _ in range(1200):  # bounded: until the copy has forked the grading's process
            if children.read_text().split():
                break
            time.sleep(0.05)
        kernel.manager.interrupt_kernel()
        while True:
            reply = kernel.client.get_shell_msg(timeout=120)
            if reply["parent_header"].get("msg_id") == msg_id:
                errors.append(reply["content"].get("ename", ""))
                break
    finally:
        grader.unlink()
    assert errors == ["KeyboardInterrupt"]
    assert kernel.value("kernel_fork.running()") is True
    for _ in range(200):  # bounded: the interrupted grading's process is gone
        if not children.read_text().split():
            break
        time.sleep(0.05)
    assert not children.read_text().split()
    assert _rubric(kernel, "grade(5, track='solutions', check_timeout=1.0, record=False)")["answer"][0] is True


def test_hypothesis_keeps_its_examples_in_the_course_folder_as_in_a_new_process_not_the_notebooks(
        kernel: Kernel, root: Path) -> None:
    detail = _details_with_grader(kernel, root, "test_task07_examples.py",
                                  "from hypothesis import given, strategies as st\n\n\n@given(st.integers())\n"
                                  "def test_negative(n):\n    assert n < 0\n",
                                  "grade(7, check_timeout=30, record=False)")
    assert "Falsifying example" in detail[0] or "assert" in detail[0]
    assert (root / ".hypothesis").is_dir() and not (kernel.folder / ".hypothesis").exists()


def test_no_copy_when_the_learners_code_ran_before_the_extension_was_loaded(root: Path) -> None:
    late = Kernel(root, "x = 1\n%load_ext rrbot_workshop")
    try:
        assert late.value("__import__('rrbot_workshop.course.grading.kernel_fork').course.grading.kernel_fork"
                          ".running()") is False
        rubric = _rubric(late, "__import__('rrbot_workshop.course.grading').course.grading.grade(5, "
                               "track='solutions', check_timeout=1.0, record=False)")
        assert rubric["answer"][0] is True  # graded the usual way
    finally:
        late.stop()


def test_the_copy_ends_with_its_kernel(root: Path) -> None:
    k = Kernel(root, "%load_ext rrbot_workshop")
    try:
        copy = k.value("__import__('rrbot_workshop.course.grading.kernel_fork').course.grading.kernel_fork"
                       "._COPY[0].pid")
        assert _alive(copy)
    finally:
        k.stop()
    for _ in range(200):  # bounded: the copy sees its socket close, or is killed with its parent
        if not _alive(copy):
            break
        time.sleep(0.05)
    assert not _alive(copy)
