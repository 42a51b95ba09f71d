"""Test goal publishers (the workshop's ros2_controllers_test_nodes)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rrbot_workshop.controllers.goal_publishers import (
    DEFAULT_GOALS,
    ForwardCommandGoalPublisher,
    JointTrajectoryGoalPublisher,
    default_config_path,
    load_goal_publishers,
)
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import Float64MultiArray, JointTrajectory


def test_defaults_are_the_workshop_numbers() -> None:
    bus = TopicBus()
    fwd, jtc = ForwardCommandGoalPublisher(bus), JointTrajectoryGoalPublisher(bus)
    assert DEFAULT_GOALS == ((0.785, 0.785), (0.0, 0.0), (-0.785, -0.785), (0.0, 0.0))
    assert (fwd.wait_sec_between_publish, jtc.wait_sec_between_publish, jtc.goal_time_from_start) == (5.0, 6.0, 3.0)
    assert (fwd.topic, jtc.topic) == ("/forward_position_controller/commands", "/joint_trajectory_controller/joint_trajectory")


def test_forward_goals_go_out_every_period_in_turn() -> None:
    bus = TopicBus()
    pub = ForwardCommandGoalPublisher(bus)
    published = [pub.step(t / 100) for t in range(0, 2101)]
    assert sum(published) == 4 and published[500] == 1 and published[499] == 0
    data = [m.data for m in bus.history("/forward_position_controller/commands")]
    assert data == [[0.785, 0.785], [0.0, 0.0], [-0.785, -0.785], [0.0, 0.0]]
    assert all(isinstance(m, Float64MultiArray) for m in bus.history(pub.topic))


def test_goals_cycle_back_to_the_first() -> None:
    bus = TopicBus()
    pub = ForwardCommandGoalPublisher(bus, goals=[[1.0], [2.0]], wait_sec_between_publish=1.0)
    pub.step(0.0)
    pub.step(3.0)
    assert [m.data for m in bus.history(pub.topic)] == [[1.0], [2.0], [1.0]]
    assert pub.current_goal_index == 0


def test_trajectory_goal_is_one_point_at_goal_time_from_start() -> None:
    bus = TopicBus()
    pub = JointTrajectoryGoalPublisher(bus)
    pub(0.0, 0.01)
    pub(6.0, 0.01)
    msg = bus.latest(pub.topic)
    assert isinstance(msg, JointTrajectory) and msg.joint_names == ["joint1", "joint2"]
    assert len(msg.points) == 1 and msg.points[0].positions == [0.785, 0.785]
    assert msg.points[0].time_from_start == 3.0 and msg.header.stamp == 0.0


def test_repeat_the_same_goal_sends_each_goal_several_times() -> None:
    bus = TopicBus()
    pub = JointTrajectoryGoalPublisher(bus, goals=[[1.0, 1.0], [2.0, 2.0]], wait_sec_between_publish=1.0,
                                       repeat_the_same_goal=2)
    pub.step(0.0)
    pub.step(4.0)
    assert [m.points[0].positions[0] for m in bus.history(pub.topic)] == [1.0, 1.0, 2.0, 2.0]


@pytest.mark.parametrize(
    "kwargs",
    [{"goals": []}, {"wait_sec_between_publish": 0.0}, {"goals": [[1.0]]}, {"goal_time_from_start": 0.0},
     {"repeat_the_same_goal": 0}],
)
def test_bad_settings_raise_parameter_error(kwargs: dict) -> None:
    with pytest.raises(ParameterError):
        JointTrajectoryGoalPublisher(TopicBus(), **kwargs)


def test_config_file_loads_both_publishers() -> None:
    pubs = load_goal_publishers(TopicBus())
    fwd = pubs["publisher_forward_position_controller"]
    jtc = pubs["publisher_joint_trajectory_controller"]
    assert isinstance(fwd, ForwardCommandGoalPublisher) and isinstance(jtc, JointTrajectoryGoalPublisher)
    assert fwd.goals == jtc.goals == [list(g) for g in DEFAULT_GOALS]
    assert (fwd.wait_sec_between_publish, jtc.wait_sec_between_publish, jtc.goal_time_from_start) == (5.0, 6.0, 3.0)
    assert default_config_path().name == "test_goal_publishers_config.yaml"


def test_config_with_an_undefined_goal_raises(tmp_path: Path) -> None:
    path = tmp_path / "goals.yaml"
    path.write_text("publisher_forward_position_controller:\n  ros__parameters:\n    goal_names: [pos1]\n")
    with pytest.raises(ParameterError, match="pos1"):
        load_goal_publishers(TopicBus(), path)


def test_config_without_ros_parameters_raises(tmp_path: Path) -> None:
    path = tmp_path / "goals.yaml"
    path.write_text("publisher_forward_position_controller:\n  goal_names: [pos1]\n")
    with pytest.raises(ParameterError, match="ros__parameters"):
        load_goal_publishers(TopicBus(), path)


def test_missing_config_file_raises(tmp_path: Path) -> None:
    with pytest.raises(ParameterError):
        load_goal_publishers(TopicBus(), tmp_path / "nope.yaml")
