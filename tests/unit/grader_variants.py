"""Wrong and alternative solutions of a task, written as learners would, graded as a learner's work is graded.

A :class:`Variant` is a copy of ``solutions/taskNN_<name>/`` with changes: exact replacements (each must apply once,
so a variant never silently stops testing anything when the solution changes) or whole new files. A grader test
module lists its variants and grades them all at once, two at a time (each grading is a subprocess, as
``rrbot-workshop grade`` runs it):

    WRONG = [Variant("goal_below_lower_limit_accepted", {"jerk_limited.py": [("if a < lo", "if False")]},
                     fails={"limits_refused"}), ...]
    RIGHT = [Variant("loop_instead_of_comprehension", {"jerk_limited.py": NEW_TEXT}), ...]

    @pytest.fixture(scope="module")
    def rubrics(tmp_path_factory):
        return grade_variants(13, WRONG + RIGHT, tmp_path_factory.mktemp("task13"))

    @pytest.mark.parametrize("variant", WRONG, ids=str)
    def test_wrong_solution_loses_points(rubrics, variant):
        assert_loses_points(rubrics[variant.name], variant)

    @pytest.mark.parametrize("variant", RIGHT, ids=str)
    def test_alternative_solution_gets_full_marks(rubrics, variant):
        assert_full_marks(rubrics[variant.name])
"""

from __future__ import annotations

import os
import re
import shutil
from collections.abc import Iterable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade
from rrbot_workshop.course.grading.pytest_process import warm_up

__all__ = ["Variant", "build_variant", "grade_variants", "assert_loses_points", "assert_full_marks",
           "reason_problems"]

#: A file's changes: exact ``(old, new)`` replacements, each applied exactly once, or the file's whole new text
#: (``None`` deletes the file).
Changes = Sequence[tuple[str, str]] | str | None


@dataclass(frozen=True)
class Variant:
    """One solution of a task, written differently from ``solutions/``.

    Attributes:
        name: What the learner did, as a test id (``"goal_below_lower_limit_accepted"``).
        changes: Relative path in the task folder -> its changes (see :data:`Changes`).
        fails: Checks that must fail (a wrong solution); empty for an alternative correct solution. A wrong
            solution must also lose points overall.
        names_file: A failing check's reason must name this file of the learner's (``"jerk_limited.py"``): the cause
            is in the learner's code and the reason says where.
        says: Check name -> a phrase its reason must contain: the reason names what is wrong, not a symptom (for a
            check that waits for another, "fails because <that check> fails" or its own detail).
        only: A slip of one rule: no check outside ``fails`` may lose points (the others are judged on their own,
            with the reference standing in for the broken part or the value taken as given).
    """

    name: str
    changes: Mapping[str, Changes] = field(default_factory=dict)
    fails: frozenset[str] | set[str] = frozenset()
    names_file: str = ""
    says: Mapping[str, str] = field(default_factory=dict)
    only: bool = False

    def __str__(self) -> str:
        return self.name


def build_variant(task: int, variant: Variant, dest: Path) -> Path:
    """Copy the task's solution into ``dest/<task folder>/``, apply the variant's changes; return ``dest``."""
    source = tracks.task_dir(task, "solutions")
    copy = dest / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__", ".progress"))
    for rel, changes in variant.changes.items():
        path = copy / rel
        if changes is None:
            path.unlink()
            continue
        if isinstance(changes, str):
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(changes)
            continue
        text = path.read_text()
        for old, new in changes:
            count = text.count(old)
            if count != 1:
                raise AssertionError(f"variant {variant.name}: {old!r} occurs {count} times in {rel}, not once")
            text = text.replace(old, new)
        path.write_text(text)
    return dest


def grade_variants(task: int, variants: Iterable[Variant], tmp: Path, workers: int | None = None) -> dict[str, Rubric]:
    """Grade every variant (``workers`` subprocesses at a time); name -> rubric.

    ``workers`` defaults to this process's share of the cores: all of them, or one per pytest-xdist worker's share.
    """
    listed = list(variants)
    names = [v.name for v in listed]
    duplicates = {n for n in names if names.count(n) > 1}
    if duplicates:
        raise AssertionError(f"variant names must be unique: {sorted(duplicates)}")
    roots = {v.name: build_variant(task, v, tmp / v.name) for v in listed}
    # many gradings follow: fork them from one process that has imported what graders use, and wait for it (a grading
    # started before it answers is a new Python process that imports all of it again, 1.5-2 s of CPU each)
    warm_up(wait=True)
    share = (os.cpu_count() or 2) // int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1") or 1)
    with ThreadPoolExecutor(max_workers=workers or max(1, share)) as pool:
        futures = {name: pool.submit(grade, task, task_root=root, record=False) for name, root in roots.items()}
        return {name: future.result() for name, future in futures.items()}


#: Text of pytest's own assertion rewriting or of ``approx``, which a learner should never be handed as a reason.
_RAW_PYTEST = re.compile(r"(^assert |\bassert .* == |\+  where |approx\(|± |Obtained: |Expected: |Regex pattern did "
                         r"not match|DID NOT RAISE)")


def reason_problems(rubric: Rubric) -> list[str]:
    """What is wrong with the reasons of the failed checks: cut short, raw pytest text, or empty."""
    problems = []
    for check in rubric.failed():
        if check.same_as:
            continue
        reason = check.detail
        if not reason.strip():
            problems.append(f"{check.name}: no reason given")
        elif reason.rstrip().endswith(("...", ":")):
            problems.append(f"{check.name}: the reason is cut short: {reason!r}")
        elif _RAW_PYTEST.search(reason):
            problems.append(f"{check.name}: the reason is pytest's text, not the grader's: {reason!r}")
    return problems


def assert_loses_points(rubric: Rubric, variant: Variant) -> None:
    """The wrong variant loses points, fails the checks it names, and every reason is whole and readable."""
    report = rubric.format()
    failed = {c.name for c in rubric.failed()}
    assert rubric.score < rubric.max_score, f"{variant.name} got full marks:\n{report}"
    missing = set(variant.fails) - failed
    assert not missing, f"{variant.name} passed {sorted(missing)}:\n{report}"
    problems = reason_problems(rubric)
    assert not problems, "\n".join(problems) + "\n" + report
    if variant.names_file:
        reasons = [c.detail for c in rubric.failed() if c.name in variant.fails]
        assert any(variant.names_file in r for r in reasons), (
            f"{variant.name}: no reason names the learner's {variant.names_file}:\n{report}")
    details = {c.name: f"{c.reason} | {c.detail}" for c in rubric.failed()}  # what the learner reads, and the cause
    for name, phrase in variant.says.items():
        assert phrase.lower() in details.get(name, "").lower(), (
            f"{variant.name}: the reason of {name} does not say {phrase!r}:\n{report}")
    if variant.only:
        beyond = sorted(failed - set(variant.fails))
        assert not beyond, f"{variant.name} is one slip, yet {beyond} lose points too:\n{report}"


def assert_full_marks(rubric: Rubric) -> None:
    """The alternative correct solution gets every point."""
    assert rubric.score == rubric.max_score, rubric.format()
