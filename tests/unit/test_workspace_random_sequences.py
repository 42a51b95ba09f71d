"""Random sequences of learner edits, course updates, ``init`` runs and kills at a random write (Hypothesis stateful,
derandomized; and real processes killed with SIGKILL at a seeded random write): nothing the learner wrote is lost,
nothing outside the workspace changes, and the next start always succeeds and leaves a complete workspace."""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, rule, run_state_machine_as_test
from workspace_helpers import FaultPlan, Killed, contents, install_faults, make_course, notebook, raise_killed, tree

from rrbot_workshop.classroom.workspace import MARKER, init_workspace
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading.course import read_pristine_archive

ARCHIVE = ".pristine/exercises.tar.gz"
#: Where the learner writes: their exercises and notebooks, and (why not) the course's own copies.
AREAS = ("exercises", "exercises", "my_notebooks", "descriptions", "notebooks", "tests")
HERE = Path(__file__).resolve().parent


def _course_exercises(course: Path) -> dict[str, bytes]:
    root = course / "exercises"
    return {f"exercises/{p.relative_to(root).as_posix()}": p.read_bytes() for p in sorted(root.rglob("*"))
            if p.is_file() and p.name != "README.md"}


def check_complete(ws: Path, course: Path, authored: set[bytes]) -> None:
    """What a finished start leaves: the record equals the course's exercises, each of which is in place, or beside a
    file the learner wrote, or the learner made something else of a path the course did not change; every notebook
    has its copy; the marker names the course."""
    exercises = _course_exercises(course)
    assert read_pristine_archive(ws / ARCHIVE) == exercises
    for rel, data in exercises.items():
        here, beside = ws / rel, ws / f"{rel}.course-update"
        in_place = not any(p.is_symlink() for p in (here, *here.parents)) and here.is_file()
        if in_place and here.read_bytes() != data:  # the learner's, or kept with the course's beside it
            assert here.read_bytes() in authored or (beside.is_file() and beside.read_bytes() == data), rel
    for nb in (course / "notebooks").glob("*.ipynb"):
        assert (ws / "my_notebooks" / nb.name).is_file() and not (ws / "my_notebooks" / nb.name).is_symlink()
    assert json.loads((ws / MARKER).read_text())["source"] == str(course)


def _without_marker(t: dict[str, str]) -> dict[str, str]:
    return {k: v for k, v in t.items() if k != MARKER}


class Room(RuleBasedStateMachine):
    """One learner's workspace, the installed course, and a folder outside both that nobody may change."""

    base: Path
    monkeypatch: pytest.MonkeyPatch
    runs = 0

    def __init__(self) -> None:
        super().__init__()
        Room.runs += 1
        self.root = self.base / f"run{Room.runs}"
        self.course = make_course(self.root / "opt" / "course")
        self.outside = self.root / "outside"
        self.outside.mkdir()
        (self.outside / "theirs.txt").write_text("not the course's, not the learner's\n")
        self.outside_tree = tree(self.outside)
        self.monkeypatch.setenv(tracks.ROOT_ENV, str(self.course))
        self.ws = init_workspace(self.root / "home" / "rrbot_workshop", self.course).workspace
        self.authored: set[bytes] = set()
        self.edits = 0

    # ------------------------------------------------------------------ the learner
    def _unique(self, what: str) -> bytes:
        self.edits += 1
        data = f"{what} by the learner, #{self.edits}\n".encode()
        self.authored.add(data)
        return data

    def _pick(self, folder: Path, pick: int, files: bool = True) -> Path | None:
        """A file (or folder) under ``folder`` that is the learner's to change: not reached through a link, not one of
        the course's notes to the learner (``.course-update``, ``.yours``, ``backups/``) nor a hidden record."""
        if not folder.is_dir():
            return None
        found = sorted(p for p in folder.rglob("*") if not any(q.is_symlink() for q in (p, *p.parents))
                       and (p.is_file() if files else p.is_dir()) and ".progress" not in p.parts
                       and not any(q.startswith(".") or ".yours" in q or q.endswith(".course-update") or q == "backups"
                                   for q in p.relative_to(folder).parts))
        return found[pick % len(found)] if found else None

    @rule(pick=st.integers(0, 99), area=st.sampled_from(AREAS))
    def learner_edits_a_file(self, pick: int, area: str) -> None:
        path = self._pick(self.ws / area, pick)
        if path is not None:
            path.write_bytes(self._unique("an edit"))

    @rule(pick=st.integers(0, 99), area=st.sampled_from(AREAS))
    def learner_adds_a_file(self, pick: int, area: str) -> None:
        folder = self._pick(self.ws / area, pick, files=False) or self.ws / area
        if folder.is_dir() and not any(q.is_symlink() for q in (folder, *folder.parents)):
            (folder / f"new{self.edits}.py").write_bytes(self._unique("a new file"))

    @rule(pick=st.integers(0, 99))
    def learner_deletes_a_file(self, pick: int) -> None:
        path = self._pick(self.ws / "exercises", pick)
        if path is not None:
            path.unlink()

    @rule(pick=st.integers(0, 99), area=st.sampled_from(AREAS))
    def learner_turns_a_file_into_a_folder(self, pick: int, area: str) -> None:
        path = self._pick(self.ws / area, pick)
        if path is not None:
            path.unlink()
            path.mkdir()
            (path / "inside.py").write_bytes(self._unique("a file in a folder"))

    @rule(pick=st.integers(0, 99))
    def learner_turns_a_folder_into_a_file(self, pick: int) -> None:
        folder = self._pick(self.ws / "exercises", pick, files=False)
        if folder is not None and folder != self.ws / "exercises":
            shutil.rmtree(folder)
            folder.write_bytes(self._unique("a file for a folder"))

    @rule(pick=st.integers(0, 99), to_folder=st.booleans())
    def learner_puts_a_link_outside(self, pick: int, to_folder: bool) -> None:
        path = self._pick(self.ws / "exercises", pick, files=not to_folder)
        if path is not None and path != self.ws / "exercises":
            shutil.rmtree(path) if to_folder else path.unlink()
            path.symlink_to(self.outside if to_folder else self.outside / "theirs.txt")

    @rule(which=st.sampled_from([ARCHIVE, MARKER, "my_notebooks/.sources.json"]), keep=st.integers(0, 200))
    def a_record_is_damaged(self, which: str, keep: int) -> None:
        path = self.ws / which
        if path.is_file() and not path.is_symlink():
            path.write_bytes(path.read_bytes()[:keep])

    # ------------------------------------------------------------------ the instructor
    @rule(pick=st.integers(0, 99))
    def course_updates_a_file(self, pick: int) -> None:
        path = self._pick(self.course / "exercises", pick)
        if path is not None:
            self.edits += 1
            path.write_text(f"course version {self.edits}\n")

    @rule(pick=st.integers(0, 99))
    def course_turns_a_file_into_a_folder(self, pick: int) -> None:
        path = self._pick(self.course / "exercises", pick)
        if path is not None and path.name != "README.md":
            path.unlink()
            path.mkdir()
            (path / "part.py").write_text("course part\n")

    @rule(pick=st.integers(0, 99))
    def course_turns_a_folder_into_a_file(self, pick: int) -> None:
        folder = self._pick(self.course / "exercises", pick, files=False)
        if folder is not None and folder.parent != self.course / "exercises" and folder != self.course / "exercises":
            shutil.rmtree(folder)
            folder.write_text("course file for a folder\n")

    @rule(n=st.integers(3, 5))
    def course_adds_a_task(self, n: int) -> None:
        folder = self.course / "exercises" / f"task0{n}_extra"
        if not folder.exists():
            folder.mkdir()
            (folder / "e.py").write_text(f"e = {n}\n")

    @rule(which=st.sampled_from(["01_fake", "02_more"]))
    def course_updates_a_notebook(self, which: str) -> None:
        self.edits += 1
        (self.course / "notebooks" / f"{which}.ipynb").write_text(notebook(f"{which} v{self.edits}"))

    @rule()
    def course_moves(self) -> None:
        moved = self.course.with_name(f"{self.course.name}_moved")
        shutil.move(str(self.course), str(moved))
        self.course = moved
        self.monkeypatch.setenv(tracks.ROOT_ENV, str(moved))

    # ------------------------------------------------------------------ starts
    def _start(self, kill_at: int | None) -> bool:
        """One init, killed before change ``kill_at``; True if it ran to the end. The learner's writing survives it,
        the course and the outside folder are unchanged."""
        mine = contents(self.ws) & self.authored
        course = tree(self.course)
        undo = install_faults(FaultPlan(kill_at, raise_killed))
        try:
            init_workspace(self.ws, now=0)
            finished = True
        except Killed:
            finished = False
        finally:
            undo()
        lost = mine - contents(self.ws)
        assert not lost, f"the learner's writing was lost: {sorted(lost)}"
        assert tree(self.course) == course and tree(self.outside) == self.outside_tree
        return finished

    @rule(kills=st.lists(st.integers(0, 45), min_size=1, max_size=4))
    def starts_killed_then_starts(self, kills: list[int]) -> None:
        for at in kills:
            self._start(at)
        assert self._start(None)
        check_complete(self.ws, self.course, self.authored)

    @rule()
    def starts_twice(self) -> None:
        assert self._start(None)
        check_complete(self.ws, self.course, self.authored)
        before = _without_marker(tree(self.ws))
        again = init_workspace(self.ws, now=0)
        assert (again.added, again.updated, again.kept, again.notebooks, again.notes) == ([], [], [], [], [])
        assert _without_marker(tree(self.ws)) == before, "a start with nothing new changed the workspace"

    @invariant()
    def outside_is_untouched(self) -> None:
        assert tree(self.outside) == self.outside_tree


def test_random_sequences_of_edits_updates_starts_and_kills_lose_nothing(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    for name in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(name, raising=False)
    Room.base, Room.monkeypatch = tmp_path, monkeypatch
    run_state_machine_as_test(Room, settings=settings(
        max_examples=30, stateful_step_count=20, derandomize=True, database=None, deadline=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture]))


# ------------------------------------------------------------------------------------------ real kills
_KILLED_INIT = """
import os, signal, sys
sys.path.insert(0, {here!r})
from workspace_helpers import FaultPlan, install_faults
from rrbot_workshop.classroom.workspace import init_workspace
install_faults(FaultPlan({at}, lambda: os.kill(os.getpid(), signal.SIGKILL)))
init_workspace({ws!r}, now=0)
"""


def test_a_start_killed_with_sigkill_at_a_random_write_is_finished_by_the_next(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Real kills (no cleanup code runs) at seeded random writes of an update that changes every kind of file."""
    course = make_course(tmp_path / "course")
    monkeypatch.setenv(tracks.ROOT_ENV, str(course))
    ws = init_workspace(tmp_path / "home" / "rrbot_workshop", course).workspace
    (ws / "exercises/task01_fake/a.py").write_text("x = 41  # mine\n")
    (ws / "my_notebooks/01_fake.ipynb").write_text(notebook("my notes"))
    (course / "exercises/task01_fake/a.py").write_text("x = None  # TODO, reworded\n")
    (course / "exercises/task01_fake/b.py").write_text("y = 2\n")
    (course / "notebooks/01_fake.ipynb").write_text(notebook("one, updated"))
    plan = FaultPlan(None, raise_killed)
    undo = install_faults(plan)
    try:
        shutil.copytree(ws, tmp_path / "dry")
        init_workspace(tmp_path / "dry", now=0)
    finally:
        undo()
    assert plan.count > 20
    for at in sorted(random.Random(28).sample(range(plan.count), 8)):
        trial = shutil.copytree(ws, tmp_path / f"kill{at}", symlinks=True)
        proc = subprocess.run([sys.executable, "-c", _KILLED_INIT.format(here=str(HERE), at=at, ws=str(trial))],
                              capture_output=True, text=True, timeout=300)
        assert proc.returncode == -signal.SIGKILL, (at, proc.stderr[-2000:])
        result = init_workspace(trial, now=0)
        check_complete(trial, course, {b"x = 41  # mine\n"})
        assert (trial / "exercises/task01_fake/a.py").read_text() == "x = 41  # mine\n"
        assert notebook("my notes").encode() in contents(trial), at
        assert not result.notes or all("rrbot-partial" not in n for n in result.notes)
    assert os.listdir(tmp_path / "course") == os.listdir(course)
