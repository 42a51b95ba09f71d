"""Fixtures of the library's tests that read real upstream files (see ``upstream.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest
from upstream import DEMOS, extract


@pytest.fixture(scope="session")
def ros2_control_demos(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """ros2_control_demos (jazzy) as a source tree, extracted from ``shared/upstream`` once per test session.

    Tests that change nothing in it may share it; a test that must prove a tool leaves a package untouched hashes it
    before and after.
    """
    return extract(DEMOS, tmp_path_factory.mktemp("upstream"))
