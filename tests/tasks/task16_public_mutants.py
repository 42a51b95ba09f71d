"""Wrong displacement controllers for the task-16 grader: the public ones, and how every wrong controller is declared.

Each wrong controller is the library's reference ``DisplacementController`` with one mistake, written as a learner
would write it, and breaks one rule of notebook 08. The grader runs the learner's tests on each; a wrong controller
that no test fails on is reported by the rule it breaks (:attr:`WrongController.rule`), never by its code.

The three below ship with every copy of the course (notebook 16 uses the first); the others live in
``task16_mutants/``, which a student copy leaves out (``rrbot-workshop export --student``). Each declares its three
hint levels: the idea of a test that would catch it, the API that sets up the situation, and an example test for
*another* rule (:data:`EXAMPLES`; a unit test checks that the example passes on the wrong controller it is shown for).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from rrbot_workshop.controllers.displacement import DisplacementController
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.msgs import Header, JointControllerState

__all__ = ["WrongController", "wrong", "REGISTRY", "EXAMPLES", "publish_state"]

#: Example tests, one per rule they show (each passes on a correct controller); a hint shows one for another rule.
#: They assume the imports and ``make_harness`` of the exercise's test file.
EXAMPLES: dict[str, str] = {
    "state_plus_displacement": '''\
def test_command_is_the_state_plus_the_displacement(controller_class):
    h = make_harness(controller_class)  # states 1.1 and 2.2
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, -0.25]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([1.1 + 0.5, 2.2 - 0.25])''',
    "nan_on_deactivate": '''\
def test_deactivation_leaves_nan_on_every_command(controller_class):
    h = make_harness(controller_class, joints=["a", "b", "c"])
    h.configure(); h.activate(); h.update()
    h.deactivate()
    assert all(math.isnan(v) for v in h.values(["a/position", "b/position", "c/position"]))''',
    "unknown_joint_refused": '''\
def test_a_message_naming_an_unknown_joint_changes_nothing(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "elbow"], displacements=[1.0, 1.0]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == [0.0, 0.0]''',
    "state_topic": '''\
def test_state_reports_the_first_joint(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, 0.0]))
    h.update()
    msg = h.latest("~/state")
    assert msg.set_point == pytest.approx(1.6) and msg.process_value == pytest.approx(1.1)''',
    "blup_refused": '''\
def test_a_blup_interface_name_is_refused_at_load(controller_class):
    with pytest.raises(ParameterError):
        make_harness(controller_class, interface="blup_position")''',
    "slow_mode": '''\
def test_slow_mode_halves_a_displacement(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.bus.call_service(f"/{h.name}/set_slow_control_mode", SetBoolRequest(data=True))
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[1.0, 1.0]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([1.1 + 0.5, 2.2 + 0.5])''',
    "used_once": '''\
def test_a_displacement_is_used_once(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, 0.5]))
    h.update()
    first = h.values(["joint1/position", "joint2/position"])
    h.set("joint1/position", 0.0); h.set("joint2/position", 0.0)  # the joints are somewhere else
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == first''',
}


@dataclass(frozen=True)
class WrongController:
    """A wrong controller and what the grader says about it.

    Attributes:
        id: Its check is ``catches_<id>``.
        rule: The rule of notebook 08 it breaks, in a sentence (the reason names it when no test fails on it).
        hints: The idea of a test that catches it, the API, an example test for another rule.
        example: The key of that example in :data:`EXAMPLES`.
        cls: The class.
        public: It ships with student copies.
    """

    id: str
    rule: str
    hints: tuple[str, str, str]
    example: str
    cls: type
    public: bool

    @property
    def spec(self) -> str:
        """``module:Class`` for :func:`rrbot_workshop.course.controller_tests.run_tests`."""
        return f"{self.cls.__module__}:{self.cls.__qualname__}"


#: Every wrong controller declared so far, in declaration order.
REGISTRY: list[WrongController] = []


def wrong(id: str, rule: str, idea: str, api: str, example: str, public: bool = False) -> Callable[[type], type]:
    """Declare the class below as a wrong controller (see :class:`WrongController`)."""
    if example not in EXAMPLES:
        raise KeyError(f"wrong controller '{id}': no example test '{example}' (valid: {sorted(EXAMPLES)})")

    def declare(cls: type) -> type:
        hint = f"{EXAMPLES[example]}\n# (an example for another rule; it needs the imports and make_harness of " \
               "your test file)"
        REGISTRY.append(WrongController(id, rule, (f"Task 16: {idea}", api, hint), example, cls, public))
        return cls

    return declare


def publish_state(controller: DisplacementController, time: float, period: float) -> None:
    """Publish ``~/state`` as the reference does (for wrong controllers whose mistake lies elsewhere in update)."""
    if controller._pub is None or not controller.command_interfaces:
        return
    set_point = float(controller.command_interfaces[0].get_value())
    process_value = float(controller.state_interfaces[0].get_value())
    controller._pub.publish(JointControllerState(
        header=Header(stamp=time, frame_id=controller._joints[0]), set_point=set_point, process_value=process_value,
        error=set_point - process_value, time_step=period, command=set_point))


# --------------------------------------------------------------------------------------------- the public three


@wrong("command_is_state_plus_displacement",
       rule="update commands the state read at that update plus the displacement, not the displacement alone",
       idea="a joint that is not at 0 shows the difference: with the states at 1.1 and 2.2, a displacement moves each "
            "joint from there. The workshop's own test expected the displacement alone.",
       api="make_harness(controller_class) starts the states at 1.1, 2.2; h.configure(); h.activate(); h.publish("
           "'~/reference', JointJog(joint_names=[...], displacements=[...])); h.update(); h.values([...]) with "
           "pytest.approx",
       example="nan_on_deactivate", public=True)
class StateNotAdded(DisplacementController):
    """The original workshop's tests' arithmetic: the command is the displacement alone."""

    def update(self, time: float, period: float) -> ReturnType:
        factor = 0.5 if self.slow_mode else 1.0
        for i, displacement in enumerate(self.displacements):
            if not math.isnan(displacement):
                self.command_interfaces[i].set_value(factor * displacement)
                self.displacements[i] = math.nan
        publish_state(self, time, period)
        return ReturnType.OK


@wrong("slow_mode_halves",
       rule="after ~/set_slow_control_mode is called with data=True, every displacement is halved",
       idea="switch slow mode on through its service, then send a displacement and update: the joint moves half "
            "as far as the message says.",
       api="h.bus.call_service(f'/{h.name}/set_slow_control_mode', SetBoolRequest(data=True)) before h.publish("
           "'~/reference', ...) and h.update()",
       example="state_plus_displacement", public=True)
class SlowModeIgnored(DisplacementController):
    """The service sets the mode; update forgets to read it."""

    def update(self, time: float, period: float) -> ReturnType:
        for i, displacement in enumerate(self.displacements):
            if not math.isnan(displacement):
                self.command_interfaces[i].set_value(self.state_interfaces[i].get_value() + displacement)
                self.displacements[i] = math.nan
        publish_state(self, time, period)
        return ReturnType.OK


@wrong("nan_on_deactivate",
       rule="deactivation leaves NaN on every command interface, so no stale command stays for the next controller",
       idea="activate, move a joint, deactivate: then look at every command interface the controller had.",
       api="h.deactivate() returns the state reached; h.values([...]) then reads the commands; math.isnan tells NaN "
           "(NaN == NaN is False)",
       example="state_plus_displacement", public=True)
class NoNanOnDeactivate(DisplacementController):
    """Deactivation that leaves the last commands where they were."""

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        return CallbackReturn.SUCCESS
