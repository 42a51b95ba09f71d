"""Running a planned controller switch, and undoing a strict one that fails (steps 9-11 of
:mod:`rrbot_workshop.controller_manager.switch`).

The hardware switches command modes first; then controllers are deactivated (users before the
controllers they use), followers change chained mode, and controllers are activated (exporters
before their users). Under STRICT the first failed activation stops the switch and everything it
did is undone.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Protocol

from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import ControllerSpec, SwitchResult
from rrbot_workshop.controller_manager.switch_chaining import ChainingRules
from rrbot_workshop.exceptions import SwitchError
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.lifecycle import State


class SwitchRequest(Protocol):
    """A planned switch, as :class:`rrbot_workshop.controller_manager.switch.SwitchRequest` hands it over."""

    controllers: Mapping[str, ControllerSpec]
    rules: ChainingRules
    claims: InterfaceClaims
    rm: ResourceManager
    strict: bool
    activate: list[str]
    deactivate: list[str]
    skipped: list[str]
    from_chained: set[str]
    must_chain: set[str]

    def hardware_lists(self) -> tuple[list[str], list[str]]: ...

__all__ = ["execute", "rollback"]

# The switch's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.switch")


def execute(request: SwitchRequest) -> SwitchResult:
    """Run a request that passed planning (steps 9-11).

    Raises:
        SwitchError: If the hardware fails to switch modes, an activation fails (strict: after the
            rollback), or a controller is still active after its deactivation; ``partial`` tells
            whether something changed.
    """
    controllers, rules, claims, rm = request.controllers, request.rules, request.claims, request.rm
    start, stop = request.hardware_lists()
    if not rm.perform_command_mode_switch(start, stop):
        raise SwitchError([f"the hardware failed to perform the command mode switch: {rm.last_switch_error}"])
    result = SwitchResult(skipped=list(request.skipped))
    was_chained = {
        n: controllers[n].controller.is_in_chained_mode()
        for n in {*request.deactivate, *request.must_chain, *request.from_chained}
        if controllers[n].controller.is_chainable()
    }
    for name in reversed(rules.dependency_order(request.deactivate)):  # users before the controllers they use
        claims.deactivate(controllers[name])
        result.deactivated.append(name)
    for name in sorted(request.must_chain):  # including followers restarted here (deactivation unchains them)
        ctrl = controllers[name].controller
        if controllers[name].state is not State.ACTIVE and not ctrl.is_in_chained_mode():
            if not ctrl.set_chained_mode(True):  # type: ignore[attr-defined]
                _log.error("controller '%s' refused to enter chained mode", name)
    for name in sorted(request.from_chained):
        if controllers[name].state is not State.ACTIVE:
            controllers[name].controller.set_chained_mode(False)  # type: ignore[attr-defined]
    failures: list[str] = []
    failed: list[str] = []
    changed_on_failure: list[str] = []  # a failed activation runs on_error: the controller leaves 'inactive'
    for name in rules.dependency_order(request.activate):  # exporters before the controllers that use them
        reason = claims.activate(controllers[name])
        if reason:
            failures.append(reason)
            failed.append(name)
            if controllers[name].state is not State.INACTIVE:
                changed_on_failure.append(name)
                failures.append(f"controller '{name}' is now '{controllers[name].state.label}' (on_error ran after its "
                                "failed activation); configure it again to use it")
            if request.strict:
                break
        else:
            result.activated.append(name)
    if failures and request.strict:
        rollback(request, result, was_chained)
        raise SwitchError(failures, partial=bool(changed_on_failure), controllers=failed)
    still_active = [d for d in request.deactivate if d not in request.activate and controllers[d].state is State.ACTIVE]
    failures += [f"controller '{d}' is still active after deactivation" for d in still_active]
    if failures:
        raise SwitchError(failures, partial=bool(result.activated or result.deactivated or changed_on_failure),
                          controllers=[*failed, *still_active])
    return result


def rollback(request: SwitchRequest, result: SwitchResult, was_chained: dict[str, bool]) -> None:
    """Strict mode: undo a switch whose activation failed while it ran.

    Jazzy only deactivates the controllers this switch activated; here the controllers it
    deactivated are also brought back, so a failed strict switch leaves the system as it was.

    Args:
        request: The switch being undone.
        result: What it did so far.
        was_chained: Chained mode, before the switch, of the chainable controllers it touched.
    """
    controllers, rules, claims, rm = request.controllers, request.rules, request.claims, request.rm
    for name in reversed(rules.dependency_order(result.activated)):
        claims.deactivate(controllers[name])
    for name, chained in was_chained.items():
        ctrl = controllers[name].controller
        if ctrl.get_lifecycle_state() is not State.ACTIVE and ctrl.is_in_chained_mode() != chained:
            ctrl.set_chained_mode(chained)  # type: ignore[attr-defined]
    for name in rules.dependency_order(result.deactivated):
        if controllers[name].state is State.INACTIVE:
            reason = claims.activate(controllers[name])
            if reason:
                _log.error("rollback could not re-activate '%s': %s", name, reason)
    start, stop = request.hardware_lists()
    rm.perform_command_mode_switch(stop, start)
