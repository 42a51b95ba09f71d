"""``/controller_manager/activity`` (a message per change of any controller's or component's state) and the
per-controller statistics (periods on the manager's clock, execution times)."""

from __future__ import annotations

import logging
from typing import Any

import pytest
from core_helpers import TestSystem, load_configure, make_cm, make_info

from rrbot_workshop.controller_manager.activity import ACTIVITY_TOPIC
from rrbot_workshop.middleware.lifecycle import ReturnType
from rrbot_workshop.msgs import ControllerManagerActivity


@pytest.fixture(autouse=True)
def _quiet() -> Any:
    logging.disable(logging.CRITICAL)
    yield
    logging.disable(logging.NOTSET)


def _states(msg: ControllerManagerActivity) -> tuple[dict[str, str], dict[str, str]]:
    return ({c.name: c.state.label for c in msg.controllers}, {h.name: h.state.label for h in msg.hardware_components})


def test_each_state_change_publishes_one_message_and_nothing_else_does() -> None:
    hw = TestSystem()
    cm = make_cm({"a": {"command_interfaces": ["joint1/position"]}, "b": {"command_interfaces": ["joint1/position"]}},
                 hardware=[(hw, make_info("arm", {"joint1": (["position"], ["position"])}))])
    history = lambda: cm.bus.history(ACTIVITY_TOPIC)  # noqa: E731
    assert [_states(m) for m in history()] == [({}, {"arm": "active"})]  # start-up, as Jazzy
    cm.load_controller("a")
    assert _states(history()[-1]) == ({"a": "unconfigured"}, {"arm": "active"})
    cm.configure_controller("a")
    cm.switch_controllers(activate=["a"], strictness="strict")
    assert [_states(m)[0] for m in history()] == [{}, {"a": "unconfigured"}, {"a": "inactive"}, {"a": "active"}]
    for k in range(5):  # cycles without a change publish nothing
        cm.update(k * 0.01, 0.01)
    with pytest.raises(Exception):  # noqa: B017 - a rejected request changes nothing, so no message
        cm.switch_controllers(activate=["nope"], strictness="strict")
    assert len(history()) == 4
    hw.read_result = ReturnType.ERROR  # a failure in the loop: the component and its controller change
    cm.update(0.05, 0.01)
    assert _states(history()[-1]) == ({"a": "inactive"}, {"arm": "unconfigured"})
    assert len(history()) == 5
    assert history()[-1].controllers[0].state.id == 2  # lifecycle_msgs/State ids


def test_activity_has_a_message_at_start_up() -> None:
    """ros2_control controller_manager/test/test_controller_manager.cpp, controller_lifecycle (jazzy): before any
    controller is loaded, ~/activity already holds the hardware components and no controllers."""
    cm = make_cm({})
    latest = cm.bus.latest(ACTIVITY_TOPIC)
    assert latest is not None and _states(latest) == ({}, {"sys": "active"})


def test_a_late_reader_finds_the_last_activity() -> None:
    cm = make_cm({"a": {"command_interfaces": ["joint1/position"]}})
    load_configure(cm, "a")
    cm.set_hardware_component_state("sys", "inactive")
    latest = cm.bus.latest(ACTIVITY_TOPIC)
    assert _states(latest) == ({"a": "inactive"}, {"sys": "inactive"})
    assert cm.bus.topic_type_name(ACTIVITY_TOPIC) == "controller_manager_msgs/msg/ControllerManagerActivity"


def test_statistics_count_periods_on_the_managers_clock_since_activation() -> None:
    """ros2_control controller_manager/test/test_controller_manager.cpp, check_the_controller_update_rate (jazzy):
    periodicity in [Hz], one measurement fewer than the updates (the first is not counted)."""
    cm = make_cm({"fast": {"command_interfaces": ["joint1/position"]},
                  "slow": {"command_interfaces": ["joint2/position"], "update_rate": 25}})
    load_configure(cm, "fast", "slow")
    cm.switch_controllers(activate=["fast", "slow"], strictness="strict")
    for k in range(100):
        cm.update(k * 0.01, 0.01)
    stats = cm.controller_statistics()
    assert stats["fast"].periodicity.count == 99 and stats["fast"].periodicity.mean == pytest.approx(100.0)
    assert stats["slow"].periodicity.count == 24 and stats["slow"].execution_time.count == 25
    assert stats["slow"].periodicity.minimum == pytest.approx(25.0) and stats["slow"].periodicity.maximum == pytest.approx(25.0)
    assert stats["fast"].execution_time.count == 100 and stats["fast"].execution_time.minimum >= 0.0
    cm.switch_controllers(deactivate=["fast"], strictness="strict")
    cm.switch_controllers(activate=["fast"], strictness="strict")
    cm.update(1.0, 0.01)
    assert cm.controller_statistics()["fast"].execution_time.count == 1, "statistics start over at activation"
    assert cm.controller_statistics()["fast"].periodicity.count == 0, "the first update after activation is no period"
