"""Fixtures of the tests that read real upstream files (see ``upstream.py``); the order of a run on many cores."""

from __future__ import annotations

from pathlib import Path

import pytest
from scheduling import load_durations, longest_first
from upstream import DEMOS, extract


@pytest.fixture(scope="session")
def ros2_control_demos(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """ros2_control_demos (jazzy) as a source tree, extracted from ``shared/upstream`` once per test session.

    Tests that change nothing in it may share it; a test that must prove a tool leaves a package untouched hashes it
    before and after.
    """
    return extract(DEMOS, tmp_path_factory.mktemp("upstream"))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Under pytest-xdist, the files hand out longest first (``scheduling.py``): this hook sees the whole session's
    items, notebooks included, wherever they were collected from."""
    if hasattr(config, "workerinput"):
        items[:] = longest_first(items, load_durations())


# ------------------------------------------------------------------ work shared by the session's processes
_SHARED: list[str] = []  # the folder this process made (the controller's, under pytest-xdist)


def pytest_configure(config: pytest.Config) -> None:
    """Every process of the run (xdist workers, the gradings they fork, notebook kernels) shares its xacro expansions
    through one folder (:mod:`rrbot_workshop.description.xacro_cache`; each entry is checked against the files before
    it is used), and the gradings the grader files rewritten by pytest (:mod:`rrbot_workshop.course.grading.plugin`).
    Set before the workers start, so they inherit them; a folder the caller already named is kept."""
    import os
    import tempfile

    from rrbot_workshop.course.grading.plugin import PYCACHE_ENV
    from rrbot_workshop.description.xacro_cache import SHARED_ENV

    missing = [name for name in (SHARED_ENV, PYCACHE_ENV) if not os.environ.get(name)]
    if missing:
        _SHARED.append(tempfile.mkdtemp(prefix="rrbot_workshop_run_"))
        for name in missing:
            os.environ[name] = os.path.join(_SHARED[0], name.lower())


def pytest_unconfigure(config: pytest.Config) -> None:
    import os
    import shutil

    for folder in _SHARED:
        shutil.rmtree(folder, ignore_errors=True)
        for name, value in list(os.environ.items()):
            if value.startswith(folder + os.sep):
                del os.environ[name]
    _SHARED.clear()
