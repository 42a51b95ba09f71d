"""The controller manager: loads controllers, switches them, and runs the control loop.

One cycle (:meth:`ControllerManager.update`) is: deliver queued topic messages (the non-real-time
side), ``read`` all hardware, ``update`` every active controller in chain order (preceding controllers
first, each at its own rate), ``write`` all hardware, then the cycle hooks. Controllers are loaded by
type string through :mod:`rrbot_workshop.plugins` with parameters from a
:class:`~rrbot_workshop.params.ControllersConfig`; switching follows :mod:`rrbot_workshop.switch`.

As with ros2_control's ``handle_exceptions`` (default true), a controller whose ``update`` raises or
returns ERROR is deactivated together with the controllers chained to it, its traceback is logged,
its ``fallback_controllers`` are activated and the loop goes on. Hardware that fails in ``read`` or
``write`` takes the controllers that use it down the same way.
"""

from __future__ import annotations

import logging
import traceback
from collections.abc import Callable, Iterable, Mapping
from types import MappingProxyType

from . import introspection, plugins
from .clock import Clock, SimClock, rate_due
from .controller_manager_services import register_services
from .controller_spec import (
    ControllerSpec,
    ControllerState,
    HardwareComponentState,
    HardwareInterfaces,
    SwitchResult,
)
from .controllers.base import ControllerInterface, InterfaceConfigurationType
from .exceptions import (
    ControllerError,
    ControllerNotFound,
    HardwareError,
    InterfaceAlreadyClaimed,
    InterfaceNotFound,
    LifecycleError,
    PluginNotFound,
    SwitchError,
)
from .lifecycle import CallbackReturn, ReturnType, State
from .params import ControllersConfig
from .resource_manager import ResourceManager
from .switch import switch_controllers as _switch
from .topics import TopicBus

__all__ = ["ControllerManager"]

_log = logging.getLogger(__name__)

CycleHook = Callable[[float, float], None]


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
        self.resource_manager = resource_manager
        self.bus = bus if bus is not None else TopicBus()
        self.robot_description = robot_description
        self.clock = clock if clock is not None else SimClock(self.update_rate)
        self.handle_exceptions = bool(self.params.manager_parameters.get("handle_exceptions", handle_exceptions))
        self._controllers: dict[str, ControllerSpec] = {}
        self._order: list[str] = []
        self._hooks: list[CycleHook] = []
        register_services(self)

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
        return list(self._order)

    def _spec(self, name: str) -> ControllerSpec:
        try:
            return self._controllers[name]
        except KeyError:
            raise ControllerNotFound(name, self._controllers) from None

    def get_controller(self, name: str) -> ControllerInterface:
        """The controller instance called ``name``.

        Raises:
            ControllerNotFound: If no such controller is loaded.
        """
        return self._spec(name).controller

    # ================================================================= interface resolution
    def _resolve(self, spec: ControllerSpec, kind: str) -> list[str]:
        ctrl = spec.controller
        if spec.state not in (State.INACTIVE, State.ACTIVE):
            return []
        try:
            cfg = ctrl.command_interface_configuration() if kind == "command" else ctrl.state_interface_configuration()
        except Exception:  # noqa: BLE001
            _log.error("%s_interface_configuration of '%s' raised:\n%s", kind, spec.name, traceback.format_exc())
            return []
        rm = self.resource_manager
        if cfg.type is InterfaceConfigurationType.NONE:
            return []
        if cfg.type is InterfaceConfigurationType.ALL:
            if kind == "command":
                own = set(rm.get_controller_reference_interface_names(spec.name))
                return [n for n in rm.available_command_interfaces() if n not in own]
            own = set(rm.get_controller_exported_state_interface_names(spec.name))
            return [n for n in rm.available_state_interfaces() if n not in own]
        names = list(cfg.names)
        if cfg.type is InterfaceConfigurationType.INDIVIDUAL_BEST_EFFORT:
            exists = rm.command_interface_exists if kind == "command" else rm.state_interface_exists
            names = [n for n in names if exists(n)]
        return names

    def command_interface_names(self, spec: ControllerSpec) -> list[str]:
        """Command interfaces a configured controller asks for (resolved against the storage)."""
        return self._resolve(spec, "command")

    def state_interface_names(self, spec: ControllerSpec) -> list[str]:
        """State interfaces a configured controller asks for (resolved against the storage)."""
        return self._resolve(spec, "state")

    # ================================================================= load / configure / cleanup / unload
    def load_controller(self, name: str, type: str | None = None) -> ControllerInterface:  # noqa: A002
        """Create controller ``name`` of plugin ``type`` (from the controllers YAML if None) and run ``on_init``.

        Raises:
            ControllerError: If the name is taken, the type is unknown or ``on_init`` fails.
            ControllerNotFound: If no type is given and the YAML declares none for ``name``.
            ParameterError: If the parameters do not match the controller's declarations.
        """
        if name in self._controllers:
            raise ControllerError(f"controller '{name}' is already loaded; unload it first or use another name")
        type_name = type or self.params.controller_types.get(name) or self.params.parameters_for(name).get("type")
        if not type_name:
            raise ControllerNotFound(
                name, self.params.controller_types, what=f"declared with a 'type' in the controllers config ({self.params.source})"
            )
        try:
            cls = plugins.resolve("controller", type_name)
        except PluginNotFound as exc:
            raise ControllerError(f"cannot load controller '{name}': {exc}") from exc
        ctrl = cls()
        parameters = self.params.parameters_for(name)
        parameters.pop("type", None)
        try:
            result = ctrl.init(name, self.robot_description, self.update_rate, self.bus, parameters, clock=self.clock.now)
        except Exception:
            self.bus.remove_owner(name)
            raise
        if result is not CallbackReturn.SUCCESS:
            self.bus.remove_owner(name)
            raise ControllerError(f"controller '{name}' ({type_name}): on_init returned {result.value}")
        fallback = parameters.get("fallback_controllers", [])
        if not isinstance(fallback, list) or not all(isinstance(f, str) for f in fallback):
            raise ControllerError(f"controller '{name}': 'fallback_controllers' must be a list of names, got {fallback!r}")
        self._controllers[name] = ControllerSpec(name, type_name, ctrl, list(fallback))
        self._order.append(name)
        _log.info("loaded controller '%s' (%s)", name, type_name)
        return ctrl

    def configure_controller(self, name: str) -> None:
        """Configure ``name`` (cleaning it up first if inactive); export a chainable controller's
        interfaces into the resource manager and rebuild the update order.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active or finalized, ``on_configure`` fails, or its exports are invalid.
            ParameterError: If its parameters fail validation.
        """
        spec = self._spec(name)
        ctrl = spec.controller
        if spec.state is State.ACTIVE:
            raise ControllerError(f"controller '{name}' is active and cannot be configured; deactivate it first")
        if spec.state is State.INACTIVE:
            self.cleanup_controller(name)
        if spec.state is not State.UNCONFIGURED:
            raise ControllerError(f"controller '{name}' is '{spec.state.label}' and cannot be configured")
        new = ctrl.configure()
        if new is not State.INACTIVE:
            raise ControllerError(f"controller '{name}' failed to configure: on_configure did not succeed (it is '{new.label}')")
        if ctrl.is_chainable():
            try:
                refs = ctrl.export_reference_interfaces()  # type: ignore[attr-defined]
                exps = ctrl.export_state_interfaces()  # type: ignore[attr-defined]
                if not refs and not exps:
                    raise ControllerError(
                        f"chainable controller '{name}' exports neither reference nor state interfaces"
                    )
                self.resource_manager.import_controller_reference_interfaces(name, refs)
                self.resource_manager.import_controller_exported_state_interfaces(name, exps)
            except Exception:
                self.resource_manager.remove_controller_reference_interfaces(name)
                self.resource_manager.remove_controller_exported_state_interfaces(name)
                ctrl.cleanup()
                raise
        if ctrl.get_node().get_parameter("is_async", False):
            _log.info("controller '%s' asks for is_async; it runs in the manager's loop here", name)
        self._rebuild_order()

    def cleanup_controller(self, name: str) -> None:
        """inactive -> unconfigured; its exported interfaces are removed.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is not inactive.
        """
        spec = self._spec(name)
        if spec.state is not State.INACTIVE:
            raise ControllerError(f"controller '{name}' is '{spec.state.label}'; only an inactive controller can be cleaned up")
        self.resource_manager.remove_controller_reference_interfaces(name)
        self.resource_manager.remove_controller_exported_state_interfaces(name)
        spec.controller.cleanup()
        self._rebuild_order()

    def unload_controller(self, name: str) -> None:
        """Clean up (if inactive), shut down and forget controller ``name``.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active.
        """
        spec = self._spec(name)
        if spec.state is State.ACTIVE:
            raise ControllerError(f"controller '{name}' is active and cannot be unloaded; deactivate it first")
        if spec.state is State.INACTIVE:
            self.cleanup_controller(name)
        if spec.state is not State.FINALIZED:
            try:
                spec.controller.shutdown()
            except LifecycleError as exc:
                _log.warning("shutting down '%s': %s", name, exc)
        spec.controller.get_node().destroy()
        del self._controllers[name]
        self._order.remove(name)

    def set_controller_state(self, name: str, state: str | State) -> None:
        """Bring a controller to ``"unconfigured"``, ``"inactive"`` or ``"active"`` (``ros2 control set_controller_state``).

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If the transition is not possible from its state (or fails).
            SwitchError: If activation or deactivation is rejected.
        """
        spec = self._spec(name)
        target = state if isinstance(state, State) else State.from_label(state)
        current = spec.state
        if target is current:
            return
        if target is State.INACTIVE:
            if current is State.UNCONFIGURED:
                self.configure_controller(name)
            elif current is State.ACTIVE:
                self.switch_controllers(deactivate=[name], strictness="strict")
            else:
                raise ControllerError(f"controller '{name}' is '{current.label}' and cannot become inactive")
        elif target is State.ACTIVE:
            if current is not State.INACTIVE:
                raise ControllerError(f"controller '{name}' is '{current.label}'; only an inactive controller can be activated")
            self.switch_controllers(activate=[name], strictness="strict")
        elif target is State.UNCONFIGURED:
            if current is not State.INACTIVE:
                raise ControllerError(f"controller '{name}' is '{current.label}'; only an inactive controller can be cleaned up")
            self.cleanup_controller(name)
        else:
            raise ControllerError(
                f"cannot set controller '{name}' to '{target.label}' (valid: 'unconfigured', 'inactive', 'active')"
            )

    # ================================================================= update order
    def _rebuild_order(self) -> None:
        """Topological order, preceding controllers first; ties keep load order."""
        rm = self.resource_manager
        names = list(self._controllers)
        before: dict[str, set[str]] = {n: set() for n in names}  # n -> controllers that must run before n
        for name in names:
            spec = self._controllers[name]
            for itf in self.command_interface_names(spec):
                owner = rm.controller_of_interface(itf)
                if owner in before and owner != name:
                    before[owner].add(name)  # name claims owner's reference: name runs first
            for itf in self.state_interface_names(spec):
                owner = rm.controller_of_interface(itf)
                if owner in before and owner != name:
                    before[name].add(owner)  # name reads owner's exported state: owner runs first
        order: list[str] = []
        remaining = list(names)
        while remaining:
            ready = next((n for n in remaining if not (before[n] - set(order))), None)
            if ready is None:
                _log.error("controllers %s form a chaining loop; keeping their load order", remaining)
                order += remaining
                break
            order.append(ready)
            remaining.remove(ready)
        self._order = order

    # ================================================================= switching
    def switch_controllers(
        self,
        activate: Iterable[str] = (),
        deactivate: Iterable[str] = (),
        strictness: str | int = "best_effort",
        activate_asap: bool = True,
        timeout: float = 0.0,
    ) -> SwitchResult:
        """Activate and deactivate controllers in one step, with ros2_control's rules.

        The switch runs at once, between two cycles: the loop is single-threaded here, so
        ``activate_asap`` and ``timeout`` are accepted for fidelity and change nothing.

        Args:
            activate: Controllers to activate.
            deactivate: Controllers to deactivate.
            strictness: ``"best_effort"`` (Jazzy's default) drops requests that cannot be done;
                ``"strict"`` rejects the whole switch. ``1``/``2`` (the service constants) work too.
            activate_asap: Kept for fidelity.
            timeout: Kept for fidelity, in [s].

        Returns:
            What was activated, deactivated and (best effort) skipped.

        Raises:
            SwitchError: If the switch is rejected; its ``reasons`` name the controllers and interfaces.
            ControllerError: If ``strictness`` is not valid.
        """
        if isinstance(activate, str) or isinstance(deactivate, str):
            raise ControllerError("activate and deactivate take lists of controller names, not a single string")
        return _switch(self, activate, deactivate, strictness)

    def _activate_now(self, name: str) -> str | None:
        """Claim interfaces and activate; returns why it failed, or None."""
        spec = self._controllers[name]
        ctrl = spec.controller
        rm = self.resource_manager
        commands, states = [], []
        try:
            for itf in self.command_interface_names(spec):
                commands.append(rm.claim_command_interface(itf, holder=name))
            for itf in self.state_interface_names(spec):
                states.append(rm.claim_state_interface(itf))
        except (InterfaceAlreadyClaimed, InterfaceNotFound) as exc:
            for loan in commands:
                loan.release()
            return f"resource conflict while activating '{name}': {exc}"
        ctrl.assign_interfaces(commands, states)
        new = ctrl.activate()
        if new is not State.ACTIVE:
            ctrl.release_interfaces()
            return f"controller '{name}' failed to activate: on_activate did not succeed (it is '{new.label}')"
        if ctrl.is_chainable():
            rm.make_controller_reference_interfaces_available(name, True)
            rm.make_controller_exported_state_interfaces_available(name, True)
        spec.last_update_time = None
        return None

    def _deactivate_now(self, name: str) -> None:
        """Deactivate, release interfaces, leave chained mode, hide exports."""
        spec = self._controllers[name]
        ctrl = spec.controller
        if spec.state is State.ACTIVE:
            ctrl.deactivate()
        if spec.state is State.ACTIVE:
            _log.error("controller '%s' failed to deactivate (on_deactivate did not succeed); it stays active", name)
            return
        ctrl.release_interfaces()
        if ctrl.is_chainable():
            ctrl.set_chained_mode(False)  # type: ignore[attr-defined]
            self.resource_manager.make_controller_reference_interfaces_available(name, False)
            self.resource_manager.make_controller_exported_state_interfaces_available(name, False)

    # ================================================================= the loop
    def add_cycle_hook(self, fn: CycleHook) -> Callable[[], None]:
        """Call ``fn(time, period)`` after every cycle (recorders, viewers). Returns a remover."""
        self._hooks.append(fn)

        def remove() -> None:
            if fn in self._hooks:
                self._hooks.remove(fn)

        return remove

    def read(self, time: float, period: float) -> None:
        """Read all hardware; controllers using failed hardware are deactivated."""
        status = self.resource_manager.read(time, period)
        if not status.ok:
            self._hardware_failed(status.failed_hardware_names, "read")

    def write(self, time: float, period: float) -> None:
        """Write all hardware; controllers using failed hardware are deactivated."""
        status = self.resource_manager.write(time, period)
        if not status.ok:
            self._hardware_failed(status.failed_hardware_names, "write")

    def update_controllers(self, time: float, period: float) -> None:
        """Update each active controller that is due, in chain order.

        Args:
            time: Current time in [s].
            period: Manager period in [s].
        """
        failed: list[str] = []
        for name in self._order:
            spec = self._controllers[name]
            ctrl = spec.controller
            if ctrl._state is not State.ACTIVE:
                continue
            rate = ctrl._update_rate or self.update_rate
            last = spec.last_update_time
            if rate < self.update_rate and not rate_due(last, time, rate, self.update_rate):
                continue
            ctrl_period = period if last is None or rate >= self.update_rate else time - last
            spec.last_update_time = time
            try:
                result = ctrl.update(time, ctrl_period)
            except Exception:
                if not self.handle_exceptions:
                    raise
                _log.error("update of controller '%s' raised:\n%s", name, traceback.format_exc())
                result = ReturnType.ERROR
            if result is not ReturnType.OK:
                if result is not ReturnType.ERROR:
                    _log.error("update of controller '%s' returned %r", name, result)
                failed.append(name)
        if failed:
            self._controllers_failed(failed)

    def update(self, time: float, period: float) -> None:
        """One control cycle: deliver topics, read, update controllers, write, hooks.

        Args:
            time: Time of this cycle in [s].
            period: Time since the previous cycle in [s].
        """
        self.bus.deliver()
        self.read(time, period)
        self.update_controllers(time, period)
        self.write(time, period)
        for hook in list(self._hooks):
            try:
                hook(time, period)
            except Exception:  # noqa: BLE001 - a plotting hook must not stop the robot
                _log.error("cycle hook %r raised:\n%s", hook, traceback.format_exc())

    # ----------------------------------------------------------------- failures
    def chain_group(self, names: Iterable[str]) -> list[str]:
        """``names`` and every active controller chained to them (either direction), in update order."""
        rm = self.resource_manager
        active = [n for n in self._order if self._controllers[n].state is State.ACTIVE]
        links: dict[str, set[str]] = {n: set() for n in active}
        for n in active:
            spec = self._controllers[n]
            for itf in [*self.command_interface_names(spec), *self.state_interface_names(spec)]:
                owner = rm.controller_of_interface(itf)
                if owner in links and owner != n:
                    links[n].add(owner)
                    links[owner].add(n)
        group = set(names)
        todo = [n for n in group if n in links]
        while todo:
            for other in links[todo.pop()]:
                if other not in group:
                    group.add(other)
                    todo.append(other)
        return [n for n in self._order if n in group]

    def _controllers_failed(self, failed: list[str]) -> None:
        group = self.chain_group(failed)
        _log.error("controller(s) %s failed in update; deactivating %s", failed, group)
        for name in group:
            self._deactivate_now(name)
        fallbacks = [fb for n in failed for fb in self._controllers[n].fallback_controllers]
        fallbacks = [fb for i, fb in enumerate(fallbacks) if fb not in fallbacks[:i]]
        if fallbacks:
            try:
                self.switch_controllers(activate=fallbacks, strictness="strict")
                _log.warning("activated fallback controllers %s", fallbacks)
            except (SwitchError, ControllerError) as exc:
                _log.error("could not activate fallback controllers %s: %s", fallbacks, exc)

    def _hardware_failed(self, hardware: list[str], where: str) -> None:
        rm = self.resource_manager
        users = []
        for name in self._order:
            ctrl = self._controllers[name].controller
            if ctrl.get_lifecycle_state() is not State.ACTIVE:
                continue
            loans = [*ctrl.command_interfaces, *ctrl.state_interfaces]
            if any(rm.hardware_of_interface(loan.name) in hardware for loan in loans):
                users.append(name)
        group = self.chain_group(users)
        if group:
            _log.error("hardware %s failed in %s; deactivating controllers %s", hardware, where, group)
        for name in group:
            self._deactivate_now(name)

    # ================================================================= introspection
    def list_controllers(self) -> list[ControllerState]:
        """``ControllerState`` of each controller, in update order."""
        return introspection.list_controllers(self)

    def list_hardware_components(self) -> list[HardwareComponentState]:
        """``HardwareComponentState`` of each hardware component."""
        return introspection.list_hardware_components(self)

    def list_hardware_interfaces(self) -> HardwareInterfaces:
        """All command and state interfaces with availability and claims."""
        return introspection.list_hardware_interfaces(self)

    def list_controller_types(self) -> list[tuple[str, str]]:
        """``(type, base_class)`` of every controller plugin."""
        return introspection.list_controller_types()

    def view_controller_chains(self) -> str:
        """Graphviz DOT text of the controller chains."""
        return introspection.view_controller_chains(self)

    def set_hardware_component_state(self, name: str, state: str | State) -> bool:
        """Drive hardware component ``name`` to ``state`` (``"unconfigured"``, ``"inactive"``, ``"active"``, ``"finalized"``).

        As in Jazzy, controllers using the component are not touched: with the hardware inactive they
        keep running but nothing is written; with it unconfigured their interfaces are unavailable.

        Returns:
            True if the component reached ``state``.

        Raises:
            HardwareError: If there is no such component or the state label is invalid.
        """
        try:
            target = state if isinstance(state, State) else State.from_label(state)
        except ValueError as exc:
            raise HardwareError(f"hardware component '{name}': {exc}") from None
        return self.resource_manager.set_component_state(name, target)

    def shutdown(self) -> None:
        """Deactivate every active controller (in update order) and unload them all."""
        for name in [n for n in self._order if self._controllers[n].state is State.ACTIVE]:
            self._deactivate_now(name)
        for name in reversed(list(self._order)):
            try:
                self.unload_controller(name)
            except (ControllerError, LifecycleError) as exc:
                _log.warning("unloading '%s' at shutdown: %s", name, exc)
        self.bus.remove_owner("controller_manager")
