"""RRBot simulated in MuJoCo (xacro sim_mujoco:=true) with the workshop's controllers, end to end."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop import msgs
from rrbot_workshop.hardware.mujoco_system import MujocoSystem

_ROOT = rw.description.descriptions_root() / "rrbot"
_XACRO = _ROOT / "urdf" / "rrbot.urdf.xacro"
_POSITION_YAML = _ROOT / "config" / "rrbot_sim_position_controllers.yaml"
_EFFORT_YAML = _ROOT / "config" / "rrbot_sim_effort_controllers.yaml"
_GOALS = ([0.785, 0.785], [0.0, 0.0], [-0.785, -0.785], [0.0, 0.0])
_Start = Callable[..., rw.System]
_CHAIN = ["joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2", "joint_trajectory_controller"]


@pytest.fixture
def start() -> Iterator[_Start]:
    """Bring RRBot up in MuJoCo with a controllers YAML and controllers to spawn; shut down afterwards."""
    started: list[rw.System] = []

    def bring_up(controllers: Path | dict[str, Any], spawn: Sequence[str], inactive: Sequence[str] = ()) -> rw.System:
        system = rw.bringup(
            description=_XACRO, controllers=controllers, xacro_args={"sim_mujoco": "true"}, spawn=spawn,
            inactive=inactive,
        )
        started.append(system)
        return system

    yield bring_up
    for system in started:
        system.shutdown()


def _positions(system: rw.System) -> list[float]:
    js = system.latest("/joint_states")
    q = dict(zip(js.name, js.position, strict=True))
    return [q["joint1"], q["joint2"]]


def _hardware(system: rw.System) -> MujocoSystem:
    impl = system.resource_manager.get_component("rrbot").impl
    assert isinstance(impl, MujocoSystem)
    return impl


def _goal(positions: list[float]) -> msgs.JointTrajectory:
    point = msgs.JointTrajectoryPoint(positions=list(positions), time_from_start=3.0)
    return msgs.JointTrajectory(joint_names=["joint1", "joint2"], points=[point])


def _drive_through_goals(system: rw.System) -> list[list[float]]:
    reached = []
    for goal in _GOALS:
        system.publish("/joint_trajectory_controller/joint_trajectory", _goal(goal))
        system.spin(seconds=4.0)  # 3 s trajectory + 1 s to settle
        reached.append(_positions(system))
    return reached


def test_jtc_reaches_the_four_workshop_goals_in_physics(start: _Start) -> None:
    """JTC on position interfaces moves the simulated arm to each goal within 0.01 rad."""
    system = start(_POSITION_YAML, ["joint_state_broadcaster", "joint_trajectory_controller"])
    system.spin(seconds=0.1)
    for goal, reached in zip(_GOALS, _drive_through_goals(system), strict=True):
        assert reached == pytest.approx(goal, abs=0.01)


def test_pid_chain_reaches_the_four_workshop_goals_in_physics(start: _Start) -> None:
    """JTC -> PID per joint -> effort: the arm reaches each goal within 0.01 rad, gravity included."""
    system = start(_EFFORT_YAML, _CHAIN)
    system.spin(seconds=0.1)
    assert _hardware(system).command_modes == {"joint1": "effort", "joint2": "effort"}
    for goal, reached in zip(_GOALS, _drive_through_goals(system), strict=True):
        assert reached == pytest.approx(goal, abs=0.01)


def test_forward_position_controller_reaches_its_command(start: _Start) -> None:
    """A [0.7, 0.7] command on /forward_position_controller/commands is reached in physics."""
    system = start(_POSITION_YAML, ["joint_state_broadcaster", "forward_position_controller"])
    system.publish("/forward_position_controller/commands", msgs.Float64MultiArray(data=[0.7, 0.7]))
    system.spin(seconds=2.0)
    assert _positions(system) == pytest.approx([0.7, 0.7], abs=0.01)


def test_gravity_moves_joint2_with_no_controller_active(start: _Start) -> None:
    """With only the broadcaster active, link2 falls: joint2 leaves 0 while the vertical joint1 stays."""
    system = start(_POSITION_YAML, ["joint_state_broadcaster"])
    system.spin(seconds=1.0)
    joint1, joint2 = _positions(system)
    assert abs(joint2) > 0.5
    assert abs(joint1) < 0.01


def test_simulated_time_matches_the_controller_manager(start: _Start) -> None:
    """After spinning 1.5 s, MuJoCo's clock and the controller manager's agree within one physics step."""
    system = start(_POSITION_YAML, ["joint_state_broadcaster"])
    offset = system.time - _hardware(system).sim_time
    system.spin(seconds=1.5)
    assert _hardware(system).sim_time == pytest.approx(system.time - offset, abs=1e-3)


def test_hardware_refuses_a_second_mode_on_a_claimed_joint(start: _Start) -> None:
    """An effort controller cannot start while the JTC drives position; with the JTC stopped in the same switch it can."""
    config = yaml.safe_load(_POSITION_YAML.read_text())
    config["controller_manager"]["ros__parameters"]["forward_effort_controller"] = {
        "type": "effort_controllers/JointGroupEffortController"
    }
    config["forward_effort_controller"] = {"ros__parameters": {"joints": ["joint1", "joint2"]}}
    system = start(config, ["joint_state_broadcaster", "joint_trajectory_controller"], ["forward_effort_controller"])
    cm = system.controller_manager
    with pytest.raises(rw.SwitchError):
        cm.switch_controllers(activate=["forward_effort_controller"], strictness="strict")
    assert _hardware(system).command_modes == {"joint1": "position", "joint2": "position"}
    cm.switch_controllers(
        activate=["forward_effort_controller"], deactivate=["joint_trajectory_controller"], strictness="strict"
    )
    assert _hardware(system).command_modes == {"joint1": "effort", "joint2": "effort"}
