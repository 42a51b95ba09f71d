"""Clocks: exact simulated time, wall-clock pacing with overrun logging, ros2_control's rate rule."""

from __future__ import annotations

import logging

import pytest

from rrbot_workshop.middleware.clock import SimClock, WallClock, make_clock, rate_due


def test_sim_clock_advances_exactly_one_period_per_tick() -> None:
    clock = SimClock(100)
    for _ in range(1000):
        clock.tick()
    assert clock.now() == 10.0 and clock.period == 0.01


def test_cycles_for_rounds_to_whole_cycles() -> None:
    assert SimClock(100).cycles_for(0.1) == 10
    assert SimClock(30).cycles_for(0.1) == 3
    with pytest.raises(ValueError, match="negative"):
        SimClock(100).cycles_for(-1.0)


def test_bad_rate_raises() -> None:
    with pytest.raises(ValueError, match="positive integer"):
        SimClock(0)


def test_make_clock_kinds() -> None:
    assert isinstance(make_clock("sim", 10), SimClock)
    assert isinstance(make_clock("wall", 10), WallClock)
    with pytest.raises(ValueError, match="'sim', 'wall'"):
        make_clock("fast", 10)


def test_wall_clock_sleeps_until_each_deadline() -> None:
    fake = {"t": 0.0}
    sleeps: list[float] = []

    def sleep(dt: float) -> None:
        sleeps.append(dt)
        fake["t"] += dt

    clock = WallClock(10, sleep=sleep, monotonic=lambda: fake["t"])
    for _ in range(3):
        clock.tick()
    assert sleeps == pytest.approx([0.1, 0.1, 0.1]) and clock.now() == pytest.approx(0.3)


def test_wall_clock_logs_overruns(caplog: pytest.LogCaptureFixture) -> None:
    fake = {"t": 0.0}
    clock = WallClock(10, sleep=lambda dt: None, monotonic=lambda: fake["t"])
    clock.tick()
    fake["t"] = 1.0  # the cycle took far longer than 0.1 s
    with caplog.at_level(logging.WARNING):
        clock.tick()
    assert clock.overruns == 1 and "overran" in caplog.text


def test_rate_rule_matches_ros2_control() -> None:
    assert rate_due(None, 0.0, 10, 100)
    assert not rate_due(0.0, 0.05, 10, 100)
    assert rate_due(0.0, 0.1, 10, 100)
    assert rate_due(0.0, 0.01, 100, 100)
