"""YAML parameters read as Jazzy's parser reads them: lists of maps (example 10's GPIO layout).

rcl_yaml_param_parser (``parse_file_events``) does not refuse a mapping inside a sequence: the mapping's keys continue
the dotted name of the parameter that holds the sequence, so ``flange: [{interfaces: [a]}]`` is the parameter
``flange.interfaces = [a]``. Scalars inside such a mapping are appended to that parameter as array entries, and a
second mapping in the same list continues the name again. A list inside a list is refused ("Sequences cannot be
key"). The robot files here are this project's own, in the layout of ros2_control_demos' example 10.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.controllers_yaml import load_controllers_yaml, rcl_parameters
from rrbot_workshop.msgs import DynamicInterfaceGroupValues, InterfaceValue

URDF = """<?xml version="1.0"?>
<robot name="io_arm">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <link name="l1"/>
  <ros2_control name="io_arm_hardware" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="j1"><command_interface name="position"/><state_interface name="position"/></joint>
    <gpio name="tool_io">
      <command_interface name="out_1"/>
      <state_interface name="out_1"/>
      <state_interface name="in_1"/>
    </gpio>
    <gpio name="gripper">
      <command_interface name="close"/>
      <state_interface name="close"><param name="initial_value">0.0</param></state_interface>
    </gpio>
  </ros2_control>
</robot>
"""

LIST_FORM_YAML = """\
controller_manager:
  ros__parameters:
    update_rate: 50
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster

io_controller:
  ros__parameters:
    type: gpio_controllers/GpioCommandController
    gpios:
      - tool_io
      - gripper
    command_interfaces:
      tool_io:
        - interfaces:
          - out_1
      gripper:
        - interfaces:
          - close
"""


@pytest.fixture
def package(tmp_path: Path) -> Path:
    (tmp_path / "description" / "urdf").mkdir(parents=True)
    (tmp_path / "bringup" / "config").mkdir(parents=True)
    (tmp_path / "description" / "urdf" / "io_arm.urdf").write_text(URDF)
    (tmp_path / "bringup" / "config" / "io_arm_controllers.yaml").write_text(LIST_FORM_YAML)
    return tmp_path


def test_a_list_of_one_map_is_the_map() -> None:
    assert rcl_parameters({"command_interfaces": {"g": [{"interfaces": ["a", "b"]}]}}) == {
        "command_interfaces": {"g": {"interfaces": ["a", "b"]}}}


def test_scalars_in_a_listed_map_become_arrays_and_a_second_map_continues_the_name() -> None:
    assert rcl_parameters({"x": [{"k": "v"}]}) == {"x": {"k": ["v"]}}
    assert rcl_parameters({"x": [{"a": 1}, {"b": 2}]}) == {"x": {"a": {"b": [1, 2]}}}
    assert rcl_parameters({"x": [{"i": [1]}, {"i": [2]}]}) == {"x": {"i": {"i": [2]}}}


def test_other_parameters_are_kept_as_they_are() -> None:
    params = {"joints": ["j1"], "gains": {"j1": {"p": 1.0}}, "rate": 5, "empty": []}
    assert rcl_parameters(params) == params


def test_rcl_refusals_are_parameter_errors() -> None:
    with pytest.raises(ParameterError, match="a sequence inside a sequence"):
        rcl_parameters({"x": [{"k": [[1, 2], [3]]}]})
    with pytest.raises(ParameterError, match="values of one type"):
        rcl_parameters({"x": [{"k": [1, "a"]}]})


def test_the_file_gives_the_gpio_controller_its_interfaces(package: Path) -> None:
    cfg = load_controllers_yaml(package / "bringup" / "config" / "io_arm_controllers.yaml")
    assert cfg.parameters_for("io_controller")["command_interfaces"] == {
        "tool_io": {"interfaces": ["out_1"]}, "gripper": {"interfaces": ["close"]}}


def test_gpio_commands_in_list_form_reach_the_hardware(package: Path) -> None:
    system = rw.bringup(package / "description" / "urdf" / "io_arm.urdf",
                        package / "bringup" / "config" / "io_arm_controllers.yaml",
                        spawn=["joint_state_broadcaster", "io_controller"])
    try:
        claimed = {c.name: c.claimed_interfaces for c in system.controller_manager.list_controllers()}
        assert claimed["io_controller"] == ["tool_io/out_1", "gripper/close"]
        system.publish("/io_controller/commands", DynamicInterfaceGroupValues(
            interface_groups=["tool_io", "gripper"],
            interface_values=[InterfaceValue(["out_1"], [1.0]), InterfaceValue(["close"], [0.5])]))
        system.spin(0.2)
        states = system.latest("/io_controller/gpio_states")
        values = {g: dict(zip(v.interface_names, v.values, strict=True))
                  for g, v in zip(states.interface_groups, states.interface_values, strict=True)}
        assert values["tool_io"]["out_1"] == 1.0  # the mock mirrors the command into its state
        assert values["gripper"]["close"] == 0.5
    finally:
        system.shutdown()


def test_a_group_given_a_value_is_refused_naming_controller_and_parameter(package: Path) -> None:
    """A value where a group is declared (here set on the node before configure) is an error, never an active
    controller with no interfaces."""
    system = rw.bringup(package / "description" / "urdf" / "io_arm.urdf",
                        package / "bringup" / "config" / "io_arm_controllers.yaml")
    try:
        ctrl = system.controller_manager.load_controller("io_controller")
        ctrl.get_node().set_parameters({"command_interfaces.gripper": [{"interfaces": ["close"]}]})
        with pytest.raises(ParameterError) as info:
            system.controller_manager.configure_controller("io_controller")
        text = str(info.value)
        assert "'io_controller'" in text and "'command_interfaces.gripper'" in text and "interfaces" in text
        assert system.controller_manager.controllers["io_controller"].state.label != "active"
    finally:
        system.shutdown()
