"""Records the controller manager keeps and returns.

``ControllerSpec`` is the manager's entry for one loaded controller. The other dataclasses mirror the
``controller_manager_msgs`` messages that the ``list_*`` services return, field for field, so that code
written against ``ros2 control`` output reads the same here.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from rrbot_workshop.controller_interface.base import ControllerInterface
from rrbot_workshop.controller_manager.statistics import ControllerStatistics
from rrbot_workshop.middleware.lifecycle import State

__all__ = [
    "ControllerSpec",
    "ChainConnection",
    "ControllerState",
    "HardwareInterface",
    "HardwareComponentState",
    "HardwareInterfaces",
    "SwitchResult",
]


@dataclass
class ControllerSpec:
    """The manager's entry for one loaded controller.

    Attributes:
        name: Controller name.
        type: Plugin type string, e.g. ``"joint_state_broadcaster/JointStateBroadcaster"``.
        controller: The controller instance.
        fallback_controllers: Controllers to activate if this one fails in ``update``.
        last_update_time: Time of its last ``update`` in [s] (None before the first after activation).
        statistics: Periods and execution times of its updates since its last activation.
    """

    name: str
    type: str
    controller: ControllerInterface
    fallback_controllers: list[str] = field(default_factory=list)
    last_update_time: float | None = None
    statistics: ControllerStatistics = field(default_factory=ControllerStatistics)

    @property
    def state(self) -> State:
        """Current lifecycle state of the controller."""
        return self.controller.get_lifecycle_state()


@dataclass
class ChainConnection:
    """``controller_manager_msgs/ChainConnection``: a following controller and the references used."""

    name: str
    reference_interfaces: list[str] = field(default_factory=list)


@dataclass
class ControllerState:
    """``controller_manager_msgs/ControllerState``, one entry of ``list_controllers``.

    The ``required_*`` lists and the exports are filled only for inactive or active controllers, and
    exported names have the ``"<controller>/"`` prefix removed, as in ros2_control.
    """

    name: str
    state: str
    type: str
    is_async: bool = False
    update_rate: int = 0
    claimed_interfaces: list[str] = field(default_factory=list)
    required_command_interfaces: list[str] = field(default_factory=list)
    required_state_interfaces: list[str] = field(default_factory=list)
    is_chainable: bool = False
    is_chained: bool = False
    exported_state_interfaces: list[str] = field(default_factory=list)
    reference_interfaces: list[str] = field(default_factory=list)
    chain_connections: list[ChainConnection] = field(default_factory=list)


@dataclass
class HardwareInterface:
    """``controller_manager_msgs/HardwareInterface``; ``is_claimed`` is always False for state interfaces."""

    name: str
    data_type: str = "double"
    is_available: bool = False
    is_claimed: bool = False


@dataclass
class HardwareComponentState:
    """``controller_manager_msgs/HardwareComponentState``, one entry of ``list_hardware_components``."""

    name: str
    type: str
    is_async: bool
    rw_rate: int
    plugin_name: str
    state: State
    command_interfaces: list[HardwareInterface] = field(default_factory=list)
    state_interfaces: list[HardwareInterface] = field(default_factory=list)


@dataclass
class HardwareInterfaces:
    """Response of ``list_hardware_interfaces``: every command and state interface, sorted by name."""

    command_interfaces: list[HardwareInterface] = field(default_factory=list)
    state_interfaces: list[HardwareInterface] = field(default_factory=list)


@dataclass
class SwitchResult:
    """What a successful ``switch_controllers`` did.

    Attributes:
        activated: Controllers that became active (including restarted ones), in activation order.
        deactivated: Controllers that were deactivated (including restarted ones).
        skipped: Best-effort only: one line per request that was dropped, and why.
    """

    activated: list[str] = field(default_factory=list)
    deactivated: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
