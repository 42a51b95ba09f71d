"""Tests for joint_state_broadcaster (Jazzy rules)."""

from __future__ import annotations

import math

from rrbot_workshop.controller_interface.base import InterfaceConfigurationType
from rrbot_workshop.controllers.joint_state_broadcaster import JointStateBroadcaster, urdf_movable_joints
from rrbot_workshop.hardware_interface.handles import StateInterface
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State
from rrbot_workshop.msgs import DynamicJointState, JointState
from rrbot_workshop.testing import ControllerHarness

# Three joints as in the upstream test: joint1..3 with position, velocity, effort.
STATES = {
    "joint1/position": 1.1, "joint1/velocity": 2.1, "joint1/effort": 3.1,
    "joint2/position": 1.2, "joint2/velocity": 2.2, "joint2/effort": 3.2,
    "joint3/position": 1.3, "joint3/velocity": 2.3, "joint3/effort": 3.3,
}

URDF = """<robot name="r">
  <link name="base_link"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="joint3" type="revolute"><parent link="base_link"/><child link="a"/></joint>
  <joint name="joint1" type="revolute"><parent link="a"/><child link="b"/></joint>
  <joint name="fixed_joint" type="fixed"><parent link="b"/><child link="c"/></joint>
  <joint name="joint2" type="prismatic"><parent link="c"/><child link="d"/></joint>
  <ros2_control name="x" type="system"><joint name="ignored_here"/></ros2_control>
</robot>"""


def _run(params=None, states=STATES, urdf="", cycles=1) -> ControllerHarness:
    h = ControllerHarness(JointStateBroadcaster(), "joint_state_broadcaster", params or {},
                          state_values=states, robot_description=urdf)
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    h.update(cycles)
    return h


def test_all_state_interfaces_claimed_when_joints_empty():
    h = ControllerHarness(JointStateBroadcaster(), "jsb", {"joints": ["joint1"]}, state_values=STATES)
    h.configure()
    assert h.controller.state_interface_configuration().type is InterfaceConfigurationType.ALL
    assert h.controller.command_interface_configuration().type is InterfaceConfigurationType.NONE


def test_individual_joint_major_when_joints_and_interfaces_given():
    h = ControllerHarness(JointStateBroadcaster(), "jsb",
                          {"joints": ["joint2", "joint1"], "interfaces": ["position", "effort"]}, state_values=STATES)
    h.configure()
    cfg = h.controller.state_interface_configuration()
    assert cfg.type is InterfaceConfigurationType.INDIVIDUAL
    assert cfg.names == ["joint2/position", "joint2/effort", "joint1/position", "joint1/effort"]


def test_joint_states_published_in_state_interface_order_without_urdf():
    h = _run()
    msg = h.latest("/joint_states")
    assert isinstance(msg, JointState)
    assert msg.name == ["joint1", "joint2", "joint3"]
    assert msg.position == [1.1, 1.2, 1.3]
    assert msg.velocity == [2.1, 2.2, 2.3]
    assert msg.effort == [3.1, 3.2, 3.3]


def test_header_stamp_is_update_time_and_frame_id_default_base_link():
    h = _run(cycles=3)
    msg = h.latest("/joint_states")
    assert math.isclose(msg.header.stamp, 0.03)
    assert msg.header.frame_id == "base_link"
    assert h.latest("/dynamic_joint_states").header.stamp == msg.header.stamp


def test_values_follow_the_state_interfaces():
    h = _run()
    h.set("joint2/position", -7.0)
    h.update()
    assert h.latest("/joint_states").position[1] == -7.0


def test_selected_joints_and_interfaces_missing_fields_are_nan():
    h = _run({"joints": ["joint3", "joint1"], "interfaces": ["position"]})
    msg = h.latest("/joint_states")
    assert msg.name == ["joint3", "joint1"]
    assert msg.position == [1.3, 1.1]
    assert all(math.isnan(v) for v in msg.velocity + msg.effort)


def test_urdf_filter_keeps_non_fixed_urdf_joints_in_alphabetical_order():
    """Jazzy iterates urdfdom's std::map, so the names come out sorted."""
    states = {"joint3/position": 3.0, "joint1/position": 1.0, "fixed_joint/position": 9.0,
              "sensor/position": 5.0, "joint2/position": 2.0}
    msg = _run(states=states, urdf=URDF).latest("/joint_states")
    assert msg.name == ["joint1", "joint2", "joint3"]
    assert msg.position == [1.0, 2.0, 3.0]


def test_urdf_filter_off_keeps_every_prefix_in_claim_order():
    states = {"joint3/position": 3.0, "sensor/position": 5.0, "joint1/position": 1.0}
    msg = _run({"use_urdf_to_filter": False}, states=states, urdf=URDF).latest("/joint_states")
    assert msg.name == ["joint3", "sensor", "joint1"]


def test_urdf_filter_is_not_applied_when_joints_are_given():
    states = {"sensor/position": 5.0, "joint1/position": 1.0}
    msg = _run({"joints": ["sensor", "joint1"], "interfaces": ["position"]}, states=states, urdf=URDF).latest(
        "/joint_states")
    assert msg.name == ["sensor", "joint1"]


def test_prefix_without_joint_state_fields_only_in_dynamic_joint_states():
    states = {**STATES, "fts/force.x": 4.0, "gpio/digital_out": 1.0}
    h = _run(states=states)
    assert h.latest("/joint_states").name == ["joint1", "joint2", "joint3"]
    dyn = h.latest("/dynamic_joint_states")
    assert isinstance(dyn, DynamicJointState)
    assert dyn.joint_names == ["joint1", "joint2", "joint3", "fts", "gpio"]
    assert dyn.interface_values[3].interface_names == ["force.x"]
    assert dyn.interface_values[3].values == [4.0]
    assert dyn.interface_values[0].interface_names == ["position", "velocity", "effort"]
    assert dyn.interface_values[0].values == [1.1, 2.1, 3.1]


def test_extra_joints_are_appended_with_zeros():
    h = _run({"extra_joints": ["extra1", "joint1", "extra2"]})
    msg = h.latest("/joint_states")
    assert msg.name == ["joint1", "joint2", "joint3", "extra1", "extra2"]
    assert msg.position[3:] == [0.0, 0.0] and msg.velocity[3:] == [0.0, 0.0] and msg.effort[3:] == [0.0, 0.0]
    dyn = h.latest("/dynamic_joint_states")
    assert dyn.joint_names[-2:] == ["extra1", "extra2"]
    assert dyn.interface_values[-1].values == [0.0, 0.0, 0.0]


def test_extra_joints_survive_urdf_filter():
    states = {"joint1/position": 1.0}
    msg = _run({"extra_joints": ["wheel"]}, states=states, urdf=URDF).latest("/joint_states")
    assert msg.name == ["joint1", "wheel"]


def test_map_interface_to_joint_state_renames_custom_interfaces():
    states = {"joint1/actual_position": 0.4, "joint1/velocity": 0.5, "joint1/torque": 0.6}
    params = {"map_interface_to_joint_state": {"position": "actual_position", "effort": "torque"}}
    msg = _run(params, states=states).latest("/joint_states")
    assert msg.name == ["joint1"]
    assert (msg.position, msg.velocity, msg.effort) == ([0.4], [0.5], [0.6])


# The upstream fixture's custom interface: joint1/measured_position = 3.5
CUSTOM = {"joint1/position": 1.1, "joint1/velocity": 2.1, "joint1/effort": 3.1, "joint1/measured_position": 3.5}


def test_custom_interface_without_mapping_is_only_in_dynamic_joint_states():
    """ros2_controllers joint_state_broadcaster/test/test_joint_state_broadcaster.cpp, TestCustomInterfaceWithoutMapping
    (jazzy): an unmapped custom interface lists no joint in /joint_states and keeps its name in the dynamic message."""
    h = _run({"joints": ["joint1"], "interfaces": ["measured_position"]}, states=CUSTOM)
    msg = h.latest("/joint_states")
    assert msg.name == [] and msg.position == [] and msg.velocity == [] and msg.effort == []
    dynamic = h.latest("/dynamic_joint_states")
    assert dynamic.joint_names == ["joint1"]
    assert dynamic.interface_values[0].interface_names == ["measured_position"]


def test_custom_interface_mapping_names_the_interface_position_in_both_messages():
    """ros2_controllers joint_state_broadcaster/test/test_joint_state_broadcaster.cpp, TestCustomInterfaceMapping
    (jazzy): map_interface_to_joint_state.position = measured_position: the joint is in /joint_states with NaN
    velocity and effort, and /dynamic_joint_states lists the interface as "position"."""
    h = _run({"joints": ["joint1"], "interfaces": ["measured_position"],
              "map_interface_to_joint_state": {"position": "measured_position"}}, states=CUSTOM)
    cfg = h.controller.state_interface_configuration()
    assert cfg.type is InterfaceConfigurationType.INDIVIDUAL and cfg.names == ["joint1/measured_position"]
    msg = h.latest("/joint_states")
    assert msg.name == ["joint1"] and math.isnan(msg.velocity[0]) and math.isnan(msg.effort[0])
    dynamic = h.latest("/dynamic_joint_states")
    assert dynamic.joint_names == ["joint1"]
    assert dynamic.interface_values[0].interface_names == ["position"]


def test_custom_interface_mapping_update_publishes_the_custom_value_as_position():
    """ros2_controllers joint_state_broadcaster/test/test_joint_state_broadcaster.cpp, TestCustomInterfaceMappingUpdate
    (jazzy): after an update both messages carry measured_position's value (3.5) under "position"."""
    h = _run({"joints": ["joint1"], "interfaces": ["measured_position"],
              "map_interface_to_joint_state": {"position": "measured_position"}}, states=CUSTOM)
    msg = h.latest("/joint_states")
    assert msg.header.frame_id == "base_link"
    assert msg.name == ["joint1"] and msg.position == [3.5]
    assert math.isnan(msg.velocity[0]) and math.isnan(msg.effort[0])
    dynamic = h.latest("/dynamic_joint_states")
    assert dynamic.header.frame_id == "base_link"
    assert dynamic.interface_values[0].interface_names == ["position"] and dynamic.interface_values[0].values == [3.5]


def test_custom_interface_mapping_ignored_when_velocity_is_requested(caplog):
    """ros2_controllers joint_state_broadcaster/test/test_joint_state_broadcaster.cpp,
    TestCustomInterfaceMappingIgnoredWhenVelocityInterfaceIsRequested (jazzy): 'velocity' listed in 'interfaces'
    keeps its own meaning, the custom mapping is dropped with a warning; position and effort stay NaN."""
    h = ControllerHarness(JointStateBroadcaster(), "joint_state_broadcaster",
                          {"joints": ["joint1"], "interfaces": ["velocity"],
                           "map_interface_to_joint_state": {"velocity": "derived_velocity"}},
                          state_values={**CUSTOM, "joint1/derived_velocity": 7.0})
    with caplog.at_level("WARNING"):
        assert h.configure() is State.INACTIVE
    assert "derived_velocity" in caplog.text and "is not applied" in caplog.text
    assert h.controller.state_interface_configuration().names == ["joint1/velocity"]
    assert h.activate() is State.ACTIVE
    h.update()
    msg = h.latest("/joint_states")
    assert msg.name == ["joint1"] and msg.velocity == [2.1]
    assert math.isnan(msg.position[0]) and math.isnan(msg.effort[0])


def test_in_all_mode_a_mapped_interface_is_named_position_in_dynamic_joint_states():
    """Same rule as TestCustomInterfaceMapping (jazzy) with every state interface claimed: each prefix lists the
    mapped name, and the other interfaces keep theirs."""
    states = {"joint1/actual_position": 0.4, "joint1/velocity": 0.5, "fts/force.x": 2.0}
    h = _run({"map_interface_to_joint_state": {"position": "actual_position"}}, states=states)
    dynamic = h.latest("/dynamic_joint_states")
    assert dynamic.joint_names == ["joint1", "fts"]
    assert dynamic.interface_values[0].interface_names == ["position", "velocity"]
    assert dynamic.interface_values[0].values == [0.4, 0.5]
    assert dynamic.interface_values[1].interface_names == ["force.x"]


def test_two_interfaces_mapped_to_one_name_share_one_value_the_later_claimed_wins():
    """Jazzy's broadcaster keeps one value per joint and mapped name (joint_state_broadcaster.cpp, init_joint_data):
    'position' and a custom interface mapped to 'position' appear once, with the value claimed last."""
    states = {"joint1/position": 1.0, "joint1/actual_position": 9.0}
    h = _run({"map_interface_to_joint_state": {"position": "actual_position"}}, states=states)
    assert h.latest("/joint_states").position == [9.0]
    dynamic = h.latest("/dynamic_joint_states")
    assert dynamic.interface_values[0].interface_names == ["position"]
    assert dynamic.interface_values[0].values == [9.0]


def test_mapping_is_not_applied_when_standard_name_is_listed_in_interfaces(caplog):
    states = {"joint1/position": 1.0, "joint1/actual_position": 9.0}
    params = {"joints": ["joint1"], "interfaces": ["position", "actual_position"],
              "map_interface_to_joint_state": {"position": "actual_position"}}
    with caplog.at_level("WARNING"):
        msg = _run(params, states=states).latest("/joint_states")
    assert msg.position == [1.0]
    assert "is not applied" in caplog.text


def test_use_local_topics_publishes_under_controller_name():
    h = _run({"use_local_topics": True})
    assert h.latest("/joint_states") is None
    assert h.latest("/joint_state_broadcaster/joint_states").name == ["joint1", "joint2", "joint3"]
    assert h.latest("/joint_state_broadcaster/dynamic_joint_states") is not None


def test_publish_dynamic_joint_states_false_publishes_only_joint_states():
    h = _run({"publish_dynamic_joint_states": False})
    assert h.latest("/dynamic_joint_states") is None
    assert h.latest("/joint_states") is not None


def test_custom_frame_id_is_used_in_both_messages():
    h = _run({"frame_id": "world"})
    assert h.latest("/joint_states").header.frame_id == "world"
    assert h.latest("/dynamic_joint_states").header.frame_id == "world"


def test_bool_interfaces_are_left_out_of_joint_states():
    """ros2_controllers joint_state_broadcaster/test/test_joint_state_broadcaster.cpp,
    NoThrowWithBooleanAndDoubleInterfaceTest (jazzy): the bool interface is skipped in both messages."""
    h = ControllerHarness(JointStateBroadcaster(), "jsb", {}, state_values={"joint1/position": 1.0})
    h.states["joint1/effort"] = StateInterface("joint1", "effort", data_type="bool", initial_value=True)
    h.configure()
    h.activate()
    h.update()
    msg = h.latest("/joint_states")
    assert msg.position == [1.0] and math.isnan(msg.effort[0])
    dynamic = h.latest("/dynamic_joint_states")
    assert dynamic.joint_names == ["joint1"]
    assert dynamic.interface_values[0].interface_names == ["position"] and dynamic.interface_values[0].values == [1.0]


def test_a_bool_interface_alone_publishes_no_joint():
    """ros2_controllers joint_state_broadcaster/test/test_joint_state_broadcaster.cpp, NoThrowWithBooleanInterfaceTest
    (jazzy): only a bool interface: configure, activate and update work, and no joint is listed."""
    h = ControllerHarness(JointStateBroadcaster(), "jsb", {"joints": ["joint1"], "interfaces": ["is_moving"]},
                          state_values={})
    h.states["joint1/is_moving"] = StateInterface("joint1", "is_moving", data_type="bool", initial_value=True)
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    h.update()
    assert h.latest("/dynamic_joint_states").joint_names == []
    assert h.latest("/joint_states").name == []


def test_activation_without_state_interfaces_fails(caplog):
    h = ControllerHarness(JointStateBroadcaster(), "jsb", {}, state_values={})
    h.configure()
    with caplog.at_level("ERROR"):
        assert h.activate() is not State.ACTIVE
    assert "no state interfaces" in caplog.text


def test_deactivate_then_reactivate_rebuilds_layout():
    h = _run()
    assert h.deactivate() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    h.update()
    assert h.latest("/joint_states").name == ["joint1", "joint2", "joint3"]


def test_urdf_movable_joints_parses_only_top_level_joints():
    every, movable = urdf_movable_joints(URDF)
    assert every == {"joint1", "joint2", "joint3", "fixed_joint"}
    assert movable == ["joint1", "joint2", "joint3"]
    assert urdf_movable_joints("") is None
    assert urdf_movable_joints("<robot") is None


def test_plugin_name_resolves():
    assert plugins.resolve("controller", "joint_state_broadcaster/JointStateBroadcaster") is JointStateBroadcaster


def test_on_init_succeeds_without_parameters():
    assert JointStateBroadcaster().on_init() is CallbackReturn.SUCCESS


def test_a_message_read_after_deactivation_is_the_last_cycles() -> None:
    """Messages are built when read: one read after the broadcaster stopped still shows the names and values of its
    last cycle, and each message in the history keeps its own cycle's values."""
    import rrbot_workshop as rw
    from rrbot_workshop.msgs import Float64MultiArray

    with rw.bringup("rrbot", "rrbot_controllers.yaml", xacro_args={"use_mock_hardware": True},
                    spawn=["joint_state_broadcaster", "forward_position_controller"]) as system:
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.3, 0.4]))
        system.spin_cycles(3)
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.5, 0.6]))
        system.spin_cycles(3)
        system.controller_manager.switch_controllers(deactivate=["joint_state_broadcaster"])
        system.spin_cycles(3)
        msg = system.latest("/joint_states")
        history = [list(m.position) for m in system.history("/joint_states")]
    assert msg.name == ["joint1", "joint2"] and list(msg.position) == [0.5, 0.6]
    assert [0.3, 0.4] in history and history[-1] == [0.5, 0.6]
