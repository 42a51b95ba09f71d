"""The JTC on mock RRBot (calculate_dynamics) and the task-9 chain JTC -> PID -> hardware."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

import rrbot_workshop as rw
from rrbot_workshop.controllers.goal_publishers import DEFAULT_GOALS, JointTrajectoryGoalPublisher

CHAIN = ["joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2", "joint_trajectory_controller"]


@pytest.fixture
def plain() -> Iterator[rw.System]:
    system = rw.bringup("rrbot", "rrbot_controllers.yaml", xacro_args={"calculate_dynamics": True},
                        spawn=["joint_state_broadcaster", "joint_trajectory_controller"])
    yield system
    system.shutdown()


@pytest.fixture
def chained() -> Iterator[rw.System]:
    system = rw.bringup("rrbot", "rrbot_chained_controllers.yaml", xacro_args={"calculate_dynamics": True}, spawn=CHAIN)
    yield system
    system.shutdown()


def _reached_goals(system: rw.System) -> list[list[float]]:
    """Run the task-2 goal publisher for four goals; joint positions just before each next goal."""
    publisher = JointTrajectoryGoalPublisher(system.bus)
    system.controller_manager.add_cycle_hook(publisher)
    reached = []
    system.spin(6.0)
    for _ in DEFAULT_GOALS:
        system.spin(6.0)
        reached.append(list(system.latest("/joint_states").position[:2]))
    return reached


def test_jtc_reaches_the_four_test_goals(plain: rw.System) -> None:
    for goal, position in zip(DEFAULT_GOALS, _reached_goals(plain), strict=True):
        assert position == pytest.approx(list(goal), abs=1e-3)


def test_chain_is_connected(chained: rw.System) -> None:
    states = {c.name: c for c in chained.controller_manager.list_controllers()}
    assert all(states[n].state == "active" for n in CHAIN)
    assert states["pid_controller_joint1"].is_chained and states["pid_controller_joint2"].is_chained
    dot = chained.controller_manager.view_controller_chains()
    assert '"joint_trajectory_controller":cmd_pid_controller_joint1_joint1_position -> "pid_controller_joint1"' in dot
    assert '"pid_controller_joint2":cmd_joint2_velocity -> "hw_command_interfaces"' in dot


def test_chain_tracks_the_four_test_goals(chained: rw.System) -> None:
    for goal, position in zip(DEFAULT_GOALS, _reached_goals(chained), strict=True):
        assert position == pytest.approx(list(goal), abs=1e-3)


def test_chain_follows_the_trajectory_closely(chained: rw.System) -> None:
    """While moving, the position error stays below 0.05 rad (PID p = 20 on a 0.26 rad/s ramp)."""
    publisher = JointTrajectoryGoalPublisher(chained.bus)
    chained.controller_manager.add_cycle_hook(publisher)
    chained.spin(7.5)
    state = chained.latest("/joint_trajectory_controller/controller_state")
    assert 0.1 < state.feedback.positions[0] < 0.7
    assert max(abs(e) for e in state.error.positions) < 0.05
