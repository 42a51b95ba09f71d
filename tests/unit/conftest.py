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
