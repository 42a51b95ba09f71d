"""Goal publishers read as Jazzy's ros2_controllers_test_nodes read their parameter files (the demos' layout).

The files are under tests/unit/data/goal_publishers/ (written here, in the demos' layout).
"""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.controllers.goal_publishers import (
    ForwardCommandGoalPublisher,
    JointTrajectoryGoalPublisher,
    goal_publisher_from_parameters,
    load_goal_publishers,
)
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import JointState

DATA = Path(__file__).parent / "data" / "goal_publishers"


def _states(*positions: float) -> JointState:
    return JointState(name=["joint1", "joint2"], position=list(positions))


# ----------------------------------------------------------------------------- forward position publisher


def test_forward_publishes_on_publish_topic_every_period_in_turn() -> None:
    bus = TopicBus()
    pub = load_goal_publishers(bus, DATA / "forward_publisher.yaml")["publisher_forward_position_controller"]
    assert isinstance(pub, ForwardCommandGoalPublisher)
    assert pub.topic == "/forward_position_controller/commands" and pub.wait_sec_between_publish == 4.0
    counts = [pub.step(t / 10) for t in range(0, 161)]  # 0 .. 16 s
    assert sum(counts) == 4 and counts[40] == 1 and counts[39] == 0  # first one period after start
    assert [m.data for m in bus.history("/forward_position_controller/commands")] == [
        [0.5, 0.5], [0.0, 0.0], [-0.5, -0.5], [0.5, 0.5]]


def test_forward_defaults_are_jazzys() -> None:
    bus = TopicBus()
    pub = goal_publisher_from_parameters(bus, "publisher_forward_position_controller",
                                         {"pos1": [1.0], "pos2": [2.0]})
    assert (pub.topic, pub.wait_sec_between_publish, pub.goals) == ("/position_commands", 5.0, [[1.0], [2.0]])


def test_forward_humble_controller_name_is_ignored_with_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING):
        pub = goal_publisher_from_parameters(TopicBus(), "publisher_forward_position_controller",
                                             {"controller_name": "fwd", "goal_names": ["a"], "a": [1.0]})
    assert pub.topic == "/position_commands"  # where Jazzy's node publishes
    assert "'controller_name' is Humble's" in caplog.text and "publish_topic: '/fwd/commands'" in caplog.text


@pytest.mark.parametrize(("params", "named"), [
    ({"goal_names": ["a"], "a": [1.0], "publish_rate": 3}, "publish_rate"),
    ({"goal_names": ["a"], "a": [1.0], "b": [2.0]}, "'b'"),
    ({"goal_names": ["a"]}, "'a'"),
    ({"goal_names": ["a"], "a": ["x"]}, "'a'"),
    ({"goal_names": ["a"], "a": [1.0], "wait_sec_between_publish": 0}, "wait_sec_between_publish"),
    ({"goal_names": ["a"], "a": [1.0], "publish_topic": ""}, "publish_topic"),
    ({"goal_names": "a", "a": [1.0]}, "goal_names"),
])
def test_forward_bad_parameters_are_refused_by_name(params: dict, named: str) -> None:
    with pytest.raises(ParameterError, match=named):
        goal_publisher_from_parameters(TopicBus(), "publisher_forward_position_controller",
                                       {"publish_topic": "/x/commands", **params})


# ----------------------------------------------------------------------------- joint trajectory publisher


def test_trajectory_goes_to_the_controller_topic_with_jazzys_point(caplog: pytest.LogCaptureFixture) -> None:
    bus = TopicBus()
    with caplog.at_level(logging.WARNING):
        pub = load_goal_publishers(bus, DATA / "trajectory_publisher.yaml")["publisher_joint_trajectory_controller"]
    assert isinstance(pub, JointTrajectoryGoalPublisher)
    assert "goal 'too_short' is not used" in caplog.text  # one value for two joints: skipped, as Jazzy
    assert pub.topic == "/arm_trajectory_controller/joint_trajectory"
    assert pub.goals == [[0.6, -0.3], {"positions": [0.0, 0.0], "velocities": [0.1, 0.1]}]
    assert pub.goal_time_from_start == 4.0  # Jazzy's fixed time_from_start
    bus.publish("/joint_states", _states(0.1, -0.1))
    bus.deliver()
    assert pub.step(0.0) == 0 and pub.step(5.0) == 1 and pub.step(10.0) == 1
    first, second = bus.history(pub.topic)
    assert first.joint_names == ["joint1", "joint2"] and first.header.stamp == 0.0
    assert first.points[0].positions == [0.6, -0.3] and first.points[0].time_from_start == 4.0
    assert second.points[0].velocities == [0.1, 0.1]


def test_trajectory_holds_back_outside_the_starting_point_limits(caplog: pytest.LogCaptureFixture) -> None:
    bus = TopicBus()
    pub = load_goal_publishers(bus, DATA / "trajectory_publisher.yaml")["publisher_joint_trajectory_controller"]
    pub.step(0.0)
    with caplog.at_level(logging.WARNING):
        assert pub.step(5.0) == 0  # no joint_states yet
    assert "could not be checked" in caplog.text
    bus.publish("/joint_states", _states(0.5, 0.0))  # joint1 outside [-0.2, 0.2]
    bus.publish("/joint_states", _states(0.0, 0.0))  # only the first message counts
    bus.deliver()
    assert pub.step(20.0) == 0 and bus.history(pub.topic) == []


def test_trajectory_runs_a_jtc_on_mock_hardware() -> None:
    with rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=["joint_state_broadcaster", "joint_trajectory_controller"],
                    xacro_args={"use_mock_hardware": True}) as system:
        pub = goal_publisher_from_parameters(system.bus, "publisher_joint_trajectory_controller", {
            "controller_name": "joint_trajectory_controller", "wait_sec_between_publish": 1,
            "goal_names": ["pos1"], "pos1": {"positions": [0.4, -0.2]}, "joints": ["joint1", "joint2"],
            "goal_time_from_start": 0.5})
        system.controller_manager.add_cycle_hook(pub)
        system.spin(3.0)
        js = system.latest("/joint_states")
        assert dict(zip(js.name, js.position, strict=True)) == pytest.approx({"joint1": 0.4, "joint2": -0.2}, abs=1e-3)


@pytest.mark.parametrize(("params", "named"), [
    ({"goal_names": ["a"], "a": {"positions": [1.0, 2.0]}}, "joints"),
    ({"joints": ["j1"], "goal_names": ["a"], "a": {"positions": [1.0]}, "goal_time": 3}, "goal_time"),
    ({"joints": ["j1"], "goal_names": ["a"], "a": {"position": [1.0]}}, r"a\.position"),
    ({"joints": ["j1"], "goal_names": ["a"], "a": {"positions": [1.0, 2.0]}}, "no valid goal"),
    ({"joints": ["j1"], "goal_names": ["a"], "a": {"positions": [1.0]}, "check_starting_point": "yes"},
     "check_starting_point"),
    ({"joints": ["j1"], "goal_names": ["a"], "a": {"positions": [1.0]}, "check_starting_point": True,
      "starting_point_limits": {"j1": [0.0]}}, r"starting_point_limits\.j1"),
])
def test_trajectory_bad_parameters_are_refused_by_name(params: dict, named: str) -> None:
    with pytest.raises(ParameterError, match=named):
        goal_publisher_from_parameters(TopicBus(), "publisher_joint_trajectory_controller", params)


def test_limits_jazzy_never_reads_are_ignored() -> None:
    """Without check_starting_point, or for a joint not in 'joints', Jazzy declares no limit: nothing to refuse."""
    base = {"joints": ["j1"], "goal_names": ["a"], "a": {"positions": [1.0]}}
    pub = goal_publisher_from_parameters(TopicBus(), "p", {**base, "starting_point_limits": {"j1": [0.0], "j9": [0, 1]}},
                                         "publisher_joint_trajectory_controller")
    assert not pub.check_starting_point
    pub = goal_publisher_from_parameters(TopicBus(), "p", {**base, "check_starting_point": True,
                                                           "starting_point_limits": {"j9": [0, 1]}},
                                         "publisher_joint_trajectory_controller")
    assert pub.starting_point_limits == {"j1": [-2 * 3.14159, 2 * 3.14159]}


# ----------------------------------------------------------------------------- the file


def test_namespaced_sections_resolve_relative_topics_in_their_namespace() -> None:
    pubs = load_goal_publishers(TopicBus(), DATA / "namespaced_publishers.yaml")
    assert pubs["/arm_a/publisher_forward_position_controller"].topic == "/arm_a/forward_position_controller/commands"
    # the trajectory topic is absolute in Jazzy: '/' + controller_name + '/joint_trajectory'
    assert pubs["/arm_b/publisher_joint_trajectory_controller"].topic == \
        "/arm_b/position_trajectory_controller/joint_trajectory"


def test_a_launch_namespace_applies_to_plain_keys(tmp_path: Path) -> None:
    path = tmp_path / "plain.yaml"
    path.write_text("publisher_forward_position_controller:\n  ros__parameters:\n"
                    "    publish_topic: forward_position_controller/commands\n    goal_names: [a]\n    a: [1.0]\n")
    pub = load_goal_publishers(TopicBus(), path, namespace="/rrbot")["publisher_forward_position_controller"]
    assert pub.topic == "/rrbot/forward_position_controller/commands"


def test_a_renamed_node_takes_its_executable(tmp_path: Path) -> None:
    path = tmp_path / "renamed.yaml"
    path.write_text("my_commands:\n  ros__parameters:\n    goal_names: [a]\n    a: [1.0]\n")
    pubs = load_goal_publishers(TopicBus(), path, executables={"my_commands": "publisher_forward_position_controller"})
    assert pubs["my_commands"].topic == "/position_commands" and pubs["my_commands"].node.get_name() == "my_commands"
    with pytest.raises(ParameterError, match="'ros2_control_node' is not a goal publisher"):
        load_goal_publishers(TopicBus(), path, executables={"my_commands": "ros2_control_node"})


def test_the_courses_own_file_loads_on_jazzys_topics() -> None:
    pubs = load_goal_publishers(TopicBus())
    assert pubs["publisher_forward_position_controller"].topic == "/forward_position_controller/commands"
    assert pubs["publisher_joint_trajectory_controller"].topic == "/joint_trajectory_controller/joint_trajectory"
