"""Every check of every grader has three hints, the idea, then the API to use, then the code (the README's promise),
and each level says something the one before did not."""

from __future__ import annotations

import importlib.util
import sys
from types import ModuleType

import pytest

from rrbot_workshop.course.grading import graded_tasks, grader_path
from rrbot_workshop.course.grading.rubric import check_spec


def _grader(task: int) -> ModuleType:
    path = grader_path(task)
    spec = importlib.util.spec_from_file_location(f"grader_hints_{path.stem}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # a grader's dataclasses look their module up while they are made
    sys.path.insert(0, str(path.parent))  # as pytest runs a grader: its helper modules beside it
    try:
        spec.loader.exec_module(module)
    finally:
        sys.modules.pop(spec.name, None)
        sys.path.remove(str(path.parent))
    return module


@pytest.mark.parametrize("task", graded_tasks())
def test_every_check_has_three_distinct_hint_levels(task: int) -> None:
    module = _grader(task)
    checks = {name: getattr(module, name) for name in dir(module) if name.startswith("test_")}
    assert checks, f"task {task}'s grader has no checks"
    for name, func in checks.items():
        hints = check_spec(func).hints
        assert len(hints) == 3, f"task {task}, {name}: {len(hints)} hint level(s), not 3 (idea, API, code)"
        assert all(h.strip() for h in hints), f"task {task}, {name}: an empty hint level"
        assert len(set(hints)) == 3, f"task {task}, {name}: two hint levels say the same"
