"""The chainable controller base class: ``ChainableControllerInterface``.

A chainable controller also *exports* reference interfaces that a preceding controller can claim instead
of listening to its topic (and may export state interfaces for others to read). While they are claimed it
runs in chained mode: its references come from the preceding controller, not from its topic.
"""

from __future__ import annotations

from typing import Any

from rrbot_workshop.controller_interface.controller import ControllerInterface
from rrbot_workshop.exceptions import ControllerError
from rrbot_workshop.hardware_interface.handles import CommandInterface, StateInterface
from rrbot_workshop.middleware.lifecycle import ReturnType, State

__all__ = ["ChainableControllerInterface"]


class ChainableControllerInterface(ControllerInterface):
    """A controller whose inputs can be *reference interfaces* written by a preceding controller.

    Subclasses implement ``on_export_reference_interfaces`` (and/or ``on_export_state_interfaces``),
    ``update_reference_from_subscribers`` (read the topic when not chained) and
    ``update_and_write_commands`` (the control law).

    Attributes:
        reference_interfaces: Exported reference handles, in export order.
        exported_state_interfaces: Exported state handles, in export order.
    """

    def __init__(self) -> None:
        super().__init__()
        self.reference_interfaces: list[CommandInterface] = []
        self.exported_state_interfaces: list[StateInterface] = []
        self._chained = False

    def is_chainable(self) -> bool:
        return True

    def is_in_chained_mode(self) -> bool:
        """True while a preceding controller claims this controller's reference interfaces."""
        return self._chained

    # ----------------------------------------------------------------- to override
    def on_export_reference_interfaces(self) -> list[CommandInterface]:
        """Reference interfaces ``<controller_name>/<name>``. Default: none."""
        return []

    def on_export_state_interfaces(self) -> list[StateInterface]:
        """State interfaces ``<controller_name>/<name>`` for others to read. Default: none."""
        return []

    def on_set_chained_mode(self, chained_mode: bool) -> bool:
        """Hook run when the chained mode changes. Default: accept."""
        return True

    def update_reference_from_subscribers(self, time: float, period: float) -> ReturnType:
        """Copy the latest topic message into the reference interfaces (unchained mode only)."""
        raise NotImplementedError(f"{type(self).__name__}.update_reference_from_subscribers() is not implemented")

    def update_and_write_commands(self, time: float, period: float) -> ReturnType:
        """Compute commands from the reference interfaces and write them."""
        raise NotImplementedError(f"{type(self).__name__}.update_and_write_commands() is not implemented")

    # ----------------------------------------------------------------- framework
    def update(self, time: float, period: float) -> ReturnType:
        """References from the topic when not chained, then the control law."""
        if not self._chained:
            result = self.update_reference_from_subscribers(time, period)
            if result is not ReturnType.OK:
                return result
        return self.update_and_write_commands(time, period)

    def _check_exports(self, handles: list[Any], kind: str) -> None:
        name = self.get_name()
        seen: set[str] = set()
        for h in handles:
            if not h.prefix_name.startswith(name):
                raise ControllerError(
                    f"controller '{name}' exports {kind} interface '{h.name}': its prefix must begin with "
                    f"the controller name ('{name}/...')"
                )
            if h.name in seen:
                raise ControllerError(f"controller '{name}' exports {kind} interface '{h.name}' twice")
            seen.add(h.name)

    def export_reference_interfaces(self) -> list[CommandInterface]:
        """Collect and check the reference interfaces (called by the manager after configure).

        Raises:
            ControllerError: If a prefix does not begin with the controller name or a name repeats.
        """
        handles = list(self.on_export_reference_interfaces())
        self._check_exports(handles, "reference")
        self.reference_interfaces = handles
        return handles

    def export_state_interfaces(self) -> list[StateInterface]:
        """Collect and check the exported state interfaces (called by the manager after configure).

        Raises:
            ControllerError: If a prefix does not begin with the controller name or a name repeats.
        """
        handles = list(self.on_export_state_interfaces())
        self._check_exports(handles, "state")
        self.exported_state_interfaces = handles
        return handles

    def set_chained_mode(self, chained_mode: bool) -> bool:
        """Enter or leave chained mode; only allowed while not active."""
        if self._state is State.ACTIVE:
            self.logger.error("'%s': chained mode can only change while the controller is not active", self.get_name())
            return False
        if self.on_set_chained_mode(chained_mode):
            self._chained = chained_mode
            return True
        return False
