"""The controller manager's services on the topic bus (``/controller_manager/<service>``).

They mirror ros2_control's services so ``System.call_service`` reads like a ROS client. Requests are
mappings (or objects) with the ROS field names (``name``, ``activate_controllers``, ``strictness``,
``target_state``...); responses are simple namespaces with the ROS response fields (``ok``,
``controller``, ``component``...). A service answers ``ok=False`` with a ``message`` instead of raising.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import SimpleNamespace
from typing import Any

from rrbot_workshop.controller_manager.context import ManagerContext
from rrbot_workshop.exceptions import HardwareError

__all__ = ["register_services", "SERVICE_NAMES"]

SERVICE_NAMES = (
    "list_controllers", "list_hardware_components", "list_hardware_interfaces", "list_controller_types",
    "load_controller", "configure_controller", "cleanup_controller", "unload_controller", "switch_controller",
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


def _set_hw(cm: ManagerContext, name: str, target: Any) -> SimpleNamespace:
    label = getattr(target, "label", target)
    try:
        ok = cm.set_hardware_component_state(name, label)
    except HardwareError as exc:
        return SimpleNamespace(ok=False, state=None, message=str(exc))
    return SimpleNamespace(ok=ok, state=cm.resource_manager.get_component(name).get_lifecycle_state(), message="")


def register_services(cm: ManagerContext) -> None:
    """Create the ``/controller_manager/...`` services of ``cm`` on its bus."""
    f = _field
    services: dict[str, Callable[[Any], Any]] = {
        "list_controllers": lambda req: SimpleNamespace(controller=cm.list_controllers()),
        "list_hardware_components": lambda req: SimpleNamespace(component=cm.list_hardware_components()),
        "list_hardware_interfaces": lambda req: cm.list_hardware_interfaces(),
        "list_controller_types": lambda req: SimpleNamespace(
            types=[t for t, _ in cm.list_controller_types()],
            base_classes=[b for _, b in cm.list_controller_types()],
        ),
        "load_controller": lambda req: _ok_call(lambda: cm.load_controller(f(req, "name"))),
        "configure_controller": lambda req: _ok_call(lambda: cm.configure_controller(f(req, "name"))),
        "cleanup_controller": lambda req: _ok_call(lambda: cm.cleanup_controller(f(req, "name"))),
        "unload_controller": lambda req: _ok_call(lambda: cm.unload_controller(f(req, "name"))),
        "switch_controller": lambda req: _ok_call(
            lambda: cm.switch_controllers(
                activate=f(req, "activate_controllers", []) or [],
                deactivate=f(req, "deactivate_controllers", []) or [],
                strictness=f(req, "strictness", 0) or 0,
                activate_asap=bool(f(req, "activate_asap", True)),
            )
        ),
        "set_hardware_component_state": lambda req: _set_hw(cm, f(req, "name"), f(req, "target_state")),
    }
    for name in SERVICE_NAMES:
        cm.bus.create_service(f"/controller_manager/{name}", services[name], None, owner="controller_manager")
