"""Grader of task 11: two RRBots in one description, under one controller manager.

The specification (the exercise's xacro header, its TODOs and notebook 11):

* ``multi_rrbot_description/urdf/multi_rrbot.urdf.xacro`` takes ``prefix_1`` (``r1_``), ``prefix_2`` (``r2_``),
  ``spacing`` (1.5 m) and ``use_mock_hardware`` (true); it places two RRBots (the library's macros) on a ``world``
  link, robot 1 at ``y = +spacing/2`` and robot 2 at ``y = -spacing/2`` (to 1 µm, for any spacing); every link,
  joint, sensor, GPIO and hardware component carries its robot's prefix, whatever the prefixes, so the two never
  collide; ``use_mock_hardware`` chooses both robots' hardware;
* giving both robots the same prefix is refused with an error that names the duplicate;
* ``multi_rrbot_bringup/config/multi_rrbot_controllers.yaml``: one ``joint_state_broadcaster`` and, per robot,
  ``<prefix>forward_position_controller`` and ``<prefix>joint_trajectory_controller`` on that robot's joints (joint1,
  then joint2), configured as in task 2 (position commands; position and velocity states); only parameters Jazzy's
  controllers declare. Each controller's ``type`` under the controller manager or in its own section, block or flow
  style (Jazzy reads both);
* running, each robot follows its own controllers (to 1 mrad), and stopping either robot's controllers leaves the
  other one running.

One slip costs the rule it breaks. The description's checks each judge one rule, with the default prefixes where the
rule is not about prefixes; the YAML's checks judge the declarations, the joints and interfaces, and the parameters
apart. The running checks run the learner's files; a file that breaks a rule its own checks judge is replaced there
by the library's (``descriptions/multi_rrbot/``), so they judge what the other file brings. A check that builds on
another names it (``graded(after=...)``). The library's description also stands for what the task asks in a
generated check, which runs the learner's xacro and it side by side on arguments within what the task allows.
"""

from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NoReturn

import description_compare
import pytest
import yaml_places
from hypothesis import strategies as st

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import first_failure, graded
from rrbot_workshop.description import descriptions_root, parse_ros2_control, process_xacro
from rrbot_workshop.msgs import Float64MultiArray, JointTrajectory, JointTrajectoryPoint
from rrbot_workshop.tools.lint import lint_controllers

TASK = 11
DESCRIPTION = "multi_rrbot_description/urdf/multi_rrbot.urdf.xacro"
CONTROLLERS = "multi_rrbot_bringup/config/multi_rrbot_controllers.yaml"
JSB = "joint_state_broadcaster"
JSB_TYPE = "joint_state_broadcaster/JointStateBroadcaster"
PREFIXES = ("r1_", "r2_")
FPC, JTC = "forward_position_controller", "joint_trajectory_controller"
TYPES = {FPC: "forward_command_controller/ForwardCommandController",
         JTC: "joint_trajectory_controller/JointTrajectoryController"}
MOCK = "mock_components/GenericSystem"
#: How far a joint may end from where its controller sent it [rad] (the task: "within 1 mrad").
POSITION_TOLERANCE = 1e-3
#: How far a pedestal may stand from +-spacing/2 [m] (the task: "to 1 µm").
PLACEMENT_TOLERANCE = 1e-6


def _reference(relative: str = "urdf/multi_rrbot.urdf.xacro") -> Path:
    return descriptions_root() / "multi_rrbot" / relative


@pytest.fixture(scope="module")
def description_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, DESCRIPTION)


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


def _fail(message: str) -> NoReturn:
    """Fail the check with ``message`` as its whole reason."""
    raise AssertionError(message) from None


_args = description_compare.arguments
_clean = description_compare.as_shown


# --------------------------------------------------------------------------------------------- the description


@functools.cache
def _expand(path: Path, args: tuple[tuple[str, Any], ...]) -> str | rw.RRBotWorkshopError:
    """The learner's description expanded with ``args``, once per grading (or the error xacro gave)."""
    try:
        return process_xacro(path, **dict(args))
    except rw.RRBotWorkshopError as exc:
        return exc


def _urdf(path: Path, **args: Any) -> str:
    urdf = _expand(path, tuple(sorted(args.items())))
    if isinstance(urdf, rw.RRBotWorkshopError):
        _fail(f"your {path.name} does not process with {_args(**args)}: {_clean(str(urdf), path)}")
    return urdf


def _numbers(text: str | None) -> bool:
    try:
        return len([float(v) for v in (text or "0 0 0").split()]) == 3
    except ValueError:
        return False


def _placed_anywhere(urdf: str) -> str:
    """The URDF with every <origin> that is not three numbers put at 0 0 0: where the robots stand is side_by_side's
    rule, so the checks of names and hardware take it as given."""
    root = ET.fromstring(urdf.lstrip())
    bad = [o for o in root.iter("origin") if not (_numbers(o.get("xyz")) and _numbers(o.get("rpy")))]
    for origin in bad:
        origin.set("xyz", "0 0 0")
        origin.set("rpy", "0 0 0")
    return ET.tostring(root, encoding="unicode") if bad else urdf


def _infos(path: Path, **args: Any) -> list[Any]:
    """The hardware components of the learner's description; none when it has no <ros2_control> tag."""
    urdf = _urdf(path, **args)
    if not ET.fromstring(urdf.lstrip()).findall("ros2_control"):
        return []
    try:
        return parse_ros2_control(_placed_anywhere(urdf))
    except rw.DescriptionError as exc:
        _fail(f"your {path.name} with {_args(**args)} is refused: {_clean(str(exc), path)}")


def _names(robot: ET.Element, infos: list[Any]) -> list[str]:
    names = [str(e.get("name")) for e in (*robot.findall("link"), *robot.findall("joint"))]
    names += [info.name for info in infos] + [j.name for i in infos for j in i.joints]
    names += [s.name for i in infos for s in i.sensors] + [g.name for i in infos for g in i.gpios]
    return names


def _mount(robot: ET.Element, prefix: str) -> tuple[str, list[float]] | None:
    """(parent link, xyz) of the joint that holds ``<prefix>base_link``, or None."""
    for joint in robot.findall("joint"):
        child, parent = joint.find("child"), joint.find("parent")
        if child is not None and child.get("link") == f"{prefix}base_link" and parent is not None:
            origin = joint.find("origin")
            xyz = (origin.get("xyz") if origin is not None else None) or "0 0 0"
            try:
                return str(parent.get("link")), [float(v) for v in xyz.split()]
            except ValueError:
                _fail(f"the joint holding {prefix}base_link has <origin xyz=\"{xyz}\">, which is not three numbers: "
                      "compute inside ${...}")
    return None


def _line(path: Path, *needles: str) -> str:
    """``"<file>, line N"``: the first line of the learner's xacro holding every needle (not an <xacro:arg>
    declaration), or the file's name alone."""
    try:
        lines = path.read_text().splitlines()
    except OSError:
        return path.name
    for number, text in enumerate(lines, 1):
        if all(n in text for n in needles) and "<xacro:arg " not in text:
            return f"{path.name}, line {number}"
    return path.name


def _robot_at(path: Path, which: int) -> str:
    """Where robot ``which`` (1 or 2) is made: the first use of its prefix argument."""
    return _line(path, f"$(arg prefix_{which})")


def _tag_at(path: Path, which: int) -> str:
    """Where robot ``which``'s <ros2_control> macro is called, else where the robot is made."""
    found = _line(path, "ros2_control", f"$(arg prefix_{which})")
    return found if found != path.name else _robot_at(path, which)


def _prefix_use(path: Path, which: int) -> str:
    """Where the learner hands prefix ``which`` to a <ros2_control> macro, in words."""
    tag = _line(path, "ros2_control", f"$(arg prefix_{which})")
    if tag != path.name:
        return f"see {tag}"
    if _robot_at(path, which) != path.name:
        return f"no <ros2_control> macro call in {path.name} takes $(arg prefix_{which})"
    return f"$(arg prefix_{which}) is used nowhere in {path.name}"


def _check_prefixes(path: Path) -> None:
    for prefixes in (PREFIXES, ("left_", "right_"), ("r2_", "r1_"), ("a_", "b_")):
        args = {"prefix_1": prefixes[0], "prefix_2": prefixes[1]}
        infos = _infos(path, **args)
        where = f"your {path.name} with {_args(**args)}"
        assert infos, f"{where} declares no hardware component yet (no <ros2_control> tag); the task asks for two, one per robot"
        assert len(infos) == 2, (
            f"{where} declares {len(infos)} hardware component(s) ({[i.name for i in infos]}); the task asks for two, "
            "one <ros2_control> tag per robot")
        for which, prefix in enumerate(prefixes, 1):
            mine = [i for i in infos if i.name.startswith(prefix)]
            other = 3 - which if len(mine) > 1 else which  # two of one prefix: the other robot's tag is at fault
            assert len(mine) == 1, (
                f"{where}: {len(mine)} hardware components' names start with '{prefix}' (components: "
                f"{[i.name for i in infos]}); robot {other}'s <ros2_control> tag takes prefix_{other} ("
                f"{_prefix_use(path, other)})")
            joints = sorted(j.name for j in mine[0].joints)
            assert joints == [f"{prefix}joint1", f"{prefix}joint2"], (
                f"{where}: component '{mine[0].name}' has the joints {joints}, expected {prefix}joint1 and {prefix}joint2")
            sensors, gpios = [s.name for s in mine[0].sensors], [g.name for g in mine[0].gpios]
            assert sensors == [f"{prefix}tcp_fts_sensor"], (
                f"{where}: component '{mine[0].name}' has the sensors {sensors}, expected ['{prefix}tcp_fts_sensor']")
            assert gpios == [f"{prefix}flange_gpios"], (
                f"{where}: component '{mine[0].name}' has the GPIOs {gpios}, expected ['{prefix}flange_gpios']")
        stray = sorted(n for n in _names(ET.fromstring(_urdf(path, **args)), infos)
                       if n != "world" and not n.startswith(prefixes))
        assert not stray, f"{where} has names that start with neither prefix: {stray}; every name comes from a prefix"


def _check_placement(path: Path) -> None:
    for spacing in (1.5, 3.0, 0.8):
        robot = ET.fromstring(_urdf(path, spacing=spacing))
        for prefix, sign, which in zip(PREFIXES, (1, -1), (1, 2), strict=True):
            mount = _mount(robot, prefix)
            where = f"your {path.name} with spacing:={spacing:g}"
            made = _robot_at(path, which)
            assert mount is not None, (
                f"{where}: no joint holds {prefix}base_link, so robot {which} stands nowhere"
                + (f" (robot {which} is made at {made.split(', ')[1]})" if ", line" in made else ""))
            parent, xyz = mount
            assert parent == "world", (
                f"{_robot_at(path, which)}: with spacing:={spacing:g}, {prefix}base_link hangs from '{parent}'; the task "
                "says from 'world'")
            expected = [0.0, sign * spacing / 2, 0.0]
            assert len(xyz) == 3 and all(math.isclose(a, b, abs_tol=PLACEMENT_TOLERANCE)
                                         for a, b in zip(xyz, expected, strict=True)), (
                f"{_robot_at(path, which)}: with spacing:={spacing:g}, robot {which} stands at {xyz}; expected "
                f"{expected} (spacing/2 = {spacing / 2:g} m on the {'+' if sign > 0 else '-'}y side, from the spacing "
                "argument)")


def _check_hardware_switch(path: Path) -> None:
    for mock in (True, False):
        expected = {i.hardware_plugin_name for i in parse_ros2_control(_reference_urdf(use_mock_hardware=mock))}
        infos = _infos(path, use_mock_hardware=mock)
        assert infos, f"your {path.name} declares no hardware component (no <ros2_control> tag) yet"
        for info in infos:
            assert info.hardware_plugin_name in expected, (
                f"{_tag_at(path, 2 if info.name.startswith(PREFIXES[1]) else 1)}: with "
                f"use_mock_hardware:={str(mock).lower()} the component '{info.name}' uses the plugin "
                f"'{info.hardware_plugin_name}', expected '{sorted(expected)[0]}': pass the argument on to each "
                "robot's <ros2_control> macro")


def _check_same_prefix(path: Path) -> None:
    for prefix in ("r1_", "twin_"):
        args = {"prefix_1": prefix, "prefix_2": prefix}
        try:
            urdf = process_xacro(path, **args)
            parse_ros2_control(urdf)
        except rw.DescriptionError as exc:
            message = _clean(str(exc), path)
            assert "twice" in message and prefix in message, (
                f"your {path.name} with {_args(**args)} is refused, but not for a name given twice: {message}")
        else:
            _fail(f"your {path.name} with {_args(**args)} is accepted; two robots with one prefix must be refused, "
                  "with an error naming the duplicate: every name of robot 2 must come from prefix_2")


@functools.cache
def _reference_urdf(**args: Any) -> str:
    return process_xacro(_reference(), **args)


@functools.cache
def _description_fault(path: Path) -> str:
    """Why the description breaks a rule its own checks judge, or ""; the running checks then use the library's."""
    return first_failure((_check_prefixes, _check_placement, _check_hardware_switch, _check_same_prefix), path)


# --------------------------------------------------------------------------------------------- 11.1 the description


@graded(given=True, points=1, hint=(
    "Task 11.1: multi_rrbot.urdf.xacro must process with its default arguments (prefix_1:=r1_ prefix_2:=r2_ "
    "spacing:=1.5 use_mock_hardware:=true).",
    "The error names the file and the line: run rw.description.process_xacro(path) in notebook 11 to see it.",
    "Every $(arg ...) needs its <xacro:arg>, every macro its <xacro:include> (the RRBot macros: $(find rrbot)/urdf/...).",
))
def test_description_processes(description_file: Path) -> None:
    _urdf(description_file)


@graded(points=3, after=("test_description_processes",), hint=(
    "Task 11.1: every name a robot brings (links, joints, the force-torque sensor, the GPIO block and its "
    "<ros2_control> component) must come from that robot's prefix argument, whatever prefixes are given.",
    "Instantiate the library's rrbot and rrbot_ros2_control macros twice, passing prefix=\"$(arg prefix_1)\" to one "
    "pair and prefix=\"$(arg prefix_2)\" to the other; the macros put the prefix before every name themselves.",
    "<xacro:rrbot prefix=\"$(arg prefix_1)\" parent=\"world\"> ... </xacro:rrbot> and "
    "<xacro:rrbot_ros2_control name=\"rrbot\" prefix=\"$(arg prefix_1)\" .../>: never a name written out"))
def test_two_prefixed_robots(description_file: Path) -> None:
    _check_prefixes(description_file)


@graded(points=1, after=("test_description_processes",), hint=(
    "Task 11.1: the pedestals stand `spacing` apart along y, centred on the world origin: robot 1 at +spacing/2, "
    "robot 2 at -spacing/2, for any spacing (checked to 1 µm).",
    "Compute the y of each robot's <origin> from the argument inside a xacro expression: ${...} can use $(arg spacing).",
    "<origin xyz=\"0 ${$(arg spacing) / 2} 0\" rpy=\"0 0 0\"/>   (robot 1; robot 2 on the other side)"))
def test_side_by_side(description_file: Path) -> None:
    _check_placement(description_file)


@graded(points=1, after=("test_description_processes", "test_two_prefixed_robots"), hint=(
    "Task 11.1: use_mock_hardware chooses the hardware of BOTH robots: true gives mock_components/GenericSystem, "
    "false the RRBot macro's other plugin.",
    "Pass the file's argument on to each rrbot_ros2_control macro: use_mock_hardware=\"$(arg use_mock_hardware)\". "
    "Its own default is true, so leaving it out only looks right with the default.",
    "<xacro:rrbot_ros2_control ... use_mock_hardware=\"$(arg use_mock_hardware)\"/> for each robot"))
def test_use_mock_hardware_reaches_both_robots(description_file: Path) -> None:
    _check_hardware_switch(description_file)


@graded(points=1, after=("test_two_prefixed_robots",), hint=(
    "Task 11.1: with the same prefix twice, the URDF must be refused with an error that names the duplicate name. "
    "That holds when every name comes from the prefix arguments and nothing is written out.",
    "Try it: rw.bringup(your_xacro, xacro_args={'prefix_1': 'r1_', 'prefix_2': 'r1_'}) must raise "
    "rw.DescriptionError ('... is declared twice').",
    "Do not give either robot a fixed name (name=\"rrbot_1\" prefix=\"r1_\"): write prefix=\"$(arg prefix_2)\" for robot 2."))
def test_same_prefix_twice_is_a_clear_error(description_file: Path) -> None:
    _check_same_prefix(description_file)


@graded(points=1, after=("test_two_prefixed_robots", "test_side_by_side", "test_use_mock_hardware_reaches_both_robots",
                         "test_same_prefix_twice_is_a_clear_error"), hint=(
    "Task 11.1: for any prefixes, spacing and use_mock_hardware, your description must give the same links, joints, "
    "placements and hardware components as two RRBots placed as the task says.",
    "Every name from a prefix argument, every number from spacing, and use_mock_hardware passed on to both "
    "rrbot_ros2_control macros; the world link is the only name of your own.",
    "Process your file with the arguments the reason names and compare its <joint> elements with the task's text."))
def test_description_matches_the_task_for_any_arguments(description_file: Path) -> None:
    prefix = st.sampled_from(["r1_", "r2_", "a_", "b_", "left_", "right_", "robot_a_", "arm2_"])
    scenario = st.fixed_dictionaries({
        "prefix_1": prefix, "prefix_2": prefix,
        "spacing": st.sampled_from([1.5, 0.5, 1.0, 2.25, 3.0, 0.8]),
        "use_mock_hardware": st.booleans(),
    }).filter(lambda a: a["prefix_1"] != a["prefix_2"])

    found = description_compare.first_difference(description_file, _reference(), scenario)
    assert not found, found


# --------------------------------------------------------------------------------------------- 11.2 the YAML


def _controllers() -> list[str]:
    return [prefix + kind for prefix in PREFIXES for kind in (FPC, JTC)]


def _check_declared(path: Path) -> None:
    cfg = yaml_places.load(path)
    names = yaml_places.declared(cfg)
    broadcasters = [n for n in names if yaml_places.type_of(cfg, n) == JSB_TYPE]
    assert broadcasters == [JSB], (
        f"{path.name} declares the joint state broadcasters {broadcasters}; the task asks for one, named '{JSB}', for "
        f"both robots (declared: {names})")
    for name in _controllers():
        found = yaml_places.type_of(cfg, name)
        assert found is not None, (
            f"{path.name} declares no '{name}' with a type (declared: {names}); give it one under controller_manager's "
            "ros__parameters (or in its own section): one controller of each kind per robot, named with its prefix")
        expected = TYPES[name[len("r1_"):]]
        assert found == expected, (
            f"{yaml_places.type_at(path, cfg, name)}: '{name}' has the type '{found}'; the task says '{expected}'")


def _check_on_their_robots(path: Path) -> None:
    cfg = yaml_places.load(path)
    for name in _controllers():
        prefix, kind = name[:3], name[3:]
        params = yaml_places.parameters(cfg, name)
        keys = yaml_places.section_keys(cfg, name)
        if not params:
            _fail(f"{path.name} gives '{name}' no parameters: it needs its own section, '{name}:' with "
                  f"'ros__parameters:' under it (sections: {sorted(cfg.section_names()) or 'none'})")
        joints = [f"{prefix}joint1", f"{prefix}joint2"]
        assert params.get("joints") == joints, (
            f"{yaml_places.at(path, keys, 'joints')}: '{name}' has the joints {params.get('joints')!r}; the task says "
            f"{joints}, in that order (its robot's joints, joint1 first as in task 2)")
        if kind == FPC:
            assert params.get("interface_name") == "position", (
                f"{yaml_places.at(path, keys, 'interface_name')}: '{name}' commands the interface "
                f"{params.get('interface_name')!r}; the task says 'position'")
        else:
            assert params.get("command_interfaces") == ["position"], (
                f"{yaml_places.at(path, keys, 'command_interfaces')}: '{name}' has the command_interfaces "
                f"{params.get('command_interfaces')!r}; the task says [position]")
            states = params.get("state_interfaces")
            assert isinstance(states, list) and sorted(states) == ["position", "velocity"], (
                f"{yaml_places.at(path, keys, 'state_interfaces')}: '{name}' has the state_interfaces {states!r}; the "
                "task says [position, velocity]")


@functools.cache
def _lint(path: Path) -> list[str]:
    """What Jazzy would refuse or ignore in the parameters of the controllers declared with the task's types: lint's
    errors and the parameters no controller declares. A controller with another type is controllers_declared's rule,
    and so is every ``type`` itself: their findings are left out."""
    cfg = yaml_places.load(path)
    judged = [name for name in (JSB, *_controllers())
              if yaml_places.type_of(cfg, name) == (JSB_TYPE if name == JSB else TYPES[name[len("r1_"):]])]
    return [f"{path.name}, line {f.line}: {f.message}" if f.line else f"{path.name}: {f.message}"
            for f in lint_controllers(path)
            if (f.level == "error" or "declares no parameter" in f.message) and f.where != "type"
            and any(f.where.startswith(f"{name}.") and f.where != f"{name}.type" for name in judged)]


def _check_jazzy_parameters(path: Path) -> None:
    cfg = yaml_places.load(path)
    if not set(_controllers()) & set(yaml_places.declared(cfg)):
        _fail(f"{path.name} declares none of the robots' controllers yet, so their parameters cannot be tried (see "
              "controllers_declared)")
    found = _lint(path)
    assert not found, f"{found[0]}" + (f" (and {len(found) - 1} more)" if len(found) > 1 else "")


@functools.cache
def _yaml_fault(path: Path) -> str:
    """Why the YAML breaks a rule its own checks judge, or ""; the running checks then use the library's."""
    return first_failure((_check_declared, _check_on_their_robots, _check_jazzy_parameters), path)


@graded(given=True, points=1, hint=(
    "Task 11.2: multi_rrbot_controllers.yaml must be YAML the controller manager reads: controller_manager with "
    "ros__parameters, each node with its ros__parameters.",
    "The error names the line; `rrbot-workshop lint multi_rrbot_controllers.yaml` says the same.",
    "controller_manager:\n  ros__parameters:\n    update_rate: 100",
))
def test_yaml_loads(controllers_file: Path) -> None:
    yaml_places.load(controllers_file)


@graded(points=2, after=("test_yaml_loads",), hint=(
    "Task 11.2: one joint_state_broadcaster for both robots, and per robot a forward position controller and a "
    "trajectory controller named with the robot's prefix: two controllers cannot share a name in one controller "
    "manager.",
    "Give r1_forward_position_controller, r1_joint_trajectory_controller, r2_... their types under "
    "controller_manager's ros__parameters (or `type:` in each controller's own section: Jazzy reads both).",
    "r2_forward_position_controller:\n  type: forward_command_controller/ForwardCommandController   (under "
    "controller_manager: ros__parameters:)"))
def test_controllers_declared(controllers_file: Path) -> None:
    _check_declared(controllers_file)


@graded(points=2, after=("test_controllers_declared",), hint=(
    "Task 11.2: each robot's controllers work on that robot's joints only, joint1 then joint2 (the order of the "
    "numbers in a command), configured as in task 2: position commands; position and velocity states.",
    "Each controller's own section, '<name>: ros__parameters:', with joints (and interface_name for the forward "
    "controller, command_interfaces and state_interfaces for the trajectory controller).",
    "r2_forward_position_controller:\n  ros__parameters:\n    joints: [r2_joint1, r2_joint2]\n    interface_name: position"))
def test_controllers_on_their_robots(controllers_file: Path) -> None:
    _check_on_their_robots(controllers_file)


@graded(points=1, after=("test_controllers_declared", "test_controllers_on_their_robots"), hint=(
    "Task 11.2: the robots' controllers take only parameters Jazzy's controllers declare (Jazzy ignores the others, "
    "or refuses the controller).",
    "`rrbot-workshop lint multi_rrbot_controllers.yaml` lists each one with its line; task 2's state_publish_rate, "
    "for one, no longer exists.",
    "Delete the line the reason names."))
def test_parameters_valid_in_jazzy(controllers_file: Path) -> None:
    _check_jazzy_parameters(controllers_file)


# --------------------------------------------------------------------------------------------- running

#: The checks whose rules the running checks build on: a file breaking one of them is replaced by the library's.
_FILE_RULES = ("test_description_processes", "test_two_prefixed_robots", "test_side_by_side",
               "test_use_mock_hardware_reaches_both_robots", "test_same_prefix_twice_is_a_clear_error",
               "test_yaml_loads", "test_controllers_declared", "test_controllers_on_their_robots",
               "test_parameters_valid_in_jazzy")


def _description_broken(path: Path) -> str:
    try:
        _urdf(path)
    except AssertionError as exc:
        return str(exc)
    return _description_fault(path)


def _yaml_broken(path: Path) -> str:
    try:
        yaml_places.load(path)
    except AssertionError as exc:
        return str(exc)
    return _yaml_fault(path)


@contextmanager
def _system(description_file: Path, controllers_file: Path, spawn: list[str]) -> Iterator[tuple[System, str]]:
    """The system of the learner's files, a file that breaks a rule judged above replaced by the library's; yields it
    with a note of what stood in (for the reason)."""
    description, controllers, notes = description_file, controllers_file, []
    if _description_broken(description_file):
        description = _reference()
        notes.append(f"the library's {description.name}")
    if _yaml_broken(controllers_file):
        controllers = _reference("config/multi_rrbot_controllers.yaml")
        notes.append(f"the library's {controllers.name}")
    if len(notes) == 2:
        _fail("neither of your files follows the task yet, so nothing of yours can run: fix the description and the "
              "controllers YAML first")
    note = f" (with {notes[0]} standing in for yours, which breaks a rule judged above)" if notes else ""
    try:
        system = bringup(description, controllers, spawn=spawn)
    except rw.RRBotWorkshopError as exc:
        text = _clean(_clean(str(exc), description_file), controllers_file)
        _fail(f"the system does not start from your files with the controllers {spawn}{note}: {text}")
    try:
        yield system, note
    finally:
        system.shutdown()


def _joints(system: System) -> dict[str, float]:
    msg = system.latest("/joint_states")
    return dict(zip(msg.name, msg.position, strict=True)) if msg is not None else {}


def _states(cm: Any) -> dict[str, str]:
    return {c.name: c.state for c in cm.list_controllers()}


def _near(joints: dict[str, float], expected: dict[str, float]) -> bool:
    return all(n in joints and abs(joints[n] - v) <= POSITION_TOLERANCE for n, v in expected.items())


def _rounded(joints: dict[str, float]) -> dict[str, float]:
    return {n: round(v, 4) for n, v in sorted(joints.items())}


@graded(points=3, after=_FILE_RULES, hint=(
    "Task 11: each robot obeys its own controllers only, both ways round: r1's forward command moves r1 while r2's "
    "trajectory moves r2, and r2's forward command moves r2 while r1's trajectory moves r1 (within 1 mrad).",
    "Each controller's joints must be its robot's (r1_joint1, r1_joint2 for r1_...), and the broadcaster must "
    "publish all four joints; `%control list_controllers -v` shows what each claims.",
    "Bring your files up in notebook 11, send the commands the reason names and look at /joint_states."))
def test_independent_control(description_file: Path, controllers_file: Path) -> None:
    for forward, trajectory in (PREFIXES, PREFIXES[::-1]):
        spawn = [JSB, forward + FPC, trajectory + JTC]
        with _system(description_file, controllers_file, spawn) as (system, note):
            system.publish(f"/{forward}{FPC}/commands", Float64MultiArray(data=[0.5, -0.25]))
            system.publish(f"/{trajectory}{JTC}/joint_trajectory", JointTrajectory(
                joint_names=[f"{trajectory}joint1", f"{trajectory}joint2"],
                points=[JointTrajectoryPoint(positions=[-0.6, 0.3], time_from_start=1.0)]))
            system.spin(1.5)
            joints = _joints(system)
        expected = {f"{forward}joint1": 0.5, f"{forward}joint2": -0.25,
                    f"{trajectory}joint1": -0.6, f"{trajectory}joint2": 0.3}
        assert _near(joints, expected), (
            f"with {forward}{FPC} sent to [0.5, -0.25] and {trajectory}{JTC} given a trajectory to [-0.6, 0.3] in 1 s, "
            f"the joints are at {_rounded(joints)} after 1.5 s{note}; expected {expected} (within 1 mrad)")


@graded(points=1, after=_FILE_RULES, hint=(
    "Task 11: stopping one robot's controllers must leave the other robot's running, whichever robot stops.",
    "Each robot's controllers claim only its own joints, so a switch that deactivates r1_... leaves r2_... active "
    "(and the other way round).",
    "cm.switch_controllers(deactivate=['r1_forward_position_controller'], strictness='strict') must leave "
    "r2_forward_position_controller active and obeying its commands."))
def test_one_robot_stops_alone(description_file: Path, controllers_file: Path) -> None:
    with _system(description_file, controllers_file, [JSB, f"r1_{FPC}", f"r2_{FPC}"]) as (system, note):
        cm = system.controller_manager
        for stopped, running, target in (("r1_", "r2_", [0.2, 0.4]), ("r2_", "r1_", [-0.3, 0.1])):
            restart = [] if _states(cm).get(running + FPC) == "active" else [running + FPC]
            cm.switch_controllers(activate=restart, deactivate=[stopped + FPC], strictness="strict")
            before = _joints(system)
            system.publish(f"/{running}{FPC}/commands", Float64MultiArray(data=target))
            system.publish(f"/{stopped}{FPC}/commands", Float64MultiArray(data=[1.0, 1.0]))
            system.spin(0.1)
            joints = _joints(system)
            states = _states(cm)
            assert states.get(running + FPC) == "active", (
                f"after deactivating {stopped}{FPC}, {running}{FPC} is {states.get(running + FPC)!r}{note}; it must "
                "stay active")
            expected = {f"{running}joint1": target[0], f"{running}joint2": target[1],
                        f"{stopped}joint1": before.get(f"{stopped}joint1", 0.0),
                        f"{stopped}joint2": before.get(f"{stopped}joint2", 0.0)}
            assert _near(joints, expected), (
                f"with {stopped}{FPC} stopped and {running}{FPC} sent to {target}, the joints are at "
                f"{_rounded(joints)}{note}; expected {expected} (within 1 mrad)")
