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


# ------------------------------------------------------------------ xacro expansions shared by the session's processes
_SHARED_XACRO: list[str] = []  # the folder this process made (the controller's, under pytest-xdist)


def pytest_configure(config: pytest.Config) -> None:
    """Every process of the run (xdist workers, the gradings they fork, notebook kernels) shares its xacro expansions
    through one folder (:mod:`rrbot_workshop.description.xacro_cache`; each entry is checked against the files before
    it is used). Set before the workers start, so they inherit it; kept if the caller already named one."""
    import os
    import tempfile

    from rrbot_workshop.description.xacro_cache import SHARED_ENV

    if not os.environ.get(SHARED_ENV):
        _SHARED_XACRO.append(tempfile.mkdtemp(prefix="rrbot_workshop_xacro_"))
        os.environ[SHARED_ENV] = _SHARED_XACRO[0]


def pytest_unconfigure(config: pytest.Config) -> None:
    import os
    import shutil

    from rrbot_workshop.description.xacro_cache import SHARED_ENV

    for folder in _SHARED_XACRO:
        shutil.rmtree(folder, ignore_errors=True)
        if os.environ.get(SHARED_ENV) == folder:
            del os.environ[SHARED_ENV]
    _SHARED_XACRO.clear()
