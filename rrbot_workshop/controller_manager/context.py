"""What the controller manager's collaborators may use of it: :class:`ManagerContext`.

The switch planner, the chaining checks, the controller lifecycle, the control loop, the services, the
introspection, the activity topic and the dry run (``explain_switch``) each receive the manager as a
``ManagerContext``: the registry of controllers and its update order, the resource manager, the bus, the clock, the
parameters, and the few requests they make of it in turn (a fallback switch from the loop, a load from a service).
Naming that interface here, below the manager, keeps the package's modules from importing the manager itself: the
manager implements this protocol, and its collaborators depend only on the protocol.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any, Protocol

from rrbot_workshop.controller_interface.base import ControllerInterface
from rrbot_workshop.controller_manager.activity import ActivitySink
from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import (
    ControllerSpec,
    ControllerState,
    HardwareComponentState,
    HardwareInterfaces,
    SwitchResult,
)
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.clock import Clock
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.params import ControllersConfig
from rrbot_workshop.middleware.topics import TopicBus

__all__ = ["ManagerContext", "ActivitySink"]


class ManagerContext(Protocol):
    """The controller manager as its collaborators see it (implemented by ``ControllerManager``)."""

    resource_manager: ResourceManager
    claims: InterfaceClaims
    bus: TopicBus
    clock: Clock
    params: ControllersConfig
    update_rate: int
    robot_description: str
    handle_exceptions: bool
    @property
    def activity(self) -> ActivitySink: ...

    @property
    def controllers(self) -> Mapping[str, ControllerSpec]: ...

    def update_order(self) -> list[str]: ...

    def command_interface_names(self, spec: ControllerSpec) -> list[str]: ...

    def state_interface_names(self, spec: ControllerSpec) -> list[str]: ...

    def chain_group(self, names: Iterable[str]) -> list[str]: ...

    def load_controller(self, name: str, type: str | None = None) -> ControllerInterface: ...  # noqa: A002

    def configure_controller(self, name: str) -> None: ...

    def cleanup_controller(self, name: str) -> None: ...

    def unload_controller(self, name: str) -> None: ...

    def switch_controllers(
        self,
        activate: Iterable[str] = (),
        deactivate: Iterable[str] = (),
        strictness: str | int | None = None,
        activate_asap: bool = True,
        timeout: float = 0.0,
    ) -> SwitchResult: ...

    def set_hardware_component_state(self, name: str, state: str | State) -> bool: ...

    def list_controllers(self) -> list[ControllerState]: ...

    def list_hardware_components(self) -> list[HardwareComponentState]: ...

    def list_hardware_interfaces(self) -> HardwareInterfaces: ...

    def list_controller_types(self) -> list[tuple[str, str]]: ...

    def view_controller_chains(self) -> str: ...

    def explain_switch(self, activate: Iterable[str] = (), deactivate: Iterable[str] = (),
                       strictness: str | int | None = None) -> Any: ...
