"""JointTrajectoryController on a ControllerHarness (after ros2_controllers' test_trajectory_controller.cpp)."""

from __future__ import annotations

import math
from typing import Any

import pytest

from rrbot_workshop.controllers.follow_joint_trajectory import FollowJointTrajectoryResult as Result
from rrbot_workshop.controllers.follow_joint_trajectory import GoalStatus
from rrbot_workshop.controllers.joint_trajectory import JointTrajectoryController
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import (
    Header,
    JointTolerance,
    JointTrajectory,
    JointTrajectoryControllerState,
    JointTrajectoryPoint,
)
from rrbot_workshop.testing import ControllerHarness

JOINTS = ["joint1", "joint2"]
TOPIC = "~/joint_trajectory"


def make(
    command_interfaces: tuple[str, ...] = ("position",),
    state_interfaces: tuple[str, ...] = ("position", "velocity"),
    state: tuple[float, float] = (1.1, 2.2),
    command: float = math.nan,
    **params: Any,
) -> ControllerHarness:
    """A configured and active JTC on two joints."""
    parameters = {"joints": JOINTS, "command_interfaces": list(command_interfaces),
                  "state_interfaces": list(state_interfaces), **params}
    states = {f"{j}/{i}": (state[k] if i == "position" else 0.0)
              for k, j in enumerate(JOINTS) for i in state_interfaces}
    commands = {f"{j}/{i}": command for j in JOINTS for i in command_interfaces}
    h = ControllerHarness(JointTrajectoryController(), "jtc", parameters, states, commands)
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    return h


def follow(h: ControllerHarness, cycles: int) -> None:
    """Step like mock hardware: position states copy the position commands."""
    for _ in range(cycles):
        h.update()
        for j in JOINTS:
            if f"{j}/position" in h.commands:
                h.states[f"{j}/position"].set_value(h.commands[f"{j}/position"].get_value())


def traj(*points: tuple[float, list[float]], names: list[str] | None = None, **fields: Any) -> JointTrajectory:
    return JointTrajectory(Header(stamp=fields.pop("stamp", 0.0)), names or list(JOINTS),
                           [JointTrajectoryPoint(positions=p, time_from_start=t, **fields) for t, p in points])


def positions(h: ControllerHarness) -> list[float]:
    return h.values([f"{j}/position" for j in JOINTS])


# ----------------------------------------------------------------------------- parameters


@pytest.mark.parametrize(
    "overrides",
    [
        {"command_interfaces": ["velocity", "effort"]},
        {"command_interfaces": ["position", "acceleration"]},
        {"command_interfaces": ["velocity", "acceleration"]},
        {"command_interfaces": ["jerk"]},
        {"command_interfaces": []},
        {"state_interfaces": ["velocity"]},
        {"state_interfaces": ["position", "acceleration"]},
        {"joints": []},
        {"joints": ["joint1", "joint1"]},
        {"interpolation_method": "cubic"},
    ],
)
def test_invalid_parameters_raise_parameter_error(overrides: dict[str, Any]) -> None:
    params = {"joints": JOINTS, "command_interfaces": ["position"], "state_interfaces": ["position"], **overrides}
    with pytest.raises(ParameterError):
        ControllerHarness(JointTrajectoryController(), "jtc", params)


@pytest.mark.parametrize(
    "overrides",
    [
        {"command_interfaces": ["velocity"], "state_interfaces": ["position"]},
        {"command_interfaces": ["effort"], "state_interfaces": ["position"]},
        {"command_interfaces": ["position", "effort"], "state_interfaces": ["position"]},
        {"command_joints": ["a", "b", "c"]},
        {"command_joints": ["joint_4"]},
    ],
)
def test_combinations_needing_several_parameters_are_refused_at_configure(overrides: dict[str, Any]) -> None:
    """ros2_controllers joint_trajectory_controller/test/test_trajectory_controller.cpp,
    incorrect_initialization_using_interface_parameters (velocity-only / effort commands with position-only state:
    init OK, configure fails) and check_interface_names_with_command_joints_greater_than_dof / _different_than_dof
    (jazzy)."""
    params = {"joints": JOINTS, "command_interfaces": ["position"], "state_interfaces": ["position"], **overrides}
    h = ControllerHarness(JointTrajectoryController(), "jtc", params)
    assert h.configure() is State.UNCONFIGURED


def test_combination_error_names_the_parameter_and_the_valid_sets() -> None:
    params = {"joints": JOINTS, "command_interfaces": ["velocity", "effort"], "state_interfaces": ["position"]}
    with pytest.raises(ParameterError) as info:
        ControllerHarness(JointTrajectoryController(), "jtc", params)
    assert info.value.parameter == "command_interfaces" and "[position, effort]" in str(info.value)


@pytest.mark.parametrize(
    "cmd", [("position",), ("position", "velocity"), ("position", "velocity", "acceleration"), ("position", "effort"),
            ("velocity",), ("effort",)],
)
def test_valid_command_interface_combinations_activate(cmd: tuple[str, ...]) -> None:
    h = make(command_interfaces=cmd)
    assert h.controller.get_lifecycle_state() is State.ACTIVE


def test_interfaces_are_claimed_per_joint_in_joint_order() -> None:
    h = make(command_interfaces=("position", "velocity"))
    assert h.controller.command_interface_configuration().names == [
        "joint1/position", "joint1/velocity", "joint2/position", "joint2/velocity"]
    assert h.controller.state_interface_configuration().names == [
        "joint1/position", "joint1/velocity", "joint2/position", "joint2/velocity"]


def test_command_joints_name_the_command_interfaces() -> None:
    c = JointTrajectoryController()
    ControllerHarness(c, "jtc", {"joints": JOINTS, "command_joints": ["pid1/joint1", "pid2/joint2"],
                                 "command_interfaces": ["position"], "state_interfaces": ["position"]})
    assert c.command_interface_configuration().names == ["pid1/joint1/position", "pid2/joint2/position"]


# ----------------------------------------------------------------------------- activation


def test_hold_on_startup_commands_the_current_state() -> None:
    h = make()
    h.update()
    assert positions(h) == pytest.approx([1.1, 2.2])
    assert h.controller.is_holding


def test_last_finite_command_is_used_as_state_on_activation() -> None:
    h = make(state_interfaces=("position",), command=0.5)
    h.update()
    assert positions(h) == pytest.approx([0.5, 0.5])


def test_nan_command_falls_back_to_the_state_on_activation() -> None:
    h = make(state_interfaces=("position",), command=math.nan)
    h.update()
    assert positions(h) == pytest.approx([1.1, 2.2])


def test_velocity_state_without_velocity_command_uses_the_state_on_activation() -> None:
    """With a velocity state but no velocity command, the commands cannot stand in for the state."""
    h = make(command=0.5)
    h.update()
    assert positions(h) == pytest.approx([1.1, 2.2])


def test_hold_with_velocity_command_writes_zero_velocity() -> None:
    h = make(command_interfaces=("position", "velocity"))
    h.update()
    assert h.values(["joint1/velocity", "joint2/velocity"]) == [0.0, 0.0]


# ----------------------------------------------------------------------------- messages


@pytest.mark.parametrize(
    ("msg", "params", "words"),
    [
        (traj((1.0, [0.5]), names=["joint1"]), {}, "allow_partial_joints_goal"),
        (JointTrajectory(Header(), [], [JointTrajectoryPoint([], time_from_start=1.0)]),
         {"allow_partial_joints_goal": True}, "no joint_names"),
        (JointTrajectory(Header(), list(JOINTS), []), {}, "no points"),
        (traj((1.0, [0.5, 0.5]), names=["joint1", "joint3"]), {}, "joint3"),
        (traj((1.0, [0.5, 0.5]), velocities=[0.1, 0.0]), {}, "not 0"),
        (traj((1.0, [0.5, 0.5]), stamp=0.001), {}, "before now"),
        (traj((1.0, [0.5, 0.5]), (1.0, [0.6, 0.6])), {}, "strictly increase"),
        (traj((1.0, [0.5])), {}, "1 positions for 2 joints"),
        (traj((1.0, [])), {}, "positions are required"),
        (traj((1.0, [0.5, 0.5]), accelerations=[0.0]), {}, "accelerations"),
        (traj((1.0, [0.5, 0.5]), effort=[0.0, 0.0]), {}, "effort"),
        (traj((1.0, [0.5, math.nan])), {}, "non-finite"),
    ],
)
def test_invalid_message_is_rejected_with_a_reason(msg: JointTrajectory, params: dict[str, Any], words: str) -> None:
    h = make(**params)
    h.update()
    h.update(100)  # advance time so that a stamped message can be "in the past"
    h.publish(TOPIC, msg)
    follow(h, 50)
    assert h.controller.last_rejection is not None and words in h.controller.last_rejection
    assert positions(h) == pytest.approx([1.1, 2.2])


def test_missing_positions_accepted_with_integration_allowed() -> None:
    h = make(allow_integration_in_goal_trajectories=True, state=(0.0, 0.0))
    h.publish(TOPIC, JointTrajectory(Header(), list(JOINTS), [
        JointTrajectoryPoint(velocities=[1.0, 1.0], time_from_start=1.0),
        JointTrajectoryPoint(velocities=[0.0, 0.0], time_from_start=2.0)]))
    follow(h, 250)
    assert h.controller.last_rejection is None
    assert positions(h) == pytest.approx([1.0, 1.0])


def test_trajectory_reaches_its_goal_and_holds() -> None:
    h = make(state=(0.0, 0.0))
    h.publish(TOPIC, traj((1.0, [0.785, -0.785])))
    follow(h, 150)
    assert positions(h) == pytest.approx([0.785, -0.785], abs=1e-12)


def test_command_is_sampled_one_period_ahead() -> None:
    """First cycle of a 1 s linear move from 0: the command is the sample at t0 + 0.01 s."""
    h = make(state=(0.0, 0.0))
    h.update()
    h.publish(TOPIC, traj((1.0, [1.0, 2.0])))
    h.update()
    assert positions(h) == pytest.approx([0.01, 0.02])
    state = h.latest("~/controller_state")
    assert state.reference.positions == pytest.approx([0.0, 0.0])


def test_partial_goal_keeps_the_other_joint_at_its_last_command() -> None:
    h = make(allow_partial_joints_goal=True)
    h.publish(TOPIC, traj((1.0, [0.5]), names=["joint2"]))
    follow(h, 150)
    assert positions(h) == pytest.approx([1.1, 0.5])


def test_jumbled_joint_order_is_sorted() -> None:
    h = make()
    h.publish(TOPIC, traj((1.0, [0.2, 0.1]), names=["joint2", "joint1"]))
    follow(h, 150)
    assert positions(h) == pytest.approx([0.1, 0.2])


def test_new_trajectory_replaces_the_running_one() -> None:
    h = make(state=(0.0, 0.0))
    h.publish(TOPIC, traj((2.0, [1.0, 1.0])))
    follow(h, 50)
    h.publish(TOPIC, traj((1.0, [-0.5, -0.5])))
    follow(h, 150)
    assert positions(h) == pytest.approx([-0.5, -0.5])


def test_first_point_at_time_zero_jumps() -> None:
    h = make(state=(0.0, 0.0))
    h.publish(TOPIC, traj((0.0, [0.3, 0.4])))
    h.update()
    assert positions(h) == pytest.approx([0.3, 0.4])


def test_controller_state_is_published() -> None:
    h = make()
    h.update()
    msg = h.latest("~/controller_state")
    assert isinstance(msg, JointTrajectoryControllerState)
    assert msg.joint_names == JOINTS and msg.feedback.positions == pytest.approx([1.1, 2.2])
    assert msg.output.positions == pytest.approx([1.1, 2.2])


def test_message_to_an_inactive_controller_is_dropped() -> None:
    h = make()
    h.update()
    h.deactivate()
    h.publish(TOPIC, traj((1.0, [0.5, 0.5])))
    assert h.activate() is State.ACTIVE
    follow(h, 150)
    assert positions(h) == pytest.approx([1.1, 2.2])


def test_deactivate_zeroes_velocity_commands() -> None:
    h = make(command_interfaces=("position", "velocity"), state=(0.0, 0.0))
    h.publish(TOPIC, traj((1.0, [1.0, 1.0])))
    follow(h, 20)
    assert h.value("joint1/velocity") != 0.0
    h.deactivate()
    assert h.value("joint1/velocity") == 0.0


# ----------------------------------------------------------------------------- closed loop (PID)


def test_velocity_only_command_runs_the_pid() -> None:
    """p = 2: the first velocity command is 2 * (sampled position - state); state stays, so it grows."""
    gains = {"joint1": {"p": 2.0}, "joint2": {"p": 2.0}}
    h = make(command_interfaces=("velocity",), state=(0.0, 0.0), gains=gains)
    h.update()
    assert h.values(["joint1/velocity", "joint2/velocity"]) == pytest.approx([0.0, 0.0])
    h.publish(TOPIC, traj((1.0, [1.0, -1.0])))
    h.update(51)
    sample = h.latest("~/controller_state").reference.positions
    assert h.values(["joint1/velocity", "joint2/velocity"]) == pytest.approx([2.0 * sample[0], 2.0 * sample[1]])


def test_velocity_feed_forward_adds_the_desired_velocity() -> None:
    gains = {"joint1": {"ff_velocity_scale": 1.0}, "joint2": {"ff_velocity_scale": 1.0}}
    h = make(command_interfaces=("velocity",), state=(0.0, 0.0), gains=gains)
    h.publish(TOPIC, traj((1.0, [1.0, 2.0])))
    h.update(10)
    assert h.values(["joint1/velocity", "joint2/velocity"]) == pytest.approx([1.0, 2.0])


# ----------------------------------------------------------------------------- goals and tolerances


def test_goal_succeeds_when_the_joints_arrive() -> None:
    h = make(state=(0.0, 0.0))
    goal = h.controller.send_goal(traj((1.0, [0.785, 0.785])))
    assert goal.accepted and goal.status is GoalStatus.EXECUTING
    follow(h, 150)
    assert goal.status is GoalStatus.SUCCEEDED and goal.result.error_code == Result.SUCCESSFUL
    assert goal.feedback is not None and goal.feedback.joint_names == JOINTS


def test_path_tolerance_violation_aborts_and_holds() -> None:
    """The joints do not move (no follower), so a 0.05 rad path tolerance is soon exceeded."""
    h = make(state=(0.0, 0.0), constraints={"joint1": {"trajectory": 0.05}})
    goal = h.controller.send_goal(traj((1.0, [1.0, 1.0])))
    h.update(100)
    assert goal.status is GoalStatus.ABORTED and goal.result.error_code == Result.PATH_TOLERANCE_VIOLATED
    h.update(2)
    assert h.controller.is_holding and positions(h) == pytest.approx([0.0, 0.0])


def test_goal_tolerance_violation_after_goal_time_aborts() -> None:
    h = make(state=(0.0, 0.0))
    goal = h.controller.send_goal(traj((0.5, [1.0, 1.0])), goal_tolerance=[JointTolerance("joint1", 0.01)],
                                  goal_time_tolerance=0.2)
    h.update(100)
    assert goal.status is GoalStatus.ABORTED and goal.result.error_code == Result.GOAL_TOLERANCE_VIOLATED


def test_goal_waits_forever_without_goal_time() -> None:
    h = make(state=(0.0, 0.0), constraints={"joint1": {"goal": 0.01}})
    goal = h.controller.send_goal(traj((0.5, [1.0, 1.0])))
    h.update(300)
    assert goal.status is GoalStatus.EXECUTING


def test_erased_path_tolerance_is_not_checked() -> None:
    h = make(state=(0.0, 0.0), constraints={"joint1": {"trajectory": 0.05}})
    goal = h.controller.send_goal(traj((1.0, [1.0, 1.0])), path_tolerance=[JointTolerance("joint1", -1.0)])
    h.update(50)
    assert goal.status is GoalStatus.EXECUTING


@pytest.mark.parametrize(
    ("msg", "code"),
    [(traj((1.0, [0.1, 0.1]), names=["joint1", "nope"]), Result.INVALID_JOINTS),
     (traj((0.01, [0.1, 0.1]), stamp=0.005), Result.OLD_HEADER_TIMESTAMP),
     (traj((1.0, [0.1])), Result.INVALID_GOAL)],
)
def test_invalid_goal_is_rejected_with_its_error_code(msg: JointTrajectory, code: int) -> None:
    h = make()
    h.update(10)
    goal = h.controller.send_goal(msg)
    assert not goal.accepted and goal.result.error_code == code and goal.result.error_string


def test_goal_to_an_inactive_controller_is_rejected() -> None:
    h = make()
    h.deactivate()
    goal = h.controller.send_goal(traj((1.0, [0.1, 0.1])))
    assert not goal.accepted and goal.done


def test_cancel_holds_position() -> None:
    h = make(state=(0.0, 0.0))
    goal = h.controller.send_goal(traj((1.0, [1.0, 1.0])))
    follow(h, 30)
    assert goal.cancel()
    follow(h, 5)
    held = positions(h)
    follow(h, 100)
    assert goal.status is GoalStatus.CANCELED and positions(h) == pytest.approx(held)
    assert not goal.cancel()


def test_new_goal_preempts_the_running_one() -> None:
    """ros2_controllers joint_trajectory_controller/test/test_trajectory_actions.cpp,
    preempted_goal_receives_aborted_result (jazzy): the preempted goal ends ABORTED with INVALID_GOAL."""
    h = make(state=(0.0, 0.0))
    first = h.controller.send_goal(traj((1.0, [1.0, 1.0])))
    follow(h, 10)
    second = h.controller.send_goal(traj((1.0, [0.5, 0.5])))
    assert first.status is GoalStatus.ABORTED and first.result.error_code == Result.INVALID_GOAL
    follow(h, 150)
    assert second.status is GoalStatus.SUCCEEDED


def test_deactivate_aborts_the_running_goal() -> None:
    h = make()
    goal = h.controller.send_goal(traj((1.0, [1.0, 1.0])))
    h.update(5)
    h.deactivate()
    assert goal.status is GoalStatus.ABORTED and goal.result.error_code == Result.INVALID_GOAL


def test_cmd_timeout_holds_after_the_end() -> None:
    """The joints never arrive; 0.2 s after the end the controller gives up and holds where they are."""
    h = make(state=(0.0, 0.0), cmd_timeout=0.2)
    h.publish(TOPIC, traj((0.5, [1.0, 1.0])))
    h.update(80)
    assert h.controller.is_holding
    h.update(2)
    assert positions(h) == pytest.approx([0.0, 0.0])


def test_interpolate_from_desired_state_starts_from_the_last_command() -> None:
    """The joints do not move; a new trajectory starts from the last command, not from the stuck state."""
    h = make(state=(0.0, 0.0), interpolate_from_desired_state=True)
    h.publish(TOPIC, traj((0.5, [1.0, 1.0])))
    h.update(60)
    h.publish(TOPIC, traj((1.0, [2.0, 2.0])))
    h.update()
    # from (t_prev, 1.0) to (t + 1.0, 2.0), sampled at t + 0.01: the last command is stamped one period back
    assert positions(h)[0] == pytest.approx(1.0 + 0.02 / 1.01, abs=1e-9)


def test_effort_only_command_runs_the_pid() -> None:
    gains = {"joint1": {"p": 3.0}, "joint2": {"p": 3.0}}
    h = make(command_interfaces=("effort",), state=(0.0, 0.0), gains=gains)
    h.publish(TOPIC, traj((0.0, [0.5, -0.5])))
    h.update()
    assert h.values(["joint1/effort", "joint2/effort"]) == pytest.approx([1.5, -1.5])
