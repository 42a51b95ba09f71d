"""A controller's lifecycle as the controller manager drives it: load, configure, clean up, shut down.

Creating a controller resolves its plugin type (given, or from the controllers YAML) and runs
``on_init`` with its parameters. Configuring a chainable controller also stores the reference and
state interfaces it exports in the resource manager, where they stay unavailable until it
activates; cleaning up removes them again. :func:`set_state` is ``ros2 control
set_controller_state``: it picks the transition (or switch) that reaches the asked state.
The controller manager keeps the registry and the update order around these steps.
"""

from __future__ import annotations

import logging
from typing import Any

from rrbot_workshop.controller_manager.context import ManagerContext
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.exceptions import ControllerError, ControllerNotFound, LifecycleError, PluginNotFound
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State

__all__ = ["create", "configure", "cleanup", "shutdown", "set_state"]

# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")


def create(cm: ManagerContext, name: str, type_name: str | None) -> ControllerSpec:
    """Instantiate controller ``name`` for ``cm`` and run its ``on_init`` (it is not registered here).

    Args:
        cm: The manager whose parameters, bus, clock, rate and robot description the controller gets.
        name: Controller name.
        type_name: Plugin type; None takes it from the controllers YAML.

    Raises:
        ControllerError: If the name is taken, the type is unknown, ``on_init`` fails, or
            ``fallback_controllers`` is not a list of names or names the controller itself.
        ControllerNotFound: If no type is given and the YAML declares none for ``name``.
        ParameterError: If the parameters do not match the controller's declarations.
    """
    if name in cm.controllers:
        raise ControllerError(f"controller '{name}' is already loaded; unload it first or use another name")
    params = cm.params
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
    try:
        result = ctrl.init(name, cm.robot_description, cm.update_rate, cm.bus, parameters, clock=cm.clock.now)
    except Exception:
        cm.bus.remove_owner(name)
        raise
    if result is not CallbackReturn.SUCCESS:
        cm.bus.remove_owner(name)
        raise ControllerError(f"controller '{name}' ({type_name}): on_init returned {result.value}")
    return ControllerSpec(name, type_name, ctrl, list(fallback))


def configure(rm: ResourceManager, spec: ControllerSpec) -> None:
    """unconfigured -> inactive; a chainable controller's exports are stored in ``rm``.

    Raises:
        ControllerError: If it is not unconfigured, ``on_configure`` fails, or its exports are invalid
            (then nothing it exported stays stored and it is unconfigured again).
        ParameterError: If its parameters fail validation.
    """
    name = spec.name
    ctrl = spec.controller
    if spec.state is State.ACTIVE:
        raise ControllerError(f"controller '{name}' is active and cannot be configured; deactivate it first")
    if spec.state is not State.UNCONFIGURED:
        raise ControllerError(f"controller '{name}' is '{spec.state.label}' and cannot be configured")
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
    if ctrl.get_node().get_parameter("is_async", False):
        _log.info("controller '%s' asks for is_async; it runs in the manager's loop here", name)


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


def cleanup(rm: ResourceManager, spec: ControllerSpec) -> None:
    """inactive -> unconfigured; the interfaces it exported are removed from ``rm``.

    Raises:
        ControllerError: If it is not inactive.
    """
    name = spec.name
    if spec.state is not State.INACTIVE:
        raise ControllerError(f"controller '{name}' is '{spec.state.label}'; only an inactive controller can be cleaned up")
    rm.remove_controller_reference_interfaces(name)
    rm.remove_controller_exported_state_interfaces(name)
    spec.controller.cleanup()


def shutdown(spec: ControllerSpec) -> None:
    """Shut a controller down (unless it is finalized already; a failure is logged) and destroy its node."""
    if spec.state is not State.FINALIZED:
        try:
            spec.controller.shutdown()
        except LifecycleError as exc:
            _log.warning("shutting down '%s': %s", spec.name, exc)
    spec.controller.get_node().destroy()


def set_state(cm: ManagerContext, spec: ControllerSpec, state: str | State) -> None:
    """Bring a loaded controller of ``cm`` to ``"unconfigured"``, ``"inactive"`` or ``"active"``.

    Activation and deactivation are strict switches of ``cm``; configure and cleanup go through its
    methods, so that the update order follows.

    Raises:
        ControllerError: If the label is not a lifecycle state, or the transition is not possible from its
            state (or fails).
        SwitchError: If activation or deactivation is rejected.
    """
    name = spec.name
    try:
        target = state if isinstance(state, State) else State.from_label(state)
    except ValueError as exc:
        raise ControllerError(f"controller '{name}': {exc}") from exc
    current = spec.state
    if target is current:
        return
    if target is State.INACTIVE:
        if current is State.UNCONFIGURED:
            cm.configure_controller(name)
        elif current is State.ACTIVE:
            cm.switch_controllers(deactivate=[name], strictness="strict")
        else:
            raise ControllerError(f"controller '{name}' is '{current.label}' and cannot become inactive")
    elif target is State.ACTIVE:
        if current is not State.INACTIVE:
            raise ControllerError(f"controller '{name}' is '{current.label}'; only an inactive controller can be activated")
        cm.switch_controllers(activate=[name], strictness="strict")
    elif target is State.UNCONFIGURED:
        if current is not State.INACTIVE:
            raise ControllerError(f"controller '{name}' is '{current.label}'; only an inactive controller can be cleaned up")
        cm.cleanup_controller(name)
    else:
        raise ControllerError(
            f"cannot set controller '{name}' to '{target.label}' (valid: 'unconfigured', 'inactive', 'active')"
        )
