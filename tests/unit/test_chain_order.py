"""Update order of chained controllers: a diff drive over two wheel PIDs (example 16's layout) is a chain, not a loop.

The diff drive claims the PIDs' reference interfaces (so it updates first) and, without position feedback, reads
the wheel velocities the PIDs export. Jazzy's chain puts the diff drive before the PIDs and logs no error; a real
loop is still reported.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import pytest
from core_helpers import load_configure, make_cm

import rrbot_workshop as rw
from rrbot_workshop.msgs import Header, TwistStamped

DATA = Path(__file__).parent / "data"
CHAIN = "test_controller/TestChainableController"
ALL = ["joint_state_broadcaster", "left_wheel_pid", "right_wheel_pid", "base_controller"]


@pytest.fixture
def diffbot(caplog: pytest.LogCaptureFixture):  # noqa: ANN201
    with caplog.at_level(logging.WARNING):
        system = rw.bringup("diffbot", DATA / "diffbot_pid_chain.yaml", spawn=ALL)
    try:
        yield system
    finally:
        system.shutdown()


def test_the_chain_activates_without_errors(diffbot: rw.System, caplog: pytest.LogCaptureFixture) -> None:
    errors = [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR]
    assert errors == []
    assert "chaining loop" not in caplog.text
    states = {c.name: (c.state, c.is_chained) for c in diffbot.controller_manager.list_controllers()}
    assert states == {"joint_state_broadcaster": ("active", False), "base_controller": ("active", False),
                      "left_wheel_pid": ("active", True), "right_wheel_pid": ("active", True)}


def test_the_diff_drive_updates_before_the_pids(diffbot: rw.System, monkeypatch: pytest.MonkeyPatch) -> None:
    cm = diffbot.controller_manager
    order = cm.update_order()
    assert order.index("base_controller") < order.index("left_wheel_pid")
    assert order.index("base_controller") < order.index("right_wheel_pid")
    calls: list[str] = []
    for name in ALL:
        ctrl = cm.get_controller(name)
        monkeypatch.setattr(ctrl, "update", lambda t, p, _u=ctrl.update, _n=name: (calls.append(_n), _u(t, p))[1])
    diffbot.spin_cycles(1)
    assert calls.index("base_controller") < calls.index("left_wheel_pid")
    assert calls.index("base_controller") < calls.index("right_wheel_pid")


def test_the_robot_drives_as_cmd_vel_says(diffbot: rw.System) -> None:
    twist = TwistStamped(Header(stamp=0.0))
    twist.twist.linear.x, twist.twist.angular.z = 0.2, 0.4
    rm = diffbot.resource_manager
    for _ in range(40):  # 2 s at 50 Hz, the twist refreshed within cmd_vel_timeout
        diffbot.publish("/base_controller/cmd_vel", twist)
        diffbot.spin_cycles(5)
    # references the diff drive wrote into the PIDs: (v -+ w*s/2) / r
    left_ref = (0.2 - 0.4 * 0.55 / 2) / 0.1
    right_ref = (0.2 + 0.4 * 0.55 / 2) / 0.1
    assert rm.get_interface_value("left_wheel_pid/left_wheel_joint/velocity", kind="command") == pytest.approx(left_ref)
    assert rm.get_interface_value("right_wheel_pid/right_wheel_joint/velocity", kind="command") == pytest.approx(right_ref)
    # the PIDs bring the (mock) wheels to those speeds
    assert rm.get_interface_value("left_wheel_joint/velocity") == pytest.approx(left_ref, abs=0.05)
    assert rm.get_interface_value("right_wheel_joint/velocity") == pytest.approx(right_ref, abs=0.05)
    odom = diffbot.latest("/base_controller/odom")
    assert odom.pose.pose.position.x > 0.1 and odom.twist.twist.angular.z == pytest.approx(0.4, abs=0.05)


def test_a_true_loop_is_still_reported(caplog: pytest.LogCaptureFixture) -> None:
    cm = make_cm({
        "a": {"type": CHAIN, "reference_interfaces": ["x"], "command_interfaces": ["b/y"]},
        "b": {"type": CHAIN, "reference_interfaces": ["y"], "command_interfaces": ["a/x"]},
    })
    with caplog.at_level(logging.ERROR):
        load_configure(cm, "a", "b")
    assert "['a', 'b'] form a chaining loop" in caplog.text
    assert sorted(cm.update_order()) == ["a", "b"]


def test_reading_a_state_without_claiming_still_orders_the_owner_first() -> None:
    cm = make_cm({
        "reader": {"state_interfaces": ["est/speed"]},
        "est": {"type": CHAIN, "exported_state_interfaces": ["speed"], "state_interfaces": ["joint1/position"]},
    })
    load_configure(cm, "reader", "est")
    assert cm.update_order() == ["est", "reader"]


def test_claim_and_state_read_together_keep_the_claim_order() -> None:
    cm = make_cm({
        "pid": {"type": CHAIN, "reference_interfaces": ["joint1/velocity"], "exported_state_interfaces":
                ["joint1/velocity"], "command_interfaces": ["joint1/position"]},
        "head": {"command_interfaces": ["pid/joint1/velocity"], "state_interfaces": ["pid/joint1/velocity"]},
    })
    load_configure(cm, "pid", "head")
    assert cm.update_order() == ["head", "pid"]
    assert not math.isnan(cm.resource_manager.get_interface_value("pid/joint1/velocity", kind="state"))
