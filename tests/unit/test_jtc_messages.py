"""Tests of rrbot_workshop.controllers.jtc_messages: reshaping and building the JTC's trajectories."""

from __future__ import annotations

from rrbot_workshop.controllers.jtc_messages import (
    controller_state_message,
    fill_partial_goal,
    hold_position_trajectory,
    last_waypoint_trajectory,
    sort_to_joint_order,
)
from rrbot_workshop.msgs import Header, JointTrajectory, JointTrajectoryPoint

_NO_COMMAND = {"position": False, "velocity": False, "acceleration": False, "effort": False}


def test_partial_goal_is_padded_with_the_hold_position_and_zero_velocity():
    msg = JointTrajectory(Header(), ["j2"], [JointTrajectoryPoint(positions=[1.0], velocities=[0.5], time_from_start=1.0)])
    fill_partial_goal(msg, ["j1", "j2", "j3"], [7.0, 8.0, 9.0])
    assert msg.joint_names == ["j2", "j1", "j3"]
    assert msg.points[0].positions == [1.0, 7.0, 9.0] and msg.points[0].velocities == [0.5, 0.0, 0.0]
    assert msg.points[0].accelerations == []


def test_sort_puts_every_field_in_the_controller_joint_order():
    point = JointTrajectoryPoint(positions=[2.0, 1.0], effort=[20.0, 10.0])
    msg = JointTrajectory(Header(), ["j2", "j1"], [point])
    sort_to_joint_order(msg, ["j1", "j2"])
    assert msg.joint_names == ["j1", "j2"]
    assert msg.points[0].positions == [1.0, 2.0] and msg.points[0].effort == [10.0, 20.0]


def test_hold_trajectory_has_zero_velocity_with_an_acceleration_command():
    traj = hold_position_trajectory(["j1", "j2"], [0.1, 0.2], {**_NO_COMMAND, "acceleration": True})
    (point,) = traj.points
    assert point.positions == [0.1, 0.2] and point.velocities == [0.0, 0.0] and point.accelerations == [0.0, 0.0]
    assert point.effort == [] and point.time_from_start == 0.0 and traj.header.stamp == 0.0


def test_last_waypoint_trajectory_starts_now_and_leaves_the_message_alone():
    msg = JointTrajectory(Header(), ["j1"], [JointTrajectoryPoint(positions=[1.0], time_from_start=2.0)])
    (point,) = last_waypoint_trajectory(msg, ["j1"]).points
    assert point.positions == [1.0] and point.time_from_start == 0.0
    assert msg.points[0].time_from_start == 2.0


def test_controller_state_repeats_reference_and_feedback_in_the_deprecated_fields():
    desired = JointTrajectoryPoint(positions=[1.0], velocities=[0.1], effort=[5.0])
    current = JointTrajectoryPoint(positions=[0.9])
    msg = controller_state_message(3.0, ["j1"], desired, current, JointTrajectoryPoint(positions=[0.1]),
                                   JointTrajectoryPoint(positions=[1.0]))
    assert msg.header.stamp == 3.0 and msg.reference.positions == [1.0] and msg.reference.effort == []
    assert msg.desired is msg.reference and msg.actual is msg.feedback and msg.output.positions == [1.0]
