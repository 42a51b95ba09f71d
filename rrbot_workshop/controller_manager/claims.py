"""Which interfaces a controller needs, and claiming them when it activates: :class:`InterfaceClaims`.

A configured controller says what it needs through ``command_interface_configuration()`` and
``state_interface_configuration()``. :meth:`InterfaceClaims.required` resolves that against the resource
manager's storage (``ALL``, ``INDIVIDUAL``, ``INDIVIDUAL_BEST_EFFORT``, ``NONE``);
:meth:`~InterfaceClaims.activate` claims those interfaces and runs ``on_activate``;
:meth:`~InterfaceClaims.deactivate` runs ``on_deactivate`` and gives them back. Both also make a chainable
controller's exported interfaces available or unavailable.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from rrbot_workshop.controller_interface.base import InterfaceConfigurationType
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.exceptions import InterfaceAlreadyClaimed, InterfaceNotFound
from rrbot_workshop.middleware.lifecycle import State

if TYPE_CHECKING:
    from rrbot_workshop.hardware_interface.resource_manager import ResourceManager

__all__ = ["InterfaceClaims"]

# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")


class InterfaceClaims:
    """The controllers' side of the resource manager's loans: what a controller requires, and claiming it.

    It keeps no state of its own: the claims live in the resource manager's storage (the holders) and in each
    controller (its loans); this object holds the rules that connect the two.

    Args:
        rm: The resource manager whose interfaces are resolved, claimed and released.
    """

    def __init__(self, rm: ResourceManager) -> None:
        self._rm = rm

    def required(self, spec: ControllerSpec, kind: str) -> list[str]:
        """Full names of the ``kind`` (``"command"`` or ``"state"``) interfaces a controller needs.

        Only a configured (inactive or active) controller needs any. ``ALL`` means every available
        interface except the controller's own exports; ``INDIVIDUAL_BEST_EFFORT`` keeps only the names that
        exist. A configuration method that raises is logged and counts as needing nothing.
        """
        rm = self._rm
        ctrl = spec.controller
        if spec.state not in (State.INACTIVE, State.ACTIVE):
            return []
        try:
            cfg = ctrl.command_interface_configuration() if kind == "command" else ctrl.state_interface_configuration()
        except Exception:  # noqa: BLE001
            _log.error("%s_interface_configuration of '%s' raised", kind, spec.name, exc_info=True)
            return []
        # learner code returning something else: needs nothing
        if not hasattr(cfg, "type") or not hasattr(cfg, "names"):
            _log.error("%s_interface_configuration of '%s' returned %r, not an InterfaceConfiguration", kind, spec.name,
                       cfg)
            return []
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
        """The command interfaces a controller needs (:meth:`required` of ``"command"``)."""
        return self.required(spec, "command")

    def state_interface_names(self, spec: ControllerSpec) -> list[str]:
        """The state interfaces a controller needs (:meth:`required` of ``"state"``)."""
        return self.required(spec, "state")

    def activate(self, spec: ControllerSpec) -> str | None:
        """Claim the interfaces an inactive controller needs and activate it.

        Returns:
            Why it failed (nothing is left claimed then), or None if the controller is active.
        """
        rm = self._rm
        name = spec.name
        ctrl = spec.controller
        commands, states = [], []
        try:
            for itf in self.required(spec, "command"):
                commands.append(rm.claim_command_interface(itf, holder=name))
            for itf in self.required(spec, "state"):
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

    def deactivate(self, spec: ControllerSpec) -> None:
        """Deactivate a controller, release its interfaces, take it out of chained mode and hide its exports.

        A controller whose ``on_deactivate`` does not succeed stays active, keeps its interfaces, and the
        failure is logged.
        """
        rm = self._rm
        name = spec.name
        ctrl = spec.controller
        if spec.state is State.ACTIVE:
            ctrl.deactivate()
        if spec.state is State.ACTIVE:
            _log.error("controller '%s' failed to deactivate (on_deactivate did not succeed); it stays active", name)
            return
        if spec.state is not State.INACTIVE:  # ERROR: on_error made it unconfigured (or finalized)
            _log.error("controller '%s' failed to deactivate (on_deactivate returned ERROR); after on_error it is "
                       "'%s', expected 'inactive'; configure it again to use it", name, spec.state.label)
        ctrl.release_interfaces()
        if ctrl.is_chainable():
            ctrl.set_chained_mode(False)  # type: ignore[attr-defined]
            rm.make_controller_reference_interfaces_available(name, False)
            rm.make_controller_exported_state_interfaces_available(name, False)
