"""Node namespaces and several controller managers: YAML node keys matched as ROS 2 matches them.

Jazzy facts this follows (rclcpp ``parameter_map_from`` and ``resolve_parameter_overrides``; rcl_yaml_param_parser):
a node key gets a leading ``/`` when it has none, so a relative key names a node of the root namespace only; ``/*``
stands for one namespace part and ``/**`` for any number of them; every matching section gives its parameters in
file order, a later one winning. A controller node lives in its manager's namespace; ``~/x`` is
``/<ns>/<controller>/x`` and a relative ``joint_states`` is ``/<ns>/joint_states``. The robot files are this
project's own, in the layout of ros2_control_demos' example 15 (one YAML for two managers).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.exceptions import HardwareError, ParameterError
from rrbot_workshop.middleware.controllers_yaml import load_controllers_yaml, node_key_matches
from rrbot_workshop.msgs import Float64MultiArray


def arm_urdf(prefix: str) -> str:
    """A two-joint arm with mock hardware, its joints named ``<prefix>j1``, ``<prefix>j2``."""
    joints = "".join(
        f"""<joint name="{prefix}j{i}" type="revolute"><parent link="{prefix}l{i - 1}"/><child link="{prefix}l{i}"/>
          <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
        <link name="{prefix}l{i}"/>"""
        for i in (1, 2))
    interfaces = "".join(
        f"""<joint name="{prefix}j{i}"><command_interface name="position"/>
          <state_interface name="position"/><state_interface name="velocity"/></joint>"""
        for i in (1, 2))
    return f"""<?xml version="1.0"?>
<robot name="{prefix}arm">
  <link name="{prefix}l0"/>{joints}
  <ros2_control name="{prefix}hardware" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>{interfaces}
  </ros2_control>
</robot>"""


TWO_ARMS_YAML = """\
/**/controller_manager:
  ros__parameters:
    update_rate: 50
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster

/**/forward_position_controller:
  ros__parameters:
    type: forward_command_controller/ForwardCommandController
    interface_name: position

/arm_a/forward_position_controller:
  ros__parameters:
    joints: [arm_a_j1, arm_a_j2]

/arm_b/forward_position_controller:
  ros__parameters:
    joints: [arm_b_j1, arm_b_j2]
"""


@pytest.fixture
def package(tmp_path: Path) -> Path:
    """A package in the demos' layout: description/urdf/ per arm, bringup/config/ with the shared YAML."""
    (tmp_path / "description" / "urdf").mkdir(parents=True)
    (tmp_path / "bringup" / "config").mkdir(parents=True)
    for ns in ("arm_a", "arm_b"):
        (tmp_path / "description" / "urdf" / f"{ns}.urdf").write_text(arm_urdf(f"{ns}_"))
    (tmp_path / "bringup" / "config" / "two_arms.yaml").write_text(TWO_ARMS_YAML)
    return tmp_path


def _bring(package: Path, ns: str, **kwargs) -> rw.System:
    return rw.bringup(package / "description" / "urdf" / f"{ns}.urdf", package / "bringup" / "config" / "two_arms.yaml",
                      namespace=f"/{ns}", spawn=["joint_state_broadcaster", "forward_position_controller"], **kwargs)


def _positions(system: rw.System, topic: str) -> list[float]:
    return list(system.latest(topic).position)


@pytest.mark.parametrize(("key", "fqn", "matches"), [
    ("/**", "/controller_manager", True),
    ("/**", "/a/b/fwd", True),
    ("/**/fwd", "/fwd", True),
    ("/**/fwd", "/a/b/fwd", True),
    ("/*/fwd", "/fwd", False),
    ("/*/fwd", "/a/fwd", True),
    ("/*/fwd", "/a/b/fwd", False),
    ("fwd", "/fwd", True),
    ("fwd", "/a/fwd", False),  # a relative key is the root namespace's
    ("/a/fwd", "/a/fwd", True),
    ("/a/fwd", "/b/fwd", False),
    ("/a/*", "/a/fwd", True),
])
def test_node_keys_match_as_rclcpp_matches_them(key: str, fqn: str, matches: bool) -> None:
    assert node_key_matches(key, fqn) is matches


def test_each_namespace_reads_its_own_sections_and_the_wildcards() -> None:
    a = load_controllers_yaml(TWO_ARMS_YAML, namespace="/arm_a")
    b = load_controllers_yaml(TWO_ARMS_YAML, namespace="/arm_b")
    root = load_controllers_yaml(TWO_ARMS_YAML)
    assert a.update_rate == b.update_rate == root.update_rate == 50  # '/**/controller_manager' matches every manager
    assert a.controller_types == {"joint_state_broadcaster": "joint_state_broadcaster/JointStateBroadcaster"}
    assert a.parameters_for("forward_position_controller") == {
        "type": "forward_command_controller/ForwardCommandController", "interface_name": "position",
        "joints": ["arm_a_j1", "arm_a_j2"]}
    assert b.parameters_for("forward_position_controller")["joints"] == ["arm_b_j1", "arm_b_j2"]
    assert "joints" not in root.parameters_for("forward_position_controller")
    assert a.manager_name == "/arm_a/controller_manager"
    assert a.section_names() == {"forward_position_controller": "/**/forward_position_controller"}
    assert root.manager_namespaces() == []  # only a wildcard manager key


def test_matching_sections_merge_in_file_order_the_later_winning() -> None:
    text = """\
/arm_a/fwd:
  ros__parameters:
    interface_name: position
    gains: {j1: {p: 1.0}}
/**/fwd:
  ros__parameters:
    interface_name: velocity
    gains: {j1: {i: 2.0}}
"""
    params = load_controllers_yaml(text, namespace="/arm_a").parameters_for("fwd")
    assert params == {"interface_name": "velocity", "gains": {"j1": {"p": 1.0, "i": 2.0}}}


def test_a_namespace_can_be_written_as_an_enclosing_key() -> None:
    text = "arm_a:\n  controller_manager:\n    ros__parameters:\n      update_rate: 20\n"
    assert load_controllers_yaml(text, namespace="/arm_a").update_rate == 20
    assert load_controllers_yaml(text).update_rate == 100  # not the root manager's


def test_two_managers_from_one_yaml_each_move_only_their_robot(package: Path) -> None:
    a = _bring(package, "arm_a")
    b = _bring(package, "arm_b")
    try:
        assert a.bus is b.bus  # one graph, as two managers in one ROS graph
        assert a.controller_manager.name == "/arm_a/controller_manager"
        assert "/arm_b/controller_manager/list_controllers" in a.bus.service_names()
        ctrls = a.call_service("/arm_a/controller_manager/list_controllers").controller
        assert [(c.name, c.state) for c in ctrls] == [("joint_state_broadcaster", "active"),
                                                   ("forward_position_controller", "active")]
        a.publish("/arm_a/forward_position_controller/commands", Float64MultiArray(data=[0.4, -0.2]))
        a.spin(0.2)
        b.spin(0.2)
        assert _positions(a, "/arm_a/joint_states") == pytest.approx([0.4, -0.2])
        assert a.latest("/arm_a/joint_states").name == ["arm_a_j1", "arm_a_j2"]
        assert _positions(b, "/arm_b/joint_states") == pytest.approx([0.0, 0.0])
        b.publish("/arm_b/forward_position_controller/commands", Float64MultiArray(data=[-0.7, 0.1]))
        b.spin(0.2)
        a.spin(0.2)
        assert _positions(b, "/arm_b/joint_states") == pytest.approx([-0.7, 0.1])
        assert _positions(a, "/arm_a/joint_states") == pytest.approx([0.4, -0.2])
        assert a.bus.publisher_owners("/arm_b/joint_states") == ["/arm_b/joint_state_broadcaster"]
        assert a.latest("/joint_states") is None  # nothing in the root namespace
    finally:
        a.shutdown()
        b.shutdown()
    assert a.bus.service_names() == []  # both managers left the graph


def test_unloading_in_one_namespace_leaves_the_same_name_in_the_other(package: Path) -> None:
    a = _bring(package, "arm_a")
    b = _bring(package, "arm_b")
    try:
        a.unspawn(["forward_position_controller"])
        assert a.bus.subscription_count("/arm_a/forward_position_controller/commands") == 0
        assert b.bus.subscription_count("/arm_b/forward_position_controller/commands") == 1
    finally:
        a.shutdown()
        b.shutdown()


def test_the_same_manager_name_twice_is_refused(package: Path) -> None:
    a = _bring(package, "arm_a")
    try:
        with pytest.raises(HardwareError, match="/arm_a/controller_manager already runs"):
            _bring(package, "arm_a", name="again")
    finally:
        a.shutdown()


def test_a_file_for_another_namespace_names_the_namespace_to_pass(package: Path) -> None:
    only_ns = "/arm_a/controller_manager:\n  ros__parameters:\n    update_rate: 50\n"
    with pytest.raises(ParameterError, match=r"namespace='/arm_a'"):
        rw.bringup(arm_urdf("arm_a_"), only_ns)


def test_an_invalid_namespace_is_refused() -> None:
    with pytest.raises(ParameterError, match="not a valid node namespace"):
        rw.bringup(arm_urdf(""), TWO_ARMS_YAML, namespace="/2arm")


def test_without_a_namespace_the_names_are_the_root_ones(package: Path) -> None:
    text = TWO_ARMS_YAML + "forward_position_controller:\n  ros__parameters:\n    joints: [j1, j2]\n"
    system = rw.bringup(arm_urdf(""), text, spawn=["joint_state_broadcaster", "forward_position_controller"])
    other = rw.bringup(arm_urdf(""), text)
    try:
        assert system.namespace == "/" and system.controller_manager.name == "/controller_manager"
        assert system.bus is not other.bus  # a system without a namespace keeps a graph of its own
        assert "/controller_manager/list_controllers" in system.bus.service_names()
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.3, 0.3]))
        system.spin(0.2)
        assert _positions(system, "/joint_states") == pytest.approx([0.3, 0.3])
        assert system.bus.publisher_owners("/joint_states") == ["joint_state_broadcaster"]
    finally:
        system.shutdown()
        other.shutdown()


def test_spawner_remaps_a_relative_name_into_the_root(package: Path) -> None:
    """Example 15's namespaced spawner: ``--controller-ros-args "-r forward_position_controller/commands:=
    /position_commands"`` (a relative name, expanded in the controller's namespace)."""
    a = rw.bringup(package / "description" / "urdf" / "arm_a.urdf", package / "bringup" / "config" / "two_arms.yaml",
                   namespace="arm_a", spawn=["joint_state_broadcaster"])
    try:
        a.spawn(["forward_position_controller"],
                controller_ros_args="-r forward_position_controller/commands:=/position_commands")
        assert a.bus.subscription_owners("/position_commands") == ["/arm_a/forward_position_controller"]
        a.publish("/position_commands", Float64MultiArray(data=[0.2, 0.5]))
        a.spin(0.2)
        assert _positions(a, "/arm_a/joint_states") == pytest.approx([0.2, 0.5])
        a.unspawn(["forward_position_controller"])
        a.spawn(["forward_position_controller"], remap={"~/commands": "cmds"})  # relative: in the namespace
        assert a.bus.subscription_count("/arm_a/cmds") == 1
    finally:
        a.shutdown()


def test_magics_pick_a_manager_by_its_name(package: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from rrbot_workshop.course.magics import control

    a = _bring(package, "arm_a")
    b = _bring(package, "arm_b")
    try:
        b.unspawn(["forward_position_controller"])
        control("-c /arm_a/controller_manager list_controllers")
        assert "forward_position_controller" in capsys.readouterr().out
        control("--controller-manager arm_b/controller_manager list_controllers")
        assert "forward_position_controller" not in capsys.readouterr().out
        control("-c /arm_c/controller_manager list_controllers")
        assert "no controller manager /arm_c/controller_manager" in capsys.readouterr().out
    finally:
        a.shutdown()
        b.shutdown()
