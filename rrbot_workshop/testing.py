"""Helpers to exercise one controller or hardware component without a controller manager.

ros2_controllers' unit tests build a controller, hand it interfaces they own, and step ``update`` by
hand. :class:`ControllerHarness` does the same here, so controller tests (and the task-8 grader) stay
small and do not depend on the manager. :class:`NullController` is the test double a test is tried on to see whether
it checks anything: a test that passes on a controller that does nothing checks nothing the controller does.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    ControllerInterface,
    InterfaceConfigurationType,
)
from rrbot_workshop.exceptions import ControllerError, InterfaceNotFound
from rrbot_workshop.hardware_interface.handles import (
    CommandInterface,
    Handle,
    LoanedCommandInterface,
    LoanedStateInterface,
    StateInterface,
)
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.topics import TopicBus

__all__ = ["ControllerHarness", "NullController"]


class ControllerHarness:
    """Owns interfaces, a topic bus and a clock, and drives one controller through its lifecycle.

    Args:
        controller: A fresh controller instance.
        name: Controller name (its node name; topics are ``/<name>/...``).
        parameters: The controller's ``ros__parameters``.
        state_values: Full name -> initial value of each state interface the test provides.
        command_values: Full name -> initial value of each command interface the test provides.
        update_rate: Controller manager rate in [Hz]; the period is ``1/update_rate``.
        robot_description: URDF text handed to the controller.

    Example:
        >>> h = ControllerHarness(ForwardCommandController(), "fwd", {"joints": ["j1"], "interface_name": "position"},
        ...                       state_values={}, command_values={"j1/position": 0.0})
        >>> h.configure(); h.activate()
    """

    def __init__(
        self,
        controller: ControllerInterface,
        name: str,
        parameters: Mapping[str, Any] | None = None,
        state_values: Mapping[str, Any] | None = None,
        command_values: Mapping[str, Any] | None = None,
        update_rate: int = 100,
        robot_description: str = "",
    ) -> None:
        self.controller = controller
        self.name = name
        self.bus = TopicBus()
        self.update_rate = update_rate
        self.period = 1.0 / update_rate
        self.time = 0.0
        self.states: dict[str, Handle] = {}
        for key, value in (state_values or {}).items():
            prefix, _, itf = key.rpartition("/")
            self.states[key] = StateInterface(prefix, itf, initial_value=value)
        self.commands: dict[str, Handle] = {}
        for key, value in (command_values or {}).items():
            prefix, _, itf = key.rpartition("/")
            self.commands[key] = CommandInterface(prefix, itf, initial_value=value)
        result = controller.init(
            name, robot_description, update_rate, self.bus, dict(parameters or {}), clock=lambda: self.time
        )
        if result is not CallbackReturn.SUCCESS:
            raise ControllerError(f"on_init of '{name}' returned {result}")

    # ----------------------------------------------------------------- lifecycle
    def configure(self) -> State:
        """Configure; for a chainable controller also collect its exported interfaces."""
        state = self.controller.configure()
        if state is State.INACTIVE and isinstance(self.controller, ChainableControllerInterface):
            for ref in self.controller.export_reference_interfaces():
                self.commands[ref.name] = ref
            for exported in self.controller.export_state_interfaces():
                self.states[exported.name] = exported
        return state

    def _names(self, config: Any, pool: Mapping[str, Handle]) -> list[str]:
        if config.type is InterfaceConfigurationType.ALL:
            return list(pool)
        if config.type is InterfaceConfigurationType.NONE:
            return []
        if config.type is InterfaceConfigurationType.INDIVIDUAL_BEST_EFFORT:
            return [n for n in config.names if n in pool]
        missing = [n for n in config.names if n not in pool]
        if missing:
            raise InterfaceNotFound(missing[0], pool)
        return list(config.names)

    def activate(self) -> State:
        """Assign loans of the configured interfaces, then activate."""
        own = set()
        if isinstance(self.controller, ChainableControllerInterface):
            own = {h.name for h in self.controller.reference_interfaces}
        cmd_pool = {k: v for k, v in self.commands.items() if k not in own}
        cmds = [LoanedCommandInterface(cmd_pool[n]) for n in self._names(
            self.controller.command_interface_configuration(), cmd_pool)]
        states = [LoanedStateInterface(self.states[n]) for n in self._names(
            self.controller.state_interface_configuration(), self.states)]
        self.controller.assign_interfaces(cmds, states)
        state = self.controller.activate()
        if state is not State.ACTIVE:
            self.controller.release_interfaces()
        return state

    def deactivate(self) -> State:
        """Deactivate and release the loans."""
        state = self.controller.deactivate()
        self.controller.release_interfaces()
        return state

    def set_chained_mode(self, chained: bool) -> bool:
        """Set chained mode (the controller must not be active)."""
        if not isinstance(self.controller, ChainableControllerInterface):
            raise ControllerError(f"'{self.name}' is not chainable")
        return self.controller.set_chained_mode(chained)

    # ----------------------------------------------------------------- running
    def publish(self, topic: str, msg: Any) -> None:
        """Publish to an absolute topic (``~/`` expands to ``/<name>/``) and deliver at once."""
        if topic.startswith("~"):
            topic = f"/{self.name}{topic[1:]}"
        self.bus.publish(topic, msg)
        self.bus.deliver()

    def update(self, cycles: int = 1) -> ReturnType:
        """Advance the clock by one period and call ``update`` (``cycles`` times); stop at a non-OK result."""
        result = ReturnType.OK
        for _ in range(cycles):
            self.bus.deliver()
            self.time += self.period
            result = self.controller.update(self.time, self.period)
            if result is not ReturnType.OK:
                break
        self.bus.deliver()
        return result

    def value(self, name: str) -> Any:
        """Current value of a state or command interface the harness owns."""
        if name in self.commands:
            return self.commands[name].get_value()
        if name in self.states:
            return self.states[name].get_value()
        raise InterfaceNotFound(name, [*self.commands, *self.states])

    def set(self, name: str, value: Any) -> None:
        """Set a state (or command) interface value, as hardware would."""
        (self.states if name in self.states else self.commands)[name].set_value(value)

    def values(self, names: Sequence[str]) -> list[Any]:
        """Values of several interfaces."""
        return [self.value(n) for n in names]

    def latest(self, topic: str) -> Any:
        """Last message on ``topic`` (``~/`` allowed)."""
        if topic.startswith("~"):
            topic = f"/{self.name}{topic[1:]}"
        return self.bus.latest(topic)


class NullController(ControllerInterface):
    """A controller that does nothing and always succeeds: every lifecycle callback answers SUCCESS, ``update``
    answers OK, it declares no parameters (any are accepted), claims no interface and creates no topic.

    A test of a controller that passes on it too checks nothing that controller does (it can only fail when the
    controller raises): the task-16 grader tries each learner test on it.
    """

    def update(self, time: float, period: float) -> ReturnType:
        """Do nothing.

        Args:
            time: Current time in [s].
            period: Time since the last update in [s].
        """
        return ReturnType.OK
