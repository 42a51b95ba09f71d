"""Grader of task 2: mock hardware (the hardware switch in xacro, the controllers YAML, the bringup).

The specification (from the ROSCon 2022 workshop, task 2):

* ``rrbot.urdf.xacro`` takes the arguments ``use_mock_hardware`` and ``mock_sensor_commands``, both ``false`` by
  default, and hands them to the ``<ros2_control>`` macro as its parameters (with the same defaults). With
  ``use_mock_hardware:=true`` the one ``<hardware>`` plugin is ``mock_components/GenericSystem`` with
  ``<param name="mock_sensor_commands">`` set from the argument; with ``false`` it is the RRBot's driver,
  ``controlko_hardware_interface/RRBotHardwareInterface``. A ``<hardware>`` block holds exactly one ``<plugin>``;
* ``rrbot_controllers.yaml``: ``controller_manager`` at ``update_rate: 100`` [Hz] declaring
  ``joint_state_broadcaster`` (JointStateBroadcaster), ``forward_position_controller``
  (ForwardCommandController on ``joints [joint1, joint2]``, ``interface_name: position``) and
  ``joint_trajectory_controller`` (JointTrajectoryController on ``joints [joint1, joint2]``,
  ``command_interfaces [position]``, ``state_interfaces [position, velocity]``,
  ``allow_partial_joints_goal: false``, ``constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}``);
  only parameters that Jazzy's controllers declare;
* ``rrbot_bringup/bringup.py``: ``start_rrbot(robot_controller="forward_position_controller",
  use_mock_hardware=True, mock_sensor_commands=False)`` returns a running system at time 0 [s], its hardware chosen
  by ``use_mock_hardware``, with ``joint_state_broadcaster`` and the robot controller active, the other robot
  controller loaded and inactive; when a step after the system came up fails, it shuts the system down and
  re-raises;
* on it, ``[0.7, 0.7]`` sent to ``/forward_position_controller/commands`` is the joints' position 0.1 s later (and
  any command within the limits, in the order of ``joints``); and the joint trajectory controller, driven by the
  workshop's test goal publisher, reaches each of its four goals within 1 mrad.

Every argument is tried both ways (a hard-coded ``true`` or ``false`` fails one of them), the ``<ros2_control>``
macro is also instantiated on its own with each value of its parameters, and the bringup is run once on a copy of
the learner's files whose trajectory controller cannot load, to see that nothing is left running.
"""

from __future__ import annotations

import importlib.util
import math
import re
import shutil
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.errors import HypothesisException

import rrbot_workshop as rw
from rrbot_workshop.bringup import bringup, systems
from rrbot_workshop.controllers.goal_publishers import DEFAULT_GOALS, JointTrajectoryGoalPublisher
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware.mock import GenericSystem
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware import plugins
from rrbot_workshop.msgs import Float64MultiArray

TASK = 2
DESCRIPTION = "rrbot_description/urdf/rrbot.urdf.xacro"
MACRO = "rrbot_description/urdf/rrbot/rrbot_macro.xacro"
ROS2_CONTROL = "rrbot_description/urdf/rrbot/rrbot_macro.ros2_control.xacro"
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
GOAL_TOL = 1e-3  # [rad]: "reaches each goal within 1 mrad"
COMMAND_TOL = 1e-9  # [rad]: the mock copies each command exactly
#: Joint limits [rad] of the RRBot: commands generated within them.
LIMITS = ((math.radians(-380), math.radians(380)), (math.radians(-60), math.radians(240)))


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
        _fail(f"{controllers_file.name} is not valid YAML: {exc}")
    assert isinstance(data, dict), (
        f"{controllers_file.name} must be a mapping of node names (controller_manager, ...), not {type(data).__name__}"
    )
    return data


def _import_bringup(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None, f"{BRINGUP} cannot be loaded as a Python module"
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        sys.modules.pop(name, None)
        raise
    assert hasattr(module, "start_rrbot"), f"{BRINGUP} defines no function start_rrbot"
    return module


@pytest.fixture(scope="module")
def bringup_module(task_file: Callable[[int, str], Path]) -> ModuleType:
    return _import_bringup(task_file(TASK, BRINGUP), "rrbot_workshop_task02_bringup")


def _call(module: ModuleType, **kwargs: Any) -> Any:
    """The learner's start_rrbot(**kwargs); what it raises propagates, so the reason shows the learner's error."""
    return module.start_rrbot(**kwargs)


def _fail(message: str) -> None:
    """Fail the check with ``message`` as its whole reason."""
    raise AssertionError(message) from None


@pytest.fixture
def start(bringup_module: ModuleType) -> Iterator[Callable[..., rw.System]]:
    """``start(**kwargs)`` calls the learner's ``start_rrbot``; every system still running is shut down after."""

    def call(**kwargs: Any) -> rw.System:
        system = _call(bringup_module, **kwargs)
        assert isinstance(system, rw.System), (
            f"start_rrbot() in {BRINGUP} must return the running system (from rrbot_workshop.bringup), not "
            f"{type(system).__name__}"
        )
        assert system.running, f"start_rrbot() in {BRINGUP} returned a system that is shut down"
        return system

    yield call
    for system in list(systems().values()):
        system.shutdown()


class _DriverStandIn(GenericSystem):
    """Stands in for the RRBot's driver (task 7), so a bringup with use_mock_hardware=False can run here."""


@pytest.fixture
def driver_stand_in() -> Iterator[None]:
    plugins.register("hardware", DRIVER, _DriverStandIn)
    try:
        yield
    finally:
        plugins.unregister("hardware", DRIVER)


# --------------------------------------------------------------------------------------------- helpers


def _hardware(description_file: Path, **xacro_args: Any) -> HardwareInfo:
    urdf = process_xacro(description_file, **xacro_args)
    count = len(ET.fromstring(urdf.lstrip()).findall("ros2_control"))
    assert count == 1, f"rrbot.urdf.xacro with {_args(xacro_args)} makes {count} <ros2_control> tags; expected one"
    return parse_ros2_control(urdf)[0]


def _args(xacro_args: dict[str, Any]) -> str:
    return " ".join(f"{k}:={str(v).lower()}" for k, v in xacro_args.items()) or "no arguments"


def _plugins(urdf: str) -> list[str]:
    """The text of every <plugin> in every <hardware> of every <ros2_control> tag."""
    root = ET.fromstring(urdf.lstrip())
    return [(p.text or "").strip() for tag in root.findall("ros2_control") for hw in tag.findall("hardware")
            for p in hw.findall("plugin")]


def _check_plugin(urdf: str, expected: str, how: str) -> None:
    found = _plugins(urdf)
    assert len(found) == 1, (
        f"{how}, <hardware> holds {len(found)} <plugin> tags ({', '.join(found)}); only one branch of the switch in "
        "rrbot_macro.ros2_control.xacro may be taken"
    )
    assert found[0] == expected, f"{how}, the <hardware> plugin is '{found[0]}'; expected '{expected}'"


def _manager_section(data: dict[str, Any]) -> dict[str, Any]:
    body = data.get("controller_manager")
    assert isinstance(body, dict) and isinstance(body.get("ros__parameters"), dict), (
        "rrbot_controllers.yaml needs 'controller_manager:' with 'ros__parameters:' under it"
    )
    return body["ros__parameters"]


def _controller_section(data: dict[str, Any], name: str) -> dict[str, Any]:
    body = data.get(name)
    assert isinstance(body, dict) and isinstance(body.get("ros__parameters"), dict), (
        f"rrbot_controllers.yaml has no '{name}:' section with 'ros__parameters:' (its top-level sections: "
        f"{sorted(data)})"
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


def _rounded(values: list[float]) -> list[float]:
    return [round(v, 4) + 0.0 for v in values]


# --------------------------------------------------------------------------------------------- description


@graded(given=True, points=1, hint=(
    "rrbot.urdf.xacro must expand with use_mock_hardware:=true mock_sensor_commands:=false into a URDF with one "
    "<ros2_control name='rrbot'> tag driving joint1 and joint2 (task 1's description).",
    "Every argument you use with $(arg ...) needs a <xacro:arg name='...' default='...'/>, and every ${...} in the "
    "macro a parameter of that name.",
    "The error names the file and the line: run rw.description.process_xacro(path, use_mock_hardware=True) in the "
    "notebook to see it.",
))
def test_description_processes(description_file: Path) -> None:
    hardware = _hardware(description_file, use_mock_hardware=True, mock_sensor_commands=False)
    assert hardware.name == "rrbot", f"the <ros2_control> tag is named '{hardware.name}', expected 'rrbot'"
    joints = [j.name for j in hardware.joints]
    assert joints == JOINTS, f"the <ros2_control> joints are {joints}, expected {JOINTS}"


@graded(points=3, hint=(
    "use_mock_hardware chooses the hardware: true gives mock_components/GenericSystem, false the robot's driver "
    "controlko_hardware_interface/RRBotHardwareInterface; exactly one <plugin> either way (Jazzy's parser would "
    "silently use the first of two).",
    "In <hardware>, <xacro:if value='${use_mock_hardware}'> holds the mock's plugin and <xacro:unless "
    "value='${use_mock_hardware}'> the driver's: xacro keeps exactly one of them.",
    "<xacro:if value='${use_mock_hardware}'><plugin>mock_components/GenericSystem</plugin>...</xacro:if>"
    "<xacro:unless value='${use_mock_hardware}'><plugin>controlko_hardware_interface/RRBotHardwareInterface"
    "</plugin></xacro:unless>",
))
def test_use_mock_hardware_switch(description_file: Path) -> None:
    for wanted, expected in ((True, MOCK), (False, DRIVER)):
        urdf = process_xacro(description_file, use_mock_hardware=wanted)
        _check_plugin(urdf, expected, f"with use_mock_hardware:={str(wanted).lower()}")


@graded(points=1, hint=(
    "Without arguments the description is the real robot's: use_mock_hardware and mock_sensor_commands default to "
    "false, and the launch file asks for the mock.",
    "A <xacro:arg name='...' default='...'/> gives the value used when the argument is not given.",
    "<xacro:arg name='use_mock_hardware' default='false'/> <xacro:arg name='mock_sensor_commands' default='false'/>",
))
def test_description_defaults_to_the_driver(description_file: Path) -> None:
    _check_plugin(process_xacro(description_file), DRIVER, "with no arguments (use_mock_hardware defaults to false)")
    hardware = _hardware(description_file, use_mock_hardware=True)
    value = hardware.hardware_parameters.get("mock_sensor_commands")
    assert value is not None and value.strip().lower() == "false", (
        f"with use_mock_hardware:=true alone, <param name='mock_sensor_commands'> is {value!r}; the argument "
        "defaults to false"
    )


@graded(points=2, hint=(
    "mock_sensor_commands reaches the mock: with true it offers a command interface per sensor state "
    "(tcp_fts_sensor/fx ...), with false it does not.",
    "With the mock, add <param name='mock_sensor_commands'>${mock_sensor_commands}</param> in <hardware>; declare "
    "<xacro:arg name='mock_sensor_commands' default='false'/> and pass it to the macro.",
    "<xacro:if value='${use_mock_hardware}'><plugin>mock_components/GenericSystem</plugin><param "
    "name='mock_sensor_commands'>${mock_sensor_commands}</param></xacro:if>",
))
def test_mock_sensor_commands_reaches_the_mock(description_file: Path) -> None:
    for wanted in (True, False):
        urdf = process_xacro(description_file, use_mock_hardware=True, mock_sensor_commands=wanted)
        (hardware,) = parse_ros2_control(urdf)
        value = hardware.hardware_parameters.get("mock_sensor_commands")
        assert value is not None, (
            f"with use_mock_hardware:=true mock_sensor_commands:={str(wanted).lower()}, <hardware> has no "
            "<param name='mock_sensor_commands'>"
        )
        assert value.strip().lower() == str(wanted).lower(), (
            f"with mock_sensor_commands:={str(wanted).lower()} the <param name='mock_sensor_commands'> is '{value}'"
        )
        rm = ResourceManager(urdf)
        try:
            assert rm.command_interface_exists("tcp_fts_sensor/fx") is wanted, (
                f"with mock_sensor_commands:={str(wanted).lower()} the command interface tcp_fts_sensor/fx "
                f"{'is missing' if wanted else 'exists'}"
            )
        finally:
            rm.shutdown_components()


#: A robot of its own that includes the learner's macro files and instantiates the <ros2_control> macro with the
#: switch given as macro parameters (or left to their defaults); it declares no xacro arguments of its own.
_WRAPPER = """<?xml version="1.0"?>
<robot name="cell" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{macro}"/>
  <xacro:include filename="{ros2_control}"/>
  <link name="world"/>
  <xacro:rrbot prefix="" parent="world"><origin xyz="0 0 0" rpy="0 0 0"/></xacro:rrbot>
  <xacro:rrbot_ros2_control name="rrbot" prefix=""{params}/>
</robot>
"""


@graded(points=2, hint=(
    "The <ros2_control> macro takes the switch as its own parameters, use_mock_hardware and mock_sensor_commands, "
    "both defaulting to false; rrbot.urdf.xacro passes its arguments on to them.",
    "A macro that reads $(arg ...) itself only works in a robot file that declares those arguments, with one value for "
    "every robot; a parameter with a default is written name:=default in the macro's params.",
    "<xacro:macro name='rrbot_ros2_control' params='name prefix use_mock_hardware:=false "
    "mock_sensor_commands:=false'>, and in rrbot.urdf.xacro: use_mock_hardware='$(arg use_mock_hardware)' "
    "mock_sensor_commands='$(arg mock_sensor_commands)'.",
))
def test_macro_takes_the_switch_as_parameters(task_file: Callable[[int, str], Path]) -> None:
    macro, ros2_control = task_file(TASK, MACRO), task_file(TASK, ROS2_CONTROL)
    cases = (
        ("", DRIVER, None),
        (' use_mock_hardware="true"', MOCK, "false"),
        (' use_mock_hardware="true" mock_sensor_commands="true"', MOCK, "true"),
        (' use_mock_hardware="false"', DRIVER, None),
    )
    with tempfile.TemporaryDirectory() as folder:
        for params, expected, sensor_commands in cases:
            how = (f"with rrbot_ros2_control given{params.replace(chr(34), chr(39))}" if params
                   else "with rrbot_ros2_control given no switch parameters")
            wrapper = Path(folder) / "cell.urdf.xacro"
            wrapper.write_text(_WRAPPER.format(macro=macro, ros2_control=ros2_control, params=params))
            try:
                urdf = process_xacro(wrapper)
            except DescriptionError as exc:
                undefined = re.search(r"undefined xacro argument '([^']+)'", str(exc))
                if undefined:
                    _fail(
                        f"rrbot_ros2_control, called in a robot file of its own, needs the xacro argument "
                        f"'{undefined.group(1)}': the macro in rrbot_macro.ros2_control.xacro reads $(arg ...) itself; "
                        "take use_mock_hardware and mock_sensor_commands as parameters with default false"
                    )
                unset = re.search(r"Undefined parameters \[([^\]]*)\]", str(exc))
                if unset:
                    _fail(
                        f"{how}, rrbot_ros2_control leaves the parameter(s) {unset.group(1).replace(',', ', ')} without a value: give the "
                        "macro's switch parameters defaults in rrbot_macro.ros2_control.xacro (use_mock_hardware:=false "
                        "mock_sensor_commands:=false)"
                    )
                _fail(f"rrbot_ros2_control, called in a robot file of its own, does not expand: {exc}")
            _check_plugin(urdf, expected, how)
            if sensor_commands is not None:
                (hardware,) = parse_ros2_control(urdf)
                value = (hardware.hardware_parameters.get("mock_sensor_commands") or "").strip().lower()
                assert value == sensor_commands, (
                    f"{how}, <param name='mock_sensor_commands'> is {value!r}; expected '{sensor_commands}'"
                )


# --------------------------------------------------------------------------------------------- controllers YAML


@graded(points=1, hint=(
    "The controller manager runs its loop at 100 Hz.",
    "controller_manager: ros__parameters: update_rate is an integer in [Hz] (Jazzy refuses 100.0).",
    "controller_manager:\n  ros__parameters:\n    update_rate: 100",
))
def test_update_rate(controllers_yaml: dict[str, Any]) -> None:
    rate = _manager_section(controllers_yaml).get("update_rate")
    assert rate is not None, "rrbot_controllers.yaml: controller_manager sets no update_rate"
    assert isinstance(rate, int) and not isinstance(rate, bool), (
        f"rrbot_controllers.yaml: update_rate is {rate!r}; Jazzy's controller manager takes an integer (100, not 100.0)"
    )
    assert rate == 100, f"rrbot_controllers.yaml: update_rate is {rate!r}; the task says 100 [Hz]"


@graded(points=2, hint=(
    "The controller manager declares three controllers by name, each with its type (the plugin).",
    "Under controller_manager: ros__parameters:, an entry '<name>: {type: <package>/<Class>}' per controller.",
    "joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}, forward_position_controller: "
    "{type: forward_command_controller/ForwardCommandController}, joint_trajectory_controller: {type: "
    "joint_trajectory_controller/JointTrajectoryController}",
))
def test_controller_types(controllers_yaml: dict[str, Any]) -> None:
    section = _manager_section(controllers_yaml)
    for name, expected in TYPES.items():
        entry = section.get(name)
        assert isinstance(entry, dict) and "type" in entry, (
            f"rrbot_controllers.yaml: controller_manager declares no '{name}' with a 'type' (declared: "
            f"{sorted(k for k, v in section.items() if isinstance(v, dict))})"
        )
        assert entry["type"] == expected, (
            f"rrbot_controllers.yaml: '{name}' has type '{entry['type']}'; the task says '{expected}'"
        )


@graded(points=1, hint=(
    "forward_position_controller commands the positions of joint1 and joint2, in that order.",
    "Its own section: forward_position_controller: ros__parameters: with joints (a list) and interface_name.",
    "forward_position_controller:\n  ros__parameters:\n    joints: [joint1, joint2]\n    interface_name: position",
))
def test_forward_position_controller_parameters(controllers_yaml: dict[str, Any]) -> None:
    params = _controller_section(controllers_yaml, FPC)
    assert params.get("joints") == JOINTS, (
        f"rrbot_controllers.yaml: {FPC} joints are {params.get('joints')!r}; the task says {JOINTS}"
    )
    assert params.get("interface_name") == "position", (
        f"rrbot_controllers.yaml: {FPC} interface_name is {params.get('interface_name')!r}; the task says 'position'"
    )


@graded(points=2, hint=(
    "joint_trajectory_controller drives joint1 and joint2 in position and reads back position and velocity.",
    "Its own section: joint_trajectory_controller: ros__parameters: with joints, command_interfaces and "
    "state_interfaces (lists).",
    "joints: [joint1, joint2]\ncommand_interfaces: [position]\nstate_interfaces: [position, velocity]",
))
def test_joint_trajectory_controller_interfaces(controllers_yaml: dict[str, Any]) -> None:
    params = _controller_section(controllers_yaml, JTC)
    for key, expected in (("joints", JOINTS), ("command_interfaces", ["position"]),
                          ("state_interfaces", ["position", "velocity"])):
        assert params.get(key) == expected, (
            f"rrbot_controllers.yaml: {JTC} {key} is {params.get(key)!r}; the task says {expected}"
        )


@graded(points=1, hint=(
    "The workshop's trajectory controller refuses partial goals and counts a joint slower than 0.01 rad/s as "
    "stopped, with no time limit after a trajectory's end.",
    "allow_partial_joints_goal is a boolean; constraints is a nested mapping with stopped_velocity_tolerance [rad/s] "
    "and goal_time [s].",
    "allow_partial_joints_goal: false\nconstraints:\n  stopped_velocity_tolerance: 0.01\n  goal_time: 0.0",
))
def test_joint_trajectory_controller_constraints(controllers_yaml: dict[str, Any]) -> None:
    params = _controller_section(controllers_yaml, JTC)
    assert params.get("allow_partial_joints_goal") is False, (
        f"rrbot_controllers.yaml: {JTC} allow_partial_joints_goal is {params.get('allow_partial_joints_goal')!r}; the "
        "task says false"
    )
    constraints = params.get("constraints")
    assert isinstance(constraints, dict), f"rrbot_controllers.yaml: {JTC} has no 'constraints:' mapping"
    for key, expected in (("stopped_velocity_tolerance", 0.01), ("goal_time", 0.0)):
        value = constraints.get(key)
        assert isinstance(value, int | float) and not isinstance(value, bool) and math.isclose(
            value, expected, abs_tol=1e-9), (
            f"rrbot_controllers.yaml: {JTC} constraints.{key} is {value!r}; the task says {expected}"
        )


@graded(points=1, hint=(
    "The three controllers must configure, and use only parameters they declare in Jazzy.",
    "The workshop's state_publish_rate no longer exists in Jazzy's trajectory controller; `rrbot-workshop lint "
    "rrbot_controllers.yaml` lists every parameter Jazzy would not take.",
    "Delete the lines the reason names.",
))
def test_parameters_valid_in_jazzy(controllers_file: Path) -> None:
    config = rw.params.load_controllers_yaml(controllers_file)
    names = sorted(config.controller_types)
    missing = sorted(set(TYPES) - set(names))
    assert not missing, f"rrbot_controllers.yaml does not declare {missing} yet: there is nothing of theirs to check"
    system = bringup("rrbot", config, inactive=names, name="task02_parameter_check")
    try:
        cm = system.controller_manager
        for name in names:
            listener = cm.get_controller(name).param_listener
            unused = listener.undeclared if listener is not None else []
            assert not unused, (
                f"rrbot_controllers.yaml: '{name}' does not declare the parameter(s) {unused} in Jazzy; remove them"
            )
    finally:
        system.shutdown()


# --------------------------------------------------------------------------------------------- bringup


@graded(points=2, hint=(
    "start_rrbot() is the launch file: the robot on mock hardware, then joint_state_broadcaster, then the robot "
    "controller, both active.",
    "rw.bringup(DESCRIPTION_FILE, CONTROLLERS_FILE, xacro_args={...}, spawn=['joint_state_broadcaster']), then on "
    "system.controller_manager: load_controller, configure_controller, switch_controllers(activate=[...]).",
    "cm.load_controller(robot_controller); cm.configure_controller(robot_controller); "
    "cm.switch_controllers(activate=[robot_controller], strictness='strict')",
))
def test_start_rrbot_activates_controllers(start: Callable[..., rw.System]) -> None:
    system = start()
    plugins_used = [h.hardware_plugin_name for h in system.hardware_infos]
    assert plugins_used == [MOCK], (
        f"start_rrbot() brought up the hardware {plugins_used}; with use_mock_hardware=True it is [{MOCK!r}]"
    )
    states = _states(system)
    for name in (JSB, FPC):
        assert states.get(name) == "active", (
            f"after start_rrbot(), '{name}' is {states.get(name, 'not loaded')}; expected active"
        )


@graded(points=1, hint=(
    "start_rrbot() returns as soon as the controllers are up: the system's simulated time is still 0 s.",
    "rw.bringup and the controller manager's load/configure/switch calls take no simulated time; only "
    "system.spin() moves the clock. The launch file's delays are not needed here: each call returns when it is done.",
    "Remove any system.spin(...) from start_rrbot(); return the system right after the last switch.",
))
def test_start_rrbot_returns_at_time_zero(start: Callable[..., rw.System]) -> None:
    for chosen in (FPC, JTC):
        system = start(robot_controller=chosen)
        assert system.time == 0.0, (
            f"start_rrbot(robot_controller='{chosen}') returned the system at t = {system.time:g} s; the task says it "
            "returns at time 0 s (the controllers are up, nothing has run yet)"
        )
        system.shutdown()


@graded(points=1, hint=(
    "The robot controller that was not chosen is loaded and configured, not activated (as `spawner <name> "
    "--inactive`): joint_trajectory_controller by default, forward_position_controller when "
    "robot_controller='joint_trajectory_controller'.",
    "On system.controller_manager, load_controller(other) and configure_controller(other), without a switch.",
    "other = next(name for name in ROBOT_CONTROLLERS if name != robot_controller); cm.load_controller(other); "
    "cm.configure_controller(other)",
))
def test_other_controller_loaded_inactive(start: Callable[..., rw.System]) -> None:
    for chosen, other in ((FPC, JTC), (JTC, FPC)):
        system = start(robot_controller=chosen)
        states = _states(system)
        assert states.get(chosen) == "active", (
            f"with robot_controller='{chosen}', '{chosen}' is {states.get(chosen, 'not loaded')}; expected active"
        )
        assert states.get(other) == "inactive", (
            f"with robot_controller='{chosen}', '{other}' is {states.get(other, 'not loaded')}; expected inactive"
        )
        system.shutdown()


@graded(points=1, hint=(
    "start_rrbot(use_mock_hardware=False) brings the robot up on its own driver, "
    "controlko_hardware_interface/RRBotHardwareInterface, with the same controllers.",
    "Hand the argument on to xacro: rw.bringup(..., xacro_args={'use_mock_hardware': use_mock_hardware, ...}).",
    "xacro_args={'use_mock_hardware': use_mock_hardware, 'mock_sensor_commands': mock_sensor_commands}",
))
def test_start_rrbot_passes_use_mock_hardware(start: Callable[..., rw.System], driver_stand_in: None) -> None:
    system = start(use_mock_hardware=False)
    plugins_used = [h.hardware_plugin_name for h in system.hardware_infos]
    assert plugins_used == [DRIVER], (
        f"start_rrbot(use_mock_hardware=False) brought up the hardware {plugins_used}; expected [{DRIVER!r}] (the "
        "robot's driver)"
    )
    states = _states(system)
    assert states.get(JSB) == "active" and states.get(FPC) == "active", (
        f"start_rrbot(use_mock_hardware=False): the controllers are {states}; expected {JSB} and {FPC} active"
    )


@graded(points=1, hint=(
    "start_rrbot(mock_sensor_commands=True) gives the mock a command interface per sensor state, such as "
    "tcp_fts_sensor/fx; the default (False) does not.",
    "Hand the argument on to xacro with the others: xacro_args={..., 'mock_sensor_commands': mock_sensor_commands}.",
    "xacro_args={'use_mock_hardware': use_mock_hardware, 'mock_sensor_commands': mock_sensor_commands}",
))
def test_start_rrbot_passes_mock_sensor_commands(start: Callable[..., rw.System]) -> None:
    for wanted in (True, False):
        system = start(mock_sensor_commands=wanted)
        exists = system.resource_manager.command_interface_exists("tcp_fts_sensor/fx")
        assert exists is wanted, (
            f"start_rrbot(mock_sensor_commands={wanted}): the hardware {'has no' if wanted else 'has a'} command "
            "interface tcp_fts_sensor/fx"
        )
        system.shutdown()


@graded(points=1, hint=(
    "When a step after the system came up fails (a controller that cannot load, configure or activate), "
    "start_rrbot() shuts the system down and re-raises the error: no half-started system is left running.",
    "Wrap the steps after rw.bringup() in try/except: system.shutdown(), then `raise` (the same exception).",
    "try:\n    cm.load_controller(...) ...\nexcept Exception:\n    system.shutdown()\n    raise",
))
def test_failure_half_way_leaves_nothing_running(task_file: Callable[[int, str], Path]) -> None:
    task_folder = task_file(TASK, BRINGUP).parents[1]
    data = yaml.safe_load(task_file(TASK, CONTROLLERS).read_text())
    broken_type = "joint_trajectory_controller/NoSuchController"
    with tempfile.TemporaryDirectory() as folder:
        copy = Path(folder) / task_folder.name
        shutil.copytree(task_folder, copy, ignore=shutil.ignore_patterns("__pycache__", ".progress"))
        manager = data.get("controller_manager", {}).get("ros__parameters", {})
        assert isinstance(manager.get(JTC), dict), f"rrbot_controllers.yaml: controller_manager declares no '{JTC}'"
        manager[JTC]["type"] = broken_type
        (copy / CONTROLLERS).write_text(yaml.safe_dump(data))
        module = _import_bringup(copy / BRINGUP, "rrbot_workshop_task02_bringup_broken")
        for chosen in (FPC, JTC):
            before = set(systems())
            try:
                _call(module, robot_controller=chosen)
            except Exception:  # noqa: BLE001 - the failure is what this check provokes
                raised = True
            else:
                raised = False
            left = sorted(set(systems()) - before)
            for name in left:
                systems()[name].shutdown()
            assert raised, (
                f"with {JTC} of type '{broken_type}' (it cannot load), start_rrbot(robot_controller='{chosen}') "
                "returned instead of raising the error"
            )
            assert not left, (
                f"with {JTC} of type '{broken_type}' (it cannot load), start_rrbot(robot_controller='{chosen}') raised "
                f"but left the system {left} running: call system.shutdown() before re-raising"
            )


@graded(points=3, hint=(
    "With the mock and forward_position_controller active, [0.7, 0.7] published on "
    "/forward_position_controller/commands is the joints' position on /joint_states 0.1 s later.",
    "system.publish(topic, Float64MultiArray(data=[...])), then system.spin(0.1); the mock copies each command to "
    "the state of the same name.",
    "If the joints do not move, check forward_position_controller's joints and interface_name in the YAML, and that "
    "start_rrbot() activates it.",
))
def test_forward_command_reaches_the_joints(start: Callable[..., rw.System]) -> None:
    system = start()
    system.publish(f"/{FPC}/commands", Float64MultiArray(data=[0.7, 0.7]))
    system.spin(0.1)
    positions = _positions(system)
    assert all(abs(p - 0.7) <= COMMAND_TOL for p in positions), (
        f"0.1 s after [0.7, 0.7] was sent to /{FPC}/commands the joints are at {_rounded(positions)} rad; expected "
        "[0.7, 0.7]"
    )


@graded(points=1, hint=(
    "Any command within the limits reaches the joints, in the order of the controller's joints: the first number "
    "is joint1's, the second joint2's.",
    "The order of forward_position_controller's joints in the YAML is the order of the numbers in each command.",
    "forward_position_controller: ros__parameters: joints: [joint1, joint2]",
))
def test_forward_commands_in_joint_order(start: Callable[..., rw.System]) -> None:
    system = start()
    found: list[str] = []

    @settings(derandomize=True, database=None, deadline=None, max_examples=6,
              suppress_health_check=list(HealthCheck))
    @given(st.lists(st.tuples(st.floats(*LIMITS[0]), st.floats(*LIMITS[1]), st.integers(2, 10)),
                    min_size=1, max_size=3))
    def reaches(commands: list[tuple[float, float, int]]) -> None:
        for q1, q2, cycles in commands:
            system.publish(f"/{FPC}/commands", Float64MultiArray(data=[q1, q2]))
            system.spin_cycles(cycles)
            positions = _positions(system)
            if any(abs(p - q) > COMMAND_TOL for p, q in zip(positions, (q1, q2), strict=True)):
                found[:] = [f"[{q1:.4f}, {q2:.4f}] sent to /{FPC}/commands left the joints at {_rounded(positions)} rad "
                            f"{cycles} cycles later; the task says joint1 then joint2 take the command's values"]
                raise AssertionError(found[0])

    try:
        reaches()
    except (AssertionError, HypothesisException):
        _fail(found[0] if found else "the forward commands could not be tried")


@graded(points=4, hint=(
    "start_rrbot(robot_controller='joint_trajectory_controller') activates the trajectory controller; driven by "
    "the test goal publisher (a goal every 6 s, reached in 3 s) the joints reach [0.785, 0.785], [0, 0], "
    "[-0.785, -0.785], [0, 0] in turn, each within 1 mrad.",
    "The trajectory controller needs joints [joint1, joint2], command_interfaces [position] and state_interfaces "
    "[position, velocity] in the YAML, and start_rrbot() must activate it when it is the robot_controller.",
    "Run notebook 02's goal publisher cell: the table shows where the joints are 6 s after each goal.",
))
def test_joint_trajectory_controller_reaches_the_goals(start: Callable[..., rw.System]) -> None:
    system = start(robot_controller=JTC)
    assert _states(system).get(JTC) == "active", (
        f"start_rrbot(robot_controller='{JTC}') left '{JTC}' {_states(system).get(JTC, 'not loaded')}"
    )
    publisher = JointTrajectoryGoalPublisher(system.bus)
    system.controller_manager.add_cycle_hook(publisher)
    system.spin(publisher.wait_sec_between_publish)  # the first goal goes out one period after the start
    for goal in DEFAULT_GOALS:
        system.spin(publisher.wait_sec_between_publish)  # 3 s of motion, then 3 s standing at the goal
        positions = _positions(system)
        assert all(abs(p - g) <= GOAL_TOL for p, g in zip(positions, goal, strict=True)), (
            f"6 s after the goal {list(goal)} was sent the joints are at {_rounded(positions)} rad; expected the goal "
            "within 1 mrad"
        )
