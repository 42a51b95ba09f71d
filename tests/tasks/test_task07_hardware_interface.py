"""Grader of task 7: the RRBot driver (``controlko_hardware_interface/RRBotHardwareInterface``) written by the learner.

The specification (the TODOs of ``rrbot_hardware_interface.py`` and ``rrbot_controllers.yaml``, and notebook 07):

* 7.1 ``on_init`` accepts RRBot's description, renamed or not, and refuses (logging why, naming the element) a joint
  whose command interfaces are not exactly position and velocity, a joint without the position and velocity states,
  and more than one sensor or one GPIO;
* 7.2 ``on_configure`` opens an ``RRBotDevice`` sized to the description's joints and seeded by the hardware parameter
  ``seed`` (default 0), forgets earlier claims, makes effort read NaN (the device measures no torque) and fills the
  states once; ``on_activate`` enables movement with the commands at the current state (no jump, in either mode);
  ``on_deactivate`` disables it;
* 7.3 ``read`` fills every state from the device, each on its own path (each joint, each of the sensor's values in the
  order of its interfaces, each GPIO), also while the component is inactive; ``write`` sends each joint's commands for
  the period that passed, and the digital outputs (above 0.5 is on, NaN is no command); a failing device is
  reported, not swallowed;
* 7.4 ``prepare_command_mode_switch``/``perform_command_mode_switch`` put the device in the mode of the controllers that
  command it, and refuse, with a reason and changing nothing, a switch after which position and velocity would both
  be commanded (on one joint or across joints);
* 7.5 the controllers YAML defines ``incompatible_joint_trajectory_controller``, a JTC commanding position and velocity.

Most checks drive the learner's class through the library's lifecycle wrapper (``HardwareComponent``), as the resource
manager does; the mode checks run a controller manager. Each check judges its own rule: the grader enables the device
or sets its mode itself where another rule's slip would hide this one's, and a failure it provokes (an unplugged
device) is not put at the head of a later reason. ``driver_comes_up`` is the root of the checks that run the driver. ``test_same_as_the_library_driver`` runs generated sequences
of commands, mode switches and lifecycle steps on the learner's driver and on the library's
(``rrbot_workshop.hardware.rrbot``) side by side and reports the smallest sequence that tells them apart.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import cache, lru_cache
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, find, settings
from hypothesis import strategies as st
from hypothesis.errors import NoSuchExample

import rrbot_workshop as rw
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.grading.learner_errors import LearnerErrorLog
from rrbot_workshop.course.grading.references import reference_or_skip
from rrbot_workshop.description import parse_ros2_control
from rrbot_workshop.description.xacro import descriptions_root
from rrbot_workshop.exceptions import SwitchError
from rrbot_workshop.hardware.rrbot_device import ControlMode, RRBotDevice
from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.msgs import Float64MultiArray

TASK = 7
FILE = "rrbot_hardware_interface.py"
YAML = "rrbot_controllers.yaml"
PLUGIN = "task07_grader/RRBotHardwareInterface"
ORIGINAL = "controlko_hardware_interface/RRBotHardwareInterface"
JSB, FWD, VEL, JTC, BAD = ("joint_state_broadcaster", "forward_position_controller", "forward_velocity_controller",
                           "joint_trajectory_controller", "incompatible_joint_trajectory_controller")
J1POS, J1VEL, J2POS, J2VEL = ("joint1_position_controller", "joint1_velocity_controller",
                              "joint2_position_controller", "joint2_velocity_controller")
IO = "flange_io_controller"
FCC = "forward_command_controller/ForwardCommandController"
JTC_TYPE = "joint_trajectory_controller/JointTrajectoryController"
FTS = ("fx", "fy", "fz", "tx", "ty", "tz")
TOL = 1e-9  # the device is deterministic: a driver passing its values on gives them exactly
_names = itertools.count()


# --------------------------------------------------------------------------------------------- the learner's class


@pytest.fixture(scope="module")
def driver(task_file: Callable[[int, str], Path]) -> Iterator[type]:
    """The learner's class (if the file does not import, the framework puts the learner's error in the reason)."""
    task_file(TASK, FILE)
    module = rw.course.load_module(TASK, FILE, quiet=True)  # why it does not import goes first in the reason
    if module is None:
        _fail(f"your {FILE} does not import, so no check can run your driver: fix that first")
    cls = getattr(module, "RRBotHardwareInterface", None)
    if not isinstance(cls, type):
        _fail(f"your {FILE} defines no class RRBotHardwareInterface (the plugin's class)")
    plugins.register("hardware", PLUGIN, cls)
    yield cls
    plugins.unregister("hardware", PLUGIN)


def _fail(message: str) -> None:
    """Fail the check with ``message`` as its whole reason."""
    raise AssertionError(message)


@contextmanager
def _provoked() -> Iterator[None]:
    """A failure the grader provokes (an unplugged device) passes through the learner's read or write, and the library
    logs it: it is not the learner's error, so a later reason must not start with it."""
    logs = [h for h in logging.getLogger().handlers if isinstance(h, LearnerErrorLog)]
    kept = [len(log.found) for log in logs]
    try:
        yield
    finally:
        for log, count in zip(logs, kept, strict=True):
            del log.found[count:]


def _raised(exc: BaseException) -> str:
    """The exception's type: the framework puts the learner's own line and message first in the reason."""
    return type(exc).__name__


#: What each callback must do, said in the reason when it stops the driver from coming up.
_DUTY = {
    "on_init": "accept RRBot's description: each joint commands position and velocity and reports position and "
               "velocity; return CallbackReturn.SUCCESS",
    "on_configure": "open the device, self.device = RRBotDevice(number of joints, seed=...), fill the states once, "
                    "return CallbackReturn.SUCCESS",
    "on_activate": "enable the device's movement (self.device.init()), set the commands to the current state, return "
                   "CallbackReturn.SUCCESS",
    "on_deactivate": "disable the device's movement (self.device.stop()), return CallbackReturn.SUCCESS",
    "read": "fill the states from the device and return ReturnType.OK",
    "write": "send the commands to the device and return ReturnType.OK",
}


def _failed(callback: str, component: HardwareComponent, before: BaseException | None, what: str = "RRBot") -> str:
    exc = component.last_error
    if exc is not None and exc is not before:
        how = f"raised {_raised(exc)}"
    else:
        how = f"did not return SUCCESS (the component is '{component.get_lifecycle_state().label}')"
    return (f"{what} does not come up on your driver: your {callback} {how}, so no check that runs the driver can "
            f"pass; fix {callback} first: {_DUTY[callback]}.")


# --------------------------------------------------------------------------------------------- descriptions


@cache
def _xacro(prefix: str) -> str:
    return rw.description.process_xacro(descriptions_root() / "rrbot/urdf/rrbot.urdf.xacro", use_mock_hardware=False,
                                        prefix=prefix)


def _urdf(prefix: str = "", seed: int | None = None, plugin: str = PLUGIN) -> str:
    urdf = _xacro(prefix).replace(ORIGINAL, plugin)
    if seed is not None:
        urdf = urdf.replace(f"<plugin>{plugin}</plugin>", f'<plugin>{plugin}</plugin><param name="seed">{seed}</param>')
    return urdf


def _element(urdf: str, tag: str, name: str) -> tuple[int, int]:
    """Start and end of ``<tag name="name">...</tag>`` inside the ``<ros2_control>`` block."""
    block = urdf.index("<ros2_control")
    start = urdf.index(f'<{tag} name="{name}">', block)
    return start, urdf.index(f"</{tag}>", start) + len(f"</{tag}>")


def _edit(urdf: str, tag: str, name: str, old: str, new: str) -> str:
    start, end = _element(urdf, tag, name)
    part = urdf[start:end]
    assert old in part, f"grader: {old!r} not in <{tag} name='{name}'>"
    return urdf[:start] + part.replace(old, new, 1) + urdf[end:]


def _drop(urdf: str, tag: str, name: str) -> str:
    start, end = _element(urdf, tag, name)
    return urdf[:start] + urdf[end:]


@lru_cache(maxsize=32)
def _info(urdf: str) -> Any:
    return parse_ros2_control(urdf)[0]


def _one_joint() -> str:
    """RRBot's tag with joint1 only (and its GPIO pair): the device must be sized to one joint."""
    urdf = _drop(_urdf(), "joint", "joint2")
    for line in ('<state_interface name="digital_in_2"/>', '<command_interface name="digital_out_2"/>',
                 '<state_interface name="digital_out_2"/>'):
        urdf = _edit(urdf, "gpio", "flange_gpios", line, "")
    return urdf


def _reordered_sensor() -> str:
    """The sensor renamed ``wrist_fts`` with its interfaces in the reverse order (tz first)."""
    urdf = _urdf()
    start, end = _element(urdf, "sensor", "tcp_fts_sensor")
    part = urdf[start:end].replace('name="tcp_fts_sensor"', 'name="wrist_fts"')
    lines = [f'<state_interface name="{k}"/>' for k in FTS]
    for k in FTS:
        part = part.replace(f'<state_interface name="{k}"/>', f"@{k}@")
    for k, line in zip(FTS, reversed(lines), strict=True):
        part = part.replace(f"@{k}@", line)
    return urdf[:start] + part + urdf[end:]


# --------------------------------------------------------------------------------------------- a component, as the RM drives it


class Rig:
    """One driver instance inside the library's lifecycle wrapper, driven as the resource manager drives it."""

    def __init__(self, cls: type, urdf: str) -> None:
        self.info = _info(urdf)
        impl = cls()
        self.component = HardwareComponent(impl)
        self.time = 0.0
        self.init_result: Any = None  # what on_init returned, or the exception it raised
        on_init = impl.on_init

        def recorded(info: Any) -> Any:
            try:
                self.init_result = on_init(info)
            except Exception as exc:
                self.init_result = exc
                raise
            return self.init_result

        impl.on_init = recorded
        self.init_state = self.component.initialize(self.info)
        self.states: dict[str, Any] = {}
        self.commands: dict[str, Any] = {}
        if self.init_state is State.UNCONFIGURED:
            self.states = {h.name: h for h in self.component.export_state_interfaces()}
            self.commands = {h.name: h for h in self.component.export_command_interfaces()}

    @property
    def impl(self) -> Any:
        return self.component.impl

    @property
    def device(self) -> Any:
        return getattr(self.component.impl, "device", None)

    @property
    def state(self) -> State:
        return self.component.get_lifecycle_state()

    def value(self, name: str) -> Any:
        return self.states[name].get_value()

    def command(self, name: str, value: float) -> None:
        self.commands[name].set_value(value)

    def up(self, target: State = State.ACTIVE, what: str = "RRBot") -> Rig:
        """configure (and activate); a failing callback fails the check with a reason naming it (and ``what``)."""
        if self.init_state is not State.UNCONFIGURED:
            _fail(_failed("on_init", self.component, None, what))
        for step, reached, callback in (("configure", State.INACTIVE, "on_configure"),
                                        ("activate", State.ACTIVE, "on_activate")):
            if self.state is target:
                break
            before = self.component.last_error
            if getattr(self.component, step)() is not reached:
                _fail(_failed(callback, self.component, before, what))
        return self

    def cycle(self, period: float = 0.01, n: int = 1, check: bool = True) -> None:
        """``n`` cycles of read then write; a failing read or write fails the check (unless ``check`` is False)."""
        for _ in range(n):
            for what in ("read", "write"):
                before = self.component.last_error
                result = getattr(self.component, what)(self.time, period)
                if check and result is not ReturnType.OK:
                    exc = self.component.last_error
                    how = f"raised {_raised(exc)}" if exc is not None and exc is not before else f"returned {result}"
                    _fail(f"your {what} {how} while the device worked; {_DUTY[what]}.")
            self.time += period

    def switch(self, start: list[str], stop: list[str]) -> bool:
        """prepare then (if accepted) perform, as the resource manager does for one component."""
        if self.component.prepare_command_mode_switch(sorted(start), sorted(stop)) is not ReturnType.OK:
            return False
        return self.component.perform_command_mode_switch(sorted(start), sorted(stop)) is ReturnType.OK


def _device(rig: Rig) -> RRBotDevice:
    device = rig.device
    if not isinstance(device, RRBotDevice):
        _fail(f"after on_configure your driver's self.device is {device!r}: open the device there, "
              "self.device = RRBotDevice(...) (the exercise's __init__ declares self.device)")
    return device


def _rig(cls: type, urdf: str | None = None, target: State = State.ACTIVE, what: str = "RRBot") -> Rig:
    return Rig(cls, urdf or _urdf()).up(target, what)


def _close(a: float, b: float, tol: float = TOL) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol


# --------------------------------------------------------------------------------------------- a running system


def _controllers(prefix: str = "") -> dict[str, tuple[str, dict[str, Any]]]:
    j1, j2 = f"{prefix}joint1", f"{prefix}joint2"
    return {
        JSB: ("joint_state_broadcaster/JointStateBroadcaster", {}),
        FWD: (FCC, {"joints": [j1, j2], "interface_name": "position"}),
        VEL: (FCC, {"joints": [j1, j2], "interface_name": "velocity"}),
        BAD: (JTC_TYPE, {"joints": [j1, j2], "command_interfaces": ["position", "velocity"],
                         "state_interfaces": ["position", "velocity"]}),
        J1POS: (FCC, {"joints": [j1], "interface_name": "position"}),
        J1VEL: (FCC, {"joints": [j1], "interface_name": "velocity"}),
        J2POS: (FCC, {"joints": [j2], "interface_name": "position"}),
        J2VEL: (FCC, {"joints": [j2], "interface_name": "velocity"}),
        IO: ("gpio_controllers/GpioCommandController", {
            "gpios": [f"{prefix}flange_gpios"],
            "command_interfaces": {f"{prefix}flange_gpios": {"interfaces": ["digital_out_1", "digital_out_2"]}}}),
    }


@contextmanager
def _system(cls: type, names: tuple[str, ...], spawn: tuple[str, ...], rate: int = 100,
            rates: dict[str, int] | None = None) -> Iterator[rw.System]:
    """RRBot on the learner's driver with the controllers ``names`` loaded and ``spawn`` active; each step checked."""
    urdf = _urdf()
    Rig(cls, urdf).up(State.UNCONFIGURED)  # on_init alone first: its failure is named as such
    table = _controllers()
    types = {n: {"type": table[n][0]} for n in names}
    params = {n: {"ros__parameters": {**table[n][1], **({"update_rate": rates[n]} if rates and n in rates else {})}}
              for n in names}
    cfg = {"controller_manager": {"ros__parameters": {"update_rate": rate, **types}}, **params}
    system = rw.bringup(urdf, cfg, inactive=list(names), hardware_initial_state={"rrbot": "unconfigured"},
                        name=f"task07_grader_{next(_names)}")
    try:
        cm = system.controller_manager
        component = system.resource_manager.get_component("rrbot")
        for target, callback in (("inactive", "on_configure"), ("active", "on_activate")):
            before = component.last_error
            if not cm.set_hardware_component_state("rrbot", target):
                _fail(_failed(callback, component, before))
        if spawn:
            before = component.last_error
            try:
                cm.switch_controllers(list(spawn), [], "strict")
            except SwitchError as exc:
                raised = component.last_error
                extra = f" Your driver raised {_raised(raised)}." if raised is not None and raised is not before else ""
                _fail(f"activating {', '.join(spawn)} on your driver was refused: {exc}.{extra} One controller "
                      "commanding the joints in one mode must be accepted (prepare_command_mode_switch returns OK).")
        yield system
    finally:
        system.shutdown()


def _system_device(system: rw.System) -> RRBotDevice:
    device = getattr(system.resource_manager.get_component("rrbot").impl, "device", None)
    if not isinstance(device, RRBotDevice):
        _fail(f"your driver's self.device is {device!r} while the component is active; open the device in on_configure")
    return device


def _positions(system: rw.System) -> list[float]:
    return list(_system_device(system).read_joint_states()[0])


# --------------------------------------------------------------------------------------------- 7.1 on_init


_INIT_HINTS = ("on_init", "info.joints lists each <joint>; joint.command_interfaces and joint.state_interfaces list "
               "their interfaces (each with .name); info.sensors and info.gpios the <sensor> and <gpio> elements. "
               "Call super().on_init(info) first.")


@graded(points=1, hint=(
    "Task 7.1: on_init accepts RRBot's description, whatever the robot's names (a prefixed RRBot too) and however many "
    "joints it has.",
    _INIT_HINTS[1],
    "return CallbackReturn.SUCCESS after the checks pass; never compare joint names with 'joint1'",
))
def test_init_accepts_rrbot(driver: type) -> None:
    Rig(driver, _urdf()).up(State.UNCONFIGURED)  # RRBot's own description, or the reason every check gives
    rejected = []
    for urdf, what in ((_urdf(prefix="left_"), "RRBot with the prefix 'left_' (joints left_joint1 and left_joint2)"),
                       (_one_joint(), "RRBot with joint1 only")):
        rig = Rig(driver, urdf)
        if rig.init_state is not State.UNCONFIGURED:
            exc = rig.component.last_error
            rejected.append(f"{what} ({'it raised ' + _raised(exc) if exc else 'it did not return SUCCESS'})")
    assert not rejected, (f"your on_init accepts RRBot's description but refused {' and '.join(rejected)}; the device "
                          "can serve it: take the names and counts from info, do not compare them with RRBot's")


_BROKEN_JOINTS = (
    ("joint1", '<command_interface name="velocity"/>', "", "no velocity command interface"),
    ("joint2", '<command_interface name="position"/>', "", "no position command interface"),
    ("joint2", '<command_interface name="velocity"/>',
     '<command_interface name="velocity"/><command_interface name="effort"/>', "an extra effort command interface"),
    ("joint2", '<state_interface name="velocity"/>', "", "no velocity state interface"),
    ("joint1", '<state_interface name="position">', '<state_interface name="angle">', "no position state interface"),
)


def _broken(joint: str, old: str, new: str) -> str:
    return _edit(_urdf(), "joint", joint, old, new)


@graded(points=2, after=("test_init_accepts_rrbot",), hint=(
    "Task 7.1: on_init refuses a joint whose command interfaces are not exactly position and velocity, or whose state "
    "interfaces lack position or velocity: on every joint, not only joint1.",
    _INIT_HINTS[1],
    "for joint in info.joints: if sorted(i.name for i in joint.command_interfaces) != ['position', 'velocity']: "
    "self.logger.error(...); return CallbackReturn.ERROR (and the same for the states)",
))
def test_init_refuses_joint_interfaces(driver: type) -> None:
    test_init_accepts_rrbot(driver)
    accepted = [f"{joint} with {what}" for joint, old, new, what in _BROKEN_JOINTS
                if Rig(driver, _broken(joint, old, new)).init_state is State.UNCONFIGURED]  # refused however it is
    assert not accepted, (f"your on_init accepted a description with {'; '.join(accepted)}: the device cannot serve "
                          "it, so on_init must return ERROR")


@graded(points=1, after=("test_init_accepts_rrbot",), hint=(
    "Task 7.1: the device has one force-torque sensor and one set of I/Os: on_init refuses a second <sensor> and a "
    "second <gpio>, each on its own.",
    "len(info.sensors) and len(info.gpios).",
    "if len(info.sensors) > 1 or len(info.gpios) > 1: self.logger.error(...); return CallbackReturn.ERROR",
))
def test_init_refuses_a_second_sensor_or_gpio(driver: type) -> None:
    test_init_accepts_rrbot(driver)
    urdf = _urdf()
    sensor = urdf[slice(*_element(urdf, "sensor", "tcp_fts_sensor"))]
    gpio = urdf[slice(*_element(urdf, "gpio", "flange_gpios"))]
    two_sensors = urdf.replace(sensor, sensor + sensor.replace("tcp_fts_sensor", "second_fts_sensor"))
    two_gpios = urdf.replace(gpio, gpio + gpio.replace("flange_gpios", "second_gpios"))
    accepted = [what for text, what in ((two_sensors, "two <sensor> elements"), (two_gpios, "two <gpio> elements"))
                if Rig(driver, text).init_state is State.UNCONFIGURED]
    assert not accepted, f"your on_init accepted a description with {' and with '.join(accepted)}; refuse it"


class _Records(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@graded(points=1, after=("test_init_refuses_joint_interfaces",), hint=(
    "Task 7.1: when on_init refuses a description it logs why, naming the joint.",
    "self.logger is the component's logger: self.logger.error('...%s...', joint.name).",
    "self.logger.error(\"joint '%s' has command interfaces %s; the device takes position and velocity\", joint.name, "
    "names)",
))
def test_init_logs_why(driver: type) -> None:
    test_init_accepts_rrbot(driver)
    root = logging.getLogger()
    silent = []
    for joint, old, new, what in _BROKEN_JOINTS[:2] + _BROKEN_JOINTS[3:4]:
        handler = _Records()
        root.addHandler(handler)
        try:
            state = Rig(driver, _broken(joint, old, new)).init_state
        finally:
            root.removeHandler(handler)
        if state is State.UNCONFIGURED or not any(joint in r.getMessage() for r in handler.records):
            silent.append(f"{joint} with {what}")
    assert not silent, (f"nothing was logged naming the joint when your on_init met {'; '.join(silent)} (or it "
                        "accepted it): log why with self.logger.error, naming the joint")


def _two(element: str) -> str:
    """RRBot's description with a second <sensor> or <gpio>."""
    urdf = _urdf()
    name = "tcp_fts_sensor" if element == "sensor" else "flange_gpios"
    block = urdf[slice(*_element(urdf, element, name))]
    return urdf.replace(block, block + block.replace(name, f"second_{name}"))


@graded(points=1, after=("test_init_refuses_joint_interfaces", "test_init_refuses_a_second_sensor_or_gpio"), hint=(
    "Task 7.1: on_init refuses as the TODO says: it logs why and returns CallbackReturn.ERROR. Not FAILURE (a "
    "different outcome in ros2_control's lifecycle), and not an exception (the resource manager would only see that "
    "something went wrong, not what).",
    "CallbackReturn has SUCCESS, FAILURE and ERROR; a refused description is ERROR. No raise in on_init.",
    "self.logger.error(\"joint '%s' has command interfaces %s; ...\", joint.name, names); return CallbackReturn.ERROR",
))
def test_init_refusal_returns_error(driver: type) -> None:
    test_init_accepts_rrbot(driver)
    wrong = []
    cases = [(_broken(joint, old, new), f"{joint} with {what}") for joint, old, new, what in _BROKEN_JOINTS]
    cases += [(_two("sensor"), "two <sensor> elements"), (_two("gpio"), "two <gpio> elements")]
    for urdf, what in cases:
        rig = Rig(driver, urdf)
        result = rig.init_result
        if rig.init_state is State.UNCONFIGURED or result is CallbackReturn.ERROR:
            continue  # accepted (the checks above judge that) or refused as the task says
        if isinstance(result, BaseException):
            wrong.append(f"for {what} it raised {type(result).__name__}")
        else:
            shown = f"CallbackReturn.{result.name}" if isinstance(result, CallbackReturn) else repr(result)
            wrong.append(f"for {what} it returned {shown}")
    assert not wrong, (f"your on_init refuses, but {'; '.join(wrong)}; the task says: log why and return "
                       "CallbackReturn.ERROR")


# --------------------------------------------------------------------------------------------- 7.2 lifecycle


@graded(points=2, after=("test_init_accepts_rrbot",), hint=(
    "Task 7.2: on_configure opens the device, sized to the description's joints (one degree of freedom per <joint>), "
    "and fills the states once, so they show the robot before any cycle runs (joints at 0.1 rad, at rest); the device "
    "does not move yet. Configured again after a cleanup, it opens a new device.",
    "self.device = RRBotDevice(len(self.joints), seed=...); then call your own read once (self.read(0.0, 0.0)).",
    "self.device = RRBotDevice(len(self.joints), seed=int(self.info.hardware_parameters.get('seed', '0'))); "
    "self.read(0.0, 0.0); return CallbackReturn.SUCCESS",
))
def test_configure_opens_the_device(driver: type) -> None:
    for urdf, joints, what in ((_urdf(), ["joint1", "joint2"], "RRBot"), (_urdf("left_"), ["left_joint1",
                               "left_joint2"], "RRBot prefixed 'left_'"), (_one_joint(), ["joint1"], "RRBot with joint1 only")):
        rig = _rig(driver, urdf, State.INACTIVE, what)
        _check_opened(rig, joints, what, "just configured (before any cycle)")
    rig = _rig(driver, _urdf(), State.INACTIVE)
    old = _device(rig)
    old.init()  # the grader moves the first device, so a device kept over the cleanup shows
    old.write_joint_commands([0.6, -0.4], [0.0, 0.0], 1.0)
    old.stop()
    for step, reached in (("cleanup", State.UNCONFIGURED), ("configure", State.INACTIVE)):
        before = rig.component.last_error
        if getattr(rig.component, step)() is not reached:
            if step == "cleanup":
                _fail(f"cleaning up your driver did not bring it back to unconfigured ({rig.state.label})")
            if rig.device is None:
                _fail("configured again after a cleanup (which dropped the device), your driver has no device: "
                      "on_configure opens it, self.device = RRBotDevice(...)")
            _fail(_failed("on_configure", rig.component, before, "RRBot configured again after a cleanup"))
    if _device(rig) is old:
        _fail("configured again after a cleanup, your driver still uses the device it opened before: on_configure "
              "opens a new one (on_cleanup dropped it)")
    _check_opened(rig, ["joint1", "joint2"], "RRBot", "configured again after a cleanup")


def _check_opened(rig: Rig, joints: list[str], what: str, when: str) -> None:
    device = _device(rig)
    assert device.number_of_dofs == len(joints), (
        f"{what}: your device has {device.number_of_dofs} joints for the description's {len(joints)}: size it "
        "with the number of <joint> elements")
    assert not device.movement_enabled, f"{what}: the device's movement is enabled after configure (only activate does)"
    for joint in joints:
        p, v = rig.value(f"{joint}/position"), rig.value(f"{joint}/velocity")
        assert _close(p, 0.1) and _close(v, 0.0), (
            f"{what}, {when}: {joint} reads position {p} and velocity {v}; the device has it at 0.1 rad, at rest: fill "
            "the states once in on_configure")


@graded(points=1, after=("test_configure_opens_the_device",), hint=(
    "Task 7.2-7.3: the driver comes up as the resource manager brings it up (on_init, on_configure, on_activate "
    "return SUCCESS) and runs cycles of read and write that return OK.",
    "Each callback returns CallbackReturn.SUCCESS; read and write return ReturnType.OK while the device works.",
    "The reason names the callback that stops it: fix that one first (notebook 07 runs the driver step by step).",
))
def test_driver_comes_up(driver: type) -> None:
    _rig(driver).cycle(n=3)


@graded(points=1, after=("test_driver_comes_up",), hint=(
    "Task 7.2: the device measures no torque, so each joint's effort state reads NaN (unknown), never another value "
    "(the original copied the acceleration there).",
    "The description gives effort an initial_value of 0.0: set it to math.nan in on_configure and never write it.",
    "for joint in self.joints: self.set_state(f'{joint}/effort', math.nan)",
))
def test_effort_reads_nan(driver: type) -> None:
    rig = _rig(driver)
    rig.command("joint1/position", 0.4)
    rig.command("joint2/position", -0.3)
    for cycle in range(6):
        for joint in ("joint1", "joint2"):
            effort = rig.value(f"{joint}/effort")
            assert math.isnan(effort), (f"{joint}'s effort reads {effort} (after {cycle} cycles); the device measures "
                                        "no torque: it must read NaN")
        rig.cycle()


@graded(points=2, after=("test_driver_comes_up",), hint=(
    "Task 7.2: on_activate enables the device's movement and sets every joint's position and velocity commands to the "
    "current state, so a controller taking over (or none) does not make the robot jump, in either mode.",
    "self.device.init(); positions, velocities, _ = self.device.read_joint_states(); self.set_command(...) for each "
    "joint's position and velocity.",
    "for joint, p, v in zip(self.joints, positions, velocities): self.set_command(f'{joint}/position', p); "
    "self.set_command(f'{joint}/velocity', v)",
))
def test_activate_without_a_jump(driver: type) -> None:
    rig = _rig(driver)
    device = _device(rig)
    assert device.movement_enabled, "after activate the device's movement is not enabled: call self.device.init()"
    rig.command("joint1/position", 0.35)
    rig.command("joint2/position", -0.05)
    rig.command("joint1/velocity", 0.3)
    rig.command("joint2/velocity", -0.2)
    rig.cycle(n=20)  # joint1 at 0.2 and joint2 at 0.0, both still moving
    for mode in ("position", "velocity"):
        if mode == "velocity":  # the grader puts the device in velocity mode (mode switches are task 7.4's rule)
            _device(rig).set_control_mode(ControlMode.VELOCITY)
            rig.command("joint1/velocity", 0.3)
            rig.command("joint2/velocity", -0.2)
            rig.cycle(n=10)
        rig.component.deactivate()
        rig.cycle(n=2)  # inactive: read runs, write does not (as between two requests in a running system)
        rig.component.activate()
        device = _device(rig)
        positions, velocities, _ = device.read_joint_states()
        for i, joint in enumerate(("joint1", "joint2")):
            pc, vc = rig.commands[f"{joint}/position"].get_value(), rig.commands[f"{joint}/velocity"].get_value()
            assert _close(pc, positions[i]) and _close(vc, velocities[i]), (
                f"re-activated in {mode} mode with {joint} at {positions[i]:.3f} rad: its commands are position {pc} "
                f"and velocity {vc}; they must be the current state ({positions[i]:.3f} rad, {velocities[i]} rad/s)")


@graded(points=1, after=("test_driver_comes_up",), hint=(
    "Task 7.2: on_deactivate disables the device's movement; a later on_activate enables it again.",
    "RRBotDevice.stop() disables movement, init() enables it; device.movement_enabled tells which.",
    "def on_deactivate(self, previous_state): self.device.stop(); return CallbackReturn.SUCCESS",
))
def test_deactivate_disables_movement(driver: type) -> None:
    rig = _rig(driver)
    for round_ in (1, 2):
        before = rig.component.last_error
        if rig.component.deactivate() is not State.INACTIVE:
            _fail(_failed("on_deactivate", rig.component, before))
        assert not _device(rig).movement_enabled, (
            f"after deactivate (time {round_}) the device's movement is still enabled")
        rig.component.activate()


@graded(points=1, after=(
    "test_driver_comes_up", "test_mode_follows_the_controllers", "test_device_failure_reported",
), hint=(
    "Task 7.2: at configure no controller holds a command interface yet: configured again after a cleanup, or after "
    "a failure (the controller manager then stops the controllers without a mode switch), the driver forgets the "
    "claims it remembered.",
    "Your record of the claimed interfaces (self.claimed) starts empty in on_configure.",
    "self.claimed = set() in on_configure",
))
def test_claims_forgotten_at_configure(driver: type) -> None:
    rig = _rig(driver)
    assert rig.switch(["joint1/velocity", "joint2/velocity"], []), "activating a velocity controller was refused"
    for step in ("deactivate", "cleanup"):
        getattr(rig.component, step)()
    rig.up()
    assert rig.switch(["joint1/position", "joint2/position"], []), (
        "configured again after a cleanup (a velocity controller held the joints before), your driver refused a "
        "position controller: it still counts the velocity interfaces as claimed; forget claims in on_configure")
    assert rig.switch(["joint1/velocity", "joint2/velocity"], ["joint1/position", "joint2/position"]), (
        "switching from the position to a velocity controller was refused")
    device = _device(rig)

    def unplugged(*args: Any) -> Any:
        raise ConnectionError("RRBot cable unplugged (the grader's simulated failure)")

    device.read_joint_states = unplugged
    with _provoked():
        rig.cycle(check=False)
    assert rig.state is not State.ACTIVE, "the device failed in read and the component stayed active"
    rig.up()
    assert rig.switch(["joint1/position", "joint2/position"], []), (
        "after a failure (the velocity controller was stopped without a mode switch) and configure + activate, your "
        "driver refused a position controller: it still counts the velocity interfaces as claimed; forget claims in "
        "on_configure")


# --------------------------------------------------------------------------------------------- 7.3 values


def _joints_swapped() -> str:
    """RRBot's tag with joint2's <joint> before joint1's: the device's joint 0 is joint2 (the description's order)."""
    urdf = _urdf()
    first, second = (urdf[slice(*_element(urdf, "joint", name))] for name in ("joint1", "joint2"))
    marker = "@@joint1@@"
    return urdf.replace(first, marker).replace(second, first).replace(marker, second)


@graded(points=3, after=("test_driver_comes_up",), hint=(
    "Task 7.3: read gives each joint its own position and velocity from the device; write sends each joint's position "
    "and velocity commands for the period that passed (whatever the controller manager's rate), joint i of the device "
    "being the description's i-th <joint>.",
    "read: self.device.read_joint_states() -> set_state of each joint; write: self.device.write_joint_commands("
    "positions, velocities, period), one value per joint in the description's order (not sorted by name).",
    "positions = [self.get_command(f'{j}/position') for j in self.joints]; velocities likewise; "
    "self.device.write_joint_commands(positions, velocities, period)",
))
def test_joint_states_and_commands(driver: type) -> None:
    cases = ((_urdf(), ("joint1", "joint2"), "RRBot"),
             (_joints_swapped(), ("joint2", "joint1"), "RRBot with joint2's <joint> listed before joint1's"))
    for urdf, order, what in cases:
        rig = _rig(driver, urdf)
        if not _device(rig).movement_enabled:
            _device(rig).init()  # enabling movement is activate_without_a_jump's rule: the grader does it here
        twin = RRBotDevice(2)
        twin.init()
        for mode, period, targets in (("position", 0.02, (0.3, -0.5)), ("position", 0.005, (-0.2, 0.4)),
                                      ("velocity", 0.01, (0.2, -0.1)), ("velocity", 0.03, (-0.3, 0.25))):
            if mode == "velocity":  # the grader puts the device in velocity mode (mode switches are task 7.4's rule)
                for device in (_device(rig), twin):
                    device.set_control_mode(ControlMode.VELOCITY)
            commanded = dict(zip(order, targets, strict=True))
            for joint, value in commanded.items():
                rig.command(f"{joint}/{mode}", value)
            for k in range(30):
                rig.cycle(period)
                unused = [math.nan, math.nan]  # the device reads only the commands of its mode
                twin.write_joint_commands(*((list(targets), unused) if mode == "position" else (unused, list(targets))),
                                          period)
                expected = twin.read_joint_states()
                got = _device(rig).read_joint_states()
                for i, joint in enumerate(order):
                    assert _close(got[0][i], expected[0][i]), (
                        f"{what}, commanded in {mode} to {[commanded[j] for j in ('joint1', 'joint2')]} (joint1, joint2) "
                        f"with a {period * 1000:g} ms period, after {k + 1} cycles {joint} (the device's joint {i}) is "
                        f"at {got[0][i]:.4f} rad; the device should be at {expected[0][i]:.4f} (pass each joint's "
                        f"{mode} command, in the description's joint order, and the period given to write)")
                rig.component.read(rig.time, period)
                for i, joint in enumerate(order):
                    p, v = rig.value(f"{joint}/position"), rig.value(f"{joint}/velocity")
                    assert _close(p, got[0][i]) and _close(v, got[1][i]), (
                        f"{what}: after read, {joint} reads position {p} and velocity {v}; the device has "
                        f"{got[0][i]:.4f} rad and {got[1][i]:.4f} rad/s for it (its joint {i})")
    # through the controller manager at 50 Hz, a position controller updating at 10 Hz (every controller slower than
    # the loop)
    with _system(driver, (FWD,), (FWD,), rate=50, rates={FWD: 10}) as system:
        if not _system_device(system).movement_enabled:
            _system_device(system).init()  # activate_without_a_jump's rule, stood in for here
        system.publish(f"/{FWD}/commands", Float64MultiArray(data=[0.3, -0.5]))
        system.spin(0.6)
        got = _positions(system)
        assert abs(got[0] - 0.3) <= 0.011 and abs(got[1] - (0.1 - 0.3)) <= 0.011, (
            f"at 50 Hz with the position controller at 10 Hz, 0.6 s after commanding [0.3, -0.5] the joints are at "
            f"{[round(q, 3) for q in got]}; at the device's 0.5 rad/s they should be at [0.3, -0.2] (within 0.01 rad)")


@graded(points=1, after=("test_driver_comes_up",), hint=(
    "Task 7.3: each joint's acceleration state (RRBot declares one) carries the device's acceleration of that joint.",
    "The third list of self.device.read_joint_states().",
    "if f'{joint}/acceleration' in self.state_interface_names: self.set_state(f'{joint}/acceleration', a)",
))
def test_acceleration_states(driver: type) -> None:
    rig = _rig(driver)
    for targets in ((0.3, -0.2), (0.1, 0.2)):
        rig.command("joint1/position", targets[0])
        rig.command("joint2/position", targets[1])
        for _ in range(3):
            rig.cycle()
            rig.component.read(rig.time, 0.01)
            accelerations = _device(rig).read_joint_states()[2]
            for i, joint in enumerate(("joint1", "joint2")):
                a = rig.value(f"{joint}/acceleration")
                assert _close(a, accelerations[i]), (
                    f"{joint}'s acceleration state reads {a}; the device's is {accelerations[i]}")


@graded(points=2, after=("test_driver_comes_up",), hint=(
    "Task 7.3: the sensor's states carry the device's sensor values, value i on the sensor's i-th state interface, "
    "whatever the sensor is called; they change every second of device time.",
    "sensor = self.info.sensors[0]; self.device.read_sensor_values(len(sensor.state_interfaces)) in every read.",
    "for itf, v in zip(sensor.state_interfaces, values): self.set_state(f'{sensor.name}/{itf.name}', v)",
))
def test_sensor_values(driver: type) -> None:
    for urdf, what in ((_urdf(), "tcp_fts_sensor"), (_reordered_sensor(), "wrist_fts (interfaces tz, ty, tx, fz, fy, fx)")):
        rig = _rig(driver, urdf)
        sensor = rig.info.sensors[0]
        for second in range(3):
            rig.cycle(0.5, n=2)
            rig.component.read(rig.time, 0.5)
            expected = _device(rig).read_sensor_values(6)
            for itf, value in zip(sensor.state_interfaces, expected, strict=True):
                got = rig.value(f"{sensor.name}/{itf.name}")
                assert _close(got, value), (
                    f"sensor {what}, {second + 1} s of device time: its state '{itf.name}' reads {got}; the device's "
                    f"value for it (number {sensor.state_interfaces.index(itf) + 1} of the sensor's interfaces) is {value}")


def _spy_inputs(device: RRBotDevice) -> list[list[bool]]:
    calls: list[list[bool]] = []
    real = device.read_gpio

    def read_gpio() -> tuple[list[bool], list[bool]]:
        inputs, outputs = real()
        calls.append(list(inputs))
        return inputs, outputs

    device.read_gpio = read_gpio
    return calls


@graded(points=1, after=("test_driver_comes_up",), hint=(
    "Task 7.3: read gives the GPIO's states from the device: each digital_in_N is input N, each digital_out_N reads "
    "back output N, as 1.0 or 0.0, in every read, also while the component is inactive (read runs then too).",
    "inputs, outputs = self.device.read_gpio(); the GPIO is self.info.gpios[0]; N is the number at the end of the "
    "interface's name.",
    "self.set_state(f'{gpio.name}/digital_in_{n}', 1.0 if inputs[n - 1] else 0.0); the same from outputs for "
    "digital_out_{n}",
))
def test_gpio_states(driver: type) -> None:
    for prefix in ("", "left_"):
        rig = _rig(driver, _urdf(prefix), State.INACTIVE)
        gpio = rig.info.gpios[0].name
        seen: dict[int, set[float]] = {1: set(), 2: set()}
        for k in range(24):
            if k == 12:
                rig.component.activate()
            status = "inactive" if k < 12 else "active"
            outputs = [bool(k & 1), bool(k & 2)]  # the grader sets the device's outputs itself: read alone is judged
            _device(rig).write_gpios(outputs)
            calls = _spy_inputs(_device(rig))
            rig.component.read(rig.time, 0.01)
            for n in (1, 2):
                got = rig.value(f"{gpio}/digital_in_{n}")
                allowed = {1.0 if c[n - 1] else 0.0 for c in calls}
                assert got in allowed, (
                    f"{gpio}/digital_in_{n} reads {got} after a read ({status} component); the device's input {n} was "
                    f"{sorted(allowed) if allowed else 'not read'} in that read")
                seen[n].add(got)
                back = rig.value(f"{gpio}/digital_out_{n}")
                assert back == (1.0 if outputs[n - 1] else 0.0), (
                    f"with the device's outputs {outputs}, {gpio}/digital_out_{n} reads {back} after a read ({status} "
                    f"component): it reads back output {n} of the device, as 1.0 or 0.0 (not the command)")
        assert all(s == {0.0, 1.0} for s in seen.values()), f"the digital inputs never changed over 24 reads: {seen}"


@graded(points=2, after=("test_driver_comes_up",), hint=(
    "Task 7.3: write sets each output N from its digital_out_N command: above 0.5 is on, 0.5 and below off; NaN is no "
    "command, so the output keeps what it was, on or off.",
    "In write: _, outputs = self.device.read_gpio(); change outputs[N - 1] for each commanded digital_out_N (skip "
    "NaN: math.isnan); self.device.write_gpios(outputs).",
    "value = self.get_command(f'{gpio.name}/{itf.name}'); if not math.isnan(value): outputs[n - 1] = value > 0.5",
))
def test_gpio_outputs(driver: type) -> None:
    rig = _rig(driver)
    rig.cycle()
    assert _device(rig).read_gpio()[1] == [False, False], (
        f"with no digital_out command yet (NaN), the outputs are {_device(rig).read_gpio()[1]}; NaN means no command")
    nan = math.nan
    for commands, outputs in (((1.0, 0.0), [True, False]), ((0.0, 1.0), [False, True]), ((0.7, 0.5), [True, False]),
                              ((0.2, 0.51), [False, True]), ((1.0, 1.0), [True, True]), ((nan, nan), [True, True]),
                              ((0.0, nan), [False, True]), ((nan, 0.3), [False, False])):
        before = _device(rig).read_gpio()[1]
        rig.command("flange_gpios/digital_out_1", commands[0])
        rig.command("flange_gpios/digital_out_2", commands[1])
        rig.cycle(n=2)
        got = _device(rig).read_gpio()[1]
        assert got == outputs, (f"with the outputs {before}, the digital_out commands {list(commands)} gave the device's "
                                f"outputs {got}; expected {outputs} (above 0.5 is on; NaN: no command, the output keeps "
                                "its value)")


# --------------------------------------------------------------------------------------------- 7.4 modes


_RUNS: dict[tuple[str, type], str | list[str]] = {}


def _once(what: str, driver: type, run: Callable[[type], list[str]]) -> list[str]:
    """``run(driver)`` once for the checks that share it; a failed bring-up fails each with the same reason."""
    key = (what, driver)
    if key not in _RUNS:
        try:
            _RUNS[key] = run(driver)
        except AssertionError as exc:
            _RUNS[key] = str(exc)
    result = _RUNS[key]
    if isinstance(result, str):
        _fail(result)
    return result


def _follow_run(driver: type) -> list[str]:
    """Switch controllers one after the other; the first way the device does not follow them, or nothing."""
    with _system(driver, (FWD, VEL, J1POS, J2POS, J1VEL, IO), (FWD,), rate=50) as system:
        cm = system.controller_manager
        for activate, deactivate, expect in (
                ([IO], [], ControlMode.POSITION),  # GPIO outputs are no joint mode
                ([VEL], [FWD], ControlMode.VELOCITY),
                ([FWD], [VEL], ControlMode.POSITION),
                ([J1VEL], [FWD], ControlMode.VELOCITY),  # joint1 alone commanded
                ([J1POS, J2POS], [J1VEL], ControlMode.POSITION),  # two controllers, one mode
                ([VEL], [J1POS, J2POS], ControlMode.VELOCITY)):
            what = (f"switching from {' and '.join(deactivate)} to {' and '.join(activate)}" if deactivate else
                    f"activating {' and '.join(activate)} (the digital outputs) beside {FWD}")
            try:
                cm.switch_controllers(activate, deactivate, "strict")
            except SwitchError as exc:
                return [f"{what} was refused ({exc}); every joint would be commanded in one mode, so it must be accepted"]
            mode = _system_device(system).get_control_mode()
            if mode is not expect:
                return [f"after {what} the device is in {mode.name} mode; it must be in {expect.name}"]
            system.spin(0.1)
    return []


def _refusal_run(driver: type) -> list[str]:
    """Ask for mixes from two position controllers; for each, what went wrong ('reason: ...' if only the reason)."""
    problems = []
    with _system(driver, (VEL, BAD, J1POS, J2POS, J1VEL, J2VEL), (J1POS, J2POS), rate=50) as system:
        cm = system.controller_manager
        impl = system.resource_manager.get_component("rrbot").impl
        prepared: list[Any] = []  # what prepare_command_mode_switch returned (or raised), call by call
        prepare = impl.prepare_command_mode_switch

        def recorded(start: list[str], stop: list[str]) -> Any:
            try:
                prepared.append(prepare(start, stop))
            except Exception as exc:
                prepared.append(exc)
                raise
            return prepared[-1]

        impl.prepare_command_mode_switch = recorded
        before = [(c.name, c.state) for c in cm.list_controllers()]
        for activate, deactivate, what in (
                ([BAD], [J1POS, J2POS], f"{BAD} (position and velocity on both joints)"),
                ([VEL], [], f"{VEL} while the position controllers stay active"),
                ([J1VEL], [J1POS], "joint1 in velocity while joint2 stays in position"),
                ([J2VEL], [J2POS], "joint2 in velocity while joint1 stays in position")):
            impl.mode_switch_rejection = ""
            prepared.clear()
            try:
                cm.switch_controllers(activate, deactivate, "strict")
            except SwitchError as exc:
                text = str(exc)
                result = prepared[-1] if prepared else None
                if "hardware component 'rrbot' rejected" not in text:
                    problems.append(f"{what}: the switch was refused, but not by your driver: {text}")
                elif isinstance(result, BaseException):
                    problems.append(f"reason: {what} (your prepare_command_mode_switch raised {type(result).__name__} "
                                    "instead of returning ReturnType.ERROR)")
                elif not (impl.mode_switch_rejection and impl.mode_switch_rejection in text):
                    problems.append(f"reason: {what} (no self.mode_switch_rejection was set)")
            else:
                problems.append(f"{what}: the switch was accepted")
                return problems  # what follows would start from a changed system
            after = [(c.name, c.state) for c in cm.list_controllers()]
            if after != before or _system_device(system).get_control_mode() is not ControlMode.POSITION:
                problems.append(f"{what}: after the refusal the controllers or the device's mode "
                                f"({_system_device(system).get_control_mode().name}) changed")
                return problems
        try:
            cm.switch_controllers([VEL], [J1POS, J2POS], "strict")
        except SwitchError as exc:
            problems.append(f"after the refusals, switching from the position controllers to {VEL} was refused too "
                            f"({exc}): a refused switch must leave nothing changed")
    return problems


@graded(points=3, after=("test_driver_comes_up",), hint=(
    "Task 7.4: the device follows the controllers: a velocity controller puts it in VELOCITY mode, a position "
    "controller back in POSITION, also when only one joint is commanded; a controller of the GPIO outputs is no "
    "joint mode.",
    "prepare_command_mode_switch works out the joint command interfaces claimed after the switch (claimed now, minus "
    "stop_interfaces, plus this component's joints in start_interfaces) and remembers the one mode; "
    "perform_command_mode_switch calls self.device.set_control_mode(...).",
    "modes = {name.rpartition('/')[2] for name in claimed_after}; if modes == {'velocity'}: self.next_mode = "
    "ControlMode.VELOCITY; elif modes == {'position'}: self.next_mode = ControlMode.POSITION",
))
def test_mode_follows_the_controllers(driver: type) -> None:
    problems = _once("follow", driver, _follow_run)
    assert not problems, problems[0] if problems else ""


@graded(points=3, after=("test_driver_comes_up", "test_mode_follows_the_controllers"), hint=(
    "Task 7.4: a switch after which position and velocity would both be commanded is refused by the hardware, whether "
    "one controller asks for both or two controllers (or two joints) would mix them; nothing changes then.",
    "In prepare_command_mode_switch: claimed_after = (claimed now - set(stop_interfaces)) | this component's joint "
    "interfaces in start_interfaces; two modes -> return ReturnType.ERROR before changing anything.",
    "if len(modes) > 1: self.mode_switch_rejection = '...'; self.logger.error(...); return ReturnType.ERROR",
))
def test_mixed_modes_refused(driver: type) -> None:
    problems = [p for p in _once("refusal", driver, _refusal_run) if not p.startswith("reason: ")]
    assert not problems, "; ".join(problems)


@graded(points=1, after=("test_mixed_modes_refused",), hint=(
    "Task 7.4: a refusal gives its reason and returns ERROR. ros2_control's controller manager only says that the "
    "hardware refused the switch, so a driver logs why; this course's also shows self.mode_switch_rejection in the "
    "switch error.",
    "self.mode_switch_rejection holds the reason (the base class declares it); set it, and log it, before returning "
    "ReturnType.ERROR (no exception).",
    "self.mode_switch_rejection = 'the RRBot device runs all joints in one mode, position or velocity'",
))
def test_refusal_gives_a_reason(driver: type) -> None:
    problems = _once("refusal", driver, _refusal_run)
    assert all(p.startswith("reason: ") for p in problems), (
        "your driver does not refuse every mix right yet (see mixed_modes_refused), so its reasons cannot be checked")
    missing = [p.removeprefix("reason: ") for p in problems]
    assert not missing, (f"refusing {'; '.join(missing)}, your driver gave no reason in the switch error: set "
                         "self.mode_switch_rejection, log it and return ReturnType.ERROR")


# --------------------------------------------------------------------------------------------- failures, seed


_DEVICE_CALLS = ("read_joint_states", "read_sensor_values", "read_gpio", "write_joint_commands", "write_gpios")


@graded(points=2, after=("test_driver_comes_up",), hint=(
    "Task 7.3: when the device fails in any call, read or write says so (lets the exception through, or returns "
    "ERROR); the resource manager then takes the component out. Do not swallow it.",
    "No try/except around the device's calls that returns OK.",
    "let exceptions of self.device.read_...() and write_...() propagate (or return ReturnType.ERROR)",
))
def test_device_failure_reported(driver: type) -> None:
    swallowed = []
    for call in _DEVICE_CALLS:
        rig = _rig(driver)
        rig.command("flange_gpios/digital_out_1", 1.0)
        rig.cycle(n=5)
        device = _device(rig)
        made: list[str] = []

        def unplugged(*args: Any, _call: str = call, _made: list[str] = made) -> Any:
            _made.append(_call)
            raise ConnectionError(f"RRBot cable unplugged during {_call} (the grader's simulated failure)")

        setattr(device, call, unplugged)
        with _provoked():
            rig.cycle(n=2, check=False)
        if rig.state is State.ACTIVE and made:  # a call the driver never makes cannot fail on it (other checks')
            swallowed.append(call)
    assert not swallowed, (f"the device failed half-way (in {', '.join(swallowed)}) and your driver went on as if "
                           "nothing happened (the component stayed active); read and write must report it")


@graded(points=1, after=("test_configure_opens_the_device",), hint=(
    "Task 7.2: the hardware parameter 'seed' (default 0) seeds the device: its sensor values depend on it.",
    "self.info.hardware_parameters is a dict of the <hardware><param> values, as strings.",
    "RRBotDevice(len(self.joints), seed=int(self.info.hardware_parameters.get('seed', '0')))",
))
def test_seed_parameter(driver: type) -> None:
    for seed in (None, 7, 123):
        device = _device(_rig(driver, _urdf(seed=seed), State.INACTIVE))
        given = "no seed parameter" if seed is None else f"the hardware parameter seed = {seed}"
        assert device.seed == (seed or 0), (
            f"with {given} your device is seeded with {device.seed!r}; the task says {seed or 0}: "
            "RRBotDevice(..., seed=int(the parameter, default '0'))")


# --------------------------------------------------------------------------------------------- 7.5 the YAML


def _yaml_problems(cfg: Any) -> list[str]:
    params = cfg.parameters_for(BAD)
    ctype = cfg.controller_types.get(BAD) or params.get("type")
    if ctype is None and not params:
        return ["it is not defined yet: declare its type under controller_manager's ros__parameters and give it "
                "joints, command_interfaces and state_interfaces under its own name"]
    problems = []
    if ctype != JTC_TYPE:
        problems.append(f"its type is {ctype!r}, not {JTC_TYPE}")
    joints = params.get("joints")
    if not isinstance(joints, list) or sorted(joints) != ["joint1", "joint2"]:
        problems.append(f"its joints are {joints!r}, not joint1 and joint2")
    commands, states = params.get("command_interfaces"), params.get("state_interfaces")
    if not isinstance(commands, list) or sorted(commands) != ["position", "velocity"]:
        problems.append(f"its command_interfaces are {commands!r}, not position and velocity")
    if not isinstance(states, list) or not {"position", "velocity"} <= set(states) <= {"position", "velocity",
                                                                                        "acceleration"}:
        problems.append(f"its state_interfaces are {states!r}; it reads position and velocity")
    return problems


@graded(points=2, hint=(
    "Task 7.5: define incompatible_joint_trajectory_controller in the controllers YAML: a joint trajectory controller "
    "for joint1 and joint2 commanding position and velocity, reading position and velocity.",
    "Declare its type under controller_manager.ros__parameters, and its parameters under its own name's "
    "ros__parameters, as joint_trajectory_controller is.",
    "incompatible_joint_trajectory_controller: {type: joint_trajectory_controller/JointTrajectoryController} and "
    "command_interfaces: [position, velocity]; state_interfaces: [position, velocity]",
))
def test_yaml_defines_the_incompatible_controller(task_file: Callable[[int, str], Path]) -> None:
    cfg = rw.params.load_controllers_yaml(task_file(TASK, YAML))
    problems = _yaml_problems(cfg)
    assert not problems, f"{YAML}: {BAD}: {'; '.join(problems)}"


@graded(points=1, after=("test_yaml_defines_the_incompatible_controller",), hint=(
    "Task 7.5: with your YAML, the RRBot driver refuses incompatible_joint_trajectory_controller, and the YAML's other "
    "controllers still come up.",
    "The YAML keeps joint_state_broadcaster, forward_position_controller, forward_velocity_controller and "
    "joint_trajectory_controller as they were.",
    "load the YAML with rw.bringup(..., spawn=['joint_state_broadcaster', 'forward_position_controller']) and switch",
))
def test_yaml_controller_refused_by_the_hardware(task_file: Callable[[int, str], Path]) -> None:
    path = task_file(TASK, YAML)
    cfg = rw.params.load_controllers_yaml(path)
    params = cfg.parameters_for(BAD)
    if (cfg.controller_types.get(BAD) or params.get("type")) is None and not params:
        _fail(f"{YAML} does not define {BAD} yet (see yaml_defines_the_incompatible_controller)")
    if _yaml_problems(cfg):  # judged by yaml_defines_the_incompatible_controller: here it stands as the task states
        cfg.controller_types[BAD] = JTC_TYPE
        key = cfg.section_names().get(BAD, BAD)
        cfg.controller_parameters[key] = {**cfg.controller_parameters.get(key, {}), "type": JTC_TYPE,
                                          "joints": ["joint1", "joint2"], "command_interfaces": ["position", "velocity"],
                                          "state_interfaces": ["position", "velocity"]}
    reference_or_skip(REFERENCE)  # the library's driver runs the YAML: this check is about the YAML
    urdf = _urdf(plugin="rrbot_workshop/RRBotHardwareInterface")
    with rw.bringup(urdf, cfg, spawn=[JSB, FWD], inactive=[VEL, JTC, BAD], name=f"task07_grader_{next(_names)}") as system:
        cm = system.controller_manager
        try:
            cm.switch_controllers([BAD], [FWD], "strict")
        except SwitchError as exc:
            assert "hardware component 'rrbot' rejected" in str(exc), (
                f"activating {BAD} from your YAML was refused, but not by the hardware: {exc}")
        else:
            _fail(f"{BAD} from your YAML was activated on the RRBot driver; it must command position and "
                  "velocity, which the driver refuses")
        for activate, deactivate in (([VEL], [FWD]), ([JTC], [VEL])):
            try:
                cm.switch_controllers(activate, deactivate, "strict")
            except SwitchError as exc:
                _fail(f"with your {YAML}, switching from {deactivate[0]} to {activate[0]} was refused: {exc}; "
                      "keep the YAML's other controllers as they were")


# --------------------------------------------------------------------------------------------- side by side


#: The controllers of the generated sequences and the command interfaces each claims.
_CLAIMS = {
    FWD: ("joint1/position", "joint2/position"), VEL: ("joint1/velocity", "joint2/velocity"),
    BAD: ("joint1/position", "joint1/velocity", "joint2/position", "joint2/velocity"),
    J1POS: ("joint1/position",), J1VEL: ("joint1/velocity",), J2POS: ("joint2/position",), J2VEL: ("joint2/velocity",),
}
_OBSERVED = [f"{j}/{k}" for j in ("joint1", "joint2") for k in ("position", "velocity", "acceleration")] + [
    f"tcp_fts_sensor/{k}" for k in FTS] + ["flange_gpios/digital_out_1", "flange_gpios/digital_out_2"]

_JOINTS = [f"{j}/{k}" for j in ("joint1", "joint2") for k in ("position", "velocity")]

_switch = st.tuples(st.just("switch"), st.lists(st.sampled_from(sorted(_CLAIMS)), min_size=1, max_size=2, unique=True),
                    st.lists(st.sampled_from(sorted(_CLAIMS)), max_size=2, unique=True))
_send = st.tuples(st.just("send"), st.sampled_from(sorted(_CLAIMS)),
                  st.lists(st.integers(-12, 12).map(lambda v: v / 10), min_size=4, max_size=4))
_run = st.tuples(st.just("run"), st.integers(1, 30), st.sampled_from((0.01, 0.02, 0.005)))
_outputs = st.tuples(st.just("outputs"), st.sampled_from((0.0, 0.3, 0.5, 0.7, 1.0)), st.sampled_from((0.0, 0.5, 1.0)))
_pause = st.tuples(st.just("pause"), st.integers(1, 5))
_SCENARIOS = st.lists(st.one_of(_switch, _send, _run, _outputs, _pause), min_size=1, max_size=7)
#: Sequences run on both drivers at most, searching and shrinking together (a count, so grading stays deterministic).
_BUDGET = 120


def _mode(rig: Rig) -> ControlMode | None:
    device = rig.device
    return device.get_control_mode() if isinstance(device, RRBotDevice) else None


class _Pair:
    """The learner's driver and the library's, given the same requests; the controllers are modelled."""

    def __init__(self, cls: type, reference: type) -> None:
        self.mine, self.ref = Rig(cls, _urdf()), Rig(reference, _urdf())
        self.active: dict[str, list[float] | None] = {}  # controller -> last command sent (None: nothing yet)
        self.lines: list[str] = []

    def both(self, fn: Callable[[Rig], Any]) -> tuple[Any, Any]:
        return fn(self.mine), fn(self.ref)

    def compare(self, when: str, names: list[str] = _OBSERVED) -> str:
        if self.mine.state is not self.ref.state:
            return f"{when} your component is '{self.mine.state.label}', the library's is '{self.ref.state.label}'"
        if self.mine.state not in (State.INACTIVE, State.ACTIVE):
            return ""
        for name in names:
            a, b = self.mine.value(name), self.ref.value(name)
            if not _close(a, b):
                return f"{when} {name} reads {a:.4g} with your driver and {b:.4g} with the library's"
        return ""

    def step(self, step: tuple[Any, ...]) -> str:
        kind = step[0]
        if kind == "switch":
            activate = [c for c in step[1] if c not in self.active]
            deactivate = [c for c in step[2] if c in self.active and c not in activate]
            kept = [c for c in self.active if c not in deactivate]
            wanted = [i for c in kept + activate for i in _CLAIMS[c]]
            if not activate or len(wanted) != len(set(wanted)) or self.mine.state is not State.ACTIVE:
                return ""  # the controller manager itself would refuse this switch: the hardware is not asked
            start = [i for c in activate for i in _CLAIMS[c]]
            stop = [i for c in deactivate for i in _CLAIMS[c]]
            ok_mine, ok_ref = self.both(lambda r: r.switch(start, stop))
            what = f"switch: activate {', '.join(activate)}" + (f", deactivate {', '.join(deactivate)}" if deactivate else "")
            self.lines.append(what)
            if ok_mine != ok_ref:
                return (f"your driver {'accepted' if ok_mine else 'refused'} it, the library's "
                        f"{'accepted' if ok_ref else 'refused'} it (the device runs all joints in one mode)")
            if ok_ref:
                for c in deactivate:
                    del self.active[c]
                for c in activate:
                    self.active[c] = None
                mode_mine, mode_ref = _mode(self.mine), self.ref.device.get_control_mode()
                if mode_mine is not mode_ref:
                    return (f"your device is in {mode_mine.name if mode_mine else 'no'} mode, the library's in "
                            f"{mode_ref.name}")
            return ""
        if kind == "send":
            controller = step[1]
            if controller not in self.active:
                return ""
            values = step[2][:len(_CLAIMS[controller])]
            if all(i.endswith("velocity") for i in _CLAIMS[controller]):
                values = [v / 2 for v in values]
            self.active[controller] = values
            self.lines.append(f"{controller} sends {values}")
            return ""
        if kind == "outputs":
            self.lines.append(f"digital_out_1 commanded {step[1]}, digital_out_2 {step[2]}")
            for rig in (self.mine, self.ref):
                rig.command("flange_gpios/digital_out_1", step[1])
                rig.command("flange_gpios/digital_out_2", step[2])
            return ""
        if kind == "pause":
            self.lines.append(f"deactivate the hardware component, {step[1]} cycles, activate it again")
            self.both(lambda r: r.component.deactivate())
            difference = self.compare("deactivated,") or self.run(step[1], 0.01, "while inactive")
            if difference:
                return difference
            self.both(lambda r: r.component.activate())
            return self.compare("re-activated,")
        if kind == "run":
            self.lines.append(f"{step[1]} cycles of {step[2] * 1000:g} ms")
            return self.run(step[1], step[2], "")
        return ""

    def run(self, n: int, period: float, note: str) -> str:
        for k in range(n):
            for rig in (self.mine, self.ref):
                rig.component.read(rig.time, period)
            last = k == n - 1
            difference = self.compare(f"after read {k + 1}{' ' + note if note else ''},", _OBSERVED if last else _JOINTS)
            if difference:
                return difference
            for controller, values in self.active.items():
                if values is not None:
                    for rig in (self.mine, self.ref):
                        for name, value in zip(_CLAIMS[controller], values, strict=True):
                            rig.command(name, value)
            for rig in (self.mine, self.ref):
                rig.component.write(rig.time, period)
                rig.time += period
        return ""

    def play(self, steps: list[tuple[Any, ...]]) -> str:
        for rig in (self.mine, self.ref):
            for step in ("configure", "activate"):
                getattr(rig.component, step)()
        difference = self.compare("configured and activated,")
        if difference:
            return difference
        for step in steps:
            difference = self.step(step)
            if difference:
                return difference
        return ""


REFERENCE = "rrbot_workshop.hardware.rrbot"  # the library's driver

#: Sequences tried before the generated ones: a pause of the hardware keeps the controllers' claims, so a mix asked
#: after it is still refused.
_KNOWN_SEQUENCES: tuple[list[tuple[Any, ...]], ...] = (
    [("switch", [VEL], []), ("pause", 1), ("switch", [J1POS], [])],
    [("switch", [J2POS], []), ("pause", 2), ("switch", [J1VEL], [])],
)


#: The checks whose rules the generated sequences also exercise: when one of them fails, so may the comparison.
_COMPARED_RULES = (
    "test_driver_comes_up", "test_effort_reads_nan", "test_activate_without_a_jump",
    "test_deactivate_disables_movement", "test_joint_states_and_commands", "test_acceleration_states",
    "test_sensor_values", "test_gpio_states", "test_gpio_outputs", "test_mode_follows_the_controllers",
    "test_mixed_modes_refused", "test_configure_opens_the_device",
)


@graded(points=2, after=_COMPARED_RULES, hint=(
    "Task 7.2-7.4: on generated sequences of controller switches, commands, digital outputs and hardware "
    "deactivation, your driver and the library's behave the same: same switches accepted and refused, same device "
    "mode, same states.",
    "The reason lists the smallest sequence found that tells them apart; replay it in notebook 07 with %control "
    "switch_controllers and the controllers' /commands topics.",
    "compare your prepare_command_mode_switch and perform_command_mode_switch with the TODOs of 7.4: claimed after = "
    "claimed now - stop + this component's joint interfaces in start",
))
def test_same_as_the_library_driver(driver: type) -> None:
    reference = reference_or_skip(REFERENCE).RRBotHardwareInterface
    _rig(driver)  # the driver comes up at all, or the reason says which callback stops it
    config = settings(derandomize=True, database=None, deadline=None, max_examples=50,
                      suppress_health_check=list(HealthCheck))
    seen: dict[str, bool] = {}  # a sequence asked again (Hypothesis replays its answer) gets the same answer

    def differs(steps: list[tuple[Any, ...]]) -> bool:
        key = repr(steps)
        if key not in seen:
            seen[key] = len(seen) < _BUDGET and bool(_Pair(driver, reference).play(steps))
        return seen[key]

    smallest = next((steps for steps in _KNOWN_SEQUENCES if differs(steps)), None)
    if smallest is None:
        try:
            smallest = find(_SCENARIOS, differs, settings=config)
        except NoSuchExample:
            return
    pair = _Pair(driver, reference)
    difference = pair.play(smallest)
    steps = "; ".join(f"{i + 1}. {line}" for i, line in enumerate(pair.lines)) or "nothing but configure and activate"
    _fail(f"your driver and the library's differ on this sequence (the smallest found): {steps}. Then "
                f"{difference}.")
