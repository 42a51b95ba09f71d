"""The controller manager: loads controllers, switches them, and runs the control loop.

One cycle (:meth:`ControllerManager.update`) is: deliver queued topic messages (the non-real-time
side), ``read`` all hardware, ``update`` every active controller in chain order (preceding controllers
first, each at its own rate), ``write`` all hardware, then the cycle hooks. Controllers are loaded by
type string through :mod:`rrbot_workshop.middleware.plugins` with parameters from a
:class:`~rrbot_workshop.middleware.params.ControllersConfig`; switching follows :mod:`rrbot_workshop.controller_manager.switch`.

As with ros2_control's ``handle_exceptions`` (default true), a controller whose ``update`` raises or
returns ERROR is deactivated together with the controllers chained to it, its traceback is logged,
its ``fallback_controllers`` are activated and the loop goes on. Hardware that fails in ``read`` or
``write`` takes the controllers that use it down the same way.

This class is the public API over the objects it composes, each handed what it needs: the registry of loaded
controllers (a dict they share), :class:`~rrbot_workshop.controller_manager.claims.InterfaceClaims`,
:class:`~rrbot_workshop.controller_manager.chains.ChainGraph`, :class:`~rrbot_workshop.controller_manager.switch.
Switcher`, :class:`~rrbot_workshop.controller_manager.lifecycle.ControllerLifecycle`,
:class:`~rrbot_workshop.controller_manager.failures.FailurePath`, :class:`~rrbot_workshop.controller_manager.loop.
ControllerLoop`, :class:`~rrbot_workshop.controller_manager.hooks.CycleHooks`, the ``~/activity`` reporter and the
services.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any

from rrbot_workshop.controller_interface.base import ControllerInterface
from rrbot_workshop.controller_manager import introspection
from rrbot_workshop.controller_manager.activity import ActivityReporter, reports_activity
from rrbot_workshop.controller_manager.chains import ChainGraph
from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.explain import SwitchExplanation
from rrbot_workshop.controller_manager.explain import explain_switch as _explain
from rrbot_workshop.controller_manager.failures import FailurePath
from rrbot_workshop.controller_manager.hooks import CycleHook, CycleHooks
from rrbot_workshop.controller_manager.lifecycle import ControllerLifecycle
from rrbot_workshop.controller_manager.loop import ControllerLoop
from rrbot_workshop.controller_manager.parameters import ManagerParameters
from rrbot_workshop.controller_manager.services import SERVICE_CALLS, register_services
from rrbot_workshop.controller_manager.spec import (
    ControllerSpec,
    ControllerState,
    HardwareComponentState,
    HardwareInterfaces,
    SwitchResult,
)
from rrbot_workshop.controller_manager.statistics import ControllerStatistics
from rrbot_workshop.controller_manager.switch import Switcher, name_list, normalize_strictness
from rrbot_workshop.exceptions import (
    ArgumentError,
    ControllerError,
    HardwareError,
    LifecycleError,
    ParameterError,
    PluginNotFound,
)
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.arguments import callable_argument, number
from rrbot_workshop.middleware.clock import Clock, SimClock
from rrbot_workshop.middleware.controllers_yaml import MANAGER_NODE
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.params import ControllersConfig
from rrbot_workshop.middleware.topics import TopicBus, node_owner

__all__ = ["ControllerManager"]

_log = logging.getLogger(__name__)


class ControllerManager:
    """Controllers, their lifecycles and chain order, and the control loop.

    Args:
        resource_manager: Owner of the hardware and interface storage.
        bus: Topic bus for controllers' topics and the manager's services (a new one if None).
        update_rate: Loop rate in [Hz]; defaults to ``params.update_rate`` (100 without params).
        robot_description: URDF text handed to controllers.
        params: The controllers YAML content (types and parameters).
        clock: Time source for controllers' nodes; a :class:`SimClock` at ``update_rate`` if None.
        handle_exceptions: Catch exceptions from controllers' ``update`` (ros2_control's parameter, default true).
    """

    def __init__(
        self,
        resource_manager: ResourceManager,
        bus: TopicBus | None = None,
        update_rate: int | None = None,
        robot_description: str = "",
        params: ControllersConfig | None = None,
        clock: Clock | None = None,
        handle_exceptions: bool = True,
    ) -> None:
        self.params = params if params is not None else ControllersConfig()
        self.update_rate = int(update_rate if update_rate is not None else self.params.update_rate)
        self.resource_manager = rm = resource_manager
        self.bus = bus if bus is not None else TopicBus()
        self.robot_description = robot_description
        self.clock = clock if clock is not None else SimClock(self.update_rate)
        own = ManagerParameters.read(self.params, handle_exceptions, rm.allow_controller_activation_with_inactive_hardware)
        #: Jazzy's ``enforce_command_limits`` (see controller_manager.parameters.ManagerParameters, as the next ones).
        self.enforce_command_limits = own.enforce_command_limits
        if own.enforce_command_limits:  # joint_limits.<joint>.* over the URDF's limits (see rrbot_workshop.joint_limits)
            rm.set_joint_limits_parameters(self.params.manager_parameters, shared=self.params.controller_parameters.get("/**"))
        elif any(str(key).split(".")[0] == "joint_limits" for key in self.params.manager_parameters):
            _log.info("the controller manager's joint_limits parameters are not applied: enforce_command_limits is false")
        self.deactivate_controllers_on_hardware_self_deactivate = own.deactivate_controllers_on_hardware_self_deactivate
        rm.allow_controller_activation_with_inactive_hardware = own.allow_controller_activation_with_inactive_hardware
        #: The registry of loaded controllers, in load order, shared with the objects below (the lifecycle writes it).
        self._controllers: dict[str, ControllerSpec] = {}
        self._claims = InterfaceClaims(rm)
        self._chains = ChainGraph(rm, self._claims, self._controllers)
        self._switcher = Switcher(self._controllers, self._chains, self._claims, rm, own.default_strictness)
        self._hooks = CycleHooks()
        self._hardware = rm.cycle  # read and write of the cycle, called without going through the resource manager
        #: Controller name or plugin type -> the library type loaded in its place (``bringup(..., controller_types=)``).
        self.controller_type_stand_ins: dict[str, str] = {}
        #: Values for ``$(var name)`` in parameter files given at load (``bringup(..., launch_args=)``); None: as is.
        self.launch_args: dict[str, Any] | None = None
        #: The namespace of the manager and its controllers (``"/"``, ``"/rrbot_1"``), from the controllers config.
        self.namespace = self.params.namespace
        #: The manager's fully qualified node name (``/controller_manager``, ``/rrbot_1/controller_manager``).
        self.name = self.params.manager_name
        self._owner = node_owner(MANAGER_NODE, self.namespace)
        register_services(self.bus, **{name: self._late(name) for name in SERVICE_CALLS},
                          hardware_state=lambda name: rm.get_component(name).get_lifecycle_state(),
                          manager_name=self.name, owner=self._owner)
        #: Publishes ``<name>/activity`` when a controller or hardware component changes state.
        self.activity = ActivityReporter(self.bus, self.clock, self._controllers, rm, f"{self.name}/activity",
                                         self._owner)
        self.activity.check()  # as Jazzy: a first message at start-up (the components' states, no controllers yet)
        switch = self._late("switch_controllers")  # set_state and the fallbacks switch as a caller of the manager would
        self._lifecycle = ControllerLifecycle(self._controllers, self._chains, rm, self.params, self.bus, self.clock,
                                              robot_description, self.update_rate, self.activity, switch)
        self._failures = FailurePath(self._controllers, self._chains, self._claims, rm, switch, self.activity)
        self._loop = ControllerLoop(self._controllers, self._chains, self.update_rate,
                                    on_failed=self._failures.controllers_failed,
                                    handle_exceptions=own.handle_exceptions)
        rm.handle_exceptions = own.handle_exceptions  # the hardware's read and write follow it too, as in Jazzy

    def _late(self, method: str) -> Callable[..., Any]:
        """Call this manager's ``method`` as it is at the time of the call (an instance may have it replaced)."""
        return lambda *args, **kwargs: getattr(self, method)(*args, **kwargs)

    # ================================================================= lookup
    @property
    def controllers(self) -> Mapping[str, ControllerSpec]:
        """Loaded controllers by name (read-only view), in load order."""
        return MappingProxyType(self._controllers)

    def get_update_rate(self) -> int:
        """Loop rate in [Hz]."""
        return self.update_rate

    def update_order(self) -> list[str]:
        """Controller names in update order (preceding controllers first)."""
        return list(self._chains.order)

    @property
    def default_strictness(self) -> str:
        """``defaults.switch_controller.strictness`` (Jazzy: best_effort): a switch asked with strictness 0 or None."""
        return self._switcher.default_strictness

    @default_strictness.setter
    def default_strictness(self, value: str) -> None:
        """Raises ControllerError (naming strictness and the valid values) for an unknown strictness."""
        self._switcher.default_strictness = normalize_strictness(value)

    @property
    def handle_exceptions(self) -> bool:
        """ros2_control's ``handle_exceptions``: catch what a controller's ``update`` raises (the loop's flag)."""
        return self._loop.handle_exceptions

    @handle_exceptions.setter
    def handle_exceptions(self, value: bool) -> None:
        """Raises ArgumentError unless ``value`` is a bool (as the ROS parameter's type)."""
        if not isinstance(value, bool):
            raise ArgumentError("ControllerManager", "handle_exceptions", value, "True or False")
        self._loop.handle_exceptions = bool(value)
        self.resource_manager.handle_exceptions = bool(value)

    def get_controller(self, name: str) -> ControllerInterface:
        """The controller instance called ``name``.

        Raises:
            ControllerNotFound: If no such controller is loaded.
        """
        return self._lifecycle.spec(name).controller

    def command_interface_names(self, spec: ControllerSpec) -> list[str]:
        """Command interfaces a configured controller asks for (resolved against the storage)."""
        return self._claims.command_interface_names(spec)

    def state_interface_names(self, spec: ControllerSpec) -> list[str]:
        """State interfaces a configured controller asks for (resolved against the storage)."""
        return self._claims.state_interface_names(spec)

    # ================================================================= lifecycle (ControllerLifecycle)
    @reports_activity
    def load_controller(
        self,
        name: str,
        type: str | None = None,  # noqa: A002
        param_file: str | Path | None = None,
        *,
        ros_args: str | Sequence[str] | None = None,
    ) -> ControllerInterface:
        """Create controller ``name`` of plugin ``type`` (from the controllers YAML if None) and run ``on_init``.

        ``ros2 control load_controller NAME PARAM_FILE`` and the spawner's ``--param-file``: with ``param_file``,
        the file is first given to the controller as Jazzy's spawner does it (see
        :meth:`~rrbot_workshop.middleware.controllers_yaml.ControllersConfig.use_param_file`): its ``type`` for
        the controller, if it has one, is the type, and its parameters for the controller override the YAML's. The
        manager keeps the file for the controller, as Jazzy keeps ``<name>.params_file``.

        Without ``param_file``, the manager's own ``<name>.params_file`` parameter (a string or a list of strings in
        the ``controller_manager`` section) names the files, as Jazzy's ``ControllerManager::load_controller`` reads
        it (ros2_control's ``spawner_test_with_params_file_string_parameter``): each file's section for the
        controller gives its parameters over the controllers YAML's, and its type if the YAML has none. They are read
        at the first load; a reload keeps what was read.

        ``ros_args`` is the spawner's ``--controller-ros-args`` (``"-r ~/cmd_vel:=/cmd_vel"``, ``-p name:=value``):
        remap rules for the controller's node, and parameters that override every file.

        A type listed in :attr:`controller_type_stand_ins` (by controller name or by type) is loaded as the
        library type it names, with the same parameters; a log line says so.

        Raises:
            ControllerError: If the name is not a valid ROS node name (see ``middleware.names``) or is taken, the
                type is unknown (the message names ``bringup(..., controller_types=...)``) or ``on_init`` fails.
            ControllerNotFound: If no type is given and the YAML declares none for ``name``.
            ParameterError: If the parameters do not match the controller's declarations, or the parameter file or
                the ros args cannot be read, or ``<name>.params_file`` is not a string or list of strings, names a
                file that cannot be read, or a file without a section for the controller.
        """
        from rrbot_workshop.middleware.names import check_node_name, parse_ros_args

        check_node_name(name)  # before any look-up by name: a name rcl refuses is refused first, as in Jazzy
        rules, overrides = parse_ros_args(ros_args) if ros_args else ([], {})
        if param_file is not None:
            if name in self._controllers:
                raise ControllerError(f"controller '{name}' is already loaded; unload it first or use another name")
            if not self.params.use_param_file(name, param_file, self.launch_args):
                _log.warning("parameter file %s has no section for '%s' (%s/%s, /**/%s, ...); it is not used",
                             param_file, name, self.namespace.rstrip("/"), name, name)
        elif name not in self._controllers and name not in self.params.param_files:
            self._use_manager_params_files(name)
        if overrides:
            for dotted, value in overrides.items():
                node = self.params.param_file_parameters.setdefault(name, {})
                *path, last = dotted.split(".")
                for part in path:
                    node = node.setdefault(part, {})
                node[last] = value
        if ros_args is not None:
            self.bus.set_remaps(node_owner(name, self.namespace), rules)
        declared = type or self.params.controller_types.get(name) or self.params.parameters_for(name).get("type")
        stand_in = self.controller_type_stand_ins.get(name) or self.controller_type_stand_ins.get(str(declared))
        if stand_in and name not in self._controllers:
            _log.warning("controller '%s': loading the library's '%s' in place of '%s' (controller_types), with the "
                         "same parameters", name, stand_in, declared)
            declared = stand_in
        try:
            return self._lifecycle.load(name, declared if (type or stand_in) else None).controller
        except ControllerError as exc:
            if isinstance(exc.__cause__, PluginNotFound):
                raise ControllerError(
                    f"{exc}; a controller of a package this library does not have can be stood in for by a library "
                    f"controller with the same parameters: bringup(..., controller_types={{'{name}': "
                    "'joint_trajectory_controller/JointTrajectoryController'}) (by controller name or by type)"
                ) from exc.__cause__
            raise

    def _use_manager_params_files(self, name: str) -> None:
        """Give controller ``name`` the files of the manager's ``<name>.params_file`` (read as rcl reads a
        ``--params-file``: no substitutions).

        Raises:
            ParameterError: If the value is not a string or list of strings, a file cannot be read, or a file has no
                section for the controller.
        """
        param = f"{name}.params_file"
        declared_type = self.params.controller_types.get(name)
        for file in self.params.params_files_of(name):
            try:
                found = self.params.use_param_file(name, file)
            except ParameterError as exc:
                why = str(exc).split(": ", 1)[1] if exc.owner == "parameter file" else str(exc)
                raise ParameterError("controller_manager", param, f"{file}, the params_file of controller '{name}', "
                                     f"{why}") from exc
            if declared_type:  # the manager's <name>.type names the plugin; the file's 'type' is only a parameter
                self.params.controller_types[name] = declared_type
            if not found:
                fqn = f"{self.namespace.rstrip('/')}/{name}"
                raise ParameterError("controller_manager", param, f"{file} has no section for controller '{name}'; "
                                     f"give it one: '{name}:', '{fqn}:', '/**/{name}:' or '/**:', each with "
                                     "'ros__parameters:'")

    @reports_activity
    def configure_controller(self, name: str) -> None:
        """Configure ``name`` (cleaning it up first if inactive); export a chainable controller's
        interfaces into the resource manager and rebuild the update order.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active or finalized, ``on_configure`` fails, its exports are invalid, or its
                command or state interface configuration lists an interface twice (then it is unconfigured).
            ParameterError: If its parameters fail validation.
        """
        self._lifecycle.configure(name)

    @reports_activity
    def cleanup_controller(self, name: str) -> None:
        """inactive -> unconfigured; its exported interfaces are removed. An unconfigured controller: nothing to do.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active or finalized.
        """
        self._lifecycle.cleanup(name)

    @reports_activity
    def unload_controller(self, name: str) -> None:
        """Clean up (if inactive), shut down and forget controller ``name``.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active.
        """
        self._lifecycle.unload(name)

    @reports_activity
    def set_controller_state(self, name: str, state: str | State) -> None:
        """Bring a controller to ``"unconfigured"``, ``"inactive"`` or ``"active"`` (``ros2 control set_controller_state``).

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If the label is not a lifecycle state, or the transition is not possible from
                its state (or fails).
            SwitchError: If activation or deactivation is rejected.
        """
        self._lifecycle.set_state(name, state)

    # ================================================================= switching
    @reports_activity
    def switch_controllers(
        self,
        activate: Iterable[str] = (),
        deactivate: Iterable[str] = (),
        strictness: str | int | None = None,
        activate_asap: bool = True,
        timeout: float = 0.0,
    ) -> SwitchResult:
        """Activate and deactivate controllers in one step, with ros2_control's rules.

        The switch runs at once, between two cycles: the loop is single-threaded here, so
        ``activate_asap`` and ``timeout`` are accepted for fidelity and change nothing.

        Args:
            activate: Controllers to activate.
            deactivate: Controllers to deactivate.
            strictness: ``"best_effort"`` drops requests that cannot be done; ``"strict"`` rejects the whole
                switch. ``1``/``2`` (the service constants) work too; None or ``0`` take the manager's
                ``defaults.switch_controller.strictness`` (``best_effort`` in Jazzy).
            activate_asap: Kept for fidelity.
            timeout: Kept for fidelity, in [s].

        Returns:
            What was activated, deactivated and (best effort) skipped.

        Raises:
            SwitchError: If the switch is rejected; its ``reasons`` name the controllers and interfaces.
            ControllerError: If ``strictness`` is not valid.
            ArgumentError: If ``activate_asap`` is not a bool or ``timeout`` not a number.
        """
        if isinstance(activate, str) or isinstance(deactivate, str):
            raise ControllerError("activate and deactivate take lists of controller names, not a single string")
        activate, deactivate = name_list(activate, "activate"), name_list(deactivate, "deactivate")
        if not isinstance(activate_asap, bool):
            raise ArgumentError("switch_controllers", "activate_asap", activate_asap, "True or False")
        number("switch_controllers", "timeout", timeout, finite=False)
        return self._switcher.switch(activate, deactivate, strictness)

    def explain_switch(
        self, activate: Iterable[str] = (), deactivate: Iterable[str] = (), strictness: str | int | None = None
    ) -> SwitchExplanation:
        """Say, without changing anything, whether this switch would go through under strict and best effort, and
        every reason it would not, with the facts behind them (see :mod:`~rrbot_workshop.controller_manager.explain`).
        """
        return _explain(self._switcher, self._controllers, self.resource_manager, activate, deactivate, strictness)

    # ================================================================= the loop
    def add_cycle_hook(self, fn: CycleHook) -> Callable[[], None]:
        """Call ``fn(time, period)`` after every cycle (recorders, viewers). Returns a remover.

        Raises:
            ArgumentError: If ``fn`` cannot be called.
        """
        callable_argument("add_cycle_hook", "hook", fn, "a function taking (time, period)")
        return self._hooks.add(fn)

    def read(self, time: float, period: float) -> None:
        """Read all hardware; controllers using failed hardware are deactivated."""
        status = self._hardware.read(time, period)
        if status is not None:
            self._failures.hardware_failed(status.failed_hardware_names, "read")
            self.activity.check()

    def write(self, time: float, period: float) -> None:
        """Write all hardware (commands limited first if ``enforce_command_limits``); controllers using failed
        hardware are deactivated."""
        if self.enforce_command_limits:
            self.resource_manager.enforce_command_limits(period)
        status = self._hardware.write(time, period)
        if status is not None:
            self._failures.write_failed(status.failed_hardware_names,
                                        self.deactivate_controllers_on_hardware_self_deactivate)
            self.activity.check()

    def update_controllers(self, time: float, period: float) -> None:
        """Update each active controller that is due, in chain order.

        Args:
            time: Current time in [s].
            period: Manager period in [s].
        """
        self._loop.update(time, period)

    def update(self, time: float, period: float) -> None:
        """One control cycle: deliver topics, read, update controllers, write, hooks.

        What each step calls is prepared when states change (the resource manager's and the loop's plans), so the
        cycle itself only calls the components and the controllers; failures take the slow path.

        Args:
            time: Time of this cycle in [s].
            period: Time since the previous cycle in [s].
        """
        self.bus.deliver()
        self.read(time, period)
        self._loop.update(time, period)
        self.write(time, period)
        self._hooks.run(time, period)

    def chain_group(self, names: Iterable[str]) -> list[str]:
        """``names`` and every active controller chained to them (either direction), in update order."""
        return self._chains.group(names)

    # ================================================================= introspection
    def list_controllers(self) -> list[ControllerState]:
        """``ControllerState`` of each controller, in update order."""
        return introspection.list_controllers(self._controllers, self._chains.order, self._claims, self.resource_manager)

    def controller_statistics(self) -> dict[str, ControllerStatistics]:
        """Each loaded controller's update periods [s] and execution times [µs] since its last activation."""
        return {name: self._controllers[name].statistics for name in self._chains.order}

    def list_hardware_components(self) -> list[HardwareComponentState]:
        """``HardwareComponentState`` of each hardware component."""
        return introspection.list_hardware_components(self.resource_manager)

    def list_hardware_interfaces(self) -> HardwareInterfaces:
        """All command and state interfaces with availability and claims."""
        return introspection.list_hardware_interfaces(self.resource_manager)

    def list_controller_types(self) -> list[tuple[str, str]]:
        """``(type, base_class)`` of every controller plugin."""
        return introspection.list_controller_types()

    def view_controller_chains(self) -> str:
        """Graphviz DOT text of the controller chains."""
        records = introspection.list_controllers(self._controllers, self._chains.order, self._claims, self.resource_manager)
        return introspection.view_controller_chains(records, self.resource_manager)

    @reports_activity
    def set_hardware_component_state(self, name: str, state: str | State) -> bool:
        """Drive hardware component ``name`` to ``state`` (``"unconfigured"``, ``"inactive"``, ``"active"``, ``"finalized"``).

        As in Jazzy, controllers using the component are not touched: with the hardware inactive they
        keep running but nothing is written; with it unconfigured their interfaces are unavailable.

        Returns:
            True if the component reached ``state``.

        Raises:
            HardwareError: If there is no such component or the state label is invalid.
        """
        if not isinstance(name, str):
            raise HardwareError(f"hardware component name must be a string, got {name!r} (valid: "
                                f"{', '.join(self.resource_manager.component_names())})")
        try:
            target = state if isinstance(state, State) else State.from_label(state)
        except ValueError as exc:
            raise HardwareError(f"hardware component '{name}': {exc}") from None
        return self.resource_manager.set_component_state(name, target)

    def shutdown(self) -> None:
        """Deactivate every active controller (in update order) and unload them all."""
        for name in [n for n in self._chains.order if self._controllers[n].state is State.ACTIVE]:
            self._claims.deactivate(self._controllers[name])
        for name in reversed(list(self._chains.order)):
            try:
                self.unload_controller(name)
            except (ControllerError, LifecycleError) as exc:
                _log.warning("unloading '%s' at shutdown: %s", name, exc)
        self.bus.remove_owner(self._owner)
