"""Grader of task 15: MyRobot's hardware component (``my_robot/MyRobotHardware``) and its controllers, ported from ROS 1.

The specification (the TODOs of ``my_robot_hardware.py`` and ``my_robot_controllers.yaml``, and notebook 15):

* 15.1 ``on_init`` accepts MyRobot's description, renamed (a prefix), reordered or with fewer joints, and refuses,
  logging why with the joint's name, a joint whose command interfaces are not exactly one of effort or position, or
  whose state interfaces lack position or velocity;
* 15.2 ``on_init`` builds one limiter per joint from the ``joint_limits.<joint>.*`` parameters of the file named by the
  hardware parameter ``joint_limits_file``, over the URDF's limits: a ``JointSoftLimiter`` where the joint has soft
  limits, a ``JointSaturationLimiter`` elsewhere; without the parameter, or with a file it cannot use, it refuses;
* 15.3 ``write`` limits each joint's command with its limiter (actual: the position and velocity states; desired: the
  joint's command in its mode; the period given to ``write``) and sends the limited commands to the device;
* 15.4 the controllers YAML is the ROS 1 file in Jazzy's layout: ``joint_state_broadcaster`` (50 Hz), a
  ``pid_controller/PidController`` from joint1's position to its effort (p 100, i 0.01, d 10), joint2's effort and
  joint3's position passed on by Jazzy's group (or forward command) controllers, the manager at 100 Hz.

Every check builds its own description and ``joint_limits.yaml`` (other numbers than the course's files, so a value
copied from them does not pass). The device is :class:`rrbot_workshop.hardware.my_robot.MyRobotDevice`; what it
receives is compared, cycle by cycle, with what Jazzy's limiters (``rrbot_workshop.joint_limits``) give on a twin device
fed the same commands, to 1e-9 (the device is deterministic, so a component that limits as specified gives the same
numbers).
"""

from __future__ import annotations

import itertools
import logging
import math
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import parse_ros2_control
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.hardware.my_robot import MyRobotDevice
from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent
from rrbot_workshop.joint_limits import (
    JointControlInterfacesData,
    JointSaturationLimiter,
    JointSoftLimiter,
    get_joint_limits,
    get_soft_joint_limits,
)
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State

TASK = 15
FILE = "my_robot_hardware.py"
YAML = "my_robot_controllers.yaml"
TOL = 1e-9  # the device is deterministic: a component limiting as specified sends the same numbers
_names = itertools.count()

#: MyRobot's joints in the grader's description: name, mode, URDF limits (lower, upper, velocity, effort).
JOINTS: tuple[tuple[str, str, tuple[float, float, float, float]], ...] = (
    ("joint1", "effort", (-2.6, 2.6, 2.0, 20.0)),
    ("joint2", "effort", (-2.4, 2.4, 2.5, 10.0)),
    ("joint3", "position", (-3.0, 3.0, 3.0, 2.0)),
)

#: The grader's joint_limits.yaml: other numbers than the course's file.
LIMITS: dict[str, dict[str, Any]] = {
    "joint1": {"has_position_limits": True, "min_position": -2.5, "max_position": 2.5, "has_velocity_limits": True,
               "max_velocity": 1.25, "has_effort_limits": True, "max_effort": 6.5, "has_soft_limits": True,
               "k_position": 2.5, "k_velocity": 8.0, "soft_lower_limit": -1.8, "soft_upper_limit": 1.9},
    "joint2": {"has_position_limits": True, "min_position": -2.2, "max_position": 2.1, "has_velocity_limits": True,
               "max_velocity": 1.75, "has_effort_limits": True, "max_effort": 3.5},
    "joint3": {"has_position_limits": True, "min_position": -1.5, "max_position": 2.75, "has_velocity_limits": True,
               "max_velocity": 0.8, "has_soft_limits": True, "k_position": 4.0, "k_velocity": 0.0,
               "soft_lower_limit": -1.25, "soft_upper_limit": 2.5},
}


# --------------------------------------------------------------------------------------------- the learner's class


@pytest.fixture(scope="module")
def hardware(task_file: Callable[[int, str], Path]) -> type:
    """The learner's class (if the file does not import, the framework puts the learner's error in the reason)."""
    task_file(TASK, FILE)
    module = rw.course.load_module(TASK, FILE, quiet=True)
    if module is None:
        _fail(f"your {FILE} does not import, so no check can run your component: fix that first")
    cls = getattr(module, "MyRobotHardware", None)
    if not isinstance(cls, type):
        _fail(f"your {FILE} defines no class MyRobotHardware (the plugin's class)")
    return cls


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Where the checks write their joint_limits.yaml files."""
    return tmp_path_factory.mktemp("task15_limits")


def _fail(message: str) -> None:
    """Fail the check with ``message`` as its whole reason."""
    raise AssertionError(message)


# --------------------------------------------------------------------------------------------- descriptions


def _limits_file(folder: Path, limits: dict[str, dict[str, Any]]) -> Path:
    path = folder / f"joint_limits_{next(_names)}.yaml"
    path.write_text(yaml.safe_dump({"joint_limits": limits}, sort_keys=False))
    return path


def _renamed(limits: dict[str, dict[str, Any]], prefix: str) -> dict[str, dict[str, Any]]:
    return {f"{prefix}{joint}": dict(values) for joint, values in limits.items()}


def _urdf(limits_file: Path | None, prefix: str = "", joints: Sequence[str] = ("joint1", "joint2", "joint3"),
          edit: Callable[[str, str], str] | None = None, safety: dict[str, str] | None = None) -> str:
    """MyRobot (a chain of revolute joints) with its arm's ``<ros2_control>`` tag; ``edit(joint, xml)`` changes one
    joint's element; ``safety`` gives joints a URDF ``<safety_controller>`` (joint -> its attributes)."""
    table = {name: (mode, lim) for name, mode, lim in JOINTS}
    links, tags = ['<link name="world"/>'], []
    parent = "world"
    for index, joint in enumerate(joints):
        mode, (lower, upper, velocity, effort) = table[joint]
        name = f"{prefix}{joint}"
        links.append(f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{prefix}l{index}"/>'
                     f'<origin xyz="0.1 0 0"/><axis xyz="0 0 1"/><limit lower="{lower}" upper="{upper}" '
                     f'velocity="{velocity}" effort="{effort}"/>'
                     + (f"<safety_controller {(safety or {})[joint]}/>" if joint in (safety or {}) else "")
                     + f'</joint><link name="{prefix}l{index}"/>')
        parent = f"{prefix}l{index}"
        states = '<state_interface name="position"/><state_interface name="velocity"/>'
        if mode == "effort":
            states += '<state_interface name="effort"/>'
        xml = f'<joint name="{name}"><command_interface name="{mode}"/>{states}</joint>'
        tags.append(edit(joint, xml) if edit is not None else xml)
    param = f'<param name="joint_limits_file">{limits_file}</param>' if limits_file is not None else ""
    hardware = f"<hardware><plugin>task15_grader/MyRobotHardware</plugin>{param}</hardware>"
    return (f'<robot name="my_robot">{"".join(links)}<ros2_control name="{prefix}my_robot" type="system">{hardware}'
            f'{"".join(tags)}</ros2_control></robot>')


def _info(urdf: str) -> Any:
    return parse_ros2_control(urdf)[0]


# --------------------------------------------------------------------------------------------- a component, as the RM drives it


#: What each callback must do, said in the reason when it stops the component from coming up.
_DUTY = {
    "on_init": "accept MyRobot's description (effort and position joints reporting position and velocity), build the "
               "limiters from joint_limits_file and return CallbackReturn.SUCCESS",
    "on_configure": "the given on_configure opens the device from self.modes",
    "on_activate": "the given on_activate powers the device and resets self.limiters",
    "write": "limit each joint's command and send them with self.device.write(commands, period), return ReturnType.OK",
    "read": "the given read fills the states from the device",
}


def _failed(callback: str, component: HardwareComponent, before: BaseException | None) -> str:
    exc = component.last_error
    if exc is not None and exc is not before:
        how = f"raised {type(exc).__name__}"
    else:
        how = f"did not return SUCCESS (the component is '{component.get_lifecycle_state().label}')"
    return (f"MyRobot does not come up on your component: your {callback} {how}, so no check that runs it can pass; "
            f"fix {callback} first: {_DUTY[callback]}.")


class Rig:
    """One component inside the library's lifecycle wrapper, driven as the resource manager drives it."""

    def __init__(self, cls: type, urdf: str) -> None:
        self.info = _info(urdf)
        self.component = HardwareComponent(cls())
        self.init_state = self.component.initialize(self.info)
        self.time = 0.0
        self.states: dict[str, Any] = {}
        self.commands: dict[str, Any] = {}
        if self.init_state is State.UNCONFIGURED:
            self.states = {h.name: h for h in self.component.export_state_interfaces()}
            self.commands = {h.name: h for h in self.component.export_command_interfaces()}

    def up(self) -> Rig:
        """configure and activate; a failing callback fails the check with a reason naming it."""
        if self.init_state is not State.UNCONFIGURED:
            _fail(_failed("on_init", self.component, None))
        for step, reached, callback in (("configure", State.INACTIVE, "on_configure"),
                                        ("activate", State.ACTIVE, "on_activate")):
            before = self.component.last_error
            if getattr(self.component, step)() is not reached:
                _fail(_failed(callback, self.component, before))
        return self

    @property
    def device(self) -> MyRobotDevice:
        device = getattr(self.component.impl, "device", None)
        if not isinstance(device, MyRobotDevice):
            _fail(f"your component's self.device is {device!r} once active; the given on_configure opens it")
        return device

    def cycle(self, commands: dict[str, float], period: float) -> list[float]:
        """read, then the controllers' commands, then write; what the device received."""
        for what in ("read", "write"):
            if what == "write":
                for name, value in commands.items():
                    self.commands[name].set_value(value)
            before = self.component.last_error
            getattr(self.component, what)(self.time, period)
            if self.component.get_lifecycle_state() is not State.ACTIVE:
                _fail(_failed(what, self.component, before))
        self.time += period
        return list(self.device.last_commands)


class Twin:
    """What Jazzy's limiters give: the library's limiters on a twin device, fed the same commands."""

    def __init__(self, info: Any, params: dict[str, Any]) -> None:
        self.joints = [j.name for j in info.joints]
        self.modes = [j.command_interfaces[0].name for j in info.joints]
        self.limiters = []
        for joint in self.joints:
            hard = get_joint_limits(joint, params, info.limits.get(joint))
            soft = get_soft_joint_limits(joint, params, info.soft_limits.get(joint))
            self.limiters.append(JointSoftLimiter([joint], [hard], [soft]) if soft is not None
                                 else JointSaturationLimiter([joint], [hard]))
        self.device = MyRobotDevice(self.modes)
        self.device.enable()

    def cycle(self, commands: dict[str, float], period: float) -> list[float]:
        positions, velocities, _ = self.device.read()
        sent = []
        for i, (joint, mode, limiter) in enumerate(zip(self.joints, self.modes, self.limiters, strict=True)):
            actual = JointControlInterfacesData(joint, position=positions[i], velocity=velocities[i])
            desired = JointControlInterfacesData(joint)
            setattr(desired, mode, commands.get(f"{joint}/{mode}", 0.0 if mode == "effort" else positions[i]))
            limiter.enforce(actual, desired, period)
            sent.append(getattr(desired, mode))
        self.device.write(sent, period)
        return sent


def _rig(cls: type, urdf: str) -> Rig:
    return Rig(cls, urdf).up()


def _close(a: float, b: float, tol: float = TOL) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol


def _follow(cls: type, urdf: str, limits: dict[str, dict[str, Any]], commands: dict[str, float], seconds: float,
            period: float, what: str) -> None:
    """Run the learner's component and the twin on the same commands; fail at the first cycle they differ."""
    rig = _rig(cls, urdf)
    twin = Twin(rig.info, {"joint_limits": limits})
    for k in range(round(seconds / period)):
        positions, velocities, _ = twin.device.read()
        expected = twin.cycle(commands, period)
        got = rig.cycle(commands, period)
        for i, joint in enumerate(twin.joints):
            if not _close(got[i], expected[i]):
                mode = twin.modes[i]
                unit = "N m" if mode == "effort" else "rad"
                _fail(f"{what}: at cycle {k + 1} ({period * 1000:g} ms each), with {joint} at {positions[i]:.4f} rad "
                      f"and {velocities[i]:.4f} rad/s, commanded {mode} {commands.get(f'{joint}/{mode}')}, your "
                      f"component sent {got[i]:.6g} {unit} to the device; the joint's limits (joint_limits.yaml over "
                      f"the URDF) give {expected[i]:.6g} {unit}")


# --------------------------------------------------------------------------------------------- 15.1 on_init


_INIT_API = ("info.joints lists each <joint>; joint.command_interfaces and joint.state_interfaces list its "
             "interfaces (each with .name). Call super().on_init(info) first; return CallbackReturn.ERROR to refuse.")


@graded(points=1, hint=(
    "Task 15.1: on_init accepts MyRobot's description, whatever the joints are called (a prefixed robot), in whatever "
    "order they come and however many there are.",
    _INIT_API,
    "self.joints = [j.name for j in info.joints]; self.modes = [j.command_interfaces[0].name for j in info.joints]; "
    "never compare a name with 'joint1'",
))
def test_init_accepts_my_robot(hardware: type, folder: Path) -> None:
    plain = _limits_file(folder, LIMITS)
    Rig(hardware, _urdf(plain)).up()  # MyRobot itself, or the reason every check gives
    variants = (
        (_urdf(_limits_file(folder, _renamed(LIMITS, "left_")), prefix="left_"), "MyRobot with the prefix 'left_'"),
        (_urdf(plain, joints=("joint3", "joint1", "joint2")), "MyRobot with joint3 declared first"),
        (_urdf(plain, joints=("joint2", "joint3")), "MyRobot with joint2 and joint3 only"),
    )
    refused = []
    for urdf, what in variants:
        rig = Rig(hardware, urdf)
        if rig.init_state is not State.UNCONFIGURED:
            exc = rig.component.last_error
            refused.append(f"{what} ({'it raised ' + type(exc).__name__ if exc else 'it did not return SUCCESS'})")
            continue
        try:  # accepted: it must also run (the names on_init remembers are the ones the states have)
            rig.up().cycle({f"{j.name}/{j.command_interfaces[0].name}": 0.0 for j in rig.info.joints}, 0.01)
        except AssertionError as exc:
            refused.append(f"{what} (accepted by on_init, then {str(exc).split(': your ', 1)[-1].split(',')[0]})")
    assert not refused, (f"your component runs MyRobot but not {' and '.join(refused)}; the device serves any "
                         "number of effort and position joints: take the names, order and count from info")


_BROKEN: tuple[tuple[str, str, str, str], ...] = (
    ("joint2", '<command_interface name="effort"/>', '<command_interface name="velocity"/>',
     "a velocity command interface"),
    ("joint3", '<command_interface name="position"/>',
     '<command_interface name="position"/><command_interface name="effort"/>', "two command interfaces"),
    ("joint1", '<command_interface name="effort"/>', "", "no command interface"),
    ("joint3", '<state_interface name="velocity"/>', "", "no velocity state interface"),
    ("joint2", '<state_interface name="position"/>', "", "no position state interface"),
)


def _broken(folder: Path, joint: str, old: str, new: str) -> str:
    return _urdf(_limits_file(folder, LIMITS), edit=lambda j, xml: xml.replace(old, new) if j == joint else xml)


@graded(after=("test_init_accepts_my_robot",), points=2, hint=(
    "Task 15.1: on_init refuses a joint that does not command exactly one of effort or position, or that does not "
    "report position and velocity: on every joint, not only the first.",
    _INIT_API,
    "for joint in info.joints: names = [i.name for i in joint.command_interfaces]; if len(names) != 1 or names[0] not "
    "in ('effort', 'position'): self.logger.error(...); return CallbackReturn.ERROR (and the states likewise)",
))
def test_init_refuses_wrong_interfaces(hardware: type, folder: Path) -> None:
    Rig(hardware, _urdf(_limits_file(folder, LIMITS))).up()
    accepted = [f"{joint} with {what}" for joint, old, new, what in _BROKEN
                if Rig(hardware, _broken(folder, joint, old, new)).init_state is State.UNCONFIGURED]
    assert not accepted, (f"your on_init accepted a description with {'; '.join(accepted)}: the device cannot serve "
                          "it, so on_init must return ERROR")


class _Records(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


def _logged(run: Callable[[], State]) -> tuple[State, list[str]]:
    handler = _Records()
    root = logging.getLogger()
    root.addHandler(handler)
    try:
        state = run()
    finally:
        root.removeHandler(handler)
    return state, [r.getMessage() for r in handler.records]


@graded(after=("test_init_accepts_my_robot", "test_init_refuses_wrong_interfaces"), points=1, hint=(
    "Task 15.1: when on_init refuses a description it logs why, naming the joint.",
    "self.logger is the component's logger: self.logger.error('...%s...', joint.name).",
    "self.logger.error(\"joint '%s' has command interfaces %s; a motor takes exactly one, effort or position\", "
    "joint.name, names)",
))
def test_init_logs_why(hardware: type, folder: Path) -> None:
    Rig(hardware, _urdf(_limits_file(folder, LIMITS))).up()
    silent = []
    for joint, old, new, what in (_BROKEN[0], _BROKEN[3]):
        state, messages = _logged(lambda: Rig(hardware, _broken(folder, joint, old, new)).init_state)  # noqa: B023
        if state is State.UNCONFIGURED or not any(joint in m for m in messages):
            silent.append(f"{joint} with {what}")
    assert not silent, (f"nothing was logged naming the joint when your on_init met {'; '.join(silent)} (or it "
                        "accepted it): log why with self.logger.error, naming the joint")


# --------------------------------------------------------------------------------------------- 15.2 the limits file


@graded(after=("test_init_accepts_my_robot",), points=1, hint=(
    "Task 15.2: the limits come from the file the hardware parameter joint_limits_file names; without it, or with a "
    "file that cannot be used (missing, a wrong value), on_init refuses and logs why instead of running unlimited.",
    "info.hardware_parameters.get('joint_limits_file'); load_joint_limits_yaml(path) raises an RRBotWorkshopError "
    "(a ParameterError) for a file it cannot use.",
    "try: params = load_joint_limits_yaml(path) ... except RRBotWorkshopError as exc: self.logger.error('...%s', exc); "
    "return CallbackReturn.ERROR",
))
def test_init_refuses_a_missing_limits_file(hardware: type, folder: Path) -> None:
    Rig(hardware, _urdf(_limits_file(folder, LIMITS))).up()
    wrong = {**LIMITS, "joint2": {**LIMITS["joint2"], "max_effort": "strong"}}
    cases = ((_urdf(None), "no joint_limits_file parameter"),
             (_urdf(folder / "no_such_joint_limits.yaml"), "a joint_limits_file that does not exist"),
             (_urdf(_limits_file(folder, wrong)), "a joint_limits.yaml with max_effort: strong"))
    problems = []
    for urdf, what in cases:
        state, messages = _logged(lambda: Rig(hardware, urdf).init_state)  # noqa: B023
        if state is State.UNCONFIGURED:
            problems.append(f"{what}: it was accepted")
        elif not messages:
            problems.append(f"{what}: it was refused, but nothing was logged")
    assert not problems, f"your on_init, given {'; '.join(problems)}; refuse it and log why"


def _init_answer(hardware: type, urdf: str) -> str | None:
    """How on_init answered a description it must refuse: None when it returned ``CallbackReturn.ERROR`` (without
    raising), else what it did, starting with the learner's file (and line, when it raised)."""
    answers: list[Any] = []

    class Answered(hardware):  # type: ignore[misc, valid-type]
        def on_init(self, *args: Any, **kwargs: Any) -> Any:
            answers.append(super().on_init(*args, **kwargs))
            return answers[-1]

    component = HardwareComponent(Answered())
    component.initialize(_info(urdf))
    if answers and answers[0] is CallbackReturn.ERROR:
        return None
    if answers:
        return f"your {FILE}: on_init returned {answers[0]!r}"
    exc = component.last_error
    lines = [f.lineno for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename).name == FILE] if exc else []
    where = f"your {FILE}, line {lines[-1]}" if lines else f"your {FILE}"
    return f"{where}: on_init raised {type(exc).__name__}" if exc else f"{where}: on_init did not return"


@graded(points=1, after=("test_init_refuses_wrong_interfaces", "test_init_refuses_a_missing_limits_file"), hint=(
    "Task 15.1-15.2: the TODOs say how on_init refuses: it logs why and returns CallbackReturn.ERROR. Not FAILURE, and "
    "not an exception: the resource manager reads the return value.",
    "Every refusal in on_init ends with `return CallbackReturn.ERROR` after self.logger.error(...); a try/except "
    "around load_joint_limits_yaml turns its RRBotWorkshopError into that.",
    "self.logger.error(\"...\", ...)\nreturn CallbackReturn.ERROR",
))
def test_init_refusal_returns_error(hardware: type, folder: Path) -> None:
    Rig(hardware, _urdf(_limits_file(folder, LIMITS))).up()
    wrong = {**LIMITS, "joint2": {**LIMITS["joint2"], "max_effort": "strong"}}
    cases = ((_broken(folder, *_BROKEN[0][:3]), _BROKEN[0][3]), (_urdf(None), "no joint_limits_file parameter"),
             (_urdf(_limits_file(folder, wrong)), "a joint_limits.yaml with max_effort: strong"))
    for urdf, what in cases:
        answer = _init_answer(hardware, urdf)
        if answer is not None:
            _fail(f"{answer} for a description with {what}; the TODO asks to log why and return CallbackReturn.ERROR")


# --------------------------------------------------------------------------------------------- 15.3 write


@graded(after=("test_init_accepts_my_robot",), points=2, hint=(
    "Task 15.3: within the limits, write sends each joint's command unchanged to the device, one per joint in the "
    "description's order: effort joints their effort, position joints their position.",
    "self.get_command(f'{joint}/{mode}') for each joint; self.device.write(commands, period) once per write.",
    "commands.append(getattr(desired, mode)) after limiter.enforce(actual, desired, period); "
    "self.device.write(commands, period)",
))
def test_commands_reach_the_device(hardware: type, folder: Path) -> None:
    path = _limits_file(folder, LIMITS)
    for joints in (("joint1", "joint2", "joint3"), ("joint3", "joint2", "joint1")):
        rig = _rig(hardware, _urdf(path, joints=joints))
        wanted = {"joint1": 1.25, "joint2": -0.75, "joint3": 0.005}
        sent = rig.cycle({f"{j}/{m}": wanted[j] for j, m, _ in JOINTS if j in joints}, 0.01)
        expected = [wanted[j] for j in joints]
        assert len(sent) == len(joints) and all(_close(a, b) for a, b in zip(sent, expected, strict=True)), (
            f"with the joints declared as {', '.join(joints)} and commands within the limits ({wanted}), the device "
            f"received {[round(v, 6) for v in sent]}; expected {expected} (each joint's own command, in the "
            "description's order)")


@graded(after=("test_commands_reach_the_device",), points=2, hint=(
    "Task 15.3: an effort command beyond max_effort reaches the device as max_effort, in both directions, on every "
    "effort joint, with the joint_limits.yaml's value (ROS 1's EffortJointSaturationInterface).",
    "One limiter per joint from get_joint_limits(joint, params, info.limits.get(joint)); in write, "
    "limiter.enforce(actual, desired, period) changes desired.effort.",
    "desired = JointControlInterfacesData(joint, effort=self.get_command(f'{joint}/effort')); "
    "limiter.enforce(actual, desired, period); commands.append(desired.effort)",
))
def test_effort_saturated_at_the_yaml_max_effort(hardware: type, folder: Path) -> None:
    other = {**LIMITS, "joint1": {**LIMITS["joint1"], "max_effort": 4.25},
             "joint2": {**LIMITS["joint2"], "max_effort": 2.75}}
    for limits in (LIMITS, other):
        path = _limits_file(folder, limits)
        for sign in (1.0, -1.0):
            rig = _rig(hardware, _urdf(path))
            sent = rig.cycle({"joint1/effort": 50.0 * sign, "joint2/effort": 50.0 * sign, "joint3/position": 0.0}, 0.01)
            for i, joint in enumerate(("joint1", "joint2")):
                bound = limits[joint]["max_effort"] * sign
                assert _close(sent[i], bound), (
                    f"joint_limits.yaml gives {joint} max_effort {abs(bound)} N m; commanded {50.0 * sign} N m at "
                    f"rest, the device received {sent[i]:.6g} N m instead of {bound} (the URDF says "
                    f"{dict((j, lim[3]) for j, _, lim in JOINTS)[joint]}: the yaml's value overrides it)")


@graded(after=("test_effort_saturated_at_the_yaml_max_effort",), points=1, hint=(
    "Task 15.2: the yaml overrides the URDF's limits; a limit the yaml does not mention keeps the URDF's value.",
    "get_joint_limits(joint, params, limits) starts from limits: pass the URDF's, info.limits.get(joint), not None.",
    "hard = get_joint_limits(joint, params, info.limits.get(joint))",
))
def test_urdf_limits_where_the_yaml_is_silent(hardware: type, folder: Path) -> None:
    quiet = {**LIMITS, "joint2": {k: v for k, v in LIMITS["joint2"].items() if k not in ("has_effort_limits",
                                                                                         "max_effort")}}
    rig = _rig(hardware, _urdf(_limits_file(folder, quiet)))
    sent = rig.cycle({"joint1/effort": 0.0, "joint2/effort": 50.0, "joint3/position": 0.0}, 0.01)
    assert _close(sent[1], 10.0), (
        f"the joint_limits.yaml gives joint2 no effort limit, so the URDF's effort=\"10.0\" stays; commanded 50 N m, "
        f"the device received {sent[1]:.6g} N m")


def _position_only(limits: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """joint3 without soft limits: saturation alone."""
    return {**limits, "joint3": {k: v for k, v in limits["joint3"].items() if k not in (
        "has_soft_limits", "k_position", "k_velocity", "soft_lower_limit", "soft_upper_limit")}}


@graded(after=("test_commands_reach_the_device", "test_effort_saturated_at_the_yaml_max_effort"), points=2, hint=(
    "Task 15.3: a position command is rate-limited: each cycle the position joint's command moves at most "
    "max_velocity x period from the last command sent, in both directions, whatever the period.",
    "The limiter of a position joint gets desired = JointControlInterfacesData(joint, position=command) and the "
    "period given to write; never the effort field.",
    "setattr(desired, mode, self.get_command(f'{joint}/{mode}')) with mode 'position' for joint3; "
    "limiter.enforce(actual, desired, period)",
))
def test_position_rate_limited(hardware: type, folder: Path) -> None:
    limits = _position_only(LIMITS)
    path = _limits_file(folder, limits)
    vmax = limits["joint3"]["max_velocity"]
    for period in (0.01, 0.004):
        rig = _rig(hardware, _urdf(path))
        last = 0.0
        for target, cycles in ((1.0, round(0.5 / period)), (-0.5, round(0.5 / period))):
            for k in range(cycles):
                sent = rig.cycle({"joint1/effort": 0.0, "joint2/effort": 0.0, "joint3/position": target}, period)[2]
                step = vmax * period
                expected = min(target, last + step) if target > last else max(target, last - step)
                assert _close(sent, expected), (
                    f"joint3 (max_velocity {vmax} rad/s in the yaml), commanded to {target} rad from {last:.4f} with a "
                    f"{period * 1000:g} ms period: cycle {k + 1} sent {sent:.6g} rad to the device; at most "
                    f"{vmax} x {period} = {step:.4g} rad per cycle gives {expected:.6g}")
                last = expected


@graded(after=("test_position_rate_limited",), points=1, hint=(
    "Task 15.3: a position command beyond the position limits reaches the device clamped to min_position or "
    "max_position of the yaml: both bounds.",
    "The position joint's limiter clamps desired.position into [min_position, max_position].",
    "JointSaturationLimiter([joint], [hard]) for a joint without soft limits; enforce then send desired.position",
))
def test_position_range(hardware: type, folder: Path) -> None:
    limits = _position_only(LIMITS)
    rig = _rig(hardware, _urdf(_limits_file(folder, limits)))
    low, high = limits["joint3"]["min_position"], limits["joint3"]["max_position"]
    for target, bound in ((9.0, high), (-9.0, low)):
        for _ in range(800):
            sent = rig.cycle({"joint1/effort": 0.0, "joint2/effort": 0.0, "joint3/position": target}, 0.01)[2]
            assert low - TOL <= sent <= high + TOL, (
                f"joint3 commanded to {target} rad: your component sent {sent:.6g} rad to the device, outside "
                f"[{low}, {high}] (the yaml's min_position and max_position)")
        assert _close(sent, bound), (f"joint3 commanded to {target} rad for 8 s ends at {sent:.6g} rad; the yaml's "
                                     f"limit is {bound}")


@graded(after=("test_effort_saturated_at_the_yaml_max_effort",), points=2, hint=(
    "Task 15.2-15.3: a joint with soft limits (joint1) is slowed down as it nears its soft bound: the velocity allowed "
    "is k_position x (distance to the bound), and the effort is cut to k_velocity x (allowed velocity - velocity), "
    "so the joint stops at the bound instead of running into its hard limit.",
    "get_soft_joint_limits(joint, params, info.soft_limits.get(joint)) is not None: that joint gets a "
    "JointSoftLimiter([joint], [hard], [soft]); actual carries the position and velocity states.",
    "actual = JointControlInterfacesData(joint, position=self.get_state(f'{joint}/position'), "
    "velocity=self.get_state(f'{joint}/velocity'))",
))
def test_soft_limits_slow_the_effort_joint(hardware: type, folder: Path) -> None:
    path = _limits_file(folder, LIMITS)
    for sign in (1.0, -1.0):
        _follow(hardware, _urdf(path), LIMITS, {"joint1/effort": 50.0 * sign, "joint2/effort": 0.0,
                                                "joint3/position": 0.0}, 3.0, 0.01,
                f"joint1 pushed with {50.0 * sign} N m toward its soft {'upper' if sign > 0 else 'lower'} limit")


#: joint2's soft limits in the URDF (``<safety_controller>``), where the joint_limits.yaml gives it none.
SAFETY = {"joint2": 'soft_lower_limit="-0.7" soft_upper_limit="0.6" k_position="3.0" k_velocity="5.0"'}


@graded(after=("test_soft_limits_slow_the_effort_joint",), points=1, hint=(
    "Task 15.2-15.3: the URDF's <safety_controller> gives a joint soft limits where the joint_limits.yaml gives none: "
    "the yaml's soft limits override the URDF's, as its hard limits override <limit>.",
    "get_soft_joint_limits(joint, params, soft) falls back on soft: pass the URDF's, info.soft_limits.get(joint).",
    "soft = get_soft_joint_limits(joint, params, info.soft_limits.get(joint))",
))
def test_urdf_safety_controller_where_the_yaml_is_silent(hardware: type, folder: Path) -> None:
    urdf = _urdf(_limits_file(folder, LIMITS), safety=SAFETY)
    for sign in (1.0, -1.0):
        _follow(hardware, urdf, LIMITS, {"joint1/effort": 0.0, "joint2/effort": 50.0 * sign, "joint3/position": 0.0},
                2.0, 0.01, f"joint2 (soft limits in the URDF's <safety_controller> only) pushed with {50.0 * sign} N m")


@graded(after=("test_effort_saturated_at_the_yaml_max_effort", "test_soft_limits_slow_the_effort_joint"), points=1,
        hint=(
    "Task 15.2-15.3: a joint without soft limits (joint2) is only saturated: its effort is clipped at max_effort and cut "
    "once the joint is faster than max_velocity; no soft slowing.",
    "A JointSaturationLimiter([joint], [hard]) for a joint whose get_soft_joint_limits(...) is None.",
    "limiter = JointSoftLimiter([joint], [hard], [soft]) if soft is not None else JointSaturationLimiter([joint], "
    "[hard])",
))
def test_saturation_only_without_soft_limits(hardware: type, folder: Path) -> None:
    path = _limits_file(folder, LIMITS)
    _follow(hardware, _urdf(path), LIMITS, {"joint1/effort": 0.0, "joint2/effort": -50.0, "joint3/position": 0.0},
            2.0, 0.01, "joint2 (no soft limits) pushed with -50 N m")


@graded(after=("test_soft_limits_slow_the_effort_joint", "test_position_rate_limited"), points=2, hint=(
    "Task 15.2-15.3: the position joint (joint3) with soft limits approaches its soft bound ever more slowly (the "
    "velocity allowed is k_position x (distance to the bound), at most max_velocity) and never passes it (ROS 1's "
    "PositionJointSoftLimitsInterface).",
    "joint3's limiter is a JointSoftLimiter; its desired carries the position command, its actual the position and "
    "velocity states.",
    "desired = JointControlInterfacesData(joint, position=self.get_command(f'{joint}/position')); "
    "limiter.enforce(actual, desired, period)",
))
def test_soft_limits_on_the_position_joint(hardware: type, folder: Path) -> None:
    path = _limits_file(folder, LIMITS)
    for target in (3.5, -2.0):
        _follow(hardware, _urdf(path), LIMITS, {"joint1/effort": 0.0, "joint2/effort": 0.0, "joint3/position": target},
                4.0, 0.01, f"joint3 commanded to {target} rad")


@graded(after=("test_init_accepts_my_robot", "test_effort_saturated_at_the_yaml_max_effort",
               "test_soft_limits_slow_the_effort_joint"), points=1, hint=(
    "Task 15.2: the limits follow the joints' names: a robot whose joints are prefixed gets the limits the yaml gives "
    "those names.",
    "Look each joint up by its own name, joint.name from info, in get_joint_limits and get_soft_joint_limits.",
    "for joint in self.joints: hard = get_joint_limits(joint, params, info.limits.get(joint)) (never 'joint1')",
))
def test_limits_follow_renamed_joints(hardware: type, folder: Path) -> None:
    renamed = _renamed(LIMITS, "left_")
    urdf = _urdf(_limits_file(folder, renamed), prefix="left_")
    rig = _rig(hardware, urdf)
    sent = rig.cycle({"left_joint1/effort": 50.0, "left_joint2/effort": -50.0, "left_joint3/position": 0.0}, 0.01)
    expected = [LIMITS["joint1"]["max_effort"], -LIMITS["joint2"]["max_effort"], 0.0]
    assert all(_close(a, b) for a, b in zip(sent, expected, strict=True)), (
        f"MyRobot prefixed 'left_', with a joint_limits.yaml for left_joint1..left_joint3: efforts of +-50 N m reached "
        f"the device as {[round(v, 6) for v in sent]}; the yaml's limits give {expected}")
    _follow(hardware, urdf, renamed, {"left_joint1/effort": 50.0, "left_joint2/effort": 0.0,
                                      "left_joint3/position": 3.5}, 2.0, 0.01, "MyRobot prefixed 'left_'")


# --------------------------------------------------------------------------------------------- 15.4 the YAML


NAMES = ("joint_state_broadcaster", "joint1_position_controller", "joint2_effort_controller",
         "joint3_position_controller")
#: ROS 1 types and what Jazzy has instead.
ROS1_TYPES = {
    "joint_state_controller/JointStateController": "joint_state_broadcaster/JointStateBroadcaster",
    "effort_controllers/JointPositionController": "pid_controller/PidController (command_interface: effort)",
    "effort_controllers/JointEffortController": "effort_controllers/JointGroupEffortController",
    "position_controllers/JointPositionController": "position_controllers/JointGroupPositionController",
}
FCC = "forward_command_controller/ForwardCommandController"
#: Controller -> accepted types -> the interface a forward command controller must name.
ACCEPTED = {
    "joint_state_broadcaster": {"joint_state_broadcaster/JointStateBroadcaster": None},
    "joint1_position_controller": {"pid_controller/PidController": None},
    "joint2_effort_controller": {"effort_controllers/JointGroupEffortController": None, FCC: "effort"},
    "joint3_position_controller": {"position_controllers/JointGroupPositionController": None, FCC: "position"},
}


def _load_yaml(task_file: Callable[[int, str], Path]) -> Any:
    path = task_file(TASK, YAML)
    try:
        return rw.params.load_controllers_yaml(path)
    except RRBotWorkshopError as exc:
        _fail(f"your {YAML} cannot be loaded: {exc}")


def _type_of(cfg: Any, name: str) -> str | None:
    return cfg.controller_types.get(name) or cfg.parameters_for(name).get("type")


@graded(points=2, hint=(
    "Task 15.4: the four controllers are declared under their ROS 2 names with Jazzy's types: joint_state_broadcaster, "
    "a PID controller for joint1, group (or forward command) controllers for joint2's effort and joint3's position; "
    "no ROS 1 type is left.",
    "Jazzy's types: joint_state_broadcaster/JointStateBroadcaster, pid_controller/PidController, "
    "effort_controllers/JointGroupEffortController, position_controllers/JointGroupPositionController.",
    "joint2_effort_controller:\\n  ros__parameters:\\n    type: effort_controllers/JointGroupEffortController\\n    "
    "joints: [joint2]",
))
def test_yaml_declares_jazzy_controllers(task_file: Callable[[int, str], Path]) -> None:
    cfg = _load_yaml(task_file)
    problems = []
    for name in NAMES:
        ctype = _type_of(cfg, name)
        if ctype is None:
            problems.append(f"{name} is not declared (no type)")
        elif ctype in ROS1_TYPES:
            problems.append(f"{name} has the ROS 1 type {ctype}; Jazzy's is {ROS1_TYPES[ctype]}")
        elif ctype not in ACCEPTED[name]:
            problems.append(f"{name} has the type {ctype}; it should be one of {', '.join(ACCEPTED[name])}")
    assert not problems, f"{YAML}: {'; '.join(problems)}"


def _robot_urdf() -> str:
    """MyRobot on mock hardware (GenericSystem), for the controllers."""
    urdf = _urdf(None).replace("<plugin>task15_grader/MyRobotHardware</plugin>",
                               "<plugin>mock_components/GenericSystem</plugin>")
    return urdf


@graded(after=("test_yaml_declares_jazzy_controllers",), points=2, hint=(
    "Task 15.4: on MyRobot, the controllers of your YAML come up together and each holds what its ROS 1 controller "
    "held: joint1's effort (reading its position), joint2's effort, joint3's position; the manager runs at 100 Hz and "
    "the broadcaster at 50 Hz (ROS 1's publish_rate).",
    "pid_controller: dof_names [joint1], command_interface effort, reference_and_state_interfaces [position]; the "
    "group controllers: joints [...]; a controller's own rate is update_rate in its ros__parameters.",
    "joint_state_broadcaster:\\n  ros__parameters:\\n    type: joint_state_broadcaster/JointStateBroadcaster\\n    "
    "update_rate: 50",
))
def test_yaml_controllers_on_my_robot(task_file: Callable[[int, str], Path]) -> None:
    cfg = _load_yaml(task_file)
    missing = [n for n in NAMES if _type_of(cfg, n) is None]
    assert not missing, f"{YAML} does not declare {', '.join(missing)} yet (see yaml_declares_jazzy_controllers)"
    try:
        system = rw.bringup(_robot_urdf(), task_file(TASK, YAML), spawn=list(NAMES),
                            name=f"task15_grader_{next(_names)}")
    except RRBotWorkshopError as exc:
        _fail(f"MyRobot with your {YAML} and {', '.join(NAMES)} activated does not come up: "
              f"{' '.join(str(exc).split())}")
    with system:
        cm = system.controller_manager
        states = {c.name: c for c in cm.list_controllers()}
        problems = []
        if cm.update_rate != 100:
            problems.append(f"the controller manager runs at {cm.update_rate} Hz, not 100 (the ROS 1 node's loop)")
        wanted = {"joint1_position_controller": (["joint1/effort"], ["joint1/position"]),
                  "joint2_effort_controller": (["joint2/effort"], []),
                  "joint3_position_controller": (["joint3/position"], [])}
        for name, (claims, reads) in wanted.items():
            got = sorted(states[name].claimed_interfaces)
            if got != claims:
                problems.append(f"{name} holds {got}, not {claims}")
            needed = [r for r in reads if r not in states[name].required_state_interfaces]
            if needed:
                problems.append(f"{name} does not read {needed} (it reads {states[name].required_state_interfaces})")
        for name, itf in (("joint2_effort_controller", "effort"), ("joint3_position_controller", "position")):
            expected = ACCEPTED[name].get(_type_of(cfg, name) or "")
            if expected is not None and cfg.parameters_for(name).get("interface_name") != itf:
                problems.append(f"{name} is a forward command controller: its interface_name must be {itf}")
        rate = states["joint_state_broadcaster"].update_rate
        if rate != 50:
            problems.append(f"joint_state_broadcaster updates at {rate} Hz, not 50 (ROS 1's publish_rate: 50)")
        assert not problems, f"with your {YAML} on MyRobot: {'; '.join(problems)}"


@graded(after=("test_yaml_controllers_on_my_robot",), points=1, hint=(
    "Task 15.4: joint1's PID has ROS 1's gains, p 100, i 0.01, d 10: commanded a position, it sends the effort they "
    "give.",
    "pid_controller reads its gains per DOF: gains.<dof>.p, .i, .d in its ros__parameters.",
    "gains:\\n      joint1: {p: 100.0, i: 0.01, d: 10.0}",
))
def test_yaml_pid_gains(task_file: Callable[[int, str], Path]) -> None:
    cfg = _load_yaml(task_file)
    assert _type_of(cfg, "joint1_position_controller") == "pid_controller/PidController", (
        f"{YAML} has no pid_controller/PidController named joint1_position_controller yet "
        "(see yaml_declares_jazzy_controllers)")
    gains = cfg.parameters_for("joint1_position_controller").get("gains", {})
    joint1 = gains.get("joint1", {}) if isinstance(gains, dict) else {}
    got = {k: joint1.get(k) for k in ("p", "i", "d")}
    expected = {"p": 100.0, "i": 0.01, "d": 10.0}
    wrong = [f"{k} is {got[k]!r}, not {v}" for k, v in expected.items()
             if not isinstance(got[k], int | float) or not _close(float(got[k]), v)]
    assert not wrong, f"{YAML}: joint1_position_controller's gains for joint1: {'; '.join(wrong)} (ROS 1's pid)"
    with rw.bringup(_robot_urdf(), task_file(TASK, YAML), spawn=["joint1_position_controller"],
                    name=f"task15_grader_{next(_names)}") as system:
        system.publish("/joint1_position_controller/reference",
                       rw.msgs.MultiDOFCommand(dof_names=["joint1"], values=[0.5], values_dot=[0.0]))
        system.spin_cycles(2)
        effort = system.resource_manager.get_component("my_robot").impl.get_command("joint1/effort")
    assert effort > 49.0, (f"joint1_position_controller, given the reference 0.5 rad with joint1 at 0, commanded "
                           f"{effort:.4g} N m; p = 100 gives at least 50")
