"""The first exercise of the course, end to end: RRBot on mock hardware, forward command -> /joint_states."""

from __future__ import annotations

import pytest

import rrbot_workshop as rw


@pytest.fixture
def rrbot():  # noqa: ANN201
    with rw.bringup(
        "rrbot", "rrbot_controllers.yaml", spawn=["joint_state_broadcaster", "forward_position_controller"]
    ) as system:
        yield system


def test_forward_command_reaches_joint_states(rrbot: rw.System) -> None:
    rrbot.publish("/forward_position_controller/commands", rw.msgs.Float64MultiArray(data=[0.7, 0.7]))
    rrbot.spin(0.1)
    js = rrbot.latest("/joint_states")
    assert dict(zip(js.name, js.position, strict=True)) == {"joint1": pytest.approx(0.7), "joint2": pytest.approx(0.7)}
    assert js.header.stamp == pytest.approx(0.1)


def test_runs_are_deterministic() -> None:
    def run() -> list[list[float]]:
        with rw.bringup("rrbot", "rrbot_controllers.yaml",
                        spawn=["joint_state_broadcaster", "forward_position_controller"]) as s:
            s.publish("/forward_position_controller/commands", rw.msgs.Float64MultiArray(data=[0.3, -0.2]))
            s.spin(0.05)
            return [list(m.position) for m in s.history("/joint_states")]

    assert run() == run()


def test_forward_controller_claims_the_position_interfaces(rrbot: rw.System) -> None:
    cm = rrbot.controller_manager
    fwd = {c.name: c for c in cm.list_controllers()}["forward_position_controller"]
    assert fwd.claimed_interfaces == ["joint1/position", "joint2/position"]
    assert cm.list_hardware_components()[0].plugin_name == "mock_components/GenericSystem"
