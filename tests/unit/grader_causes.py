"""What a grader's checks build on (``graded(after=...)``), and the causes a graded variant's failures come down to.

A check marked ``after=("test_other",)`` builds on the rule of ``test_other``: when both fail, the learner's cause is in
``other``, and the runner shows hints only there. So a wrong solution with one slip must come down to one cause: of
its failing checks, exactly one builds on no other failing check. A test of each grader asserts it for its wrong
variants (see :func:`assert_one_cause`), and that every ``after`` names a check of the same grader.

The checks' specifications are read from the grader file itself (imported under a name of its own, never run).
"""

from __future__ import annotations

import functools
import importlib.util
import sys
from collections.abc import Iterable, Mapping

from rrbot_workshop.course.grading import Rubric, grader_path
from rrbot_workshop.course.grading.rubric import CheckSpec, check_spec

__all__ = ["check_specs", "causes", "assert_one_cause", "unknown_after"]


@functools.cache
def check_specs(task: int) -> Mapping[str, CheckSpec]:
    """Check name (the test function's name without ``test_``) -> its :class:`CheckSpec`, for task ``task``'s grader."""
    path = grader_path(task)
    name = f"_grader_specs_task{task:02d}"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None, path
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    folder = str(path.parent)  # the grader imports its helpers (description_compare, ...) from its own folder
    added = folder not in sys.path
    if added:
        sys.path.insert(0, folder)
    try:
        spec.loader.exec_module(module)
    finally:
        if added:
            sys.path.remove(folder)
    return {attr.removeprefix("test_"): check_spec(func) for attr, func in vars(module).items()
            if attr.startswith("test_") and callable(func)}


def _after(spec: CheckSpec) -> tuple[str, ...]:
    """The check names ``spec`` builds on, as the rubric names checks (the test function's name without ``test_``)."""
    return tuple(name.removeprefix("test_") for name in spec.after)


def _builds_on(name: str, specs: Mapping[str, CheckSpec]) -> set[str]:
    """Every check ``name`` builds on, directly or through others."""
    seen: set[str] = set()
    todo = list(_after(specs[name])) if name in specs else []
    while todo:
        other = todo.pop()
        if other not in seen:
            seen.add(other)
            todo.extend(_after(specs[other]) if other in specs else ())
    return seen


def causes(failed: Iterable[str], specs: Mapping[str, CheckSpec]) -> list[str]:
    """The failed checks that build on no other failed check: where the learner's causes are."""
    failing = set(failed)
    return sorted(name for name in failing if not (_builds_on(name, specs) & failing))


def assert_one_cause(rubric: Rubric, specs: Mapping[str, CheckSpec], name: str = "") -> None:
    """The rubric's failures come down to one cause: every other failing check builds on it."""
    found = causes((c.name for c in rubric.failed()), specs)
    assert len(found) == 1, (
        f"{name}: one slip, yet {len(found)} checks fail on their own (each would show hints): {found}; a check that "
        f"fails only because another does must name it in graded(after=...)\n{rubric.format()}")


def unknown_after(specs: Mapping[str, CheckSpec]) -> list[str]:
    """``after`` entries that name no check of the grader (a typo would silently show hints again)."""
    return [f"{name} after {other}" for name, spec in specs.items() for other in spec.after
            if not other.startswith("test_") or other.removeprefix("test_") not in specs]
