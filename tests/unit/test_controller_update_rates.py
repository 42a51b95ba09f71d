"""Each controller's own update rate and its statistics, ported from Jazzy's ``test_controller_manager.cpp``
(ros2_control, controller_manager/test): ``check_the_controller_update_rate`` (controller rates 10 ... 90 Hz under a
100 Hz manager) and ``per_controller_equal_and_higher_update_rate`` (100, 232 and 400 Hz: the manager's rate).

What both assert of the statistics: every update is timed (execution time count = updates), and the first update after
activation is no period (periodicity count = updates - 1); the periodicity's mean, minimum and maximum stay near the
expected rate. The upstream tests run on the wall clock with tolerances; here the manager runs on simulated time, so
the bounds are the same but the run is exact and quick.
"""

from __future__ import annotations

import math

import pytest
from core_helpers import load_configure, make_cm

from rrbot_workshop.controller_manager.manager import ControllerManager

CM_RATE = 100
PERIOD = 1.0 / CM_RATE


def _activated(update_rate: int) -> tuple[ControllerManager, object]:
    """A 100 Hz manager whose one controller (``update_rate``) is configured and activated, as the upstream tests
    start: one cycle while inactive updates nothing."""
    cm = make_cm({"ctrl": {"command_interfaces": ["joint1/position"], "update_rate": update_rate}},
                 update_rate=CM_RATE)
    load_configure(cm, "ctrl")
    ctrl = cm.get_controller("ctrl")
    cm.update(0.37, PERIOD)  # a time that is not zero: the period must be right whenever the controller starts
    assert ctrl.updates == []  # type: ignore[attr-defined]
    cm.switch_controllers(activate=["ctrl"], strictness="strict")
    return cm, ctrl


@pytest.mark.parametrize("rate", [10, 12, 16, 23, 37, 40, 50, 63, 71, 85, 90])
def test_check_the_controller_update_rate(rate: int) -> None:
    """check_the_controller_update_rate: a controller slower than the manager updates at about its own rate (the
    manager's period rounded), its first period is 1 / its update rate, and periodicity counts one update fewer than execution
    time, with mean, minimum and maximum within the upstream bounds, at every whole second of ten."""
    cm, ctrl = _activated(rate)
    exp_period = round(CM_RATE / rate - 0.01) / CM_RATE
    exp_rate = 1.0 / exp_period
    assert ctrl.get_update_rate() == math.floor(exp_rate)  # type: ignore[attr-defined]
    start = 0.37
    for cycle in range(1, 10 * CM_RATE + 1):
        cm.update(start + cycle * PERIOD, PERIOD)
        updates = ctrl.updates  # type: ignore[attr-defined]
        if len(updates) == 1:
            nominal = 1.0 / ctrl.get_update_rate()  # type: ignore[attr-defined]
            assert updates[0][1] == pytest.approx(nominal, abs=1e-6), "the first update gets a nominal period"
        elif updates:
            assert 0.65 * exp_period < updates[-1][1] < 1.2 * exp_period + PERIOD
        if cycle % CM_RATE == 0:
            count = len(updates)
            expected = int(exp_rate * cycle / CM_RATE)
            assert expected - 1 <= count <= expected + 1
            stats = cm.controller_statistics()["ctrl"]
            assert stats.execution_time.count == count
            assert stats.periodicity.count == count - 1, "the first update is not counted in periodicity"
            assert 0.9 * exp_rate <= stats.periodicity.mean < 1.05 * exp_rate
            assert 0.5 * exp_rate <= stats.periodicity.minimum < 1.2 * exp_rate
            assert 0.75 * exp_rate <= stats.periodicity.maximum < 2.0 * exp_rate


@pytest.mark.parametrize("rate", [100, 232, 400])
def test_per_controller_equal_and_higher_update_rate(rate: int) -> None:
    """per_controller_equal_and_higher_update_rate: a controller asking for the manager's rate or more updates every
    cycle (two seconds: 200 updates) with the manager's period; after each, execution time counts every update and
    periodicity one fewer, its mean, minimum and maximum near the manager's rate."""
    cm, ctrl = _activated(rate)
    for cycle in range(1, 2 * CM_RATE + 1):
        cm.update(0.37 + cycle * PERIOD, PERIOD)
        updates = ctrl.updates  # type: ignore[attr-defined]
        assert 0.65 / CM_RATE <= updates[-1][1] < 1.6 / CM_RATE
        stats = cm.controller_statistics()["ctrl"]
        assert stats.execution_time.count == len(updates)
        assert stats.periodicity.count == len(updates) - 1, "the first update is not counted in periodicity"
        if stats.periodicity.count:
            assert 0.9 * CM_RATE <= stats.periodicity.mean < 1.05 * CM_RATE
            assert 0.5 * CM_RATE <= stats.periodicity.minimum < 1.2 * CM_RATE
            assert 0.75 * CM_RATE <= stats.periodicity.maximum < 2.0 * CM_RATE
    assert len(ctrl.updates) == 2 * CM_RATE  # type: ignore[attr-defined]
    assert ctrl.get_update_rate() == CM_RATE  # type: ignore[attr-defined]
