"""On a learner's machine a browser test without its browser skips; in CI (.ci/run) the same reason fails it."""

from __future__ import annotations

import pytest
from browser_driver import unavailable


def test_without_the_requirement_a_missing_browser_skips(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RRBOT_WORKSHOP_REQUIRE_BROWSER", raising=False)
    with pytest.raises(pytest.skip.Exception, match="no chromium here"):
        unavailable("no chromium here")


def test_in_ci_a_missing_browser_fails_and_says_why(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RRBOT_WORKSHOP_REQUIRE_BROWSER", "1")
    with pytest.raises(pytest.fail.Exception, match=r"no chromium here \(RRBOT_WORKSHOP_REQUIRE_BROWSER=1: the browser tests may not skip\)"):
        unavailable("no chromium here")
