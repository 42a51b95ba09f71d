"""%control and %topic print like ros2 control / ros2 topic, and report bad input without raising."""

from __future__ import annotations

import core_helpers  # noqa: F401  (registers the test plugins)
import pytest

from rrbot_workshop.bringup import bringup
from rrbot_workshop.course.magics import (
    control,
    load_ipython_extension,
    message_from_dict,
    message_to_yaml,
    ros_time,
    topic,
)
from rrbot_workshop.exceptions import MessageError
from rrbot_workshop.msgs import (
    Float64MultiArray,
    Header,
    JointState,
    JointTrajectory,
    JointTrajectoryPoint,
    MultiArrayDimension,
    MultiArrayLayout,
)

URDF = """<robot name="magic">
  <link name="base"/><link name="l1"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <ros2_control name="magic_hw" type="system">
    <hardware><plugin>test_hardware/TestSystem</plugin></hardware>
    <joint name="j1"><command_interface name="position"/><state_interface name="position"/></joint>
  </ros2_control>
</robot>"""

CONTROLLERS = {
    "controller_manager": {"ros__parameters": {
        "fwd": {"type": "test_controller/TestController"},
        "other_fwd": {"type": "test_controller/TestController"},
    }},
    "fwd": {"ros__parameters": {"command_interfaces": ["j1/position"], "state_interfaces": ["j1/position"]}},
    "other_fwd": {"ros__parameters": {"command_interfaces": ["j1/position"]}},
}


@pytest.fixture
def system():  # noqa: ANN201
    with bringup(URDF, CONTROLLERS, spawn=["fwd"], inactive=["other_fwd"], name="magic_test") as s:
        yield s


def _out(capsys: pytest.CaptureFixture[str]) -> str:
    return capsys.readouterr().out


def test_list_controllers_prints_name_type_state_columns(system, capsys) -> None:  # noqa: ANN001
    control("list_controllers")
    lines = _out(capsys).splitlines()
    assert lines == [
        "fwd       test_controller/TestController  active",
        "other_fwd test_controller/TestController  inactive",
    ]


def test_list_controllers_verbose_shows_interfaces(system, capsys) -> None:  # noqa: ANN001
    control("list_controllers -v")
    out = _out(capsys)
    assert "\tclaimed interfaces:\n\t\tj1/position" in out and "\trequired state interfaces:" in out


def test_list_hardware_components(system, capsys) -> None:  # noqa: ANN001
    control("list_hardware_components -v")
    out = _out(capsys)
    assert "Hardware Component 1\n\tname: magic_hw\n\ttype: system\n\tplugin name: test_hardware/TestSystem" in out
    assert "\tstate: id=3 label=active" in out
    assert "\t\tj1/position [available] [claimed]" in out and "\tstate interfaces\n\t\tj1/position [available]" in out


def test_list_hardware_interfaces(system, capsys) -> None:  # noqa: ANN001
    control("list_hardware_interfaces")
    assert _out(capsys) == "command interfaces\n\tj1/position [available] [claimed]\nstate interfaces\n\tj1/position\n"


def test_switch_controllers_and_error_message(system, capsys) -> None:  # noqa: ANN001
    control("switch_controllers --activate other_fwd --strict")
    out = _out(capsys)
    assert out.startswith("Error: switch rejected") and "already claimed by 'fwd'" in out
    control("switch_controllers --activate other_fwd --deactivate fwd --strict")
    assert _out(capsys) == "Successfully switched controllers\n"
    assert system.controller_manager.controllers["other_fwd"].state.label == "active"


def test_why_explains_without_switching(system, capsys) -> None:  # noqa: ANN001
    control("why other_fwd")
    out = _out(capsys)
    assert out.startswith("Switch: activate other_fwd\n  strict       would be rejected, nothing would change:")
    assert "already claimed by 'fwd'" in out and "interface 'j1/position': is claimed by 'fwd'" in out
    assert system.controller_manager.controllers["other_fwd"].state.label == "inactive"
    control("why --activate other_fwd --deactivate fwd")
    assert "strict       would go through: activate other_fwd and deactivate fwd" in _out(capsys)
    control("why fwd")  # active: the question is whether it can be deactivated
    assert _out(capsys).startswith("Switch: deactivate fwd\n  strict       would go through")
    control("why fwd --activate")
    assert "controller 'fwd' is already active" in _out(capsys)
    control("why")
    assert _out(capsys).startswith("Error: %control why needs a controller")
    control("why fwd --activate --deactivate")
    assert _out(capsys).startswith("Error: why NAME takes --activate or --deactivate, not both")


def test_statistics_prints_periods_on_the_managers_clock(system, capsys) -> None:  # noqa: ANN001
    system.spin(0.5)
    control("statistics --no-execution-time")
    lines = _out(capsys).splitlines()
    assert lines[0].split() == ["controller", "updates", "periodicity", "mean/min/max", "[Hz]"]
    assert lines[1].split() == ["fwd", "50", "100.00", "100.00", "100.00"] and lines[2].split() == ["other_fwd", "0"]
    control("statistics")
    assert "execution mean/max [us]" in _out(capsys)


def test_load_set_state_unload(system, capsys) -> None:  # noqa: ANN001
    control("unload_controller other_fwd")
    control("load_controller other_fwd --set-state inactive")
    control("set_controller_state other_fwd unconfigured")
    assert _out(capsys).splitlines() == [
        "Successfully unloaded controller other_fwd",
        "Successfully loaded controller other_fwd",
        "Successfully set controller other_fwd to inactive",
        "Successfully set controller other_fwd to unconfigured",
    ]


def test_set_hardware_component_state(system, capsys) -> None:  # noqa: ANN001
    control("set_hardware_component_state magic_hw inactive")
    assert _out(capsys) == "Successfully set hardware component magic_hw to inactive\n"
    control("set_hardware_component_state nope inactive")
    assert "no hardware component named 'nope'" in _out(capsys)


def test_view_controller_chains_prints_dot(system, capsys) -> None:  # noqa: ANN001
    control("view_controller_chains")
    assert _out(capsys).startswith("digraph controller_chains {")


def test_list_controller_types(system, capsys) -> None:  # noqa: ANN001
    control("list_controller_types")
    assert "test_controller/TestChainableController" in _out(capsys)


def test_unknown_verb_and_system_are_reported(system, capsys) -> None:  # noqa: ANN001
    control("dance")
    assert "invalid choice: 'dance'" in _out(capsys)
    control("--system nope list_controllers")
    assert "no running system 'nope'" in _out(capsys)
    control("")
    assert "needs a verb" in _out(capsys)


def test_no_system_is_reported(capsys) -> None:  # noqa: ANN001
    from rrbot_workshop import bringup as bringup_module

    if bringup_module.current_system() is None:
        control("list_controllers")
        assert "no running system" in _out(capsys)
    else:  # another test's system is alive; --system still works
        control("--system nope list_controllers")
        assert "no running system 'nope'" in _out(capsys)


def test_topic_pub_then_echo(system, capsys) -> None:  # noqa: ANN001
    topic('pub /cmd std_msgs/msg/Float64MultiArray "{data: [0.7, 1]}"')
    assert "publishing #1: Float64MultiArray(layout=MultiArrayLayout(dim=[], data_offset=0), data=[0.7, 1.0])" in _out(
        capsys
    )
    topic("echo /cmd --once")
    assert _out(capsys) == "layout:\n  dim: []\n  data_offset: 0\ndata:\n- 0.7\n- 1.0\n---\n"
    topic("list -t")
    assert "/cmd [std_msgs/msg/Float64MultiArray]" in _out(capsys)


def test_topic_errors_are_reported(system, capsys) -> None:  # noqa: ANN001
    topic("echo /silent")
    assert "no message" in _out(capsys)
    topic('pub /x std_msgs/msg/Nope "{}"')
    assert "unknown message type" in _out(capsys)
    topic('pub /x std_msgs/msg/Float64MultiArray "{datum: [1]}"')
    assert "no field 'datum'" in _out(capsys)


def test_message_from_dict_builds_nested_messages() -> None:
    msg = message_from_dict(JointTrajectory, {"joint_names": ["j1"], "points": [{"positions": [1], "time_from_start": 2}]})
    assert msg.points[0].positions == [1.0] and msg.points[0].time_from_start == 2.0
    assert message_to_yaml(Float64MultiArray(data=[1.0])) == "layout:\n  dim: []\n  data_offset: 0\ndata:\n- 1.0"
    with pytest.raises(MessageError, match="mapping"):
        message_from_dict(Float64MultiArray, [1, 2])


def test_float64_multi_array_accepts_the_layout_of_std_msgs() -> None:
    # The original workshop's command carries a layout; std_msgs/MultiArrayLayout and MultiArrayDimension.
    msg = message_from_dict(Float64MultiArray, {
        "layout": {"dim": [{"label": "joints", "size": 2, "stride": 2}], "data_offset": 0}, "data": [0.7, 0.7]})
    assert msg.layout == MultiArrayLayout(dim=[MultiArrayDimension("joints", 2, 2)], data_offset=0)
    assert msg.data == [0.7, 0.7]
    assert Float64MultiArray([0.5]).data == [0.5]  # layout is keyword-only: a positional list is the data
    with pytest.raises(MessageError, match="MultiArrayDimension has no field 'name'"):
        message_from_dict(Float64MultiArray, {"layout": {"dim": [{"name": "x"}]}})


def test_echo_writes_stamps_and_durations_as_sec_and_nanosec() -> None:
    text = message_to_yaml(JointState(header=Header(stamp=12.25, frame_id="base"), name=["j1"], position=[0.5]))
    assert text.startswith("header:\n  stamp:\n    sec: 12\n    nanosec: 250000000\n  frame_id: base\n")
    point = JointTrajectoryPoint(positions=[1.0], time_from_start=3.0)
    assert "time_from_start:\n    sec: 3\n    nanosec: 0" in message_to_yaml(JointTrajectory(points=[point]))
    assert ros_time(0.1) == {"sec": 0, "nanosec": 100000000}
    assert ros_time(1.9999999999) == {"sec": 2, "nanosec": 0}


def test_pub_accepts_ros_shaped_times() -> None:
    msg = message_from_dict(JointTrajectory, {
        "header": {"stamp": {"sec": 1, "nanosec": 500000000}},
        "points": [{"positions": [1], "time_from_start": {"sec": 3}}]})
    assert msg.header.stamp == 1.5 and msg.points[0].time_from_start == 3.0
    with pytest.raises(MessageError, match="valid: sec, nanosec"):
        message_from_dict(JointTrajectory, {"points": [{"time_from_start": {"secs": 3}}]})
    with pytest.raises(MessageError, match="0 <= nanosec"):
        message_from_dict(JointTrajectory, {"points": [{"time_from_start": {"sec": 0, "nanosec": 2000000000}}]})


FORWARD = {
    "controller_manager": {"ros__parameters": {"update_rate": 50,
                           "jsb": {"type": "joint_state_broadcaster/JointStateBroadcaster"},
                           "fwd": {"type": "forward_command_controller/ForwardCommandController"}}},
    "fwd": {"ros__parameters": {"joints": ["j1"], "interface_name": "position"}},
}


@pytest.fixture
def forward():  # noqa: ANN201
    with bringup(URDF, FORWARD, spawn=["jsb", "fwd"], name="forward_test") as s:
        yield s


def test_topic_info_counts_publishers_and_subscriptions(forward, capsys) -> None:  # noqa: ANN001
    topic("info /fwd/commands")
    assert _out(capsys) == "Type: std_msgs/msg/Float64MultiArray\nPublisher count: 0\nSubscription count: 1\n"
    topic("info /fwd/commands -v")
    out = _out(capsys)
    assert "Subscription count: 1\n\nNode name: fwd\nNode namespace: /\n" in out
    assert "Endpoint type: SUBSCRIPTION" in out and "Endpoint type: PUBLISHER" not in out


def test_topic_info_of_an_unknown_topic_suggests_the_close_name(forward, capsys) -> None:  # noqa: ANN001
    topic("info /fwd/comands")
    assert _out(capsys) == "Unknown topic '/fwd/comands'; did you mean '/fwd/commands'?\n"


def test_topic_hz_measures_the_rate_on_simulated_time(forward, capsys) -> None:  # noqa: ANN001
    start = forward.time
    topic("hz /joint_states --duration 2")
    out = _out(capsys)
    assert forward.time == pytest.approx(start + 2.0)
    assert forward.bus.subscription_count("/joint_states") == 0  # the listener is gone again
    first, second = out.splitlines()[:2]
    assert first == "average rate: 50.000"
    assert second.startswith("\tmin: 0.020s max: 0.020s std dev: 0.00000s window: ")


def test_topic_hz_without_messages_says_so(forward, capsys) -> None:  # noqa: ANN001
    topic("hz /fwd/commands --duration 0.1")
    assert "0 message(s) on '/fwd/commands'" in _out(capsys)
    topic("hz /fwd/commands --duration 0")
    assert "--duration must be > 0" in _out(capsys)


def test_load_ipython_extension_registers_the_magics() -> None:
    registered: list[tuple[str, str]] = []

    class Shell:
        def register_magic_function(self, fn, kind, name) -> None:  # noqa: ANN001
            registered.append((kind, name))

    load_ipython_extension(Shell())
    assert registered == [("line", "control"), ("line", "topic"), ("cell", "pytest")]
