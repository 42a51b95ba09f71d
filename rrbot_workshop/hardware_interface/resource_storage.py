"""Interface storage of the resource manager: handles, availability and claims.

One float (or bool/int) per full interface name ``"<prefix>/<interface>"``, all in one flat list (:attr:`values`):
the storage adopts the handles it is given (:func:`~rrbot_workshop.hardware_interface.handles.adopt`), so a
controller's loans can be read in one call. The storage keeps which names
exist, which are *available* (their owner is configured, or the exporting controller is active) and which
command interfaces are *claimed* and by whom. Hardware handles and the interfaces that chainable
controllers export (reference interfaces are command interfaces; exported states are state interfaces)
live side by side, as in ros2_control, so a controller claims either kind the same way.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from rrbot_workshop.exceptions import ControllerError, InterfaceAlreadyClaimed, InterfaceNotFound
from rrbot_workshop.hardware_interface.handles import (
    CommandInterface,
    LoanedCommandInterface,
    LoanedStateInterface,
    StateInterface,
    adopt,
)

__all__ = ["InterfaceStorage"]


class InterfaceStorage:
    """Handles by full name, their availability and command claims."""

    def __init__(self) -> None:
        #: The value of every interface the storage holds, in the order they came (a removed one leaves its slot).
        self.values: list[Any] = []
        self.states: dict[str, StateInterface] = {}
        self.commands: dict[str, CommandInterface] = {}
        self.available_states: set[str] = set()
        self.available_commands: set[str] = set()
        self.claims: dict[str, str] = {}
        #: interface name -> hardware component name (hardware interfaces only).
        self.hardware_owner: dict[str, str] = {}
        #: controller name -> names of its exported reference / state interfaces.
        self.controller_references: dict[str, list[str]] = {}
        self.controller_states: dict[str, list[str]] = {}
        #: exported interface name -> the controller that exports it (an index of the two above).
        self.exporter: dict[str, str] = {}

    # ----------------------------------------------------------------- adding and removing
    def add_hardware(self, component: str, states: Sequence[StateInterface], commands: Sequence[CommandInterface]) -> None:
        """Store a component's handles (unavailable until the component is configured); their values move into
        :attr:`values`."""
        adopt([*states, *commands], self.values)
        for h in states:
            self.states[h.name] = h
            self.hardware_owner.setdefault(h.name, component)
        for c in commands:
            self.commands[c.name] = c
            self.hardware_owner[c.name] = component

    def remove_hardware(self, component: str, state_names: Iterable[str], command_names: Iterable[str]) -> None:
        """Forget a component's handles (used to undo a load that failed part-way)."""
        for name in state_names:
            self.states.pop(name, None)
            self.available_states.discard(name)
        for name in command_names:
            self.commands.pop(name, None)
            self.available_commands.discard(name)
            self.claims.pop(name, None)
        for name in [n for n, owner in self.hardware_owner.items() if owner == component]:
            del self.hardware_owner[name]

    def set_available(self, state_names: Iterable[str], command_names: Iterable[str], available: bool) -> None:
        """Mark interfaces available or not."""
        if available:
            self.available_states.update(state_names)
            self.available_commands.update(command_names)
        else:
            self.available_states.difference_update(state_names)
            self.available_commands.difference_update(command_names)

    def import_controller_interfaces(self, controller: str, handles: Sequence[Any], kind: str) -> None:
        """Store the reference (``kind="reference"``) or state interfaces a chainable controller exports.

        Raises:
            ControllerError: If an exported name already exists.
        """
        pool: dict[str, Any] = self.commands if kind == "reference" else self.states
        clash = [h.name for h in handles if h.name in pool]
        if clash:
            raise ControllerError(
                f"controller '{controller}' exports {kind} interface(s) {clash} that already exist; "
                "exported names must be unique"
            )
        adopt(handles, self.values)
        for h in handles:
            pool[h.name] = h
        target = self.controller_references if kind == "reference" else self.controller_states
        target[controller] = [h.name for h in handles]
        for h in handles:
            self.exporter[h.name] = controller

    def remove_controller_interfaces(self, controller: str, kind: str) -> None:
        """Forget the interfaces a controller exported."""
        source = self.controller_references if kind == "reference" else self.controller_states
        other = self.controller_states if kind == "reference" else self.controller_references
        names = source.pop(controller, [])
        still = set(other.get(controller, ()))
        for n in names:
            if n not in still and self.exporter.get(n) == controller:
                del self.exporter[n]
        pool: dict[str, Any] = self.commands if kind == "reference" else self.states
        avail = self.available_commands if kind == "reference" else self.available_states
        for n in names:
            pool.pop(n, None)
            avail.discard(n)
            self.claims.pop(n, None)

    # ----------------------------------------------------------------- claims
    def claim_state(self, name: str) -> LoanedStateInterface:
        """Loan a state interface (any number of loans may exist).

        Raises:
            InterfaceNotFound: If it does not exist or is not available.
        """
        if name not in self.states:
            raise InterfaceNotFound(name, self.available_states, "does not exist as a state interface")
        if name not in self.available_states:
            raise InterfaceNotFound(name, self.available_states, "is not available (its owner is not configured or not active)")
        return LoanedStateInterface(self.states[name])

    def claim_command(self, name: str, holder: str = "") -> LoanedCommandInterface:
        """Loan a command interface exclusively to ``holder``.

        Raises:
            InterfaceNotFound: If it does not exist or is not available.
            InterfaceAlreadyClaimed: If someone holds it; the error names the holder.
        """
        if name not in self.commands:
            raise InterfaceNotFound(name, self.available_commands, "does not exist as a command interface")
        if name not in self.available_commands:
            raise InterfaceNotFound(
                name, self.available_commands, "is not available (its owner is not configured or not active)"
            )
        if name in self.claims:
            raise InterfaceAlreadyClaimed(name, holder=self.claims[name] or None, requester=holder or None)
        self.claims[name] = holder

        def release() -> None:
            if self.claims.get(name) == holder:
                del self.claims[name]

        return LoanedCommandInterface(self.commands[name], release)

    def holder(self, name: str) -> str | None:
        """Who claims command interface ``name`` (``""`` for an anonymous claim), or None."""
        return self.claims.get(name)

    def controller_of(self, name: str) -> str | None:
        """The controller that exports ``name``, or None for hardware interfaces."""
        return self.exporter.get(name)

    def value(self, name: str, kind: str | None = None) -> Any:
        """Current value of a stored interface.

        Args:
            name: Full interface name.
            kind: ``"state"`` or ``"command"``; None looks at state interfaces first, then command ones
                (``"joint1/position"`` is usually both).

        Raises:
            InterfaceNotFound: If no interface of that kind has that name.
        """
        handle: Any = None
        if kind in (None, "state"):
            handle = self.states.get(name)
        if handle is None and kind in (None, "command"):
            handle = self.commands.get(name)
        if handle is None:
            pool = [*(self.states if kind != "command" else ()), *(self.commands if kind != "state" else ())]
            raise InterfaceNotFound(name, pool)
        return handle.get_value()
