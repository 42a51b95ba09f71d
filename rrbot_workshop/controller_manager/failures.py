"""The slow path of a control cycle: what a failed controller or failed hardware stops, and what takes over.

As with ros2_control's ``handle_exceptions``, a controller whose ``update`` raised or did not return OK (the
:class:`~rrbot_workshop.controller_manager.loop.ControllerLoop` hands them over) is deactivated with its chain group,
and its ``fallback_controllers`` are activated in one strict switch. Hardware that fails in ``read`` or ``write``
deactivates the active controllers holding its interfaces, with their chain groups; hardware that deactivates itself
from ``write`` stops only the controllers commanding it.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

from rrbot_workshop.controller_manager.activity import ActivitySink
from rrbot_workshop.controller_manager.chains import ChainGraph
from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.controller_manager.switch import SwitchCall
from rrbot_workshop.exceptions import ControllerError, SwitchError
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.lifecycle import State

__all__ = ["FailurePath"]

# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")


class FailurePath:
    """Takes down what a failure in the cycle concerns, and brings up the fallbacks.

    Args:
        controllers: The manager's loaded controllers by name (the live mapping).
        chains: The manager's chain graph (the update order and the chain groups).
        claims: Releases what a deactivated controller held.
        rm: The resource manager (which hardware an interface belongs to, and its states).
        switch: The manager's ``switch_controllers``, for the fallbacks.
        activity: Told once the failure of a controller has been handled.
    """

    def __init__(self, controllers: Mapping[str, ControllerSpec], chains: ChainGraph, claims: InterfaceClaims,
                 rm: ResourceManager, switch: SwitchCall, activity: ActivitySink) -> None:
        self._controllers = controllers
        self._chains = chains
        self._claims = claims
        self._rm = rm
        self._switch = switch
        self._activity = activity

    def controllers_failed(self, failed: list[str]) -> None:
        """Deactivate ``failed`` controllers with their chain group, then activate their fallbacks (strict)."""
        controllers = self._controllers
        group = self._chains.group(failed)
        _log.error("controller(s) %s failed in update; deactivating %s", failed, group)
        for name in group:
            self._claims.deactivate(controllers[name])
        fallbacks = [fb for n in failed for fb in controllers[n].fallback_controllers]
        fallbacks = [fb for i, fb in enumerate(fallbacks) if fb not in fallbacks[:i]]
        if fallbacks:
            try:
                self._switch(activate=fallbacks, strictness="strict")
                _log.warning("activated fallback controllers %s", fallbacks)
            except (SwitchError, ControllerError) as exc:
                _log.error("could not activate fallback controllers %s: %s", fallbacks, exc)
        self._activity.check()

    def hardware_failed(self, hardware: list[str], where: str, commanders_only: bool = False) -> None:
        """Deactivate the active controllers holding interfaces of failed ``hardware``, with their chain groups.

        Args:
            hardware: Names of the hardware components that failed.
            where: ``"read"`` or ``"write"``, for the log.
            commanders_only: Only controllers that command the hardware (a component that deactivated itself from
                ``write`` is INACTIVE: its states stay readable, so broadcasters keep running).
        """
        rm, controllers = self._rm, self._controllers
        users = []
        for name in list(self._chains.order):
            ctrl = controllers[name].controller
            if ctrl.get_lifecycle_state() is not State.ACTIVE:
                continue
            loans = [*ctrl.command_interfaces] if commanders_only else [*ctrl.command_interfaces, *ctrl.state_interfaces]
            if any(rm.hardware_of_interface(loan.name) in hardware for loan in loans):
                users.append(name)
        group = self._chains.group(users)
        if group:
            _log.error("hardware %s failed in %s; deactivating controllers %s", hardware, where, group)
        for name in group:
            self._claims.deactivate(controllers[name])

    def write_failed(self, hardware: list[str], deactivate_on_self_deactivate: bool) -> None:
        """Hardware that failed in ``write``: a component left INACTIVE deactivated itself (DEACTIVATE) and stops only
        its commanders, if ``deactivate_on_self_deactivate``; one that failed went through ``error()``."""
        rm = self._rm
        quiet = [h for h in hardware if rm.get_component(h).get_lifecycle_state() is State.INACTIVE]
        failed = [h for h in hardware if h not in quiet]
        if failed:
            self.hardware_failed(failed, "write")
        if quiet and deactivate_on_self_deactivate:
            self.hardware_failed(quiet, "write", commanders_only=True)
