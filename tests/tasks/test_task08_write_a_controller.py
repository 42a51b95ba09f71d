"""Grader of task 8: the DisplacementController, written by the learner on the course's controller base class.

The specification (``displacement_controller.py`` and ``rrbot_controllers.yaml`` of the task folder):

* parameters ``joints``, ``state_joints`` (empty: the joints) and ``interface_name``, validated at load as the
  original's parameter file says, including the custom validator ``forbidden_interface_name_prefix`` refusing names
  that start with ``blup_``; ``state_joints`` of another size fails configure;
* claims ``<joint>/<interface_name>`` as commands and ``<state_joint>/<interface_name>`` as states, in order;
* ``~/reference`` (``control_msgs/JointJog``): one displacement per joint, matched by name, or the message is refused
  and changes nothing;
* ``update``: ``command = state + displacement`` (the original's own tests wrongly expected the displacement alone),
  halved in slow mode (``~/set_slow_control_mode``, ``std_srvs/SetBool``), each displacement used once; ``~/state``
  (``JointControllerState``) for the first joint;
* nothing received before activation is applied; deactivation leaves NaN commands;
* the controllers YAML declares ``displacement_controller`` with the original's plugin name, and it moves the RRBot.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course.grading import graded
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import params as params_module
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import JointControllerState, JointJog, SetBoolRequest
from rrbot_workshop.testing import ControllerHarness

TASK = 8
FILE = "displacement_controller.py"
YAML = "rrbot_controllers.yaml"
NAME = "disp"
PARAMS = {"joints": ["joint1", "joint2"], "interface_name": "position"}
STATES = {"joint1/position": 1.1, "joint2/position": 2.2}
COMMANDS = {"joint1/position": 0.0, "joint2/position": 0.0}
PLUGINS = ("displacement_controller/DisplacementController", "controlko_controllers/DisplacementController")
_VALIDATOR_NAMES = ("displacement_controller::forbidden_interface_name_prefix", "forbidden_interface_name_prefix")


@pytest.fixture(scope="module")
def learner(task_file: Callable[[int, str], Path]) -> Iterator[ModuleType]:
    """The learner's module, imported afresh with no other validator of the same name registered (the library's
    reference registers one: it must not stand in for the learner's)."""
    task_file(TASK, FILE)
    saved = {n: params_module._CUSTOM_VALIDATORS.pop(n) for n in _VALIDATOR_NAMES if n in params_module._CUSTOM_VALIDATORS}
    module = rw.course.load_module(TASK, FILE, quiet=True)
    if module is None:
        pytest.fail(f"{FILE} does not import", pytrace=False)
    if not isinstance(getattr(module, "DisplacementController", None), type):
        pytest.fail(f"{FILE} defines no class DisplacementController", pytrace=False)
    yield module
    for name in _VALIDATOR_NAMES:
        params_module._CUSTOM_VALIDATORS.pop(name, None)
    params_module._CUSTOM_VALIDATORS.update(saved)


def _harness(learner: ModuleType, params: dict[str, Any] | None = None, states: dict[str, float] | None = None,
             commands: dict[str, float] | None = None) -> ControllerHarness:
    return ControllerHarness(learner.DisplacementController(), NAME, dict(PARAMS if params is None else params),
                             state_values=dict(STATES if states is None else states),
                             command_values=dict(COMMANDS if commands is None else commands))


def _step(what: str, call: Callable[[], Any]) -> Any:
    try:
        return call()
    except NotImplementedError as exc:
        pytest.fail(f"{what}: {exc}", pytrace=False)


def _active(learner: ModuleType, **kwargs: Any) -> ControllerHarness:
    h = _harness(learner, **kwargs)
    state = _step("configure", h.configure)
    assert state is State.INACTIVE, f"configure did not succeed: the controller is '{state.label}' (see the log)"
    state = _step("activate", h.activate)
    assert state is State.ACTIVE, f"activate did not succeed: the controller is '{state.label}' (see the log)"
    return h


def _commands(h: ControllerHarness) -> list[float]:
    return h.values(["joint1/position", "joint2/position"])


def _jog(h: ControllerHarness, names: list[str], displacements: list[float]) -> None:
    _step("~/reference callback", lambda: h.publish("~/reference", JointJog(joint_names=names,
                                                                              displacements=displacements)))


def _update(h: ControllerHarness) -> None:
    _step("update", h.update)


# --------------------------------------------------------------------------------------------- 8.1 parameters


@graded(points=1, hint=(
    "Task 8.1: a validator answers None for a valid value and a sentence for an invalid one; it never raises.",
    "forbidden_interface_name_prefix(value, prefix) receives the prefix the schema gives as its argument.",
    "return f\"'{value}' must not start with '{prefix}'\" if value.startswith(prefix) else None",
))
def test_validator_function(learner: ModuleType) -> None:
    check = learner.forbidden_interface_name_prefix
    refused = _step("forbidden_interface_name_prefix", lambda: check("blup_position", "blup_"))
    assert isinstance(refused, str) and refused, f"'blup_position' with prefix 'blup_' must be refused, got {refused!r}"
    for fine in ("position", "velocity_blup_"):
        got = check(fine, "blup_")
        assert got is None, f"'{fine}' does not start with 'blup_' and must be accepted (None), got {got!r}"
    assert isinstance(check("xx_effort", "xx_"), str), "the prefix comes from the schema's argument, not a constant"


@graded(points=1, hint=(
    "Task 8.1: the schema must use your validator on interface_name, with 'blup_' as its argument.",
    "In PARAMETERS, interface_name's validation gets a line naming the validator as registered, before one_of<>.",
    "displacement_controller::forbidden_interface_name_prefix: [\"blup_\"]",
))
def test_blup_prefix_refused_at_load(learner: ModuleType) -> None:
    reason = _step("forbidden_interface_name_prefix", lambda: learner.forbidden_interface_name_prefix("blup_position",
                                                                                                     "blup_"))
    with pytest.raises(ParameterError) as err:
        _harness(learner, {"joints": ["joint1"], "interface_name": "blup_position"})
    assert "interface_name" in str(err.value)
    assert isinstance(reason, str) and reason in str(err.value), (
        f"loading with interface_name 'blup_position' was refused with '{err.value}', not by your validator "
        f"({reason!r})"
    )


@graded(given=True, points=1, hint="The handed-out schema refuses empty or repeated joints and unknown interfaces.")
def test_schema_refuses_bad_values(learner: ModuleType) -> None:
    for bad in ({"joints": [], "interface_name": "position"}, {"joints": ["j", "j"], "interface_name": "position"},
                {"joints": ["joint1"], "interface_name": "torque"}, {"joints": ["joint1"]}):
        with pytest.raises(ParameterError):
            _harness(learner, bad)


# --------------------------------------------------------------------------------------------- 8.2 configure


@graded(points=2, hint=(
    "Task 8.2: after configure the controller knows its joints and claims one command and one state interface per "
    "joint, in the joints' order.",
    "on_configure reads self.param_listener.get_params(); the two *_interface_configuration methods return an "
    "InterfaceConfiguration of type INDIVIDUAL with full names '<joint>/<interface>'.",
    "[f'{joint}/{self.interface_name}' for joint in self.joints] (and self.state_joints for the states)",
))
def test_configure_and_claimed_interfaces(learner: ModuleType) -> None:
    h = _harness(learner, {"joints": ["joint2", "joint1"], "interface_name": "position"})
    state = _step("on_configure", h.configure)
    assert state is State.INACTIVE, f"configure did not succeed: the controller is '{state.label}'"
    commands = _step("command_interface_configuration", h.controller.command_interface_configuration)
    states = _step("state_interface_configuration", h.controller.state_interface_configuration)
    assert list(commands.names) == ["joint2/position", "joint1/position"], commands.names
    assert list(states.names) == ["joint2/position", "joint1/position"], states.names
    h = _harness(learner, {"joints": ["joint1", "joint2"], "state_joints": ["s1", "s2"], "interface_name": "velocity"},
                 states={"s1/velocity": 0.0, "s2/velocity": 0.0},
                 commands={"joint1/velocity": 0.0, "joint2/velocity": 0.0})
    assert h.configure() is State.INACTIVE
    assert list(h.controller.command_interface_configuration().names) == ["joint1/velocity", "joint2/velocity"]
    assert list(h.controller.state_interface_configuration().names) == ["s1/velocity", "s2/velocity"], (
        "with state_joints set, the states are read from those joints"
    )


@graded(points=1, hint=(
    "Task 8.2: state_joints and joints of different sizes cannot be paired: configure must fail.",
    "Return CallbackReturn.FAILURE from on_configure (and log why): the controller stays unconfigured.",
    "if len(self.state_joints) != len(self.joints): self.logger.error(...); return CallbackReturn.FAILURE",
))
def test_state_joints_of_another_size_fail_configure(learner: ModuleType) -> None:
    valid = _harness(learner, {"joints": ["joint1", "joint2"], "state_joints": ["s1", "s2"], "interface_name": "position"},
                     states={"s1/position": 0.0, "s2/position": 0.0})
    state = _step("on_configure", valid.configure)
    assert state is State.INACTIVE, f"configure with two joints and two state joints must succeed, got '{state.label}'"
    h = _harness(learner, {"joints": ["joint1", "joint2"], "state_joints": ["s1"], "interface_name": "position"})
    state = _step("on_configure", h.configure)
    assert state is State.UNCONFIGURED, f"configure with 2 joints and 1 state joint must fail, got '{state.label}'"


@graded(points=1, hint=(
    "Task 8.2: configure creates the controller's topics and service on its node (names start with ~/).",
    "self.get_node().create_subscription(JointJog, '~/reference', callback), create_service(SetBoolRequest, "
    "'~/set_slow_control_mode', callback), create_publisher(JointControllerState, '~/state').",
    "See the three lines in the hint before: the callbacks are self._on_reference and self._on_set_slow_control_mode.",
))
def test_topics_and_service(learner: ModuleType) -> None:
    h = _harness(learner)
    assert _step("on_configure", h.configure) is State.INACTIVE
    bus = h.bus
    assert bus.subscription_count(f"/{NAME}/reference") == 1, "no subscription on ~/reference"
    assert f"/{NAME}/set_slow_control_mode" in bus.service_names(), f"services: {bus.service_names()}"
    assert bus.publisher_count(f"/{NAME}/state") == 1, "no publisher on ~/state"


# --------------------------------------------------------------------------------------------- 8.3, 8.4 behaviour


@graded(points=3, hint=(
    "Task 8.4: a displacement moves the joint from where it is: the command is the current state plus the "
    "displacement. (The original workshop's tests expected the displacement alone: its code and README disagree.)",
    "In update, read self.state_interfaces[i].get_value() and write self.command_interfaces[i].set_value(...).",
    "self.command_interfaces[i].set_value(self.state_interfaces[i].get_value() + displacement)",
))
def test_command_is_state_plus_displacement(learner: ModuleType) -> None:
    h = _active(learner)
    _jog(h, ["joint1", "joint2"], [23.24, 1.0])
    _update(h)
    assert _commands(h) == pytest.approx([1.1 + 23.24, 2.2 + 1.0]), f"commands {_commands(h)} for states [1.1, 2.2]"


@graded(points=2, hint=(
    "Task 8.4: each displacement is applied in one update only; later updates leave the command as it is.",
    "After using a displacement, mark it as used (the class keeps NaN for 'none pending').",
    "self.displacements[i] = math.nan",
))
def test_displacement_used_once(learner: ModuleType) -> None:
    h = _active(learner)
    _jog(h, ["joint1", "joint2"], [0.5, -0.5])
    _update(h)
    first = _commands(h)
    h.set("joint1/position", first[0])  # the joint got there
    h.set("joint2/position", first[1])
    for _ in range(3):
        _update(h)
    assert _commands(h) == pytest.approx(first), f"after one message the commands moved on to {_commands(h)}"


@graded(points=2, hint=(
    "Task 8.3: JointJog names its joints: a message may list them in another order than the controller.",
    "Match msg.joint_names to self.joints by name, not by position in the list.",
    "by_name = dict(zip(msg.joint_names, msg.displacements)); [by_name[j] for j in self.joints]",
))
def test_displacements_matched_by_name(learner: ModuleType) -> None:
    h = _active(learner)
    _jog(h, ["joint2", "joint1"], [1.0, 10.0])
    _update(h)
    assert _commands(h) == pytest.approx([1.1 + 10.0, 2.2 + 1.0]), f"got {_commands(h)}"


@graded(points=2, hint=(
    "Task 8.3: a message must give one displacement for each joint of the controller (as in the original); any "
    "other message is refused and changes nothing.",
    "Compare the sizes of msg.joint_names and msg.displacements with self.joints, and that the names are the joints; "
    "log the reason with self.logger.error and return.",
    "if len(msg.joint_names) != len(self.joints) or len(msg.displacements) != len(self.joints): log; return",
))
def test_wrong_joint_count_refused(learner: ModuleType) -> None:
    h = _active(learner)
    for names, values in ((["joint1"], [5.0]), (["joint1", "joint2", "joint3"], [1.0, 1.0, 1.0]),
                          (["joint1", "joint2"], [1.0]), (["joint1", "elbow"], [1.0, 1.0])):
        try:
            h.publish("~/reference", JointJog(joint_names=names, displacements=values))
        except NotImplementedError as exc:
            pytest.fail(f"~/reference callback: {exc}", pytrace=False)
        except Exception as exc:  # noqa: BLE001 - a bad message must be refused, not crash the callback
            pytest.fail(f"a JointJog for {names} with {values} raised {type(exc).__name__}: {exc}; refuse it with a "
                        "logged reason instead", pytrace=False)
        _update(h)
        assert _commands(h) == pytest.approx([0.0, 0.0]), f"a JointJog for {names} with {values} moved the commands"
    assert h.controller.get_lifecycle_state() is State.ACTIVE


@graded(points=2, hint=(
    "Task 8.3: ~/set_slow_control_mode with data=True halves every displacement; data=False goes back.",
    "The service callback gets a SetBoolRequest and returns a SetBoolResponse(success=True, ...).",
    "self.slow_mode = bool(request.data); return SetBoolResponse(success=True, message=...)",
))
def test_slow_mode(learner: ModuleType) -> None:
    h = _active(learner)
    response = _step("~/set_slow_control_mode", lambda: h.bus.call_service(f"/{NAME}/set_slow_control_mode",
                                                                          SetBoolRequest(data=True)))
    assert getattr(response, "success", False), f"the service answered {response!r}"
    _jog(h, ["joint1", "joint2"], [23.24, 2.0])
    _update(h)
    assert _commands(h) == pytest.approx([1.1 + 11.62, 2.2 + 1.0]), f"slow mode: got {_commands(h)}"
    h.bus.call_service(f"/{NAME}/set_slow_control_mode", SetBoolRequest(data=False))
    _jog(h, ["joint1", "joint2"], [1.0, 1.0])
    _update(h)
    assert _commands(h) == pytest.approx([2.1, 3.2]), f"back in fast mode: got {_commands(h)}"


@graded(points=1, hint=(
    "Task 8.4: ~/state reports the first joint every update: its command, its state and their difference.",
    "JointControllerState(header=Header(stamp=time, frame_id=self.joints[0]), set_point=..., process_value=..., "
    "error=..., time_step=period, command=...)",
    "set_point = command = self.command_interfaces[0].get_value(); process_value = self.state_interfaces[0].get_value()",
))
def test_state_published(learner: ModuleType) -> None:
    h = _active(learner)
    _jog(h, ["joint1", "joint2"], [0.4, 0.0])
    _update(h)
    msg = h.latest("~/state")
    assert isinstance(msg, JointControllerState), f"~/state carries {type(msg).__name__}"
    assert msg.header.frame_id == "joint1" and msg.header.stamp == pytest.approx(h.time)
    assert msg.set_point == pytest.approx(1.5) and msg.command == pytest.approx(1.5)
    assert msg.process_value == pytest.approx(1.1) and msg.error == pytest.approx(0.4)
    assert msg.time_step == pytest.approx(h.period)


@graded(points=1, hint=(
    "Task 8.4: a displacement received while the controller was inactive must not move the robot at activation.",
    "on_activate starts with no displacement pending.",
    "self.displacements = [math.nan] * len(self.joints)",
))
def test_activation_forgets_earlier_messages(learner: ModuleType) -> None:
    h = _harness(learner)
    assert _step("on_configure", h.configure) is State.INACTIVE
    _jog(h, ["joint1", "joint2"], [3.0, 3.0])
    assert _step("on_activate", h.activate) is State.ACTIVE
    _update(h)
    assert _commands(h) == pytest.approx([0.0, 0.0]), f"a message from before activation moved the commands: {_commands(h)}"


@graded(points=2, hint=(
    "Task 8.4: after deactivation no stale command may stay on the interfaces.",
    "In on_deactivate write NaN to every command interface, then return SUCCESS.",
    "for interface in self.command_interfaces: interface.set_value(math.nan)",
))
def test_nan_commands_on_deactivate(learner: ModuleType) -> None:
    h = _active(learner)
    _jog(h, ["joint1", "joint2"], [0.4, 0.4])
    _update(h)
    assert _step("on_deactivate", h.deactivate) is State.INACTIVE
    assert all(math.isnan(v) for v in _commands(h)), f"commands after deactivation: {_commands(h)}"


# --------------------------------------------------------------------------------------------- 8.5 on the robot


def _yaml(task_file: Callable[[int, str], Path]) -> rw.params.ControllersConfig:
    path = task_file(TASK, YAML)
    return rw.params.load_controllers_yaml(path)


@graded(points=2, hint=(
    "Task 8.5: the controllers YAML declares displacement_controller with your plugin's name, and its parameters.",
    "Under controller_manager: ros__parameters: add displacement_controller: type: ...; then a "
    "displacement_controller: ros__parameters: section with joints and interface_name.",
    "type: displacement_controller/DisplacementController; joints: [joint1, joint2]; interface_name: position",
))
def test_yaml_declares_the_controller(task_file: Callable[[int, str], Path]) -> None:
    cfg = _yaml(task_file)
    ctype = cfg.controller_types.get("displacement_controller")
    assert ctype in PLUGINS, f"displacement_controller's type is {ctype!r} (valid: {', '.join(PLUGINS)})"
    values = cfg.parameters_for("displacement_controller")
    assert values.get("joints") == ["joint1", "joint2"], f"joints: {values.get('joints')!r}"
    assert values.get("interface_name") == "position", f"interface_name: {values.get('interface_name')!r}"


@graded(points=3, hint=(
    "Task 8.5: on the RRBot mock, your controller (not the library's) moves the joints by the displacements sent.",
    "rw.bringup('rrbot', your YAML, spawn=['joint_state_broadcaster', 'displacement_controller']), then publish a "
    "JointJog on /displacement_controller/reference.",
    "Both the YAML entry and every method of the class are needed; the notebook's last cells run exactly this.",
))
def test_moves_the_rrbot(learner: ModuleType, task_file: Callable[[int, str], Path]) -> None:
    cfg = _yaml(task_file)
    assert "displacement_controller" in cfg.controller_types, "the YAML declares no displacement_controller"
    with rw.bringup("rrbot", cfg, spawn=["joint_state_broadcaster", "displacement_controller"],
                    name="task08_grader") as system:
        ctrl = system.controller_manager.get_controller("displacement_controller")
        assert type(ctrl).__module__.startswith("rrbot_workshop_track_"), (
            f"the running controller is {type(ctrl).__module__}.{type(ctrl).__name__}, the library's reference: "
            f"{FILE} could not be used (see the notebook's message)"
        )
        system.publish("/displacement_controller/reference",
                       JointJog(joint_names=["joint2", "joint1"], displacements=[-0.3, 0.5]))
        system.spin(0.05)
        assert system.latest("/joint_states").position == pytest.approx([0.5, -0.3])
        system.publish("/displacement_controller/reference",
                       JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, 0.0]))
        system.spin(0.05)
        assert system.latest("/joint_states").position == pytest.approx([1.0, -0.3])
