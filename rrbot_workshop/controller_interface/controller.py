"""The controller base class: ``ControllerInterface``, with what it is handed and what it asks for.

A controller is a lifecycle node. The controller manager loads it (``init`` -> ``on_init``),
configures it (``on_configure``: read parameters, create topics), activates it (claims the interfaces
named by ``command_interface_configuration`` / ``state_interface_configuration``, then ``on_activate``)
and calls ``update(time, period)`` every cycle. This module holds :class:`ControllerInterface`, its node
(:class:`ControllerNode`: topics, services, parameter values) and its interface requests
(:class:`InterfaceConfiguration`, :class:`InterfaceConfigurationType`); the chainable controller is in
:mod:`rrbot_workshop.controller_interface.chainable`.
"""

from __future__ import annotations

import enum
import functools
import logging
from dataclasses import dataclass, field
from typing import Any, ClassVar

from rrbot_workshop.exceptions import ControllerError, LifecycleError, ParameterError
from rrbot_workshop.hardware_interface.handles import LoanedCommandInterface, LoanedStateInterface
from rrbot_workshop.middleware.lifecycle import TRANSITION_SOURCES, TRANSITIONS, CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.params import ParameterSchema, ParamListener
from rrbot_workshop.middleware.topics import Node, TopicBus

__all__ = ["InterfaceConfigurationType", "InterfaceConfiguration", "ControllerNode", "ControllerInterface"]


class InterfaceConfigurationType(enum.Enum):
    """Which interfaces a controller asks for (``controller_interface::interface_configuration_type``)."""

    ALL = "all"
    INDIVIDUAL = "individual"
    INDIVIDUAL_BEST_EFFORT = "individual_best_effort"
    NONE = "none"


@dataclass
class InterfaceConfiguration:
    """A controller's interface request: a type and, for INDIVIDUAL, the full names."""

    type: InterfaceConfigurationType
    names: list[str] = field(default_factory=list)


class ControllerNode(Node):
    """The node of a controller: its topics, services, clock and parameter values.

    Attributes:
        parameters: The controller's ``ros__parameters`` (nested dict), live: ``set_parameters``
            before configure changes what ``on_configure`` reads.
    """

    def __init__(
        self, name: str, bus: TopicBus, parameters: dict[str, Any], namespace: str = "/", clock: Any = None
    ) -> None:
        super().__init__(name, bus, namespace, clock)
        self.parameters: dict[str, Any] = parameters
        #: Bumped by every :meth:`set_parameters`: a controller that watches its parameters while running (as Jazzy's
        #: ``param_listener_->is_old(params_)``) compares it with the revision it last read.
        self.parameters_revision = 0

    def get_parameter(self, name: str, default: Any = None) -> Any:
        """Value of a (dotted) parameter name as given in the YAML, or ``default``."""
        node: Any = self.parameters
        for part in name.split("."):
            if not isinstance(node, dict) or part not in node:
                return default
            node = node[part]
        return node

    def set_parameters(self, values: dict[str, Any]) -> None:
        """Set parameters by dotted name (like ``ros2 param set``); read at the next configure.

        A controller that re-reads its parameters while it runs (``pid_controller``, as in Jazzy) also sees them at its
        next update.
        """
        for name, value in values.items():
            node = self.parameters
            parts = name.split(".")
            for part in parts[:-1]:
                node = node.setdefault(part, {})
            node[parts[-1]] = value
        self.parameters_revision += 1


_BASE_SCHEMA = ParameterSchema(
    """
controller_interface:
  update_rate:
    type: int
    default_value: 0
    description: "Update rate in [Hz]; 0 means the controller manager's rate."
  is_async:
    type: bool
    default_value: false
    description: "Run in its own thread (accepted for fidelity; this library runs every controller in the loop)."
"""
)


@functools.lru_cache(maxsize=64)
def _parsed_schema(text: str) -> ParameterSchema:
    return ParameterSchema(text).merged(_BASE_SCHEMA)


def _schema(declarations: Any) -> ParameterSchema:
    """A controller type's declarations merged with the base ones. YAML text is parsed once per text (not once per
    instance: a manager may load hundreds of controllers of one type; the schema is only read afterwards); declarations
    already parsed (a mapping) are merged as they are."""
    if isinstance(declarations, str):
        return _parsed_schema(declarations)
    return ParameterSchema(declarations).merged(_BASE_SCHEMA)


class ControllerInterface:
    """Base of every controller.

    Subclasses set :attr:`PARAMETERS` (generate_parameter_library YAML) and override ``on_init``,
    ``command_interface_configuration``, ``state_interface_configuration``, ``on_configure``,
    ``on_activate``, ``on_deactivate`` and ``update``.

    Attributes:
        command_interfaces: Loaned command interfaces, in the order of the configuration (set on activate).
        state_interfaces: Loaned state interfaces, in the order of the configuration (set on activate).
        param_listener: Validated parameters of this controller (None if it declares none).
        logger: Logger named after the controller.
    """

    #: generate_parameter_library-style YAML declaring this controller's parameters.
    PARAMETERS: ClassVar[str | None] = None

    def __init__(self) -> None:
        self.command_interfaces: list[LoanedCommandInterface] = []
        self.state_interfaces: list[LoanedStateInterface] = []
        self.param_listener: ParamListener | None = None
        self.logger = logging.getLogger(f"rrbot_workshop.controllers.{type(self).__name__}")
        self._node: ControllerNode | None = None
        self._state = State.UNKNOWN
        self._update_rate = 0
        self._cm_update_rate = 100
        self._robot_description = ""
        self._type_name = ""

    # ----------------------------------------------------------------- set-up by the controller manager
    def init(
        self,
        controller_name: str,
        robot_description: str,
        cm_update_rate: int,
        bus: TopicBus,
        parameters: dict[str, Any] | None = None,
        namespace: str = "/",
        clock: Any = None,
    ) -> CallbackReturn:
        """Create the node, check parameters against the schema, call ``on_init``.

        Exceptions from ``on_init`` and parameter errors give ERROR and the controller stays UNKNOWN.
        """
        self._node = ControllerNode(controller_name, bus, parameters if parameters is not None else {}, namespace, clock)
        self._robot_description = robot_description
        self._cm_update_rate = cm_update_rate
        self.logger = logging.getLogger(f"rrbot_workshop.controllers.{controller_name}")
        try:
            if self.PARAMETERS:
                self.param_listener = ParamListener(
                    _schema(self.PARAMETERS), self._node.parameters, controller_name
                )
            result = self.on_init()
        except ParameterError:
            raise
        except Exception as exc:  # noqa: BLE001
            self.logger.error("on_init of '%s' raised", controller_name, exc_info=True)
            raise ControllerError(f"controller '{controller_name}' failed in on_init: {exc}") from exc
        if result is CallbackReturn.SUCCESS:
            self._state = State.UNCONFIGURED
            TRANSITIONS.bump()
        return result

    def get_node(self) -> ControllerNode:
        """The controller's node (topics, services, parameters).

        Raises:
            ControllerError: If the controller was not initialised by a controller manager.
        """
        if self._node is None:
            raise ControllerError(f"{type(self).__name__} has no node: it was not loaded by a controller manager")
        return self._node

    def get_name(self) -> str:
        """Controller name (the key in the controllers YAML)."""
        return self._node.get_name() if self._node else ""

    def get_update_rate(self) -> int:
        """Effective update rate in [Hz] (set at configure)."""
        return self._update_rate

    def get_robot_description(self) -> str:
        """The URDF text the controller manager was started with."""
        return self._robot_description

    def get_lifecycle_state(self) -> State:
        """Current lifecycle state."""
        return self._state

    def is_chainable(self) -> bool:
        """True for controllers that export reference interfaces."""
        return False

    def is_in_chained_mode(self) -> bool:
        """Always False for a non-chainable controller."""
        return False

    # ----------------------------------------------------------------- to override
    def on_init(self) -> CallbackReturn:
        """Declare things that do not depend on parameter values. Default: success."""
        return CallbackReturn.SUCCESS

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """Command interfaces to claim on activation. Default: none."""
        return InterfaceConfiguration(InterfaceConfigurationType.NONE)

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """State interfaces to read. Default: none."""
        return InterfaceConfiguration(InterfaceConfigurationType.NONE)

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read parameters, create publishers and subscriptions. Default: success."""
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Interfaces are assigned; prepare to run. Default: success."""
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Stop commanding; interfaces are released after this. Default: success."""
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Undo ``on_configure``. Default: success."""
        return CallbackReturn.SUCCESS

    def on_shutdown(self, previous_state: State) -> CallbackReturn:
        """Last call before unloading. Default: success."""
        return CallbackReturn.SUCCESS

    def on_error(self, previous_state: State) -> CallbackReturn:
        """Recover from an error in a transition. SUCCESS -> unconfigured, else finalized.

        Default: SUCCESS, as rclcpp_lifecycle's ``LifecycleNodeInterface::on_error``: a controller whose
        ``on_activate`` fails ends ``unconfigured`` and can be configured again.
        """
        return CallbackReturn.SUCCESS

    def update(self, time: float, period: float) -> ReturnType:
        """Compute and write commands.

        Args:
            time: Current time in [s].
            period: Time since this controller's last update in [s].
        """
        raise NotImplementedError(f"{type(self).__name__}.update() is not implemented")

    # ----------------------------------------------------------------- interfaces
    def assign_interfaces(
        self, command_interfaces: list[LoanedCommandInterface], state_interfaces: list[LoanedStateInterface]
    ) -> None:
        """Receive loans (called by the controller manager before ``on_activate``)."""
        self.command_interfaces = list(command_interfaces)
        self.state_interfaces = list(state_interfaces)

    def release_interfaces(self) -> None:
        """Give every loan back (called after ``on_deactivate``)."""
        for loan in [*self.command_interfaces, *self.state_interfaces]:
            loan.release()
        self.command_interfaces = []
        self.state_interfaces = []

    # ----------------------------------------------------------------- lifecycle driving
    def _run_callback(self, name: str, previous: State) -> CallbackReturn:
        try:
            result = getattr(self, name)(previous)
        except Exception:  # noqa: BLE001 - learner code must not kill the manager
            self.logger.error("%s of '%s' raised", name, self.get_name(), exc_info=True)
            return CallbackReturn.ERROR
        if not isinstance(result, CallbackReturn):
            self.logger.error(
                "%s of '%s' returned %r; it must return a CallbackReturn", name, self.get_name(), result
            )
            return CallbackReturn.ERROR
        return result

    def _transition(self, transition: str, success: State, failure: State) -> State:
        if self._state not in TRANSITION_SOURCES[transition]:
            raise LifecycleError(
                self.get_name(), self._state.label, transition, [s.label for s in TRANSITION_SOURCES[transition]]
            )
        previous = self._state
        result = self._run_callback(f"on_{transition}", previous)
        if result is CallbackReturn.SUCCESS:
            self._state = success
        elif result is CallbackReturn.FAILURE:
            self._state = failure
        else:
            self._state = previous
            self.handle_error()
            self.logger.error("on_%s of '%s' did not succeed (ERROR); after on_error it is '%s'", transition,
                              self.get_name(), self._state.label)
        TRANSITIONS.bump()  # the compiled cycles rebuild their plans
        return self._state

    def configure(self) -> State:
        """unconfigured -> inactive. Also fixes the effective update rate (see ros2_control's rules).

        Raises:
            LifecycleError: If the controller is not unconfigured.
        """
        if self._state is State.UNCONFIGURED:
            rate = 0
            if self._node is not None:
                rate = self._node.get_parameter("update_rate", 0) or 0
            if not isinstance(rate, int) or rate < 0:
                self.logger.error("'%s': update_rate must be a non-negative integer, got %r", self.get_name(), rate)
                return self._state
            if self.param_listener is not None:
                self.param_listener.refresh()
            self._update_rate = _effective_rate(rate, self._cm_update_rate)
        return self._transition("configure", State.INACTIVE, State.UNCONFIGURED)

    def cleanup(self) -> State:
        """inactive -> unconfigured."""
        return self._transition("cleanup", State.UNCONFIGURED, State.INACTIVE)

    def activate(self) -> State:
        """inactive -> active (interfaces must already be assigned)."""
        return self._transition("activate", State.ACTIVE, State.INACTIVE)

    def deactivate(self) -> State:
        """active -> inactive."""
        return self._transition("deactivate", State.INACTIVE, State.ACTIVE)

    def shutdown(self) -> State:
        """any primary state but finalized -> finalized."""
        return self._transition("shutdown", State.FINALIZED, State.FINALIZED)

    def handle_error(self) -> State:
        """Run ``on_error``: SUCCESS -> unconfigured, otherwise finalized."""
        previous = self._state
        result = self._run_callback("on_error", previous)
        self._state = State.UNCONFIGURED if result is CallbackReturn.SUCCESS else State.FINALIZED
        TRANSITIONS.bump()
        return self._state


def _effective_rate(rate: int, cm_rate: int) -> int:
    """ros2_control's rule: 0 or above the CM rate -> CM rate; a non-divisor -> cm/round(cm/rate)."""
    if rate == 0 or rate >= cm_rate:
        return cm_rate
    if cm_rate % rate == 0:
        return rate
    # ros2_control divides unsigned integers here: 30 Hz on 200 Hz gives 200 // 7 = 28.
    return cm_rate // round(cm_rate / rate)
