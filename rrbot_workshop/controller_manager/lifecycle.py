"""A controller's lifecycle as the controller manager drives it: :class:`ControllerLifecycle`.

Loading a controller resolves its plugin type (given, or from the controllers YAML), runs ``on_init`` with its
parameters and registers it. Configuring a chainable controller also stores the reference and state interfaces it
exports in the resource manager, where they stay unavailable until it activates; cleaning up removes them again.
Unloading shuts the controller down and forgets it. Each step tells the chain graph, which keeps the update order.
:meth:`ControllerLifecycle.set_state` is ``ros2 control set_controller_state``: it picks the transition (or switch)
that reaches the asked state.
"""

from __future__ import annotations

import logging
from typing import Any

from rrbot_workshop.controller_manager.activity import ActivitySink
from rrbot_workshop.controller_manager.chains import ChainGraph
from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.controller_manager.switch import SwitchCall
from rrbot_workshop.exceptions import ControllerError, ControllerNotFound, LifecycleError, PluginNotFound
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.clock import Clock
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State
from rrbot_workshop.middleware.names import check_node_name
from rrbot_workshop.middleware.params import ControllersConfig
from rrbot_workshop.middleware.topics import TopicBus, node_owner

__all__ = ["ControllerLifecycle"]

# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")


class ControllerLifecycle:
    """The registry side of the controllers' lifecycles: load, configure, clean up, unload, set a state.

    It is the one writer of the registry it is handed, and tells the chain graph of every change that moves the
    update order. Activation and deactivation are switches: :meth:`set_state` asks them through ``switch``.

    Args:
        controllers: The manager's registry of loaded controllers by name (load order).
        chains: The manager's chain graph.
        rm: The resource manager that stores a chainable controller's exported interfaces.
        params: The controllers YAML content (types and parameters).
        bus: The bus a controller's node is created on.
        clock: The time source of the controllers' nodes.
        robot_description: The URDF text handed to controllers.
        update_rate: The manager's rate in [Hz], handed to controllers.
        activity: Told when a request made of several steps has finished one (``~/activity``).
        switch: The manager's ``switch_controllers``.
    """

    def __init__(self, controllers: dict[str, ControllerSpec], chains: ChainGraph, rm: ResourceManager,
                 params: ControllersConfig, bus: TopicBus, clock: Clock, robot_description: str, update_rate: int,
                 activity: ActivitySink, switch: SwitchCall) -> None:
        self._controllers = controllers
        self._chains = chains
        self._rm = rm
        self._params = params
        self._bus = bus
        self._clock = clock
        self._robot_description = robot_description
        self._update_rate = update_rate
        self._activity = activity
        self._switch = switch

    def spec(self, name: str) -> ControllerSpec:
        """The record of loaded controller ``name``.

        Raises:
            ControllerNotFound: If no such controller is loaded.
        """
        try:
            return self._controllers[name]
        except (KeyError, TypeError):  # TypeError: an unhashable value given as a name
            raise ControllerNotFound(name, self._controllers) from None

    def load(self, name: str, type_name: str | None) -> ControllerSpec:
        """Create controller ``name``, run its ``on_init`` and register it (it updates last until configured).

        Raises:
            ControllerError: If the name is not a valid ROS node name or is taken, the type is unknown, ``on_init``
                fails, or ``fallback_controllers`` is not a list of names or names the controller itself.
            ControllerNotFound: If no type is given and the YAML declares none for ``name``.
            ParameterError: If the parameters do not match the controller's declarations.
        """
        spec = self._create(name, type_name)
        self._controllers[name] = spec
        self._chains.loaded(name)
        _log.info("loaded controller '%s' (%s)", name, spec.type)
        return spec

    def configure(self, name: str) -> None:
        """Configure ``name``, cleaning it up first if inactive (a step of its own for ``~/activity``); the update
        order is worked out again.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active or finalized, ``on_configure`` fails, its exports are invalid, or it lists
                an interface twice.
            ParameterError: If its parameters fail validation.
        """
        spec = self.spec(name)
        if spec.state is State.INACTIVE:
            self.cleanup(name)
            self._activity.check()
        self._configure(spec)
        self._chains.rebuild()

    def cleanup(self, name: str) -> None:
        """inactive -> unconfigured; its exported interfaces are removed and the update order worked out again.

        An unconfigured controller has nothing to clean up: the request succeeds and changes nothing, as in Jazzy
        (``test_controller_manager_srvs.cpp``, ``cleanup_controller_srv``, variation 2).

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active or finalized.
        """
        spec = self.spec(name)
        if spec.state is State.UNCONFIGURED:
            _log.debug("controller '%s' is unconfigured: nothing to clean up", name)
            return
        self._cleanup(spec)
        self._chains.rebuild()

    def unload(self, name: str) -> None:
        """Clean up (if inactive; a step of its own for ``~/activity``), shut down and forget controller ``name``.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If it is active.
        """
        spec = self.spec(name)
        if spec.state is State.ACTIVE:
            raise ControllerError(f"controller '{name}' is active and cannot be unloaded; deactivate it first")
        if spec.state is State.INACTIVE:
            self.cleanup(name)
            self._activity.check()
        self._rm.remove_controller_reference_interfaces(name)  # left over when on_error made it unconfigured
        self._rm.remove_controller_exported_state_interfaces(name)
        self._shutdown(spec)
        del self._controllers[name]
        self._chains.unloaded(name)

    def _create(self, name: str, type_name: str | None) -> ControllerSpec:
        """Instantiate controller ``name`` and run its ``on_init`` (it is not registered here).

        Args:
            name: Controller name.
            type_name: Plugin type; None takes it from the controllers YAML.

        Raises:
            ControllerError: If the name is taken, the type is unknown, ``on_init`` fails, or
                ``fallback_controllers`` is not a list of names or names the controller itself.
            ControllerNotFound: If no type is given and the YAML declares none for ``name``.
            ParameterError: If the parameters do not match the controller's declarations.
        """
        check_node_name(name)  # every controller is a node: Jazzy refuses the load of a name rcl refuses
        if type_name is not None and not isinstance(type_name, str):
            raise ControllerError(f"controller '{name}': the type must be a string such as "
                                  f"'forward_command_controller/ForwardCommandController', got {type_name!r}")
        if name in self._controllers:
            raise ControllerError(f"controller '{name}' is already loaded; unload it first or use another name")
        params = self._params
        type_name = type_name or params.controller_types.get(name) or params.parameters_for(name).get("type")
        if not type_name:
            raise ControllerNotFound(
                name, params.controller_types, what=f"declared with a 'type' in the controllers config ({params.source})"
            )
        try:
            cls = plugins.resolve("controller", type_name)
        except PluginNotFound as exc:
            raise ControllerError(f"cannot load controller '{name}': {exc}") from exc
        ctrl = cls()
        parameters = params.parameters_for(name)
        parameters.pop("type", None)
        fallback = parameters.get("fallback_controllers", [])
        if not isinstance(fallback, list) or not all(isinstance(f, str) for f in fallback):
            raise ControllerError(f"controller '{name}': 'fallback_controllers' must be a list of names, got {fallback!r}")
        if name in fallback:  # Jazzy refuses to load it: a failing controller cannot take over from itself
            raise ControllerError(f"controller '{name}' names itself in 'fallback_controllers' {fallback}; list other "
                                  "controllers that can take over when it fails")
        namespace = self._params.namespace
        try:
            result = ctrl.init(name, self._robot_description, self._update_rate, self._bus, parameters,
                               namespace=namespace, clock=self._clock.now)
        except Exception:
            self._bus.remove_owner(node_owner(name, namespace))
            raise
        if result is not CallbackReturn.SUCCESS:
            self._bus.remove_owner(node_owner(name, namespace))
            if not isinstance(result, CallbackReturn):
                hint = " (did it forget to `return CallbackReturn.SUCCESS`?)" if result is None else ""
                raise ControllerError(f"controller '{name}' ({type_name}): on_init returned {result!r}{hint}; it must "
                                      "return a CallbackReturn (SUCCESS, FAILURE or ERROR)")
            raise ControllerError(f"controller '{name}' ({type_name}): on_init returned {result.value}")
        return ControllerSpec(name, type_name, ctrl, list(fallback))

    def _configure(self, spec: ControllerSpec) -> None:
        """unconfigured -> inactive; a chainable controller's exports are stored in the resource manager.

        Raises:
            ControllerError: If it is not unconfigured, ``on_configure`` fails, its exports are invalid, or its command
                or state interface configuration lists an interface twice (then nothing it exported stays stored
                and it is unconfigured again).
            ParameterError: If its parameters fail validation.
        """
        rm = self._rm
        name = spec.name
        ctrl = spec.controller
        if spec.state is State.ACTIVE:
            raise ControllerError(f"controller '{name}' is active and cannot be configured; deactivate it first")
        if spec.state is not State.UNCONFIGURED:
            raise ControllerError(f"controller '{name}' is '{spec.state.label}' and cannot be configured")
        # A controller can reach 'unconfigured' without a cleanup (on_error after a failed activation): what it
        # exported then is still stored. Forget it first, as Jazzy does before every configure.
        rm.remove_controller_reference_interfaces(name)
        rm.remove_controller_exported_state_interfaces(name)
        new = ctrl.configure()
        if new is not State.INACTIVE:
            raise ControllerError(f"controller '{name}' failed to configure: on_configure did not succeed (it is '{new.label}')")
        problem = _interface_configuration_problem(ctrl)
        if problem:  # a learner's configuration method without `return`, or one that raises: refuse it here, clearly
            ctrl.cleanup()
            raise ControllerError(f"controller '{name}' cannot be configured: {problem}")
        if ctrl.is_chainable():
            try:
                refs = ctrl.export_reference_interfaces()  # type: ignore[attr-defined]
                exps = ctrl.export_state_interfaces()  # type: ignore[attr-defined]
                if not refs and not exps:
                    raise ControllerError(f"chainable controller '{name}' exports neither reference nor state interfaces")
                rm.import_controller_reference_interfaces(name, refs)
                rm.import_controller_exported_state_interfaces(name, exps)
            except Exception:
                rm.remove_controller_reference_interfaces(name)
                rm.remove_controller_exported_state_interfaces(name)
                ctrl.cleanup()
                raise
        for kind in ("command", "state"):  # Jazzy's configure_controller (test_controller_manager_srvs.cpp,
            names = InterfaceClaims(rm).required(spec, kind)  # configure_controller_srv): each listed once
            twice = list(dict.fromkeys(n for n in names if names.count(n) > 1))
            if twice:
                rm.remove_controller_reference_interfaces(name)
                rm.remove_controller_exported_state_interfaces(name)
                ctrl.cleanup()
                _log.error("the %s interfaces of controller '%s' are not unique: %s", kind, name, ", ".join(names))
                raise ControllerError(f"controller '{name}' cannot be configured: its {kind} interfaces are not "
                                      f"unique ({', '.join(twice)} listed more than once in {names}); list each "
                                      f"interface once in {kind}_interface_configuration()")
        if ctrl.get_node().get_parameter("is_async", False):
            _log.info("controller '%s' asks for is_async; it runs in the manager's loop here", name)

    def _cleanup(self, spec: ControllerSpec) -> None:
        """inactive -> unconfigured; the interfaces it exported are removed from the resource manager.

        Raises:
            ControllerError: If it is not inactive.
        """
        rm = self._rm
        name = spec.name
        if spec.state is not State.INACTIVE:
            raise ControllerError(f"controller '{name}' is '{spec.state.label}' and cannot be cleaned up; an inactive "
                                  "controller can (deactivate it first), an unconfigured one has nothing to clean up")
        new = spec.controller.cleanup()
        if new is not State.INACTIVE:  # cleaned up, or unconfigured/finalized by on_error: its exports go
            rm.remove_controller_reference_interfaces(name)
            rm.remove_controller_exported_state_interfaces(name)
        if new is not State.UNCONFIGURED:
            why = "on_cleanup returned FAILURE" if new is State.INACTIVE else "on_cleanup did not succeed"
            _log.error("controller '%s' was not cleaned up properly (%s); it is '%s'", name, why, new.label)
            raise ControllerError(f"controller '{name}' was not cleaned up: {why}; it is '{new.label}', expected "
                                  "'unconfigured'")

    def _shutdown(self, spec: ControllerSpec) -> None:
        """Shut a controller down (unless it is finalized already; a failure is logged) and destroy its node."""
        if spec.state is not State.FINALIZED:
            try:
                spec.controller.shutdown()
            except LifecycleError as exc:
                _log.warning("shutting down '%s': %s", spec.name, exc)
        spec.controller.get_node().destroy()

    def set_state(self, name: str, state: str | State) -> None:
        """Bring loaded controller ``name`` to ``"unconfigured"``, ``"inactive"`` or ``"active"``.

        Activation and deactivation are strict switches through the manager's ``switch_controllers``; configure and
        cleanup are this object's own, so that the update order follows.

        Raises:
            ControllerNotFound: If it is not loaded.
            ControllerError: If the label is not a lifecycle state, or the transition is not possible from its
                state (or fails).
            SwitchError: If activation or deactivation is rejected.
        """
        spec = self.spec(name)
        try:
            if not isinstance(state, State | str):
                raise ValueError(f"the state must be a label such as 'active', got {state!r}")
            target = state if isinstance(state, State) else State.from_label(state)
        except ValueError as exc:
            raise ControllerError(f"controller '{name}': {exc}") from exc
        current = spec.state
        if target is current:
            return
        if target is State.INACTIVE:
            if current is State.UNCONFIGURED:
                self.configure(name)
            elif current is State.ACTIVE:
                self._switch(deactivate=[name], strictness="strict")
            else:
                raise ControllerError(f"controller '{name}' is '{current.label}' and cannot become inactive")
        elif target is State.ACTIVE:
            if current is not State.INACTIVE:
                raise ControllerError(f"controller '{name}' is '{current.label}'; only an inactive controller can be activated")
            self._switch(activate=[name], strictness="strict")
        elif target is State.UNCONFIGURED:
            if current is not State.INACTIVE:
                raise ControllerError(f"controller '{name}' is '{current.label}'; only an inactive controller can be cleaned up")
            self.cleanup(name)
        else:
            raise ControllerError(
                f"cannot set controller '{name}' to '{target.label}' (valid: 'unconfigured', 'inactive', 'active')"
            )


def _interface_configuration_problem(ctrl: Any) -> str:
    """Why the controller's interface configuration methods are unusable, or ``""``."""
    from rrbot_workshop.controller_interface.base import InterfaceConfiguration

    for method in ("command_interface_configuration", "state_interface_configuration"):
        try:
            cfg = getattr(ctrl, method)()
        except Exception as exc:  # noqa: BLE001 - learner code: report it, do not let it escape
            return f"{method}() raised {type(exc).__name__}: {exc}"
        if not isinstance(cfg, InterfaceConfiguration):
            hint = " (did it forget to `return` it?)" if cfg is None else ""
            return (f"{method}() returned {type(cfg).__name__}{hint}; it must return an InterfaceConfiguration, e.g. "
                    "InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, ['joint1/position'])")
        if not isinstance(cfg.names, list | tuple) or not all(isinstance(n, str) for n in cfg.names):
            return f"{method}() returned names {cfg.names!r}; they must be a list of interface names (strings)"
    return ""
