"""Grader of task 2: mock hardware (the hardware switch in xacro, the controllers YAML, the bringup).

The specification (from the ROSCon 2022 workshop, task 2):

* ``rrbot.urdf.xacro`` takes the arguments ``use_mock_hardware`` and ``mock_sensor_commands``. With
  ``use_mock_hardware:=true`` the ``<hardware>`` plugin is ``mock_components/GenericSystem`` with
  ``<param name="mock_sensor_commands">`` set from the argument; with ``false`` it is the RRBot's driver,
  ``controlko_hardware_interface/RRBotHardwareInterface``;
* ``rrbot_controllers.yaml``: ``controller_manager`` at ``update_rate: 100`` [Hz] declaring
  ``joint_state_broadcaster`` (JointStateBroadcaster), ``forward_position_controller``
  (ForwardCommandController on ``joints [joint1, joint2]``, ``interface_name: position``) and
  ``joint_trajectory_controller`` (JointTrajectoryController on ``joints [joint1, joint2]``,
  ``command_interfaces [position]``, ``state_interfaces [position, velocity]``,
  ``allow_partial_joints_goal: false``, ``constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}``);
  only parameters that Jazzy's controllers declare;
* ``rrbot_bringup/bringup.py``: ``start_rrbot(robot_controller="forward_position_controller",
  use_mock_hardware=True, mock_sensor_commands=False)`` returns a running system with
  ``joint_state_broadcaster`` and the robot controller active, the other robot controller loaded and inactive;
* on it, ``[0.7, 0.7]`` sent to ``/forward_position_controller/commands`` is the joints' position 0.1 s later;
  and the joint trajectory controller, driven by the workshop's test goal publisher, reaches each of its four
  goals.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.bringup import bringup, systems
from rrbot_workshop.controllers.goal_publishers import DEFAULT_GOALS, JointTrajectoryGoalPublisher
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.msgs import Float64MultiArray

TASK = 2
DESCRIPTION = "rrbot_description/urdf/rrbot.urdf.xacro"
CONTROLLERS = "rrbot_bringup/config/rrbot_controllers.yaml"
BRINGUP = "rrbot_bringup/bringup.py"

MOCK = "mock_components/GenericSystem"
DRIVER = "controlko_hardware_interface/RRBotHardwareInterface"
JSB, FPC, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"
TYPES = {
    JSB: "joint_state_broadcaster/JointStateBroadcaster",
    FPC: "forward_command_controller/ForwardCommandController",
    JTC: "joint_trajectory_controller/JointTrajectoryController",
}
JOINTS = ["joint1", "joint2"]
GOAL_TOL = 1e-3  # [rad]


# --------------------------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def description_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, DESCRIPTION)


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


@pytest.fixture(scope="module")
def controllers_yaml(controllers_file: Path) -> dict[str, Any]:
    try:
        data = yaml.safe_load(controllers_file.read_text())
    except yaml.YAMLError as exc:
        pytest.fail(f"{controllers_file.name} is not valid YAML: {exc}", pytrace=False)
    assert isinstance(data, dict), f"{controllers_file.name} must be a mapping of node names (controller_manager, ...)"
    return data


@pytest.fixture(scope="module")
def bringup_module(task_file: Callable[[int, str], Path]) -> ModuleType:
    path = task_file(TASK, BRINGUP)
    name = "rrbot_workshop_task02_bringup"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None, f"cannot load {path} as a Python module"
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:  # noqa: BLE001 - any error in the learner's file fails the check with its message
        sys.modules.pop(name, None)
        pytest.fail(f"{BRINGUP} cannot be imported: {type(exc).__name__}: {exc}", pytrace=False)
    assert hasattr(module, "start_rrbot"), f"{BRINGUP} defines no function start_rrbot"
    return module


@pytest.fixture
def start(bringup_module: ModuleType) -> Iterator[Callable[..., rw.System]]:
    """``start(**kwargs)`` calls the learner's ``start_rrbot``; every system still running is shut down after."""

    def call(**kwargs: Any) -> rw.System:
        try:
            system = bringup_module.start_rrbot(**kwargs)
        except NotImplementedError as exc:
            pytest.fail(f"start_rrbot() is not written yet: {exc}", pytrace=False)
        assert isinstance(system, rw.System), (
            f"start_rrbot() must return the running system (from rrbot_workshop.bringup), not {type(system).__name__}"
        )
        assert system.running, "start_rrbot() returned a system that is shut down"
        return system

    yield call
    for system in list(systems().values()):
        system.shutdown()


# --------------------------------------------------------------------------------------------- helpers


def _hardware(description_file: Path, **xacro_args: Any) -> HardwareInfo:
    infos = parse_ros2_control(process_xacro(description_file, **xacro_args))
    assert len(infos) == 1, f"expected one <ros2_control> tag with {xacro_args}, found {len(infos)}"
    return infos[0]


def _manager_section(data: dict[str, Any]) -> dict[str, Any]:
    body = data.get("controller_manager")
    assert isinstance(body, dict) and isinstance(body.get("ros__parameters"), dict), (
        "the file needs 'controller_manager:' with 'ros__parameters:' under it"
    )
    return body["ros__parameters"]


def _controller_section(data: dict[str, Any], name: str) -> dict[str, Any]:
    body = data.get(name)
    assert isinstance(body, dict) and isinstance(body.get("ros__parameters"), dict), (
        f"no '{name}:' section with 'ros__parameters:' (top-level sections: {sorted(data)})"
    )
    return body["ros__parameters"]


def _states(system: rw.System) -> dict[str, str]:
    return {c.name: c.state for c in system.controller_manager.list_controllers()}


def _positions(system: rw.System) -> list[float]:
    msg = system.latest("/joint_states")
    assert msg is not None, "nothing was published on /joint_states: is joint_state_broadcaster active?"
    by_name = dict(zip(msg.name, msg.position, strict=False))
    missing = [j for j in JOINTS if j not in by_name]
    assert not missing, f"/joint_states has no {missing} (names: {msg.name})"
    return [float(by_name[j]) for j in JOINTS]


# --------------------------------------------------------------------------------------------- description


@graded(given=True, points=1, hint="rrbot.urdf.xacro must expand with use_mock_hardware:=true mock_sensor_commands:=false into a "
        "URDF with one <ros2_control name='rrbot'> tag driving joint1 and joint2 (task 1's description).")
def test_description_processes(description_file: Path) -> None:
    hardware = _hardware(description_file, use_mock_hardware=True, mock_sensor_commands=False)
    assert hardware.name == "rrbot", f"the <ros2_control> tag is named '{hardware.name}', expected 'rrbot'"
    assert [j.name for j in hardware.joints] == JOINTS, f"<ros2_control> joints are {[j.name for j in hardware.joints]}"


@graded(points=3, hint="In <hardware>, choose the plugin with <xacro:if value='${use_mock_hardware}'>: "
        "mock_components/GenericSystem when true, else (<xacro:unless>) "
        "controlko_hardware_interface/RRBotHardwareInterface. Declare <xacro:arg name='use_mock_hardware' "
        "default='false'/> in rrbot.urdf.xacro and pass it to the macro as a parameter.")
def test_use_mock_hardware_switch(description_file: Path) -> None:
    mock = _hardware(description_file, use_mock_hardware=True)
    assert mock.hardware_plugin_name == MOCK, (
        f"with use_mock_hardware:=true the plugin is '{mock.hardware_plugin_name}', expected '{MOCK}'"
    )
    real = _hardware(description_file, use_mock_hardware=False)
    assert real.hardware_plugin_name == DRIVER, (
        f"with use_mock_hardware:=false the plugin is '{real.hardware_plugin_name}', expected the robot's driver "
        f"'{DRIVER}'"
    )


@graded(points=2, hint="With the mock, add <param name='mock_sensor_commands'>${mock_sensor_commands}</param> in "
        "<hardware>; declare <xacro:arg name='mock_sensor_commands' default='false'/> and pass it to the macro. "
        "With true, the mock then offers command interfaces such as tcp_fts_sensor/fx.")
def test_mock_sensor_commands_reaches_the_mock(description_file: Path) -> None:
    for wanted in (True, False):
        urdf = process_xacro(description_file, use_mock_hardware=True, mock_sensor_commands=wanted)
        (hardware,) = parse_ros2_control(urdf)
        value = hardware.hardware_parameters.get("mock_sensor_commands")
        assert value is not None, "<hardware> has no <param name='mock_sensor_commands'>"
        assert value.strip().lower() == str(wanted).lower(), (
            f"with mock_sensor_commands:={str(wanted).lower()} the param is '{value}'"
        )
        rm = ResourceManager(urdf)
        try:
            assert rm.command_interface_exists("tcp_fts_sensor/fx") is wanted, (
                f"with mock_sensor_commands:={str(wanted).lower()} the command interface tcp_fts_sensor/fx "
                f"{'is missing' if wanted else 'exists'}"
            )
        finally:
            rm.shutdown_components()


# --------------------------------------------------------------------------------------------- controllers YAML


@graded(points=1, hint="controller_manager: ros__parameters: update_rate: 100 (the loop's rate in Hz).")
def test_update_rate(controllers_yaml: dict[str, Any]) -> None:
    rate = _manager_section(controllers_yaml).get("update_rate")
    assert rate is not None, "controller_manager sets no update_rate"
    assert rate == 100, f"update_rate is {rate!r}, expected 100 [Hz]"


@graded(points=2, hint="Under controller_manager: ros__parameters:, declare each controller with its type: "
        "joint_state_broadcaster/JointStateBroadcaster, forward_command_controller/ForwardCommandController, "
        "joint_trajectory_controller/JointTrajectoryController.")
def test_controller_types(controllers_yaml: dict[str, Any]) -> None:
    section = _manager_section(controllers_yaml)
    for name, expected in TYPES.items():
        entry = section.get(name)
        assert isinstance(entry, dict) and "type" in entry, (
            f"controller_manager declares no '{name}' with a 'type' (declared: "
            f"{sorted(k for k, v in section.items() if isinstance(v, dict))})"
        )
        assert entry["type"] == expected, f"'{name}' has type '{entry['type']}', expected '{expected}'"


@graded(points=1, hint="forward_position_controller: ros__parameters: joints: [joint1, joint2] and "
        "interface_name: position.")
def test_forward_position_controller_parameters(controllers_yaml: dict[str, Any]) -> None:
    params = _controller_section(controllers_yaml, FPC)
    assert params.get("joints") == JOINTS, f"{FPC} joints are {params.get('joints')!r}, expected {JOINTS}"
    assert params.get("interface_name") == "position", (
        f"{FPC} interface_name is {params.get('interface_name')!r}, expected 'position'"
    )


@graded(points=2, hint="joint_trajectory_controller: ros__parameters: joints: [joint1, joint2], "
        "command_interfaces: [position], state_interfaces: [position, velocity].")
def test_joint_trajectory_controller_interfaces(controllers_yaml: dict[str, Any]) -> None:
    params = _controller_section(controllers_yaml, JTC)
    assert params.get("joints") == JOINTS, f"{JTC} joints are {params.get('joints')!r}, expected {JOINTS}"
    assert params.get("command_interfaces") == ["position"], (
        f"{JTC} command_interfaces are {params.get('command_interfaces')!r}, expected ['position']"
    )
    assert params.get("state_interfaces") == ["position", "velocity"], (
        f"{JTC} state_interfaces are {params.get('state_interfaces')!r}, expected ['position', 'velocity']"
    )


@graded(points=1, hint="joint_trajectory_controller also sets allow_partial_joints_goal: false and "
        "constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}, as in the workshop.")
def test_joint_trajectory_controller_constraints(controllers_yaml: dict[str, Any]) -> None:
    params = _controller_section(controllers_yaml, JTC)
    assert params.get("allow_partial_joints_goal") is False, (
        f"{JTC} allow_partial_joints_goal is {params.get('allow_partial_joints_goal')!r}, expected false"
    )
    constraints = params.get("constraints")
    assert isinstance(constraints, dict), f"{JTC} has no 'constraints:' mapping"
    for key, expected in (("stopped_velocity_tolerance", 0.01), ("goal_time", 0.0)):
        value = constraints.get(key)
        assert isinstance(value, int | float) and math.isclose(value, expected, abs_tol=1e-9), (
            f"{JTC} constraints.{key} is {value!r}, expected {expected}"
        )


@graded(given=True, points=1, hint="Every controller in the file must configure, and use only parameters it declares in "
        "Jazzy: for example the workshop's state_publish_rate no longer exists in the trajectory controller.")
def test_parameters_valid_in_jazzy(controllers_file: Path) -> None:
    config = rw.params.load_controllers_yaml(controllers_file)
    names = sorted(config.controller_types)
    assert names, "the file declares no controllers"
    system = bringup("rrbot", config, inactive=names, name="task02_parameter_check")
    try:
        cm = system.controller_manager
        for name in names:
            listener = cm.get_controller(name).param_listener
            unused = listener.undeclared if listener is not None else []
            assert not unused, f"'{name}' does not declare the parameter(s) {unused} in Jazzy; remove them"
    finally:
        system.shutdown()


# --------------------------------------------------------------------------------------------- bringup


@graded(points=2, hint="start_rrbot() brings the robot up on mock hardware (rw.bringup with the xacro and YAML "
        "files of the task and xacro_args) and activates joint_state_broadcaster, then forward_position_controller.")
def test_start_rrbot_activates_controllers(start: Callable[..., rw.System]) -> None:
    system = start()
    plugins = [h.hardware_plugin_name for h in system.hardware_infos]
    assert plugins == [MOCK], f"the system's hardware is {plugins}, expected [{MOCK!r}] (use_mock_hardware=True)"
    states = _states(system)
    for name in (JSB, FPC):
        assert states.get(name) == "active", f"'{name}' is {states.get(name, 'not loaded')}, expected active"


@graded(points=1, hint="Load and configure the robot controller that was not chosen without activating it "
        "(as `spawner <name> --inactive`): joint_trajectory_controller by default, forward_position_controller "
        "when robot_controller='joint_trajectory_controller'.")
def test_other_controller_loaded_inactive(start: Callable[..., rw.System]) -> None:
    for chosen, other in ((FPC, JTC), (JTC, FPC)):
        system = start(robot_controller=chosen)
        states = _states(system)
        assert states.get(chosen) == "active", f"with robot_controller='{chosen}' it is {states.get(chosen)}"
        assert states.get(other) == "inactive", (
            f"with robot_controller='{chosen}', '{other}' is {states.get(other, 'not loaded')}, expected inactive"
        )
        system.shutdown()


@graded(points=1, hint="Pass mock_sensor_commands on to xacro: start_rrbot(mock_sensor_commands=True) gives the "
        "mock a command interface per sensor state, such as tcp_fts_sensor/fx.")
def test_start_rrbot_passes_mock_sensor_commands(start: Callable[..., rw.System]) -> None:
    system = start(mock_sensor_commands=True)
    assert system.resource_manager.command_interface_exists("tcp_fts_sensor/fx"), (
        "start_rrbot(mock_sensor_commands=True): the hardware has no command interface tcp_fts_sensor/fx"
    )


@graded(points=3, hint="With the mock and forward_position_controller active, [0.7, 0.7] published on "
        "/forward_position_controller/commands must be the joint positions on /joint_states 0.1 s later.")
def test_forward_command_reaches_the_joints(start: Callable[..., rw.System]) -> None:
    system = start()
    system.publish(f"/{FPC}/commands", Float64MultiArray(data=[0.7, 0.7]))
    system.spin(0.1)
    positions = _positions(system)
    assert positions == pytest.approx([0.7, 0.7], abs=1e-9), f"joint positions are {positions}, expected [0.7, 0.7]"


@graded(points=4, hint="start_rrbot(robot_controller='joint_trajectory_controller') activates the trajectory "
        "controller; driven by the test goal publisher (a goal every 6 s, reached in 3 s) the joints must reach "
        "[0.785, 0.785], [0, 0], [-0.785, -0.785], [0, 0] in turn.")
def test_joint_trajectory_controller_reaches_the_goals(start: Callable[..., rw.System]) -> None:
    system = start(robot_controller=JTC)
    assert _states(system).get(JTC) == "active", f"'{JTC}' is not active"
    publisher = JointTrajectoryGoalPublisher(system.bus)
    system.controller_manager.add_cycle_hook(publisher)
    system.spin(publisher.wait_sec_between_publish)  # the first goal goes out one period after the start
    for goal in DEFAULT_GOALS:
        system.spin(publisher.wait_sec_between_publish)  # 3 s of motion, then 3 s standing at the goal
        positions = _positions(system)
        assert positions == pytest.approx(list(goal), abs=GOAL_TOL), (
            f"after the goal {list(goal)} the joints are at {[round(p, 4) for p in positions]}"
        )
