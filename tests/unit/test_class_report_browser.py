"""report.html in headless Chromium: a room of several learners is drawn with its statuses and plot, and the texts a
learner planted (a script, an image with ``onerror``) are shown as text, never run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from browser_driver import CHROMIUM, Browser, unavailable

from rrbot_workshop.classroom.class_report import WORKSPACE_NAME, build_report
from rrbot_workshop.classroom.class_report_page import write_report
from rrbot_workshop.classroom.task_status import STATUSES

pytestmark = [pytest.mark.browser]

T0 = 1_800_000_000.0
NOW = T0 + 75 * 60
PLANTED = '<img src=x onerror="window.pwned=1"><script>window.pwned=2</script>'


def _attempt(minute: float, score: float, failed: dict[str, str], version: str = "") -> dict:
    return {"time": T0 + 60 * minute, "score": score, "max_score": 10, "failed": sorted(failed), "reasons": failed,
            "version": version or f"v{minute}"}


def make_room(homes: Path) -> None:
    """Eight learners on tasks 1-4: passed at the first try or after a while, stuck, working, untouched, and one
    whose folder, check names and reasons carry HTML."""
    limits = {"joint_limits": "joint1 upper limit is 3.14 rad; the task states 1.57 rad"}
    goal = {"forward_reaches_goal": "joint2 at 0.0 rad after 2 s; expected 0.7 rad"}
    logs = {
        "ana": {1: [_attempt(2, 6, limits), _attempt(11, 10, {})], 2: [_attempt(20, 10, {})],
                3: [_attempt(40, 4, goal), _attempt(70, 6, goal)]},
        "ben": {1: [_attempt(3, 6, limits), _attempt(30, 6, limits), _attempt(58, 6, limits)]},
        "cleo": {1: [_attempt(5, 10, {})], 2: [_attempt(25, 3, goal), _attempt(31, 10, {})],
                 3: [_attempt(50, 10, {})], 4: [_attempt(72, 2, {"a": "x", "b": "y"})]},
        "dan": {},
        "eve": {1: [_attempt(6, 10, {})], 2: [_attempt(44, 0, goal), _attempt(69, 5, goal)]},
        "fay": {1: [_attempt(1, 0, limits), _attempt(64, 10, {})]},
        "gus": {1: [_attempt(12, 0, {**limits, **goal})], 2: [_attempt(60, 0, goal)]},
        PLANTED.replace("/", "|"): {1: [_attempt(9, 0, {PLANTED: PLANTED})]},
    }
    for name, tasks in logs.items():
        progress = homes / name / WORKSPACE_NAME / "exercises" / ".progress"
        progress.mkdir(parents=True)
        for task, attempts in tasks.items():
            (progress / f"task{task:02d}.json").write_text(json.dumps({"attempts": attempts}))


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory):
    if CHROMIUM is None:
        unavailable("headless Chromium not installed (apt-get install -y chromium)")
    b = Browser(CHROMIUM, tmp_path_factory.mktemp("profile"), size=(1400, 1000))
    try:
        yield b
    finally:
        b.close()


def test_the_page_shows_every_learner_and_status_and_runs_nothing_planted(browser: Browser, tmp_path: Path) -> None:
    make_room(tmp_path / "home")
    report = build_report([str(tmp_path / "home" / "*")], now=NOW, course=tmp_path / "no-course")
    page = write_report(report, tmp_path / "out")[2]
    browser.open(page.as_uri())
    browser.frames(2)
    assert browser.js("window.pwned === undefined"), "a planted script or handler ran"
    assert browser.js("document.scripts.length") == 0
    shown = browser.js("Array.from(document.querySelectorAll('th.who')).map(e => e.textContent)")
    assert shown[1:] == [lr.name for lr in report.learners]  # the planted name is shown as text
    statuses = json.dumps(list(STATUSES))
    grid = browser.js(f"Object.fromEntries({statuses}.map(s => [s, document.querySelectorAll("
                      "'table:nth-of-type(2) td.' + s.replace(' ', '-')).length]))")
    expected = {s: sum(lr.state(t).status == s for lr in report.learners for t in report.tasks()) for s in STATUSES}
    assert grid == expected and all(expected.values())
    assert browser.js("document.querySelector('svg polyline').getBBox().width") > 100
    browser.viewport(1400, 1000)
    shot = browser.screenshot(tmp_path / "report.png")
    assert shot.stat().st_size > 10_000
