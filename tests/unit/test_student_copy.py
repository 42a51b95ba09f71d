"""A student copy holds no answers beyond what the course teaches on purpose: none of the graders' own wrong and right
solutions, no file outside the library that defines what an exercise asks for, and no file that holds most of a
solution file (the library's documented references and the descriptions the notebooks run on excepted).

The copy is exported from git ``HEAD`` as ``rrbot-workshop export --student --withhold-references`` makes it.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import export_student_copy
from rrbot_workshop.course.grading.references import INSTRUCTOR_ONLY, REFERENCES, instructor_only

ROOT = tracks.course_root()
pytestmark = pytest.mark.skipif(not (ROOT / ".git").exists(), reason="a student copy is exported from git HEAD")

#: A solution file is fingerprinted by its lines that the exercise does not have; one with fewer is too small to say.
MIN_LINES = 8
#: A kept file holding this share of a solution file's fingerprint holds the answer.
MOST = 0.6


@pytest.fixture(scope="module")
def copy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return export_student_copy(tmp_path_factory.mktemp("student") / "copy", withhold_references=True)


def _kept(copy: Path) -> list[tuple[str, Path]]:
    return sorted((p.relative_to(copy).as_posix(), p) for p in copy.rglob("*")
                  if p.is_file() and ".git" not in p.relative_to(copy).parts)


def test_instructor_only_names_what_it_should() -> None:
    assert instructor_only("tests/unit/test_grader_task07.py") and instructor_only("tests/unit/grader_variants.py")
    assert instructor_only("tests/unit/task08_alternatives/counter_checks.py")
    assert not instructor_only("tests/unit/test_grader_hints.py") and not instructor_only("tests/unit/test_graders.py")
    assert not instructor_only("tests/tasks/test_task07_hardware_interface.py")


def test_the_copy_holds_none_of_the_graders_own_solutions(copy: Path) -> None:
    kept = [rel for rel, _ in _kept(copy)]
    assert not [rel for rel in kept if instructor_only(rel)], INSTRUCTOR_ONLY
    assert not [rel for rel in kept if rel.startswith("solutions/")]
    importers = [rel for rel, path in _kept(copy) if path.suffix == ".py"
                 and re.search(r"^\s*(from|import) grader_variants\b", path.read_text(), re.MULTILINE)]
    assert not importers, f"{importers} need the graders' variants, which a student copy leaves out"
    readme = (copy / "README.md").read_text()
    assert all(f"`{pattern}`" in readme for pattern in INSTRUCTOR_ONLY), "the README lists what the copy leaves out"
    assert "task 15" in readme and "descriptions/my_robot/" in readme


def _top_level_names(path: Path) -> set[str]:
    try:
        tree = ast.parse(path.read_text())
    except (SyntaxError, UnicodeDecodeError, ValueError):
        return set()
    return {node.name for node in tree.body if isinstance(node, ast.FunctionDef | ast.ClassDef)}


def test_no_file_outside_the_library_defines_what_an_exercise_asks_for(copy: Path) -> None:
    """Pasted into its exercise, such a file would stand in for the learner's work: none is kept (the library's own
    references are listed in the README, and withheld here)."""
    asked = {name: rel for rel, path in _kept(copy) if rel.startswith("exercises/") and path.suffix == ".py"
             for name in _top_level_names(path)}
    found = [(rel, sorted(_top_level_names(path) & set(asked))) for rel, path in _kept(copy)
             if path.suffix == ".py" and not rel.startswith(("exercises/", "rrbot_workshop/"))]
    found = [(rel, names) for rel, names in found if names]
    assert not found, f"files that define what an exercise asks for: {found}"


def _normal(line: str) -> str:
    return re.sub(r"\s+", " ", line.strip())


def _lines(path: Path) -> set[str]:
    try:
        return {_normal(line) for line in path.read_text().splitlines()}
    except (UnicodeDecodeError, OSError):
        return set()


@pytest.mark.skipif(not (ROOT / "solutions").is_dir(), reason="this copy of the course has no solutions/")
def test_no_kept_file_holds_most_of_a_solution_file(copy: Path) -> None:
    library = set().union(*(_lines(p) for p in (copy / "rrbot_workshop").rglob("*.py")))
    fingerprints: dict[str, set[str]] = {}
    for path in sorted((ROOT / "solutions").rglob("*")):
        if not path.is_file() or "__pycache__" in path.parts:
            continue
        rel = path.relative_to(ROOT / "solutions")
        own = {line for line in _lines(path) - _lines(ROOT / "exercises" / rel) - library
               if len(line) >= 20 and not line.startswith("#")}
        if len(own) >= MIN_LINES:
            fingerprints[rel.as_posix()] = own
    assert len(fingerprints) >= 10, "too few solution files to fingerprint"
    references = tuple(ref.path for ref in REFERENCES if not ref.module and ref.path.endswith("/"))
    holding = []
    for rel, path in _kept(copy):
        if rel.startswith(("exercises/", *references)) or path.suffix in (".png", ".gz", ".stl", ".dae", ".obj"):
            continue
        text = "\n".join(sorted(_lines(path)))
        for solution, own in fingerprints.items():
            share = sum(line in text for line in own) / len(own)
            if share >= MOST:
                holding.append(f"{rel} holds {share:.0%} of solutions/{solution}")
    assert not holding, holding
