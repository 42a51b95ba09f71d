"""Grader of task 10: RRBot on DiffBot, two robots' macros reused in one description with one controller manager.

The specification (the exercise's xacro header and TODOs, notebook 10):

* ``rrbot_on_diffbot_description/urdf/rrbot_on_diffbot.urdf.xacro`` takes ``base_prefix`` (default ``base_``),
  ``arm_prefix`` (default ``arm_``) and ``use_mock_hardware`` (default true, for both components); it reuses the
  library's DiffBot and RRBot macros unchanged: the DiffBot is the root of the tree, the RRBot stands on
  ``<base_prefix>top_plate``, 0.1 m towards the front (to 1 µm); every link, joint, sensor and GPIO carries its
  robot's prefix, whatever the prefixes;
* one ``<ros2_control>`` tag per robot: two hardware components with different names, the base's with the two wheel
  joints, the arm's with the two arm joints, the force-torque sensor and the GPIOs;
* ``rrbot_on_diffbot_bringup/config/rrbot_on_diffbot_controllers.yaml``: ``joint_state_broadcaster``,
  ``diffbot_base_controller`` (DiffDriveController on the base's wheels, wheel separation 0.55 m and radius 0.1 m,
  the description's, to 1 µm) and ``joint_trajectory_controller`` (the arm's joints, position commands, position and
  velocity states, task 2's constraints); parameters Jazzy's controllers declare;
* running, the three controllers are active at once; the base's odometry follows a circle of radius v/w (within
  5 cm) while the arm reaches its trajectory's goal (within 1 mrad); stopping either robot's controller leaves the
  other one moving;
* ``answers.py``: the original workshop's three questions, one point each.

The library's ``descriptions/rrbot_on_diffbot/`` does what the description must do: a generated-scenario check runs
the learner's xacro and it side by side on arguments within what the task allows.
"""

from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import description_compare
import pytest
from controllers_layout import read_controllers
from hypothesis import strategies as st

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import descriptions_root, parse_ros2_control, process_xacro
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint, Twist, TwistStamped, Vector3
from rrbot_workshop.tools.lint import lint_controllers

TASK = 10
DESCRIPTION = "rrbot_on_diffbot_description/urdf/rrbot_on_diffbot.urdf.xacro"
CONTROLLERS = "rrbot_on_diffbot_bringup/config/rrbot_on_diffbot_controllers.yaml"
JSB, BASE, ARM = "joint_state_broadcaster", "diffbot_base_controller", "joint_trajectory_controller"
WHEEL_SEPARATION, WHEEL_RADIUS = 0.55, 0.1  # [m], the DiffBot macro's geometry
#: Distances the task states to the micrometre (the arm's mount, the wheel geometry) [m].
LENGTH_TOLERANCE = 1e-6
#: How far the odometry may be from the circle of radius v/w [m].
CIRCLE_TOLERANCE = 0.05
#: How far an arm joint may end from its trajectory's goal [rad].
POSITION_TOLERANCE = 1e-3
#: The rules of the description the side-by-side comparison builds on: a slip in one of them shows there too.
DESCRIPTION_RULES = ("test_both_robots_in_one_tree", "test_prefix_arguments_rename_everything",
                     "test_two_hardware_components", "test_use_mock_hardware_reaches_both_components")
#: What the running checks build on: the components and their names (a YAML that breaks test_controllers_yaml's
#: rules is replaced by the library's while they run, see _running_yaml).
RUNNING_NEEDS = ("test_prefix_arguments_rename_everything", "test_two_hardware_components")


def _reference() -> Path:
    return descriptions_root() / "rrbot_on_diffbot" / "urdf" / "rrbot_on_diffbot.urdf.xacro"


_args = description_compare.arguments
_clean = description_compare.as_shown


@pytest.fixture(scope="module")
def description_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, DESCRIPTION)


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


def _urdf(description_file: Path, **args: Any) -> str:
    try:
        return process_xacro(description_file, **args)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"your {description_file.name} does not process with {_args(**args)}: "
                    f"{_clean(str(exc), description_file)}", pytrace=False)
    raise AssertionError("unreachable")


def _components(urdf: str, description_file: Path, **args: Any) -> list[Any]:
    try:
        return parse_ros2_control(urdf)
    except rw.DescriptionError as exc:
        pytest.fail(f"the <ros2_control> tags of your {description_file.name} with {_args(**args)} are refused: "
                    f"{_clean(str(exc), description_file)}", pytrace=False)
    raise AssertionError("unreachable")


def _component_with(infos: list[Any], joint: str) -> Any:
    found = [info for info in infos if joint in [j.name for j in info.joints]]
    if len(found) != 1:
        pytest.fail(f"the joint '{joint}' is in {len(found)} hardware components of your description; it must be in "
                    "exactly one.", pytrace=False)
    return found[0]


@contextmanager
def _system(description_file: Path, controllers_file: Path, spawn: list[str]) -> Iterator[System]:
    try:
        system = bringup(description_file, controllers_file, spawn=spawn)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"the system does not start from your files with the controllers {spawn}: "
                    f"{_clean(_clean(str(exc), description_file), controllers_file)}", pytrace=False)
    try:
        yield system
    finally:
        system.shutdown()


def _passes(check: Callable[[Path], None], path: Path) -> bool:
    """Whether the grader's ``check`` passes on ``path`` (run here to choose what stands in, never scored here)."""
    try:
        check(path)
    except (AssertionError, pytest.fail.Exception):
        return False
    return True


@functools.cache
def _running_files(description_file: Path, controllers_file: Path) -> tuple[Path, Path, str]:
    """The description and controllers file the running checks use: the learner's, with the library's standing in for
    one of them that its own checks refuse (a slip there costs those checks only); what stands in, said for reasons."""
    description_ok = (_passes(test_prefix_arguments_rename_everything, description_file)
                      and _passes(test_two_hardware_components, description_file))
    controllers_ok = _passes(test_controllers_yaml, controllers_file)
    if not description_ok and not controllers_ok:
        pytest.fail(f"neither your {description_file.name} nor your {controllers_file.name} is right yet (see their "
                    "checks above), so the two robots cannot run on anything of yours yet", pytrace=False)
    if not description_ok:
        return _reference(), controllers_file, f" (the library's {_reference().name} standing in for yours)"
    if not controllers_ok:
        library = descriptions_root() / "rrbot_on_diffbot" / "config" / "rrbot_on_diffbot_controllers.yaml"
        return description_file, library, f" (the library's {library.name} standing in for yours)"
    return description_file, controllers_file, ""


def _drive(system: System, v: float, w: float, seconds: float) -> None:
    for _ in range(system.clock.cycles_for(seconds)):
        system.publish(f"/{BASE}/cmd_vel", TwistStamped(twist=Twist(linear=Vector3(x=v), angular=Vector3(z=w))))
        system.spin_cycles(1)


def _joints(system: System) -> dict[str, float]:
    msg = system.latest("/joint_states")
    return dict(zip(msg.name, msg.position, strict=True)) if msg is not None else {}



# --------------------------------------------------------------------------------------------- 10.1 the tree


@graded(points=2, hint=(
    "Task 10.1: the base is the root of the tree (a mobile robot has no world link), and the arm's base_link hangs "
    "from the base's top plate, 0.1 m towards the front (checked to 1 µm).",
    "The rrbot macro takes a parent link and an <origin> block; the diffbot macro creates <prefix>top_plate. Give "
    "the arm parent=\"$(arg base_prefix)top_plate\".",
    "<xacro:diffbot prefix=\"$(arg base_prefix)\"/>\n<xacro:rrbot prefix=\"$(arg arm_prefix)\" "
    "parent=\"$(arg base_prefix)top_plate\">\n  <origin xyz=\"0.1 0 0\" rpy=\"0 0 0\"/>\n</xacro:rrbot>"))
def test_both_robots_in_one_tree(description_file: Path) -> None:
    for base, arm in (("base_", "arm_"), ("mobile_", "manip_")):
        args = {"base_prefix": base, "arm_prefix": arm}
        where = f"your {description_file.name} with {_args(**args)}"
        robot = ET.fromstring(_urdf(description_file, **args))
        links = {link.get("name") for link in robot.findall("link")}
        joints = {j.get("name"): (j.find("parent").get("link"), j.find("child").get("link"))  # type: ignore[union-attr]
                  for j in robot.findall("joint")}
        for name in (f"{base}base_link", f"{base}top_plate", f"{arm}base_link", f"{arm}link1", f"{arm}link2"):
            assert name in links, f"{where} has no link '{name}' (its links: {sorted(str(n) for n in links)})."
        roots = sorted(str(n) for n in links - {child for _parent, child in joints.values()})
        assert roots == [f"{base}base_link"], (
            f"{where}: the tree must have one root, the base's {base}base_link; its roots are {roots}.")
        mount = [(name, pc) for name, pc in joints.items() if pc[1] == f"{arm}base_link"]
        assert mount and mount[0][1][0] == f"{base}top_plate", (
            f"{where}: the arm's {arm}base_link must hang from {base}top_plate, it hangs from "
            f"{mount[0][1][0] if mount else 'nothing'}.")
        origin = robot.find(f"joint[@name='{mount[0][0]}']/origin")
        xyz = [float(v) for v in ((origin.get("xyz") if origin is not None else None) or "0 0 0").split()]
        assert len(xyz) == 3 and all(math.isclose(a, b, abs_tol=LENGTH_TOLERANCE)
                                     for a, b in zip(xyz, (0.1, 0.0, 0.0), strict=True)), (
            f"{where}: the arm stands at {xyz} on the top plate, expected [0.1, 0.0, 0.0] (0.1 m towards the front).")


@graded(points=2, after=("test_both_robots_in_one_tree",), hint=(
    "Task 10.1: every name comes from its robot's prefix argument, never written out: with other prefixes (even "
    "swapped ones), every base name starts with base_prefix and every arm name with arm_prefix.",
    "Pass prefix=\"$(arg base_prefix)\" to both DiffBot macros and prefix=\"$(arg arm_prefix)\" to both RRBot macros "
    "(and to the arm's parent link name).",
    "<xacro:diffbot_ros2_control name=\"DiffBot\" prefix=\"$(arg base_prefix)\" "
    "use_mock_hardware=\"$(arg use_mock_hardware)\"/>"))
def test_prefix_arguments_rename_everything(description_file: Path) -> None:
    for base, arm in (("b_", "a_"), ("arm_", "base_"), ("mobile_", "manip_")):
        args = {"base_prefix": base, "arm_prefix": arm}
        urdf = _urdf(description_file, **args)
        infos = _components(urdf, description_file, **args)
        robot = ET.fromstring(urdf)
        wheels = {j.name for info in infos for j in info.joints if "wheel" in j.name}
        arm_names = [j.name for info in infos for j in info.joints if j.name not in wheels]
        arm_names += [s.name for info in infos for s in info.sensors] + [g.name for info in infos for g in info.gpios]
        links_and_joints = [str(e.get("name")) for e in (*robot.findall("link"), *robot.findall("joint"))]
        where = f"your {description_file.name} with {_args(**args)}"
        assert not wheels or sorted(wheels) == [f"{base}left_wheel_joint", f"{base}right_wheel_joint"], (  # none: a
            # component left out, which two_hardware_components judges
            f"{where}: the wheel joints of its components are {sorted(wheels)}, expected {base}left_wheel_joint and "
            f"{base}right_wheel_joint.")
        wrong = sorted(n for n in arm_names if not n.startswith(arm))
        assert not wrong, f"{where}: the arm's joints, sensor or GPIOs {wrong} do not start with '{arm}'."
        stray = sorted(n for n in links_and_joints + [i.name for i in infos] if not n.startswith((base, arm)))
        assert not stray, f"{where} has names that start with neither prefix: {stray}."


# --------------------------------------------------------------------------------------------- 10.2 components


@graded(points=3, after=("test_prefix_arguments_rename_everything",), hint=(
    "Task 10.2: one <ros2_control> tag per robot (each macro writes one): two hardware components with different "
    "names, the wheels in one, the arm's joints, sensor and GPIOs in the other.",
    "Call diffbot_ros2_control and rrbot_ros2_control once each; each names its component <prefix><name>, so the "
    "prefixes keep the two names apart.",
    "<xacro:diffbot_ros2_control name=\"DiffBot\" prefix=\"$(arg base_prefix)\" use_mock_hardware=\"$(arg "
    "use_mock_hardware)\"/>\n<xacro:rrbot_ros2_control name=\"RRBot\" prefix=\"$(arg arm_prefix)\" "
    "use_mock_hardware=\"$(arg use_mock_hardware)\"/>"))
def test_two_hardware_components(description_file: Path) -> None:
    infos = _components(_urdf(description_file), description_file)
    names = [i.name for i in infos]
    assert len(infos) == 2, f"your description declares {len(infos)} hardware components ({names}), expected 2."
    assert len(set(names)) == 2, f"the two hardware components of your description have the same name: {names}."
    base = _component_with(infos, "base_left_wheel_joint")
    arm = _component_with(infos, "arm_joint1")
    assert base is not arm, "the base's wheels and the arm's joints are in the same hardware component."
    wheels = sorted(j.name for j in base.joints)
    assert wheels == ["base_left_wheel_joint", "base_right_wheel_joint"], (
        f"the base's component '{base.name}' holds the joints {wheels}, expected the two wheel joints.")
    joints = sorted(j.name for j in arm.joints)
    assert joints == ["arm_joint1", "arm_joint2"], f"the arm's component '{arm.name}' holds the joints {joints}."
    sensors, gpios = [s.name for s in arm.sensors], [g.name for g in arm.gpios]
    assert sensors == ["arm_tcp_fts_sensor"] and gpios == ["arm_flange_gpios"], (
        f"the arm's component '{arm.name}' has the sensors {sensors} and GPIOs {gpios}, expected "
        "['arm_tcp_fts_sensor'] and ['arm_flange_gpios'].")


@graded(points=1, after=("test_two_hardware_components",), hint=(
    "Task 10.2: use_mock_hardware chooses the hardware of BOTH components: true gives mock_components/GenericSystem "
    "to both, false each macro's other plugin.",
    "Pass the file's argument on to each <ros2_control> macro; their own default is true, so leaving it out only "
    "looks right with the default.",
    "<xacro:rrbot_ros2_control name=\"RRBot\" prefix=\"$(arg arm_prefix)\" use_mock_hardware=\"$(arg use_mock_hardware)\"/>"))
def test_use_mock_hardware_reaches_both_components(description_file: Path) -> None:
    for mock in (True, False):
        expected = {tuple(sorted(j.name for j in i.joints)): i.hardware_plugin_name
                    for i in parse_ros2_control(process_xacro(_reference(), use_mock_hardware=mock))}
        infos = _components(_urdf(description_file, use_mock_hardware=mock), description_file, use_mock_hardware=mock)
        got = {tuple(sorted(j.name for j in i.joints)): i.hardware_plugin_name for i in infos}
        for joints, plugin in expected.items():
            assert got.get(joints) == plugin, (
                f"your {description_file.name} with use_mock_hardware:={str(mock).lower()} gives the component of "
                f"{list(joints)} the plugin {got.get(joints)!r}, expected '{plugin}'.")


@graded(points=2, after=DESCRIPTION_RULES, hint=(
    "Task 10.1/10.2: for any prefixes and use_mock_hardware, your description must give the same links, joints, "
    "placements and hardware components as the two macros composed as the task says.",
    "Every name from a prefix argument, the arm's mount from the base's prefix, use_mock_hardware passed on to both "
    "<ros2_control> macros, nothing else of your own.",
    "<xacro:diffbot prefix=\"$(arg base_prefix)\"/>\n<xacro:rrbot prefix=\"$(arg arm_prefix)\" "
    "parent=\"$(arg base_prefix)top_plate\"><origin xyz=\"0.1 0 0\" rpy=\"0 0 0\"/></xacro:rrbot>\n(and one "
    "<ros2_control> macro per robot)"))
def test_description_matches_the_task_for_any_arguments(description_file: Path) -> None:
    prefix = st.sampled_from(["base_", "arm_", "b_", "a_", "mobile_", "manip_", "left_"])
    scenario = st.fixed_dictionaries({"base_prefix": prefix, "arm_prefix": prefix,
                                      "use_mock_hardware": st.booleans()}).filter(
        lambda a: a["base_prefix"] != a["arm_prefix"])
    found = description_compare.first_difference(description_file, _reference(), scenario)
    assert not found, found


@graded(points=2, hint=(
    "Task 10.2: a diff drive controller on the base's wheel joints with the description's geometry (wheels 0.55 m "
    "apart, 0.1 m in radius, to 1 µm) and the arm's trajectory controller on its prefixed joints, configured as in "
    "task 2.",
    "diff_drive_controller's left_wheel_names, right_wheel_names, wheel_separation, wheel_radius; the trajectory "
    "controller's joints, command_interfaces, state_interfaces. `rrbot-workshop lint` checks the names.",
    "diffbot_base_controller:\n  ros__parameters:\n    left_wheel_names: [base_left_wheel_joint]\n"
    "    right_wheel_names: [base_right_wheel_joint]\n    wheel_separation: 0.55\n    wheel_radius: 0.1"))
def test_controllers_yaml(controllers_file: Path) -> None:
    _check_controllers_yaml(controllers_file)


def _yaml_problem(controllers_file: Path) -> str | None:
    """Why the learner's controllers YAML breaks a rule of test_controllers_yaml, or None."""
    try:
        _check_controllers_yaml(controllers_file)
    except (AssertionError, pytest.fail.Exception) as exc:
        return str(exc)
    return None


def _running_yaml(controllers_file: Path) -> Path:
    """The learner's controllers YAML when it keeps the rules of test_controllers_yaml, else the library's: the
    running checks judge the description and the composition, and a slip in the YAML costs its own check only."""
    if _yaml_problem(controllers_file) is None:
        return controllers_file
    return descriptions_root() / "rrbot_on_diffbot" / "config" / "rrbot_on_diffbot_controllers.yaml"


def _check_controllers_yaml(controllers_file: Path) -> None:
    name = controllers_file.name
    declared = read_controllers(controllers_file)
    if isinstance(declared, str):
        pytest.fail(declared, pytrace=False)
    expected_types = {JSB: "joint_state_broadcaster/JointStateBroadcaster",
                      BASE: "diff_drive_controller/DiffDriveController",
                      ARM: "joint_trajectory_controller/JointTrajectoryController"}
    for controller, type_name in expected_types.items():
        given = declared[controller].type if controller in declared else None
        assert given is not None, (f"your {name} gives '{controller}' no type (under controller_manager or in its own "
                                   f"section); it is a '{type_name}'.")
        assert given == type_name, (
            f"your {name} declares '{controller}' with the type {given!r}, expected '{type_name}'.")
    base = declared[BASE].params
    for key, wheel in (("left_wheel_names", "base_left_wheel_joint"), ("right_wheel_names", "base_right_wheel_joint")):
        assert base.get(key) == [wheel], f"your {name}: {BASE}'s {key} is {base.get(key)}, expected [{wheel}]."
    for key, value in (("wheel_separation", WHEEL_SEPARATION), ("wheel_radius", WHEEL_RADIUS)):
        got = base.get(key)
        assert isinstance(got, (int, float)) and math.isclose(got, value, abs_tol=LENGTH_TOLERANCE), (
            f"your {name}: {BASE}'s {key} is {got!r} m, the description's is {value} m.")
    arm = declared[ARM].params
    joints = arm.get("joints")
    assert isinstance(joints, list) and len(joints) == 2 and set(joints) == {"arm_joint1", "arm_joint2"}, (
        f"your {name}: {ARM}'s joints are {joints}, expected the arm's two joints, arm_joint1 and arm_joint2 (in "
        "either order: a trajectory names its joints).")
    assert arm.get("command_interfaces") == ["position"], (
        f"your {name}: {ARM}'s command_interfaces are {arm.get('command_interfaces')}, expected [position].")
    states = arm.get("state_interfaces")
    assert isinstance(states, list) and sorted(states) == ["position", "velocity"], (
        f"your {name}: {ARM}'s state_interfaces are {states}, expected [position, velocity].")
    constraints = arm.get("constraints") or {}
    for key, value in (("stopped_velocity_tolerance", 0.01), ("goal_time", 0.0)):  # task 2's (and Jazzy's defaults)
        got = constraints.get(key, value)
        assert isinstance(got, (int, float)) and math.isclose(got, value, abs_tol=1e-9), (
            f"your {name}: {ARM}'s constraints.{key} is {got!r}; task 2's is {value}.")
    errors = [f.message for f in lint_controllers(controllers_file) if f.level == "error"]
    assert not errors, f"your {name} would not load on a Jazzy robot: " + "; ".join(errors)


# --------------------------------------------------------------------------------------------- running


@graded(points=3, after=RUNNING_NEEDS, hint=(
    "Task 10: with disjoint interfaces, the base's and the arm's controllers run at the same time: the base's "
    "odometry follows a circle of radius v/w (within 5 cm) while the arm reaches its goal (within 1 mrad).",
    "Spawn joint_state_broadcaster, diffbot_base_controller and joint_trajectory_controller together; the base's "
    "controller needs the description's wheel names, the arm's the prefixed joints.",
    "rw.bringup(your_xacro, your_yaml, spawn=['joint_state_broadcaster', 'diffbot_base_controller', "
    "'joint_trajectory_controller'])"))
def test_base_and_arm_move_together(description_file: Path, controllers_file: Path) -> None:
    description_file, controllers_file, standing_in = _running_files(description_file, controllers_file)
    for v, w, goal in ((0.5, 0.5, [0.8, -0.4]), (0.3, -0.6, [-0.5, 0.7])):
        radius = v / w
        with _system(description_file, _running_yaml(controllers_file), [JSB, BASE, ARM]) as system:
            states = {c.name: c.state for c in system.controller_manager.list_controllers()}
            inactive = {n: states.get(n, "not loaded") for n in (JSB, BASE, ARM) if states.get(n) != "active"}
            assert not inactive, f"with your files these controllers are not active: {inactive}."
            system.publish(f"/{ARM}/joint_trajectory", JointTrajectory(
                joint_names=["arm_joint1", "arm_joint2"],
                points=[JointTrajectoryPoint(positions=goal, time_from_start=2.0)]))
            _drive(system, v, w, 1.0)  # accelerate onto the circle
            distances = []
            for _ in range(8):
                _drive(system, v, w, 0.5)
                p = system.latest(f"/{BASE}/odom").pose.pose.position
                distances.append(math.hypot(p.x, p.y - radius) - abs(radius))
            joints = _joints(system)
        worst = max(distances, key=abs)
        assert abs(worst) <= CIRCLE_TOLERANCE, (
            f"driving at v = {v} m/s, w = {w} rad/s{standing_in}, the odometry leaves the circle of radius {abs(radius):.2f} m by "
            f"{worst:+.3f} m (allowed {CIRCLE_TOLERANCE} m).")
        arm = [joints.get("arm_joint1"), joints.get("arm_joint2")]
        assert all(a is not None and abs(a - g) <= POSITION_TOLERANCE for a, g in zip(arm, goal, strict=True)), (
            f"while the base drives{standing_in}, the arm ends at {arm}, its trajectory's goal is {goal} (within 1 mrad).")


@graded(points=2, after=(*RUNNING_NEEDS, "test_base_and_arm_move_together"), hint=(
    "Task 10: the robots share a controller manager, nothing else: deactivating the base's controller must not stop "
    "the arm, and deactivating the arm's must not stop the base.",
    "Each controller claims only its own robot's interfaces; a strict switch that deactivates one leaves the other "
    "active.",
    "cm.switch_controllers(deactivate=['diffbot_base_controller'], strictness='strict') leaves "
    "joint_trajectory_controller active and moving the arm."))
def test_base_and_arm_are_independent(description_file: Path, controllers_file: Path) -> None:
    description_file, controllers_file, standing_in = _running_files(description_file, controllers_file)
    with _system(description_file, _running_yaml(controllers_file), [JSB, BASE, ARM]) as system:
        cm = system.controller_manager
        cm.switch_controllers(deactivate=[BASE], strictness="strict")
        system.publish(f"/{ARM}/joint_trajectory", JointTrajectory(
            joint_names=["arm_joint1", "arm_joint2"],
            points=[JointTrajectoryPoint(positions=[-0.5, 0.3], time_from_start=1.0)]))
        system.spin(1.5)
        arm = _joints(system)
        cm.switch_controllers(activate=[BASE], deactivate=[ARM], strictness="strict")
        _drive(system, 0.4, 0.0, 2.0)
        x = system.latest(f"/{BASE}/odom").pose.pose.position.x
    reached = [arm.get("arm_joint1"), arm.get("arm_joint2")]
    assert all(a is not None and abs(a - g) <= POSITION_TOLERANCE for a, g in zip(reached, [-0.5, 0.3], strict=True)), (
        f"with the base's controller stopped{standing_in}, the arm ends at {reached} instead of [-0.5, 0.3]: it stopped with the base.")
    assert x > 0.5, (f"with the arm's controller stopped{standing_in}, the base drove to x = {x:.3f} m in 2 s at 0.4 m/s (expected "
                     "more than 0.5 m): it stopped with the arm.")


# --------------------------------------------------------------------------------------------- 10.3 answers


def _answer(task_file: Callable[[int, str], Path], name: str) -> Any:
    task_file(TASK, "answers.py")
    answers: ModuleType | None = rw.course.load_module(TASK, "answers.py", quiet=True)
    if answers is None:
        pytest.fail("your answers.py does not import; run notebook 10's cell that loads it to see the error",
                    pytrace=False)
    return getattr(answers, name, None)


def _answer_hint(question: str, idea: str) -> tuple[str, str, str]:
    return (f"Task 10.3: {question} {idea}",
            "Count from your description, then confirm on the running system: %control list_hardware_components "
            "lists the components with their plugin.",
            "In answers.py, replace the None with a whole number (an int, not a string or a bool).")


@graded(points=1, hint=_answer_hint("How many hardware components does the controller manager load?",
                                    "One per <ros2_control> tag."))
def test_answer_hardware_components(task_file: Callable[[int, str], Path]) -> None:
    value = _answer(task_file, "HARDWARE_COMPONENTS")
    assert value == 2 and not isinstance(value, bool), f"your answers.py: HARDWARE_COMPONENTS = {value!r} is not right yet."


@graded(points=1, hint=_answer_hint("How many hardware plugins does each <ros2_control> tag name?",
                                    "Look at the <hardware> element of one tag."))
def test_answer_plugins_per_tag(task_file: Callable[[int, str], Path]) -> None:
    value = _answer(task_file, "PLUGINS_PER_ROS2_CONTROL_TAG")
    assert value == 1 and not isinstance(value, bool), (
        f"your answers.py: PLUGINS_PER_ROS2_CONTROL_TAG = {value!r} is not right yet.")


@graded(points=1, hint=_answer_hint("How many controller managers run the two robots?",
                                    "One bringup, one controllers YAML."))
def test_answer_controller_managers(task_file: Callable[[int, str], Path]) -> None:
    value = _answer(task_file, "CONTROLLER_MANAGERS")
    assert value == 1 and not isinstance(value, bool), f"your answers.py: CONTROLLER_MANAGERS = {value!r} is not right yet."
