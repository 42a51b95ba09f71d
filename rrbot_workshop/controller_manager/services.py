"""The controller manager's services on the topic bus (``/controller_manager/<service>``).

They mirror ros2_control's services so ``System.call_service`` reads like a ROS client. Requests are
mappings (or objects) with the ROS field names (``name``, ``activate_controllers``, ``strictness``,
``target_state``...); responses are simple namespaces with the ROS response fields (``ok``,
``controller``, ``component``...). A service answers ``ok=False`` with a ``message`` instead of raising.

The services are registered with the calls they make, handed by the manager (its public methods of the same names).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import SimpleNamespace
from typing import Any

from rrbot_workshop.exceptions import HardwareError
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.topics import TopicBus

__all__ = ["register_services", "SERVICE_NAMES", "SERVICE_CALLS"]

SERVICE_NAMES = (
    "list_controllers", "list_hardware_components", "list_hardware_interfaces", "list_controller_types",
    "load_controller", "configure_controller", "cleanup_controller", "unload_controller", "switch_controller",
    "set_hardware_component_state",
)

#: The manager's methods the services call, each handed to :func:`register_services` under its own name.
SERVICE_CALLS = (
    "list_controllers", "list_hardware_components", "list_hardware_interfaces", "list_controller_types",
    "load_controller", "configure_controller", "cleanup_controller", "unload_controller", "switch_controllers",
    "set_hardware_component_state",
)


def _field(req: Any, key: str, default: Any = None) -> Any:
    if isinstance(req, Mapping):
        return req.get(key, default)
    return getattr(req, key, default)


def _ok_call(fn: Callable[[], Any]) -> SimpleNamespace:
    try:
        fn()
        return SimpleNamespace(ok=True, message="")
    except Exception as exc:  # noqa: BLE001 - a service answers, it does not raise
        return SimpleNamespace(ok=False, message=str(exc))


def register_services(
    bus: TopicBus,
    *,
    list_controllers: Callable[[], Any],
    list_hardware_components: Callable[[], Any],
    list_hardware_interfaces: Callable[[], Any],
    list_controller_types: Callable[[], list[tuple[str, str]]],
    load_controller: Callable[[str], Any],
    configure_controller: Callable[[str], Any],
    cleanup_controller: Callable[[str], Any],
    unload_controller: Callable[[str], Any],
    switch_controllers: Callable[..., Any],
    set_hardware_component_state: Callable[[str, Any], bool],
    hardware_state: Callable[[str], State],
    manager_name: str = "/controller_manager",
    owner: str = "controller_manager",
) -> None:
    """Create the ``/controller_manager/...`` services on ``bus``, each answering with the calls it is handed.

    Args:
        bus: The bus the services are created on (owner ``controller_manager``).
        list_controllers: The first of the manager's methods the services call, each given under its own name
            (:data:`SERVICE_CALLS`, down to ``set_hardware_component_state``).
        hardware_state: The lifecycle state of a hardware component, by name.
        manager_name: The manager's fully qualified name: the services are ``<manager_name>/<service>``.
        owner: The manager's node on the bus.
    """
    f = _field

    def set_hw(name: str, target: Any) -> SimpleNamespace:
        label = getattr(target, "label", target)
        try:
            ok = set_hardware_component_state(name, label)
        except HardwareError as exc:
            return SimpleNamespace(ok=False, state=None, message=str(exc))
        return SimpleNamespace(ok=ok, state=hardware_state(name), message="")

    services: dict[str, Callable[[Any], Any]] = {
        "list_controllers": lambda req: SimpleNamespace(controller=list_controllers()),
        "list_hardware_components": lambda req: SimpleNamespace(component=list_hardware_components()),
        "list_hardware_interfaces": lambda req: list_hardware_interfaces(),
        "list_controller_types": lambda req: SimpleNamespace(
            types=[t for t, _ in list_controller_types()],
            base_classes=[b for _, b in list_controller_types()],
        ),
        "load_controller": lambda req: _ok_call(lambda: load_controller(f(req, "name"))),
        "configure_controller": lambda req: _ok_call(lambda: configure_controller(f(req, "name"))),
        "cleanup_controller": lambda req: _ok_call(lambda: cleanup_controller(f(req, "name"))),
        "unload_controller": lambda req: _ok_call(lambda: unload_controller(f(req, "name"))),
        "switch_controller": lambda req: _ok_call(
            lambda: switch_controllers(
                activate=f(req, "activate_controllers", []) or [],
                deactivate=f(req, "deactivate_controllers", []) or [],
                strictness=f(req, "strictness", 0) or 0,
                activate_asap=bool(f(req, "activate_asap", True)),
            )
        ),
        "set_hardware_component_state": lambda req: set_hw(f(req, "name"), f(req, "target_state")),
    }
    for name in SERVICE_NAMES:
        bus.create_service(f"{manager_name}/{name}", services[name], None, owner=owner)
