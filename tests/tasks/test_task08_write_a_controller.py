"""Grader of task 8: the DisplacementController, written by the learner on the course's controller base class.

The specification (``displacement_controller.py`` and ``rrbot_controllers.yaml`` of the task folder, notebook 08):

* parameters ``joints``, ``state_joints`` (empty: the joints) and ``interface_name``, validated at load as the
  original's parameter file says, including the custom validator ``forbidden_interface_name_prefix`` refusing names
  that start with ``blup_`` (before ``one_of<>``); ``state_joints`` of another size fails configure;
* claims ``<joint>/<interface_name>`` as commands and ``<state_joint>/<interface_name>`` as states, in order;
* ``~/reference`` (``control_msgs/JointJog``): one displacement per joint, matched by name, or the message is refused
  (with a logged reason) and changes nothing; a newer message replaces one not yet applied;
* ``update``: ``command = state + displacement`` with the state at the update (the original's own tests wrongly
  expected the displacement alone), halved in slow mode (``~/set_slow_control_mode``, ``std_srvs/SetBool``; the mode
  at the update counts), each displacement used once; ``~/state`` (``JointControllerState``) for the first joint,
  every update, with ``time_step`` the period the controller is updated with;
* nothing received before an activation is applied; deactivation leaves NaN on every command interface;
* the controllers YAML declares ``displacement_controller`` with the original's plugin name, and it moves the RRBot,
  also when the controller runs slower than the loop.

Every rule is tried with other joint names and counts, other interfaces and other rates than the notebook's, and a
generated-scenario check runs the learner's controller and the library's reference side by side. Commands are
compared to 1e-9 (the task's arithmetic is exact).
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
import random
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.grading.references import reference_or_skip
from rrbot_workshop.description.xacro import descriptions_root
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import params as params_module
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.msgs import JointControllerState, JointJog, SetBoolRequest
from rrbot_workshop.testing import ControllerHarness

TASK = 8
FILE = "displacement_controller.py"
YAML = "rrbot_controllers.yaml"
NAME = "arm_jog"  # not the notebook's name: topics must be made with ~/, not spelled out
PLUGINS = ("displacement_controller/DisplacementController", "controlko_controllers/DisplacementController")
INTERFACES = ("position", "velocity", "acceleration", "effort")
_VALIDATOR_NAMES = ("displacement_controller::forbidden_interface_name_prefix", "forbidden_interface_name_prefix")
TOL = 1e-9


@pytest.fixture(scope="module")
def learner(task_file: Callable[[int, str], Path]) -> Iterator[ModuleType]:
    """The learner's module, imported afresh with no other validator of the same name registered (the library's
    reference registers its own under another name: it must not stand in for the learner's)."""
    task_file(TASK, FILE)
    saved = {n: params_module._CUSTOM_VALIDATORS.pop(n) for n in _VALIDATOR_NAMES if n in params_module._CUSTOM_VALIDATORS}
    module = rw.course.load_module(TASK, FILE, quiet=True)
    if module is None:
        pytest.fail(f"your {FILE} does not import; run the first cell of notebook 08 to see why", pytrace=False)
    if not isinstance(getattr(module, "DisplacementController", None), type):
        pytest.fail(f"your {FILE} defines no class DisplacementController", pytrace=False)
    yield module
    for name in _VALIDATOR_NAMES:
        params_module._CUSTOM_VALIDATORS.pop(name, None)
    params_module._CUSTOM_VALIDATORS.update(saved)


# --------------------------------------------------------------------------------------------- a controller on a rig


def _close(a: float, b: float) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) <= TOL


def _fmt(values: Sequence[float]) -> str:
    return "[" + ", ".join(f"{v:.10g}" for v in values) + "]"


class Rig:
    """A controller in a :class:`ControllerHarness`, with joints, an interface and a rate of the test's choosing.

    States start at 1.1, 2.2, 3.3... (per state joint), commands at 0.0.
    """

    def __init__(self, controller: Any, joints: Sequence[str] = ("joint1", "joint2"), interface: str = "position",
                 state_joints: Sequence[str] = (), rate: int = 100, name: str = NAME,
                 states: Sequence[float] | None = None) -> None:
        self.joints = list(joints)
        self.interface = interface
        self.read = list(state_joints) or list(joints)
        params: dict[str, Any] = {"joints": list(joints), "interface_name": interface}
        if state_joints:
            params["state_joints"] = list(state_joints)
        initial = list(states) if states is not None else [round(1.1 * (i + 1), 10) for i in range(len(self.read))]
        self.h = ControllerHarness(controller, name, params,
                                   state_values={f"{j}/{interface}": v for j, v in zip(self.read, initial, strict=True)},
                                   command_values={f"{j}/{interface}": 0.0 for j in self.joints}, update_rate=rate)
        self.controller = controller

    def describe(self) -> str:
        states = "" if self.read == self.joints else f", states read from {self.read}"
        return f"joints {self.joints}, interface_name '{self.interface}'{states}, {self.h.update_rate} Hz"

    def configure(self) -> State:
        return self.h.configure()

    def activate(self) -> State:
        return self.h.activate()

    def deactivate(self) -> State:
        return self.h.deactivate()

    def start(self) -> Rig:
        state = self.configure()
        assert state is State.INACTIVE, (
            f"configure with {self.describe()} did not succeed: the controller is '{state.label}' (see the log)")
        state = self.activate()
        assert state is State.ACTIVE, (
            f"activate with {self.describe()} did not succeed: the controller is '{state.label}' (see the log)")
        return self

    def commands(self) -> list[float]:
        return [float(self.h.commands[f"{j}/{self.interface}"].get_value()) for j in self.joints]

    def set_commands(self, values: Sequence[float]) -> None:
        for joint, value in zip(self.joints, values, strict=True):
            self.h.commands[f"{joint}/{self.interface}"].set_value(value)

    def states(self) -> list[float]:
        return [float(self.h.states[f"{j}/{self.interface}"].get_value()) for j in self.read]

    def set_states(self, values: Sequence[float]) -> None:
        for joint, value in zip(self.read, values, strict=True):
            self.h.states[f"{joint}/{self.interface}"].set_value(value)

    def jog(self, names: Sequence[str], displacements: Sequence[float]) -> BaseException | None:
        """Publish a JointJog on ``~/reference``; the exception its callback raised (the bus logs it), if any."""
        caught = _Lines(logging.ERROR)
        bus_log = logging.getLogger("rrbot_workshop.middleware.topics")
        bus_log.addHandler(caught)
        try:
            self.h.publish("~/reference", JointJog(joint_names=list(names), displacements=list(displacements)))
        finally:
            bus_log.removeHandler(caught)
        return caught.raised[0] if caught.raised else None

    def slow(self, on: bool) -> Any:
        return self.h.bus.call_service(f"/{self.h.name}/set_slow_control_mode", SetBoolRequest(data=on))

    def update(self) -> Any:
        """One update; what it returned (update_returns_ok judges it, the other checks take it as given)."""
        return self.h.update()

    def latest_state(self) -> Any:
        return self.h.latest("~/state")


_log = logging.getLogger("rrbot_workshop.course.grading.task08")


@functools.cache
def _watched(cls: type) -> type:
    """``cls`` whose lifecycle callbacks log, with its traceback, what they raise before the library catches it (as
    ros2_control does, it turns it into ERROR): the grading puts the learner's own line first in the reason. What each
    callback returned (or raised) is kept, in order, in the instance's ``_grader_returned``."""

    def watch(name: str) -> Callable[..., Any]:
        original = getattr(cls, name)

        def callback(self: Any, previous_state: Any) -> Any:
            try:
                result = original(self, previous_state)
            except Exception as exc:
                self.__dict__.setdefault("_grader_returned", []).append((name, exc))
                _log.error("%s of your %s raised", name, FILE, exc_info=True)
                raise
            self.__dict__.setdefault("_grader_returned", []).append((name, result))
            return result

        return callback

    return type(cls.__name__, (cls,), {"__module__": cls.__module__,
                                       **{n: watch(n) for n in ("on_configure", "on_activate", "on_deactivate")}})


def _new(learner: ModuleType) -> Any:
    return _watched(learner.DisplacementController)()


def _rig(learner: ModuleType, **kwargs: Any) -> Rig:
    return Rig(_new(learner), **kwargs)


def _rig0(learner: ModuleType, **kwargs: Any) -> Rig:
    """A rig whose states start at 0: ``command = state + displacement`` gives the displacement itself, so a check of
    another rule is not failed by a slip in that arithmetic."""
    joints = kwargs.get("state_joints") or kwargs.get("joints") or ("joint1", "joint2")
    return Rig(_new(learner), states=[0.0] * len(joints), **kwargs)


def _expect(rig: Rig, expected: Sequence[float], what: str) -> None:
    got = rig.commands()
    ok = len(got) == len(expected) and all(_close(a, b) for a, b in zip(got, expected, strict=True))
    assert ok, (f"{what} (with {rig.describe()}): the commands of {rig.joints} should be {_fmt(expected)}, your "
                f"controller left {_fmt(got)}")


def _refused(rig: Rig, names: Sequence[str], displacements: Sequence[float]) -> list[str]:
    """Publish a message the task says must be refused; the lines the controller logged at WARNING or above."""
    caught = _Lines(logging.WARNING)
    root = logging.getLogger()
    root.addHandler(caught)
    try:
        _jog(rig, names, displacements)
    finally:
        root.removeHandler(caught)
    return caught.lines


class _Lines(logging.Handler):
    """Keeps the messages logged, and the exceptions logged with their traceback."""

    def __init__(self, level: int) -> None:
        super().__init__(level)
        self.lines: list[str] = []
        self.raised: list[BaseException] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())
        if record.exc_info and record.exc_info[1] is not None:
            self.raised.append(record.exc_info[1])


def _jog(rig: Rig, names: Sequence[str], displacements: Sequence[float]) -> None:
    """Publish a JointJog to the learner's controller; a callback that raised fails the check, naming the line."""
    raised = rig.jog(names, displacements)
    if raised is not None:
        pytest.fail(f"{_where(raised)}. A JointJog naming {list(names)} with {list(displacements)} made your "
                    "_on_reference raise: a message the controller cannot use is refused with a logged reason "
                    "(and changes nothing), never with an exception", pytrace=False)


# --------------------------------------------------------------------------------------------- 8.1 parameters


@graded(points=1, hint=(
    "Task 8.1: a validator answers None for a valid value and a sentence for an invalid one; it never raises, and "
    "the prefix it refuses is the argument the schema gives it.",
    "forbidden_interface_name_prefix(value, prefix): str.startswith tells whether value begins with prefix.",
    "return f\"'{value}' must not start with '{prefix}'\" if value.startswith(prefix) else None",
))
def test_validator_function(learner: ModuleType) -> None:
    check = learner.forbidden_interface_name_prefix
    for value, prefix in (("blup_position", "blup_"), ("blup_", "blup_"), ("xx_effort", "xx_")):
        got = check(value, prefix)
        assert isinstance(got, str) and got.strip(), (
            f"forbidden_interface_name_prefix({value!r}, {prefix!r}) returned {got!r}: '{value}' starts with "
            f"'{prefix}', so it must be refused with a sentence saying why")
    for value, prefix in (("position", "blup_"), ("velocity_blup_", "blup_"), ("Blup_effort", "blup_"),
                          ("blup_effort", "xx_"), ("", "blup_")):
        got = check(value, prefix)
        assert got is None, (
            f"forbidden_interface_name_prefix({value!r}, {prefix!r}) returned {got!r}: '{value}' does not start "
            f"with '{prefix}', so it is valid and the answer must be None")


@graded(points=2, after=("test_validator_function",), hint=(
    "Task 8.1: the schema runs your validator on interface_name with 'blup_' as its argument, before one_of<>, so a "
    "'blup_' name is refused with your validator's sentence; the rest of interface_name's validation stays.",
    "In PARAMETERS, interface_name's validation gets a line naming the validator as registered "
    "(displacement_controller::forbidden_interface_name_prefix) with a list of its arguments, above one_of<>.",
    "displacement_controller::forbidden_interface_name_prefix: [\"blup_\"]",
))
def test_blup_prefix_refused_at_load(learner: ModuleType) -> None:
    for name in ("blup_position", "blup_effort"):
        reason = learner.forbidden_interface_name_prefix(name, "blup_")
        try:
            _rig(learner, joints=["joint1"], interface=name)
        except ParameterError as err:
            assert "interface_name" in str(err), f"interface_name '{name}' was refused, but for another parameter: {err}"
            assert isinstance(reason, str) and reason in str(err), (
                f"interface_name '{name}' was refused at load with \"{err}\", not with your validator's sentence "
                f"({reason!r}): name the validator in interface_name's validation, above one_of<>")
        else:
            pytest.fail(f"a controller with interface_name '{name}' loaded; the schema must refuse it with "
                        "forbidden_interface_name_prefix", pytrace=False)
    for bad in ("torque", ""):
        try:
            _rig(learner, joints=["joint1"], interface=bad)
        except ParameterError as err:
            assert "interface_name" in str(err), f"interface_name {bad!r} was refused for another reason: {err}"
        else:
            pytest.fail(f"a controller with interface_name {bad!r} loaded: interface_name must still be one of "
                        f"{list(INTERFACES)} and not empty", pytrace=False)
    for good in INTERFACES:
        try:
            _rig(learner, joints=["joint1"], interface=good)
        except ParameterError as err:
            pytest.fail(f"interface_name '{good}' is valid, but loading refused it: {err}", pytrace=False)


@graded(given=True, points=1, hint=(
    "The handed-out schema refuses empty or repeated joints and repeated state joints, and accepts the rest.",
    "PARAMETERS: joints has not_empty<> and unique<>; state_joints has unique<>.",
    "Keep the validation lines of joints and state_joints as they were handed out.",
))
def test_schema_refuses_bad_values(learner: ModuleType) -> None:
    for params, why in (({"joints": [], "interface_name": "position"}, "joints is empty"),
                        ({"joints": ["j", "j"], "interface_name": "position"}, "joints repeats j"),
                        ({"joints": ["a", "b"], "state_joints": ["s", "s"], "interface_name": "position"},
                         "state_joints repeats s")):
        try:
            ControllerHarness(_new(learner), NAME, params)
        except ParameterError:
            continue
        pytest.fail(f"parameters {params} loaded, but {why}: the schema must refuse them", pytrace=False)
    for params in ({"joints": ["a"], "interface_name": "position"},
                   {"joints": ["a", "b", "c"], "state_joints": ["x", "y", "z"], "interface_name": "velocity"}):
        try:
            ControllerHarness(_new(learner), NAME, params)
        except ParameterError as err:
            pytest.fail(f"parameters {params} are valid, but loading refused them: {err}", pytrace=False)


# --------------------------------------------------------------------------------------------- 8.2 configure


@graded(points=2, hint=(
    "Task 8.2: after configure the controller claims '<joint>/<interface_name>' for each joint as commands and for "
    "each state joint as states (the joints when state_joints is empty), in the order of the parameters.",
    "on_configure reads self.param_listener.get_params(); the two *_interface_configuration methods return an "
    "InterfaceConfiguration of type INDIVIDUAL with those full names.",
    "[f'{joint}/{self.interface_name}' for joint in self.joints] (and self.state_joints for the states)",
))
def test_configure_and_claimed_interfaces(learner: ModuleType) -> None:
    for joints, interface, state_joints in ((["joint2", "joint1"], "position", []),
                                            (["shoulder", "elbow", "wrist"], "velocity", []),
                                            (["joint1", "joint2"], "effort", ["sensor2", "sensor1"]),
                                            (["slider"], "acceleration", [])):
        rig = _rig(learner, joints=joints, interface=interface, state_joints=state_joints)
        state = rig.configure()
        assert state is State.INACTIVE, f"configure with {rig.describe()} did not succeed: the controller is '{state.label}'"
        commands = list(rig.controller.command_interface_configuration().names)
        states = list(rig.controller.state_interface_configuration().names)
        want_commands = [f"{j}/{interface}" for j in joints]
        want_states = [f"{j}/{interface}" for j in (state_joints or joints)]
        assert commands == want_commands, (
            f"with {rig.describe()}, command_interface_configuration names {commands}, not {want_commands}")
        assert states == want_states, (
            f"with {rig.describe()}, state_interface_configuration names {states}, not {want_states}")


@graded(points=1, hint=(
    "Task 8.2: state_joints and joints of different sizes cannot be paired: configure fails, with fewer state joints "
    "and with more; the same size, or an empty state_joints, configures.",
    "Compare the sizes after the fallback to joints; return CallbackReturn.FAILURE from on_configure (and log why): "
    "the controller stays unconfigured.",
    "if len(self.state_joints) != len(self.joints): self.logger.error(...); return CallbackReturn.FAILURE",
))
def test_state_joints_of_another_size_fail_configure(learner: ModuleType) -> None:
    for joints, state_joints in ((["joint1", "joint2"], ["s1", "s2"]), (["a", "b", "c"], ["x", "y", "z"]),
                                 (["a"], ["x"]), (["a", "b", "c"], [])):
        rig = _rig(learner, joints=joints, state_joints=state_joints)
        state = rig.configure()
        assert state is State.INACTIVE, (
            f"configure with {len(joints)} joints and {len(state_joints) or 'no'} state joints must succeed, "
            f"got '{state.label}'")
    for joints, state_joints in MISMATCHED:
        params = {"joints": joints, "state_joints": state_joints, "interface_name": "position"}
        h = ControllerHarness(_new(learner), NAME, params)
        state = h.configure()
        assert state is State.UNCONFIGURED, (
            f"configure with {len(joints)} joints {joints} and {len(state_joints)} state joints {state_joints} must "
            f"fail (the controller stays unconfigured), got '{state.label}'")


#: joints and state_joints of different sizes: configure must fail.
MISMATCHED = ((["joint1", "joint2"], ["s1"]), (["joint1", "joint2"], ["s1", "s2", "s3"]), (["a"], ["x", "y"]),
              (["a", "b", "c"], ["x", "y"]))


def _returned(controller: Any, callback: str) -> list[Any]:
    """What the learner's ``callback`` returned (or raised), call by call (see :func:`_watched`)."""
    return [value for name, value in controller.__dict__.get("_grader_returned", []) if name == callback]


def _said(value: Any) -> str:
    if isinstance(value, BaseException):
        return f"raised {type(value).__name__}" + (f" ({value})" if str(value) else "")
    return f"returned {value!r}"


@graded(points=1, after=("test_state_joints_of_another_size_fail_configure",), hint=(
    "Task 8.2: the TODO says how a configuration error ends: say so in the log and return CallbackReturn.FAILURE. "
    "FAILURE (the parameters are wrong, nothing broke) leaves the controller unconfigured, ready to be configured "
    "again; ERROR and an exception mean the controller itself failed.",
    "In on_configure: self.logger.error('...why...') then return CallbackReturn.FAILURE; not raise, not ERROR, not a "
    "print().",
    "self.logger.error(\"'state_joints' has %d joints and 'joints' %d\", ...); return CallbackReturn.FAILURE",
))
def test_size_mismatch_returns_failure_and_logs(learner: ModuleType) -> None:
    judged = 0
    for joints, state_joints in MISMATCHED:
        params = {"joints": joints, "state_joints": state_joints, "interface_name": "position"}
        h = ControllerHarness(_new(learner), NAME, params)
        caught = _Lines(logging.WARNING)
        root = logging.getLogger()
        root.addHandler(caught)
        try:
            state = h.configure()
        finally:
            root.removeHandler(caught)
        if state is State.INACTIVE:
            continue  # accepted: state_joints_of_another_size_fail_configure says so; here the refusals are judged
        judged += 1
        returned = _returned(h.controller, "on_configure")
        what = f"configure with joints {joints} and state_joints {state_joints}"
        got = returned[-1] if returned else None
        if isinstance(got, BaseException):
            pytest.fail(f"{_where(got)}. {what}: your on_configure raised; a configuration error is logged and "
                        "answered with CallbackReturn.FAILURE, never raised", pytrace=False)
        assert got is CallbackReturn.FAILURE, (
            f"{what}: your on_configure {_said(got)}; the task asks for CallbackReturn.FAILURE (ERROR means the "
            "controller itself failed, not its parameters)")
        assert caught.lines, (f"{what}: your on_configure returned FAILURE with nothing in the log; say why with "
                              "self.logger.error, so whoever configured it can find out")
    assert judged, ("your on_configure accepts every state_joints of another size (see "
                    "state_joints_of_another_size_fail_configure), so how it refuses cannot be judged yet")


@graded(points=1, after=("test_configure_and_claimed_interfaces", "test_topics_and_service", "test_slow_mode"), hint=(
    "Task 8.2: a controller configured again after a cleanup (the manager's cleanup_controller, then "
    "configure_controller) starts as the TODO says: its parameters read afresh, no displacement pending, in fast "
    "mode, whatever the mode was before.",
    "Set every piece of state in on_configure itself, not only in __init__: __init__ runs once per load, on_configure "
    "at every configure; lists built there start empty.",
    "In on_configure: self.joints = list(params.joints) (not +=), self.displacements = [math.nan] * "
    "len(self.joints), self.slow_mode = False",
))
def test_configure_again_after_cleanup(learner: ModuleType) -> None:
    rig = _rig0(learner, joints=["shoulder", "elbow"]).start()
    rig.slow(True)
    _jog(rig, ["shoulder", "elbow"], [0.5, 0.5])
    assert rig.deactivate() is State.INACTIVE, "deactivate did not succeed"
    state = rig.controller.cleanup()
    assert state is State.UNCONFIGURED, f"cleanup did not succeed: the controller is '{state.label}'"
    state = rig.configure()
    if state is not State.INACTIVE:
        returned = _returned(rig.controller, "on_configure")
        if returned and isinstance(returned[-1], BaseException):
            pytest.fail(f"{_where(returned[-1])}. Configured again after a cleanup, your on_configure raised: it must "
                        "work every time the manager configures the controller", pytrace=False)
        pytest.fail(f"configure again after a cleanup did not succeed (the controller is '{state.label}'; see the "
                    "log): on_configure must work every time the manager configures the controller", pytrace=False)
    commands = list(rig.controller.command_interface_configuration().names)
    want = ["shoulder/position", "elbow/position"]
    assert commands == want, (f"configured again after a cleanup, command_interface_configuration names {commands}, "
                              f"not {want}: on_configure must start its lists afresh")
    rig.set_commands([0.0, 0.0])
    assert rig.activate() is State.ACTIVE, "activate after configuring again did not succeed"
    rig.update()
    _expect(rig, [0.0, 0.0], "configured again after a cleanup, an update before any message")
    _jog(rig, ["shoulder", "elbow"], [2.0, 1.0])
    rig.update()
    expected = [2.0, 1.0]
    deliveries = rig.h.bus.subscription_count(f"/{NAME}/reference")
    if deliveries > 1:  # configure subscribed again: each message arrives that many times. What the learner's
        # controller makes of a message received that often (newer_message_replaces_pending judges it) is taken as given
        fresh = _rig0(learner, joints=["shoulder", "elbow"]).start()
        for _ in range(deliveries):
            _jog(fresh, ["shoulder", "elbow"], [2.0, 1.0])
        fresh.update()
        expected = fresh.commands()
    _expect(rig, expected, "slow mode switched on, then cleanup and configure again (the controller starts in fast "
            "mode), a JointJog {shoulder: 2.0, elbow: 1.0}")


@graded(points=1, hint=(
    "Task 8.2: configure creates the controller's topics and service on its node, with names that start with ~/ "
    "(so they follow the controller's name).",
    "self.get_node().create_subscription(JointJog, '~/reference', callback), create_service(SetBoolRequest, "
    "'~/set_slow_control_mode', callback), create_publisher(JointControllerState, '~/state').",
    "See the three calls in the hint before: the callbacks are self._on_reference and self._on_set_slow_control_mode.",
))
def test_topics_and_service(learner: ModuleType) -> None:
    for name in (NAME, "displacement_controller"):
        rig = _rig(learner, name=name)
        state = rig.configure()
        assert state is State.INACTIVE, f"configure did not succeed: the controller is '{state.label}'"
        bus = rig.h.bus
        assert bus.subscription_count(f"/{name}/reference") == 1, (
            f"after configure, a controller named '{name}' has no subscription on /{name}/reference (~/reference)")
        assert f"/{name}/set_slow_control_mode" in bus.service_names(), (
            f"after configure, a controller named '{name}' offers no /{name}/set_slow_control_mode service; "
            f"services: {bus.service_names()}")
        assert bus.publisher_count(f"/{name}/state") == 1, (
            f"after configure, a controller named '{name}' has no publisher on /{name}/state (~/state)")


# --------------------------------------------------------------------------------------------- 8.3 messages
# The checks of one rule keep the others out of the way: the states start at 0 (so `command = state + displacement`
# and a slip in it agree), messages name the joints in the controller's order (except where matching by name is the
# rule), and each message is followed by one update (except where using a displacement once is the rule).

_STARTED = ("test_configure_and_claimed_interfaces", "test_topics_and_service")


@graded(points=2, after=_STARTED, hint=(
    "Task 8.3: JointJog names its joints: a message may list them in another order than the controller.",
    "Match msg.joint_names to self.joints by name, not by position in the list.",
    "by_name = dict(zip(msg.joint_names, msg.displacements)); [by_name[j] for j in self.joints]",
))
def test_displacements_matched_by_name(learner: ModuleType) -> None:
    rig = _rig0(learner).start()
    _jog(rig, ["joint2", "joint1"], [1.0, 10.0])
    rig.update()
    _expect(rig, [10.0, 1.0], "a JointJog naming ['joint2', 'joint1'] with [1.0, 10.0], the joints at 0")
    rig = _rig0(learner, joints=["shoulder", "elbow", "wrist"]).start()
    _jog(rig, ["wrist", "shoulder", "elbow"], [0.3, -0.1, 0.2])
    rig.update()
    _expect(rig, [-0.1, 0.2, 0.3], "a JointJog naming ['wrist', 'shoulder', 'elbow'] with [0.3, -0.1, 0.2], the joints "
            "at 0")


#: Messages the task says to refuse for the joints ["joint1", "joint2"]: (names, displacements, what is wrong).
INVALID = ((["joint1"], [9.0], "too few joints"), (["joint1", "joint2"], [9.0], "fewer displacements than names"),
           (["joint1", "joint1"], [9.0, 9.0], "joint1 named twice"), (["joint1", "elbow"], [9.0, 9.0], "an unknown joint"),
           (["joint1", "joint2", "joint3"], [9.0, 9.0, 9.0], "too many joints"))


def _refusals(learner: ModuleType) -> list[tuple[list[str], list[float], str]]:
    """The messages of :data:`INVALID` the learner's controller refuses (without raising, without moving anything):
    the checks of what a refusal does are judged on those."""
    out = []
    for names, values, why in INVALID:
        rig = _rig0(learner).start()
        if rig.jog(names, values) is not None:
            continue
        rig.update()
        if all(_close(v, 0.0) for v in rig.commands()):
            out.append((names, values, why))
    return out


def _try_refused(rig: Rig, messages: Sequence[tuple[list[str], list[float]]]) -> None:
    before = rig.commands()
    for names, values in messages:
        _jog(rig, names, values)
        rig.update()
        _expect(rig, before, f"a JointJog naming {names} with {values} must be refused and change nothing")
    assert rig.controller.get_lifecycle_state() is State.ACTIVE, "a refused message must leave the controller active"


@graded(points=2, after=_STARTED, hint=(
    "Task 8.3: a message must give one displacement for each joint of the controller: fewer or more names, or a "
    "number of displacements other than the number of names, is refused and changes nothing.",
    "Compare len(msg.joint_names) and len(msg.displacements) with len(self.joints); log the reason with "
    "self.logger.error and return without touching the pending displacements.",
    "if len(msg.joint_names) != len(self.joints) or len(msg.displacements) != len(self.joints): log; return",
))
def test_wrong_joint_count_refused(learner: ModuleType) -> None:
    _try_refused(_rig0(learner).start(), [
        (["joint1"], [5.0]), (["joint1", "joint2", "joint3"], [1.0, 1.0, 1.0]), (["joint1", "joint2"], [1.0]),
        (["joint1", "joint2"], [1.0, 1.0, 1.0]), (["joint2"], [1.0, 1.0]), ([], []),
        (["joint1", "joint2", "joint2"], [1.0, 1.0, 1.0]),
    ])
    _try_refused(_rig0(learner, joints=["shoulder", "elbow", "wrist"]).start(), [
        (["shoulder", "elbow"], [0.5, 0.5]), (["wrist"], [0.5]), (["shoulder", "elbow", "wrist"], [0.5, 0.5]),
    ])
    _try_refused(_rig0(learner, joints=["slider"]).start(), [(["slider", "slider2"], [0.5, 0.5]),
                                                             (["slider"], [0.5, 0.5])])


@graded(points=2, after=_STARTED, hint=(
    "Task 8.3: the names of a message must be the controller's joints, each once: an unknown joint, or a joint named "
    "twice (even with the right count), refuses the whole message, with a logged reason and no exception.",
    "Compare the names as a sorted list (or count each) with self.joints: a set hides a repeated name.",
    "if sorted(msg.joint_names) != sorted(self.joints): self.logger.error(...); return",
))
def test_unknown_or_repeated_joint_refused(learner: ModuleType) -> None:
    _try_refused(_rig0(learner).start(), [
        (["joint1", "elbow"], [1.0, 1.0]), (["joint1", "joint1"], [1.0, 2.0]), (["joint2", "joint2"], [0.5, 0.5]),
    ])
    _try_refused(_rig0(learner, joints=["shoulder", "elbow", "wrist"]).start(), [
        (["shoulder", "shoulder", "elbow"], [0.1, 0.2, 0.3]), (["wrist", "elbow", "wrist"], [0.1, 0.2, 0.3]),
        (["shoulder", "elbow", "joint1"], [0.1, 0.2, 0.3]),
    ])


_REFUSING = ("test_wrong_joint_count_refused", "test_unknown_or_repeated_joint_refused")


def _no_refusal(what: str) -> str:
    return (f"your controller refuses none of the messages the task says to refuse (see wrong_joint_count_refused and "
            f"unknown_or_repeated_joint_refused), so {what} cannot be judged yet")


@graded(points=1, after=_REFUSING, hint=(
    "Task 8.3: a refused message changes nothing, not even a displacement that is still waiting for the next update.",
    "Check the message first; only a valid message replaces self.displacements.",
    "if <message invalid>: self.logger.error(...); return  # before any assignment to self.displacements",
))
def test_refused_message_keeps_the_pending_one(learner: ModuleType) -> None:
    refused = _refusals(learner)
    assert refused, _no_refusal("what a refusal leaves pending")
    rig = _rig0(learner).start()
    _jog(rig, ["joint1", "joint2"], [0.4, -0.4])
    for names, values, _ in refused:
        _jog(rig, names, values)
    rig.update()
    whats = ", ".join(why for _, _, why in refused)
    _expect(rig, [0.4, -0.4], f"a valid JointJog [0.4, -0.4], then refused ones ({whats}), then an update")


@graded(points=1, after=_REFUSING, hint=(
    "Task 8.3: a refused message is refused with a logged reason, so whoever sent it can find out why.",
    "self.logger.error(...) (or warning) in _on_reference before returning; print() does not reach the log.",
    "self.logger.error('rejected a JointJog for %s: this controller moves %s', msg.joint_names, self.joints)",
))
def test_refusal_logged(learner: ModuleType) -> None:
    refused = _refusals(learner)
    assert refused, _no_refusal("how a refusal is logged")
    rig = _rig0(learner).start()
    for names, values, why in refused:
        lines = _refused(rig, names, values)
        assert lines, (f"a JointJog naming {names} with {values} ({why}) was refused without a warning or error in the "
                       "log: log the reason with self.logger.error")


@graded(points=1, after=_STARTED, hint=(
    "Task 8.3: a newer message replaces a displacement not applied yet (the original keeps only the last message); "
    "displacements are not added up.",
    "_on_reference assigns the message's displacements to self.displacements; it does not add to them.",
    "self.displacements = [float(by_name[joint]) for joint in self.joints]",
))
def test_newer_message_replaces_pending(learner: ModuleType) -> None:
    rig = _rig0(learner).start()
    _jog(rig, ["joint1", "joint2"], [0.5, 0.5])
    _jog(rig, ["joint1", "joint2"], [0.3, -0.2])
    rig.update()
    _expect(rig, [0.3, -0.2], "two JointJogs, [0.5, 0.5] then [0.3, -0.2], before an update")


@graded(points=2, after=_STARTED, hint=(
    "Task 8.3: ~/set_slow_control_mode with data=True halves every displacement from then on, until data=False; "
    "the controller starts fast, setting a mode twice keeps it, the mode at the update counts, and the service "
    "answers success=True.",
    "The service callback sets the mode from request.data (not by flipping it) and returns "
    "SetBoolResponse(success=True, ...); update reads the mode.",
    "self.slow_mode = bool(request.data); return SetBoolResponse(success=True, message=...)",
))
def test_slow_mode(learner: ModuleType) -> None:
    rig = _rig0(learner, joints=["shoulder", "elbow", "wrist"]).start()

    def jog(values: list[float], factor: float, what: str) -> None:
        _jog(rig, rig.joints, values)
        rig.update()
        _expect(rig, [factor * v for v in values], what)

    jog([1.0, 2.0, -4.0], 1.0, "before any service call (the controller starts fast)")
    calls: list[str] = []
    for flag in (False, True, True, False, False, True):
        response = rig.slow(flag)
        assert getattr(response, "success", False) is True, (
            f"~/set_slow_control_mode with data={flag} answered {response!r}: it must answer success=True")
        calls.append(f"data={flag}")
        factor = 0.5 if flag else 1.0
        said = f"after the service calls {', '.join(calls)}"
        jog([0.5, -1.0, 3.0], factor, f"{said}, a JointJog [0.5, -1.0, 3.0] ({'halved' if flag else 'not halved'})")
        jog([0.2, 0.2, 0.2], factor, f"{said}, a second JointJog [0.2, 0.2, 0.2]")
    rig.slow(False)
    _jog(rig, rig.joints, [1.0, 1.0, 1.0])
    rig.slow(True)
    rig.update()
    _expect(rig, [0.5, 0.5, 0.5], "a JointJog [1.0, 1.0, 1.0] received in fast mode, slow mode switched on before the "
            "update (the mode at the update counts, as in the original)")


# --------------------------------------------------------------------------------------------- 8.4 update


@graded(points=1, after=_STARTED, hint=(
    "Task 8.4: update returns ReturnType.OK, every cycle: the controller manager deactivates a controller whose "
    "update returns anything else (or nothing).",
    "The last line of update: return ReturnType.OK (also after an update that moved nothing).",
    "return ReturnType.OK",
))
def test_update_returns_ok(learner: ModuleType) -> None:
    rig = _rig0(learner).start()
    for what, before in (("with nothing pending", None), ("after a JointJog [0.1, 0.2]", (["joint1", "joint2"],
                                                                                        [0.1, 0.2]))):
        if before is not None:
            _jog(rig, *before)
        result = rig.update()
        assert result is ReturnType.OK, (f"an update {what} returned {result!r}: it must return ReturnType.OK (the "
                                         "controller manager deactivates a controller whose update returns anything "
                                         "else)")


@graded(points=3, after=_STARTED, hint=(
    "Task 8.4: a displacement moves the joint from where it is at the update: the command is the state read in "
    "update plus the displacement. (The original workshop's tests expected the displacement alone: its code and "
    "README disagree.)",
    "In update, read self.state_interfaces[i].get_value() and write self.command_interfaces[i].set_value(...); the "
    "callback only keeps the displacements.",
    "self.command_interfaces[i].set_value(self.state_interfaces[i].get_value() + displacement)",
))
def test_command_is_state_plus_displacement(learner: ModuleType) -> None:
    rig = _rig(learner).start()
    _jog(rig, ["joint1", "joint2"], [23.24, 1.0])
    rig.update()
    _expect(rig, [1.1 + 23.24, 2.2 + 1.0], "a JointJog [23.24, 1.0] with the states at [1.1, 2.2]")
    rig = _rig(learner, joints=["shoulder", "elbow", "wrist"], interface="velocity",
               state_joints=["s_shoulder", "s_elbow", "s_wrist"], states=[0.5, -0.25, 2.0]).start()
    _jog(rig, ["shoulder", "elbow", "wrist"], [0.1, 0.2, -0.3])
    rig.set_states([-1.0, 4.0, 0.75])
    rig.update()
    _expect(rig, [-1.0 + 0.1, 4.0 + 0.2, 0.75 - 0.3],
            "a JointJog [0.1, 0.2, -0.3], then the state joints move to [-1.0, 4.0, 0.75] before the update")
    _jog(rig, ["shoulder", "elbow", "wrist"], [0.0, 0.0, 0.0])
    rig.set_states([2.0, 2.5, 3.0])
    rig.update()
    _expect(rig, [2.0, 2.5, 3.0], "a JointJog of zeros with the states at [2.0, 2.5, 3.0] (the joints hold where they "
            "are)")


@graded(points=2, after=_STARTED, hint=(
    "Task 8.4: each displacement is applied in one update only; later updates leave the command as it is, whether "
    "the joint got there or not.",
    "After using a displacement, mark it as used (the class keeps NaN for 'none pending'); a joint with nothing "
    "pending is not written at all.",
    "self.displacements[i] = math.nan",
))
def test_displacement_used_once(learner: ModuleType) -> None:
    rig = _rig0(learner, joints=["joint1", "joint2", "joint3"]).start()
    _jog(rig, ["joint1", "joint2", "joint3"], [0.5, -0.5, 0.25])
    rig.update()
    first = rig.commands()
    rig.set_states(first)  # the joints got there
    for _ in range(3):
        rig.update()
    _expect(rig, first, "three more updates after one JointJog, with the joints at their commands")
    rig.set_states([-1.0, 2.0, 0.5])  # the joints are somewhere else
    rig.update()
    _expect(rig, first, "one more update with the joints somewhere else")
    rig = _rig(learner).start()
    rig.update()
    _expect(rig, [0.0, 0.0], "updates before any message (nothing to apply), with the states at [1.1, 2.2]")


@graded(points=2, after=_STARTED, hint=(
    "Task 8.4: ~/state reports the first joint after every update, also one that moved nothing: set_point and "
    "command are its command, process_value its state, error = set_point - process_value, the header's stamp the "
    "update's time and frame_id the first joint's name.",
    "Publish a JointControllerState at the end of update, outside any 'if a displacement was pending'.",
    "set_point = self.command_interfaces[0].get_value(); process_value = self.state_interfaces[0].get_value(); "
    "JointControllerState(header=Header(stamp=time, frame_id=self.joints[0]), set_point=set_point, "
    "process_value=process_value, error=set_point - process_value, time_step=period, command=set_point)",
))
def test_state_published(learner: ModuleType) -> None:
    rig = _rig(learner, joints=["elbow", "shoulder"], state_joints=["elbow_sensor", "shoulder_sensor"],
               states=[0.75, -2.0]).start()

    def check(what: str) -> None:
        msg = rig.latest_state()
        assert msg is not None, f"{what}: nothing was published on ~/state"
        assert isinstance(msg, JointControllerState), f"{what}: ~/state carries a {type(msg).__name__}"
        command, state = rig.commands()[0], rig.states()[0]  # the controller's own command, whatever it is
        fields = {"header.frame_id": (msg.header.frame_id, "elbow"), "header.stamp": (msg.header.stamp, rig.h.time),
                  "set_point": (msg.set_point, command), "command": (msg.command, command),
                  "process_value": (msg.process_value, state), "error": (msg.error, command - state)}
        for name, (got, want) in fields.items():
            ok = got == want if isinstance(want, str) else isinstance(got, float | int) and _close(float(got), want)
            assert ok, (f"{what} (with joints ['elbow', 'shoulder'] read from ['elbow_sensor', 'shoulder_sensor']), "
                        f"~/state's {name} is {got!r}; it should be {want!r} (elbow's command is {command:.10g}, its "
                        f"state {state:.10g})")

    rig.set_states([0.5, -2.0])
    rig.update()
    check("after an update with no message, the state at 0.5")
    rig.set_states([0.7, -2.0])
    rig.update()
    check("after another update with no message, the state at 0.7")
    rig.set_states([0.0, 0.0])
    _jog(rig, ["elbow", "shoulder"], [0.25, 1.0])
    rig.update()
    check("after an update that applied a JointJog {elbow: 0.25, shoulder: 1.0}")


@graded(points=1, after=_STARTED, hint=(
    "Task 8.4: ~/state's time_step is the period the controller was updated with; a controller at 40 Hz gets 0.025 s, "
    "one slower than the loop gets its own period. No rate is hard-coded.",
    "update(time, period) receives the period in [s]: publish it as it comes.",
    "JointControllerState(..., time_step=period, ...)",
))
def test_state_time_step_is_the_period(learner: ModuleType) -> None:
    for rate in (40, 250):
        rig = _rig0(learner, rate=rate).start()
        for _ in range(2):
            _jog(rig, ["joint1", "joint2"], [0.1, 0.1])
            rig.update()
            msg = rig.latest_state()
            assert msg is not None, f"at {rate} Hz, nothing was published on ~/state after an update that moved"
            assert _close(float(msg.time_step), 1.0 / rate), (
                f"at {rate} Hz, ~/state's time_step is {msg.time_step!r}; it should be the period, {1.0 / rate} s")
    # a controller at 100 Hz in a 250 Hz loop: its period is not a whole number of the loop's (0.008 s, then 0.012 s)
    cfg = _stand_in_yaml()
    cfg.update_rate = 250
    cfg.controller_parameters["displacement_controller"]["update_rate"] = 100
    with rw.bringup("rrbot", cfg, spawn=[JSB, "displacement_controller"], name="task08_grader") as system:
        seen: list[Any] = []
        for _ in range(12):  # a displacement every cycle: an update that moves something publishes in any case
            system.publish("/displacement_controller/reference",
                           JointJog(joint_names=["joint1", "joint2"], displacements=[0.001, 0.001]))
            now = system.spin_cycles(1)
            msg = system.latest("/displacement_controller/state")
            if msg is not None and (not seen or msg is not seen[-1][0]):
                seen.append((msg, now))  # when it was published, by the system's clock (not the learner's stamp)
        running = system.controller_manager.get_controller("displacement_controller").get_lifecycle_state()
    periods = [(b, t_b - t_a) for (_, t_a), (b, t_b) in zip(seen, seen[1:], strict=False)]
    if not periods and running is not State.ACTIVE:
        return  # the manager stopped the controller after its first update: update_returns_ok judges why
    assert periods, "with the loop at 250 Hz and the controller at 100 Hz, ~/state was published at most once in 12 cycles"
    for msg, period in periods:
        assert _close(float(msg.time_step), period), (
            f"with the loop at 250 Hz and the controller at update_rate 100 (its period is not a whole number of the "
            f"loop's: the manager updates it after {period:.3f} s here), ~/state's time_step is {msg.time_step!r}: "
            "publish the period update() receives, not one worked out from a rate")


@graded(points=1, after=_STARTED, hint=(
    "Task 8.4: a displacement received while the controller was inactive, or left pending when it was deactivated, "
    "must not move the robot at the next activation.",
    "on_activate starts with no displacement pending.",
    "self.displacements = [math.nan] * len(self.joints)",
))
def test_activation_forgets_earlier_messages(learner: ModuleType) -> None:
    rig = _rig0(learner, joints=["joint1", "joint2", "joint3"])
    assert rig.configure() is State.INACTIVE, "configure did not succeed"
    _jog(rig, ["joint1", "joint2", "joint3"], [3.0, 3.0, 3.0])
    assert rig.activate() is State.ACTIVE, "activate did not succeed"
    rig.update()
    _expect(rig, [0.0, 0.0, 0.0], "a JointJog received before the first activation, then an update")
    _jog(rig, ["joint1", "joint2", "joint3"], [1.0, 1.0, 1.0])
    assert rig.deactivate() is State.INACTIVE, "deactivate did not succeed"
    _jog(rig, ["joint1", "joint2", "joint3"], [2.0, 2.0, 2.0])
    rig.set_commands([0.0, 0.0, 0.0])  # the NaN of deactivation, back to 0.0 to see any move
    assert rig.activate() is State.ACTIVE, "activating again after a deactivation did not succeed"
    rig.update()
    _expect(rig, [0.0, 0.0, 0.0], "a JointJog pending at deactivation and another received while inactive, then "
            "activation and an update")


@graded(points=2, after=_STARTED, hint=(
    "Task 8.4: after deactivation no stale command may stay on any of the controller's command interfaces.",
    "In on_deactivate write NaN to every command interface, then return SUCCESS.",
    "for interface in self.command_interfaces: interface.set_value(math.nan)",
))
def test_nan_commands_on_deactivate(learner: ModuleType) -> None:
    for joints, interface in ((["joint1", "joint2"], "position"), (["shoulder", "elbow", "wrist"], "velocity")):
        rig = _rig0(learner, joints=joints, interface=interface).start()
        _jog(rig, joints, [0.4] * len(joints))
        rig.update()
        state = rig.deactivate()
        assert state is State.INACTIVE, f"deactivate with {rig.describe()} did not succeed: '{state.label}'"
        commands = rig.commands()
        assert all(math.isnan(v) for v in commands), (
            f"after deactivation with {rig.describe()}, the commands of {joints} are {_fmt(commands)}; every one "
            "must be NaN")


@graded(points=1, after=_STARTED, hint=(
    "Task 8.4: a controller deactivated and activated again works as before: messages move the joints and ~/state is "
    "published.",
    "Keep nothing in on_deactivate that stops the next activation (the subscription and the publisher stay).",
    "on_deactivate only writes NaN and returns CallbackReturn.SUCCESS; on_activate only forgets pending displacements.",
))
def test_reactivation_works(learner: ModuleType) -> None:
    rig = _rig0(learner).start()
    _jog(rig, ["joint1", "joint2"], [0.1, 0.1])
    rig.update()
    for round_ in (1, 2):
        assert rig.deactivate() is State.INACTIVE, "deactivate did not succeed"
        assert rig.activate() is State.ACTIVE, f"activating again (time {round_}) did not succeed"
        _jog(rig, ["joint1", "joint2"], [0.25 * round_, 0.5])
        before = rig.latest_state()
        rig.update()
        _expect(rig, [0.25 * round_, 0.5], f"after deactivation and activation number {round_}, a JointJog "
                f"[{0.25 * round_}, 0.5]")
        assert rig.latest_state() is not before, (
            f"after deactivation and activation number {round_}, an update published nothing on ~/state")


# --------------------------------------------------------------------------------------------- generated scenarios

POOL = ("joint1", "joint2", "shoulder", "elbow", "wrist")
RATES = (100, 40, 250, 50)
KINDS = ("jog", "update", "jog", "move", "slow", "switch")  # a message twice as often as the rest
#: Generated scenarios tried on each grading (seeded: the same ones every time), and the seed.
SCENARIOS, SEED = 1000, 8


@dataclass(frozen=True)
class Setup:
    joints: tuple[str, ...]
    interface: str
    separate_states: bool
    rate: int
    start_active: bool

    def rig(self, controller: Any, name: str) -> Rig:
        return Rig(controller, self.joints, self.interface,
                   tuple(f"{j}_sensor" for j in self.joints) if self.separate_states else (), self.rate, name)

    def describe(self) -> str:
        states = f", states read from {[f'{j}_sensor' for j in self.joints]}" if self.separate_states else ""
        start = "configure, activate" if self.start_active else "configure (not activated)"
        return (f"with joints {list(self.joints)}, interface_name '{self.interface}'{states}, {self.rate} Hz: "
                f"{start}")


Step = tuple[Any, ...]


def _random_scenario(rng: random.Random) -> tuple[Setup, list[Step]]:
    """One scenario: a setup and up to 9 drawn steps (indices, not names), which :func:`_realize` turns into the steps
    a controller sees. Plain seeded draws: Hypothesis spent most of this check's time drawing."""
    joints = tuple(rng.sample(POOL, rng.randint(1, 3)))
    setup = Setup(joints, rng.choice(INTERFACES), rng.random() < 0.5, rng.choice(RATES), rng.random() < 0.5)
    raw = [(rng.choice(KINDS), rng.choice((True, True, False)), [rng.randint(0, 3) for _ in range(rng.randint(1, 4))],
            rng.choice((0, 0, 0, -1, 1)), [rng.randint(-30, 30) for _ in range(4)], rng.random() < 0.5)
           for _ in range(rng.randint(1, 9))]
    return setup, _realize(setup, raw)


def _realize(setup: Setup, raw: Sequence[tuple[Any, ...]]) -> list[Step]:
    joints = list(setup.joints)
    named = [*joints, "gripper"]
    steps: list[Step] = []
    active, slow = setup.start_active, False
    for kind, flag, picks, extra, numbers, then_update in raw:
        values = [k / 10 for k in numbers]
        if kind == "jog":
            if flag:  # the controller's joints, in an order of the draw's choosing
                keys = [*picks, *range(len(joints))][: len(joints)]
                names = [j for _, _, j in sorted(zip(keys, range(len(joints)), joints, strict=True))]
            else:  # any names, unknown and repeated ones included
                names = [named[k % len(named)] for k in picks]
            count = max(0, min(4, len(names) + extra))
            steps.append(("jog", tuple(names), tuple(values[:count])))
        elif kind == "slow":
            slow = flag
            steps.append(("slow", flag))
        elif kind == "move":
            steps.append(("move", tuple(values[: len(joints)])))
        elif kind == "update" and active:
            steps.append(("update",))
        elif kind == "switch" and not slow:  # slow mode across a deactivation is not stated by the task: left out
            active = not active
            steps.append(("activate",) if active else ("deactivate",))
        if then_update and active and steps and steps[-1] != ("update",):
            steps.append(("update",))
    return steps


def _where(exc: BaseException) -> str:
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename).name == FILE]
    if frames:
        return f"your {FILE}, line {frames[-1].lineno}, in {frames[-1].name}: {type(exc).__name__}: {exc}"
    return f"{type(exc).__name__}: {exc}"


def _say(step: Step) -> str:
    kind = step[0]
    if kind == "jog":
        return f"a JointJog naming {list(step[1])} with displacements {list(step[2])}"
    if kind == "slow":
        return f"~/set_slow_control_mode called with data={step[1]}"
    if kind == "move":
        return f"the state joints move to {list(step[1])}"
    return {"update": "an update", "deactivate": "deactivate", "activate": "activate"}[kind]


def _compare(mine: Rig, ref: Rig, kind: str, mine_before: Any, ref_before: Any) -> str:
    if mine.controller.get_lifecycle_state() is not ref.controller.get_lifecycle_state():
        return (f"your controller is '{mine.controller.get_lifecycle_state().label}', the reference's "
                f"'{ref.controller.get_lifecycle_state().label}'")
    for joint, got, want in zip(mine.joints, mine.commands(), ref.commands(), strict=True):
        if not _close(got, want):
            return f"your command of {joint}/{mine.interface} is {got:.10g}; the reference's is {want:.10g}"
    if kind != "update":
        return ""
    got_msg, want_msg = mine.latest_state(), ref.latest_state()
    if want_msg is not ref_before and got_msg is mine_before:
        return "your update published nothing on ~/state (the reference publishes after every update)"
    if not isinstance(got_msg, JointControllerState):
        return f"your ~/state carries {type(got_msg).__name__}, not JointControllerState"
    for field in ("frame_id", "stamp", "set_point", "process_value", "error", "time_step", "command"):
        owner_got, owner_want = (got_msg.header, want_msg.header) if field in ("frame_id", "stamp") else (got_msg, want_msg)
        got, want = getattr(owner_got, field), getattr(owner_want, field)
        same = got == want if field == "frame_id" else isinstance(got, float | int) and _close(float(got), float(want))
        if not same:
            return f"your ~/state's {field} is {got!r}; the reference's is {want!r}"
    return ""


def _run_scenario(cls: type, reference: type, setup: Setup, steps: Sequence[Step]) -> str:
    """Run one scenario on the learner's class and the reference; where they part, in the learner's terms ("": never).
    """
    told = [setup.describe()]
    reasons: list[str] = []
    ref_log = logging.getLogger("rrbot_workshop.controllers.reference")
    caught = _Lines(logging.WARNING)
    ref_log.addHandler(caught)
    ref_log.propagate = False
    try:
        ref = setup.rig(reference(), "reference")
        ref.configure()
        if setup.start_active:
            ref.activate()
        try:
            mine = setup.rig(cls(), NAME)
            mine.configure()
            if setup.start_active:
                mine.activate()
        except Exception as exc:  # noqa: BLE001 - reported with the scenario
            return f"{told[0]}: {_where(exc)}"
        problem = _compare(mine, ref, "start", None, None)
        if problem:
            return f"{told[0]}: {problem}"
        for number, step in enumerate(steps, 1):
            told.append(f"{number}. {_say(step)}")
            caught.lines.clear()
            mine_before, ref_before = mine.latest_state(), ref.latest_state()
            for rig in (ref, mine):
                try:
                    if step[0] == "jog":
                        raised = rig.jog(step[1], step[2])
                        if raised is not None and rig is mine:
                            return f"{'; '.join(told)}. At step {number}, {_where(raised)}"
                    elif step[0] == "slow":
                        rig.slow(step[1])
                    elif step[0] == "move":
                        rig.set_states(step[1])
                    elif step[0] == "update":
                        rig.h.update()
                    elif step[0] == "deactivate":
                        rig.deactivate()
                    else:
                        rig.activate()
                except Exception as exc:  # noqa: BLE001 - reported with the scenario
                    if rig is ref:
                        raise
                    return f"{'; '.join(told)}. At step {number}, {_where(exc)}"
            if step[0] == "jog" and caught.lines:
                reasons.append(f"the reference refused message {number}: {caught.lines[-1].split(': ', 2)[-1]}")
            problem = _compare(mine, ref, step[0], mine_before, ref_before)
            if problem:
                why = f" ({'; '.join(reasons)})" if reasons else ""
                return f"{'; '.join(told)}. After step {number}, {problem}{why}."
        return ""
    finally:
        ref_log.removeHandler(caught)
        ref_log.propagate = True


def _possible(setup: Setup, steps: Sequence[Step]) -> bool:
    """Whether a controller manager could run ``steps`` (updates only while active, no switch in slow mode)."""
    active, slow = setup.start_active, False
    for step in steps:
        if step[0] == "update" and not active:
            return False
        if step[0] in ("activate", "deactivate"):
            if slow or active != (step[0] == "deactivate"):
                return False
            active = not active
        if step[0] == "slow":
            slow = step[1]
    return True


def _simpler(run: Callable[[Setup, Sequence[Step]], str], setup: Setup, steps: Sequence[Step], report: str,
             budget: int = 200) -> str:
    """Leave out steps one at a time, and simplify the setup, while the scenario still tells the controllers apart;
    the last report."""
    changed = True
    while changed and budget > 0:
        changed = False
        candidates: list[tuple[Setup, Sequence[Step]]] = [(setup, [*steps[:k], *steps[k + 1:]])
                                                      for k in reversed(range(len(steps)))]
        if not setup.start_active and steps and steps[0] == ("activate",):
            candidates.append((dataclasses.replace(setup, start_active=True), steps[1:]))
        candidates += [(dataclasses.replace(setup, **{name: plain}), steps)
                       for name, plain in (("separate_states", False), ("rate", 100), ("interface", "position"))
                       if getattr(setup, name) != plain]
        for new_setup, new_steps in candidates:
            if budget <= 0:
                break
            if not _possible(new_setup, new_steps):
                continue
            budget -= 1
            found = run(new_setup, new_steps)
            if found:
                setup, steps, report, changed = new_setup, new_steps, found, True
                break
    return report


#: The rules the generated scenarios combine: when one of them fails, a scenario failing too is that rule's failure.
_RULES = ("test_configure_and_claimed_interfaces", "test_topics_and_service", "test_displacements_matched_by_name",
          "test_wrong_joint_count_refused", "test_unknown_or_repeated_joint_refused",
          "test_refused_message_keeps_the_pending_one", "test_newer_message_replaces_pending", "test_slow_mode",
          "test_command_is_state_plus_displacement", "test_displacement_used_once", "test_state_published",
          "test_state_time_step_is_the_period", "test_activation_forgets_earlier_messages",
          "test_nan_commands_on_deactivate", "test_reactivation_works")


@graded(points=3, after=_RULES, hint=(
    "Task 8.3-8.4: generated sequences of messages, service calls, state changes, updates, deactivations and "
    "activations, with other joints, interfaces and rates, give your controller and the library's reference "
    "different results; the reason gives the shortest such sequence found.",
    "Replay the sequence in the reason with rrbot_workshop.testing.ControllerHarness, and read the rule of the task "
    "it breaks in the TODOs of 8.3 and 8.4.",
    "h = ControllerHarness(DisplacementController(), 'arm_jog', {'joints': [...], 'interface_name': ...}, "
    "state_values=..., command_values=..., update_rate=...); h.configure(); h.activate(); h.publish('~/reference', "
    "JointJog(...)); h.update(); h.latest('~/state')",
))
def test_matches_the_reference(learner: ModuleType) -> None:
    module = reference_or_skip("rrbot_workshop.controllers.displacement")
    # as they are: the library parses a PARAMETERS text once per text and merges it with the base declarations once,
    # where a parsed mapping would be merged again at every load (a tenth of a scenario's time)
    reference = module.DisplacementController  # type: ignore[attr-defined]
    _rig(learner).start()  # a controller that does not start fails here, with its own reason
    cls = learner.DisplacementController

    def run(setup: Setup, steps: Sequence[Step]) -> str:
        return _run_scenario(cls, reference, setup, steps)

    rng = random.Random(SEED)
    for _ in range(SCENARIOS):
        setup, steps = _random_scenario(rng)
        report = run(setup, steps)
        if report:
            report = _simpler(run, setup, steps, report)
            pytest.fail(f"A scenario tells your controller apart from the reference: {report}", pytrace=False)


# --------------------------------------------------------------------------------------------- 8.5 on the robot


JSB = "joint_state_broadcaster"
#: The controllers the YAML was handed out with (notebook 08 switches to the forward controller).
HANDED_OUT = {JSB: "joint_state_broadcaster/JointStateBroadcaster",
              "forward_position_controller": "forward_command_controller/ForwardCommandController"}


def _yaml(task_file: Callable[[int, str], Path]) -> rw.params.ControllersConfig:
    path = task_file(TASK, YAML)
    try:
        return rw.params.load_controllers_yaml(path)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"your {YAML} cannot be read: {' '.join(str(exc).split())}", pytrace=False)
    raise AssertionError("unreachable")


def _type_of(cfg: rw.params.ControllersConfig, name: str) -> Any:
    """A controller's type, declared under the controller manager or in the controller's own section (both are read
    by Jazzy: the manager's parameters, the spawner's --param-file)."""
    return cfg.controller_types.get(name) or cfg.parameters_for(name).get("type")


def _yaml_problem(cfg: rw.params.ControllersConfig) -> str | None:
    """What is wrong with the learner's controllers YAML for task 8.5, or None."""
    ctype = _type_of(cfg, "displacement_controller")
    if ctype is None:
        return f"your {YAML} declares no displacement_controller (no type, under controller_manager or in its section)"
    if ctype not in PLUGINS:
        return f"in your {YAML}, displacement_controller's type is {ctype!r}; it must be one of {', '.join(PLUGINS)}"
    values = cfg.parameters_for("displacement_controller")
    joints = values.get("joints")
    if not isinstance(joints, list) or sorted(map(str, joints)) != ["joint1", "joint2"]:
        return f"in your {YAML}, displacement_controller's joints are {joints!r}: it moves both joints of the RRBot"
    if values.get("interface_name") != "position":
        return (f"in your {YAML}, displacement_controller's interface_name is {values.get('interface_name')!r}, "
                "not 'position'")
    state_joints = values.get("state_joints", [])
    if state_joints not in ([], joints):
        return (f"in your {YAML}, displacement_controller's state_joints are {state_joints!r}: it reads the joints it "
                "moves (leave state_joints out)")
    for name, ctype in HANDED_OUT.items():
        if _type_of(cfg, name) != ctype:
            return f"your {YAML} no longer declares {name} ({ctype}), which was handed out with it"
    return None


def _stand_in_yaml() -> rw.params.ControllersConfig:
    """The RRBot's controllers with a displacement_controller, for judging the class on the robot when the learner's
    YAML is not right yet (that costs the YAML's own check only)."""
    cfg = rw.params.load_controllers_yaml(descriptions_root() / "rrbot" / "config" / "rrbot_controllers.yaml")
    cfg.controller_types["displacement_controller"] = PLUGINS[0]
    cfg.controller_parameters["displacement_controller"] = {"joints": ["joint1", "joint2"], "interface_name": "position"}
    return cfg


@graded(points=2, hint=(
    "Task 8.5: the controllers YAML declares displacement_controller with your plugin's name, and its parameters: "
    "both joints of the RRBot, commanded in position. Jazzy reads the type under controller_manager or in the "
    "controller's own section.",
    "Under controller_manager: ros__parameters: add displacement_controller: type: ...; then a "
    "displacement_controller: ros__parameters: section with joints and interface_name.",
    "type: displacement_controller/DisplacementController; joints: [joint1, joint2]; interface_name: position",
))
def test_yaml_declares_the_controller(task_file: Callable[[int, str], Path]) -> None:
    problem = _yaml_problem(_yaml(task_file))
    assert problem is None, problem


def _on_the_robot(cfg: Any, moves: Sequence[tuple[list[str], list[float], list[float]]], what: str) -> Any:
    with rw.bringup("rrbot", cfg, spawn=[JSB, "displacement_controller"], name="task08_grader") as system:
        ctrl = system.controller_manager.get_controller("displacement_controller")
        assert type(ctrl).__module__.startswith("rrbot_workshop_track_"), (
            f"the running controller is {type(ctrl).__module__}.{type(ctrl).__name__}, the library's reference: "
            f"your {FILE} could not be used (see the notebook's message)")
        for names, displacements, expected in moves:
            system.publish("/displacement_controller/reference",
                           JointJog(joint_names=names, displacements=displacements))
            system.spin(0.1)
            got = list(system.latest("/joint_states").position)
            assert all(_close(a, b) for a, b in zip(got, expected, strict=True)), (
                f"{what}, after a JointJog naming {names} with {displacements}, the RRBot's joints are at "
                f"{_fmt(got)}, not {_fmt(expected)}")
        return system.latest("/displacement_controller/state")


@graded(points=3, after=("test_configure_and_claimed_interfaces", "test_topics_and_service",
                         "test_displacements_matched_by_name", "test_command_is_state_plus_displacement",
                         "test_displacement_used_once", "test_update_returns_ok", "test_state_time_step_is_the_period"),
        hint=(
    "Task 8.5: on the RRBot mock, your controller (not the library's) moves the joints by the displacements sent, "
    "also when every controller runs slower than the control loop.",
    "rw.bringup('rrbot', your YAML, spawn=['joint_state_broadcaster', 'displacement_controller']), then publish a "
    "JointJog on /displacement_controller/reference.",
    "Every method of the class is needed; the notebook's last cells run exactly this.",
))
def test_moves_the_rrbot(learner: ModuleType, task_file: Callable[[int, str], Path]) -> None:
    _rig(learner).start()  # a controller that does not start fails here, with its own reason
    mine = _yaml(task_file)
    yours = _yaml_problem(mine) is None
    cfg = mine if yours else _stand_in_yaml()  # a YAML slip costs yaml_declares_the_controller only
    where = f"with your {YAML}" if yours else "with the RRBot's controllers YAML and a displacement_controller entry"
    moves = [(["joint2", "joint1"], [-0.3, 0.5], [0.5, -0.3]), (["joint1", "joint2"], [0.5, 0.0], [1.0, -0.3])]
    _on_the_robot(cfg, moves, where)
    slower = _yaml(task_file) if yours else _stand_in_yaml()
    slower.update_rate = 200
    slower.controller_parameters.setdefault("displacement_controller", {})["update_rate"] = 50
    slower.controller_parameters.setdefault(JSB, {})["update_rate"] = 100
    state = _on_the_robot(slower, moves, f"{where}, the loop at 200 Hz, displacement_controller at 50 Hz and {JSB} "
                          "at 100 Hz")
    assert state is not None and _close(float(state.time_step), 0.02), (
        "with the loop at 200 Hz and displacement_controller at update_rate 50, ~/state's time_step is "
        f"{getattr(state, 'time_step', None)!r}; it should be the controller's period, 0.02 s")
