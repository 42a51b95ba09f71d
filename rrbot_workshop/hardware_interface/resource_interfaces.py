"""The resource manager's interface API: which interfaces exist, are available and claimed; loans;
values; and the interfaces chainable controllers export.

:class:`ResourceInterfaces` owns the :class:`~rrbot_workshop.hardware_interface.resource_storage.InterfaceStorage` and
answers for it. :class:`~rrbot_workshop.hardware_interface.resource_manager.ResourceManager` is one, and adds the
hardware components that fill the storage and keep its availability up to date. Interface names are
full names ``"<prefix>/<interface>"``; lists of names come out sorted.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rrbot_workshop.hardware_interface.handles import LoanedCommandInterface, LoanedStateInterface
from rrbot_workshop.hardware_interface.resource_storage import InterfaceStorage

__all__ = ["ResourceInterfaces"]


class ResourceInterfaces:
    """Queries, claims and controller exports over one interface storage."""

    def __init__(self) -> None:
        self._storage = InterfaceStorage()

    # ================================================================= availability
    def state_interface_keys(self) -> list[str]:
        """Every state interface name, sorted."""
        return sorted(self._storage.states)

    def command_interface_keys(self) -> list[str]:
        """Every command interface name (hardware and controller references), sorted."""
        return sorted(self._storage.commands)

    def available_state_interfaces(self) -> list[str]:
        """Available state interface names, sorted."""
        return sorted(self._storage.available_states)

    def available_command_interfaces(self) -> list[str]:
        """Available command interface names, sorted."""
        return sorted(self._storage.available_commands)

    def state_interface_exists(self, name: str) -> bool:
        """Whether a state interface of that name is stored."""
        return name in self._storage.states

    def command_interface_exists(self, name: str) -> bool:
        """Whether a command interface of that name is stored."""
        return name in self._storage.commands

    def state_interface_is_available(self, name: str) -> bool:
        """Whether state interface ``name`` can be read now."""
        return name in self._storage.available_states

    def command_interface_is_available(self, name: str) -> bool:
        """Whether command interface ``name`` can be claimed now (claims aside)."""
        return name in self._storage.available_commands

    def command_interface_is_claimed(self, name: str) -> bool:
        """Whether someone holds command interface ``name``."""
        return name in self._storage.claims

    def command_interface_holder(self, name: str) -> str | None:
        """Name of the holder of command interface ``name``, or None."""
        return self._storage.holder(name)

    def interface_data_type(self, name: str) -> str:
        """Data type of an interface (``"double"`` if unknown)."""
        handle = self._storage.states.get(name) or self._storage.commands.get(name)
        return handle.data_type if handle is not None else "double"

    def hardware_of_interface(self, name: str) -> str | None:
        """Name of the component that exports interface ``name``, or None (controller export or unknown)."""
        return self._storage.hardware_owner.get(name)

    # ================================================================= claims and values
    def claim_state_interface(self, name: str) -> LoanedStateInterface:
        """Loan state interface ``name``.

        Raises:
            InterfaceNotFound: If it does not exist or is not available.
        """
        return self._storage.claim_state(name)

    def claim_command_interface(self, name: str, holder: str = "") -> LoanedCommandInterface:
        """Loan command interface ``name`` exclusively; ``release()`` on the loan frees it.

        Raises:
            InterfaceNotFound: If it does not exist or is not available.
            InterfaceAlreadyClaimed: If it is claimed; the error names the holder.
        """
        return self._storage.claim_command(name, holder)

    def get_interface_value(self, name: str, kind: str | None = None) -> Any:
        """Value of a state, command or reference interface (state first if both exist).

        Raises:
            InterfaceNotFound: If nothing has that name.
        """
        return self._storage.value(name, kind)

    # ================================================================= controller exports
    def import_controller_reference_interfaces(self, controller_name: str, handles: Sequence[Any]) -> None:
        """Store a chainable controller's reference interfaces (unavailable until it activates).

        Raises:
            ControllerError: If a name already exists.
        """
        self._storage.import_controller_interfaces(controller_name, handles, "reference")

    def import_controller_exported_state_interfaces(self, controller_name: str, handles: Sequence[Any]) -> None:
        """Store a chainable controller's exported state interfaces (unavailable until it activates).

        Raises:
            ControllerError: If a name already exists.
        """
        self._storage.import_controller_interfaces(controller_name, handles, "state")

    def get_controller_reference_interface_names(self, controller_name: str) -> list[str]:
        """Full names of the reference interfaces ``controller_name`` exported."""
        return list(self._storage.controller_references.get(controller_name, []))

    def get_controller_exported_state_interface_names(self, controller_name: str) -> list[str]:
        """Full names of the state interfaces ``controller_name`` exported."""
        return list(self._storage.controller_states.get(controller_name, []))

    def make_controller_reference_interfaces_available(self, controller_name: str, available: bool = True) -> None:
        """Make a controller's reference interfaces (un)available."""
        self._storage.set_available((), self.get_controller_reference_interface_names(controller_name), available)

    def make_controller_exported_state_interfaces_available(self, controller_name: str, available: bool = True) -> None:
        """Make a controller's exported state interfaces (un)available."""
        self._storage.set_available(self.get_controller_exported_state_interface_names(controller_name), (), available)

    def remove_controller_reference_interfaces(self, controller_name: str) -> None:
        """Forget a controller's reference interfaces (cleanup / unload)."""
        self._storage.remove_controller_interfaces(controller_name, "reference")

    def remove_controller_exported_state_interfaces(self, controller_name: str) -> None:
        """Forget a controller's exported state interfaces (cleanup / unload)."""
        self._storage.remove_controller_interfaces(controller_name, "state")

    def has_controller_exports(self) -> bool:
        """Whether any controller has exported interfaces stored here (else nothing can chain)."""
        return bool(self._storage.exporter)

    def controller_of_interface(self, name: str) -> str | None:
        """The controller that exports interface ``name``, or None."""
        return self._storage.controller_of(name)
