"""``switch_controllers``: ros2_control's ``switch_controller`` rules, step by step.

The steps follow ``controller_manager.cpp`` (Jazzy):

1. unknown names: STRICT rejects, BEST_EFFORT drops them (rejects only if nothing known is left);
2. followers of controllers being deactivated leave chained mode;
3. each activation is checked (configured, not already active, every controller whose reference or
   exported state interfaces it uses is active or activated in the same switch, fallbacks configured);
   followers whose references it claims enter chained mode;
4. each deactivation is checked (active; no preceding controller that needs it stays or becomes active);
5. nothing left: done;
6. active controllers whose chained mode changes are restarted;
7. interface availability, checked whatever the strictness: every command interface exists, is
   available, is not claimed by a controller that stays active, and is asked for by one controller only;
8. the hardware is asked (``prepare_command_mode_switch``);
9-10. the switch runs: hardware mode switch, deactivations, chained modes, activations (followers
   first); under STRICT a failed activation rolls back the others activated here;
11. the result is an error if a requested controller did not reach its state.

Every rejection before step 10 leaves all states as they were. The caller gets a :class:`SwitchError`
listing every reason, naming controllers and interfaces.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from .controller_spec import SwitchResult
from .controllers.base import InterfaceConfigurationType
from .exceptions import ControllerError, SwitchError
from .lifecycle import State

if TYPE_CHECKING:
    from .controller_manager import ControllerManager

__all__ = ["STRICTNESS", "normalize_strictness", "switch_controllers"]

_log = logging.getLogger(__name__)

#: Accepted strictness values (``controller_manager_msgs/SwitchController``: 1 BEST_EFFORT, 2 STRICT,
#: 3 AUTO and 4 FORCE_AUTO act as BEST_EFFORT in Jazzy).
STRICTNESS = {"best_effort": "best_effort", "strict": "strict", "auto": "best_effort", "force_auto": "best_effort",
              1: "best_effort", 2: "strict", 3: "best_effort", 4: "best_effort"}


def normalize_strictness(strictness: str | int) -> str:
    """``"strict"`` or ``"best_effort"`` from a name or the service's integer constant.

    Raises:
        ControllerError: If the value is not a known strictness.
    """
    key: Any = strictness.lower() if isinstance(strictness, str) else strictness
    if key == 0:  # 0 = the manager's default, which is best_effort in Jazzy (strict on master)
        return "best_effort"
    try:
        return STRICTNESS[key]
    except KeyError:
        raise ControllerError(
            f"unknown strictness {strictness!r} (valid: 'strict', 'best_effort', 'auto', 'force_auto', or 1-4)"
        ) from None


def _dedupe(names: Iterable[str]) -> list[str]:
    out: list[str] = []
    for n in names:
        if n not in out:
            out.append(n)
    return out


class _Switch:
    """One switch request being planned and executed."""

    def __init__(self, cm: ControllerManager, activate: list[str], deactivate: list[str], strictness: str) -> None:
        self.cm = cm
        self.rm = cm.resource_manager
        self.strict = strictness == "strict"
        self.activate = _dedupe(activate)
        self.deactivate = _dedupe(deactivate)
        self.skipped: list[str] = []
        self.to_chained: set[str] = set()
        self.from_chained: set[str] = set()
        self.was_chained: dict[str, bool] = {}

    def state(self, name: str) -> State:
        return self.cm.controllers[name].state

    # ----------------------------------------------------------------- relations
    def followers(self, name: str) -> list[tuple[str, str, str]]:
        """(follower, interface, "reference"|"state") for each exported interface ``name`` uses."""
        spec = self.cm.controllers[name]
        out = []
        for itf in self.cm.command_interface_names(spec):
            owner = self.rm.controller_of_interface(itf)
            if owner is not None and owner != name and itf in self.rm.get_controller_reference_interface_names(owner):
                out.append((owner, itf, "reference"))
        for itf in self.cm.state_interface_names(spec):
            owner = self.rm.controller_of_interface(itf)
            if owner is not None and owner != name and itf in self.rm.get_controller_exported_state_interface_names(owner):
                out.append((owner, itf, "state"))
        return out

    def preceding(self, name: str) -> list[tuple[str, str]]:
        """(controller, interface) for each configured controller that uses an interface ``name`` exports."""
        refs = set(self.rm.get_controller_reference_interface_names(name))
        exps = set(self.rm.get_controller_exported_state_interface_names(name))
        out = []
        for other, spec in self.cm.controllers.items():
            if other == name or spec.state not in (State.INACTIVE, State.ACTIVE):
                continue
            for itf in self.cm.command_interface_names(spec):
                if itf in refs:
                    out.append((other, itf))
            for itf in self.cm.state_interface_names(spec):
                if itf in exps:
                    out.append((other, itf))
        return out

    def dependency_order(self, names: Iterable[str]) -> list[str]:
        """``names`` ordered so that a controller comes after every controller whose interfaces it uses
        (references or exported states); ties keep the update order."""
        order = self.cm.update_order()
        todo = sorted(set(names), key=order.index)
        deps = {n: {f for f, _i, _k in self.followers(n) if f in todo and f != n} for n in todo}
        out: list[str] = []
        while todo:
            ready = next((n for n in todo if deps[n] <= set(out)), todo[0])
            out.append(ready)
            todo.remove(ready)
        return out

    # ----------------------------------------------------------------- step 3
    def check_activation(self, name: str) -> tuple[list[str], set[str]]:
        """Reasons ``name`` cannot be activated, and the followers it would put in chained mode."""
        state = self.state(name)
        if state is State.UNCONFIGURED:
            return [f"controller '{name}' is unconfigured; configure it before activating it"], set()
        if state is State.ACTIVE and name not in self.deactivate:
            return [f"controller '{name}' is already active"], set()
        if state not in (State.INACTIVE, State.ACTIVE):
            return [f"controller '{name}' is '{state.label}' and cannot be activated (it must be inactive)"], set()
        reasons: list[str] = []
        chained: set[str] = set()
        self._check_followers(name, reasons, chained, visited={name})
        spec = self.cm.controllers[name]
        for fb in spec.fallback_controllers:
            if fb not in self.cm.controllers:
                reasons.append(f"fallback controller '{fb}' of '{name}' is not loaded")
            elif self.state(fb) not in (State.INACTIVE, State.ACTIVE):
                reasons.append(f"fallback controller '{fb}' of '{name}' is '{self.state(fb).label}'; it must be configured")
        return reasons, chained

    def _check_followers(self, name: str, reasons: list[str], chained: set[str], visited: set[str]) -> None:
        uses_all = self.cm.controllers[name].controller.command_interface_configuration().type is InterfaceConfigurationType.ALL
        for follower, itf, kind in self.followers(name):
            fstate = self.state(follower)
            staying = fstate is State.ACTIVE and (follower not in self.deactivate or follower in self.activate)
            coming = fstate is State.INACTIVE and follower in self.activate
            leaving = fstate is State.ACTIVE and follower in self.deactivate and follower not in self.activate
            if not (staying or coming or (leaving and uses_all)):
                what = "being deactivated" if leaving else f"'{fstate.label}' and not activated in this switch"
                reasons.append(
                    f"controller '{name}' uses {kind} interface '{itf}' of controller '{follower}', which is {what}; "
                    f"activate '{follower}' first or in the same switch"
                )
                continue
            if kind == "reference" and not self.cm.controllers[follower].controller.is_in_chained_mode():
                chained.add(follower)
            if coming and follower not in visited:
                visited.add(follower)
                self._check_followers(follower, reasons, chained, visited)

    # ----------------------------------------------------------------- step 4
    def check_deactivation(self, name: str) -> list[str]:
        state = self.state(name)
        if state is not State.ACTIVE:
            return [f"controller '{name}' is not active (it is '{state.label}'); it cannot be deactivated"]
        reasons = []
        for other, itf in self.preceding(name):
            ostate = self.state(other)
            if ostate is State.INACTIVE and other in self.activate:
                reasons.append(
                    f"cannot deactivate '{name}': preceding controller '{other}' is being activated and uses its "
                    f"interface '{itf}'"
                )
            elif ostate is State.ACTIVE and other not in self.deactivate:
                reasons.append(
                    f"cannot deactivate '{name}': preceding controller '{other}' stays active and uses its "
                    f"interface '{itf}'; deactivate '{other}' too (or first)"
                )
        return reasons

    # ----------------------------------------------------------------- planning
    def plan(self) -> bool:
        """Steps 1-8. Returns False if there is nothing to do. Raises SwitchError on rejection."""
        loaded = self.cm.controllers
        if not self.activate and not self.deactivate:
            _log.info("switch_controllers: empty activate and deactivate lists, nothing to do")
            return False
        unknown = [n for n in [*self.activate, *self.deactivate] if n not in loaded]
        if unknown:
            lines = [f"controller '{n}' is not loaded (loaded: {sorted(loaded) or 'none'})" for n in _dedupe(unknown)]
            if self.strict:
                raise SwitchError(lines)
            self.skipped += lines
            self.activate = [n for n in self.activate if n in loaded]
            self.deactivate = [n for n in self.deactivate if n in loaded]
            if not self.activate and not self.deactivate:
                raise SwitchError(lines)

        # steps 3-4, repeated until no best-effort drop changes the picture
        while True:
            self.to_chained, self.from_chained = set(), set()
            for d in self.deactivate:  # step 2
                if self.state(d) is State.ACTIVE:
                    for follower, _itf, kind in self.followers(d):
                        if kind == "reference" and loaded[follower].controller.is_in_chained_mode():
                            self.from_chained.add(follower)
            problems: dict[str, list[str]] = {}
            for a in self.activate:
                reasons, chained = self.check_activation(a)
                if reasons:
                    problems[a] = reasons
                else:
                    self.to_chained |= chained
            for d in self.deactivate:
                reasons = self.check_deactivation(d)
                if reasons:
                    problems.setdefault(d, []).extend(reasons)
            if not problems:
                break
            all_reasons = [r for rs in problems.values() for r in rs]
            if self.strict:
                raise SwitchError(all_reasons)
            self.skipped += all_reasons
            self.activate = [n for n in self.activate if n not in problems]
            self.deactivate = [n for n in self.deactivate if n not in problems]
        self.from_chained -= self.to_chained
        if not self.activate and not self.deactivate:  # step 5
            return False

        for f in sorted(self.to_chained | self.from_chained):  # step 6: restart to change chained mode
            if self.state(f) is State.ACTIVE and f not in self.deactivate:
                self.deactivate.append(f)
                self.activate.append(f)

        self.check_interfaces()  # step 7
        start, stop = self.hardware_lists()
        if not self.rm.prepare_command_mode_switch(start, stop):  # step 8
            raise SwitchError([f"the hardware rejected the command mode switch: {self.rm.last_switch_error}"])
        return True

    def check_interfaces(self) -> None:
        """Step 7 (ERROR whatever the strictness)."""
        leaving = set(self.deactivate) - set(self.activate)
        lost: set[str] = set()
        for d in leaving:
            lost |= set(self.rm.get_controller_reference_interface_names(d))
            lost |= set(self.rm.get_controller_exported_state_interface_names(d))
        coming_cmd: set[str] = set()
        coming_state: set[str] = set()
        for a in self.activate:
            coming_cmd |= set(self.rm.get_controller_reference_interface_names(a))
            coming_state |= set(self.rm.get_controller_exported_state_interface_names(a))
        reasons: list[str] = []
        requested: dict[str, str] = {}
        for a in self.activate:
            spec = self.cm.controllers[a]
            for itf in self.cm.command_interface_names(spec):
                if not self.rm.command_interface_exists(itf):
                    reasons.append(
                        f"controller '{a}' needs command interface '{itf}', which does not exist "
                        f"(available: {self.rm.available_command_interfaces()})"
                    )
                    continue
                if not ((self.rm.command_interface_is_available(itf) and itf not in lost) or itf in coming_cmd):
                    reasons.append(f"controller '{a}' needs command interface '{itf}', which is not available{self._why(itf)}")
                holder = self.rm.command_interface_holder(itf)
                if holder is not None and holder not in self.deactivate:
                    reasons.append(
                        f"command interface '{itf}' is already claimed by '{holder or 'someone'}'; '{a}' cannot claim "
                        f"it unless '{holder}' is deactivated in the same switch"
                    )
                if itf in requested:
                    reasons.append(
                        f"controllers '{requested[itf]}' and '{a}' both claim command interface '{itf}'; "
                        "a command interface can have one owner only"
                    )
                requested.setdefault(itf, a)
            for itf in self.cm.state_interface_names(spec):
                if not self.rm.state_interface_exists(itf):
                    reasons.append(
                        f"controller '{a}' needs state interface '{itf}', which does not exist "
                        f"(available: {self.rm.available_state_interfaces()})"
                    )
                elif not ((self.rm.state_interface_is_available(itf) and itf not in lost) or itf in coming_state):
                    reasons.append(f"controller '{a}' needs state interface '{itf}', which is not available{self._why(itf)}")
        if reasons:
            raise SwitchError(reasons)

    def _why(self, itf: str) -> str:
        hw = self.rm.hardware_of_interface(itf)
        if hw is not None:
            return f" (hardware component '{hw}' is '{self.rm.get_component(hw).get_lifecycle_state().label}')"
        ctrl = self.rm.controller_of_interface(itf)
        if ctrl is not None:
            return f" (controller '{ctrl}' that exports it is '{self.state(ctrl).label}')"
        return ""

    def hardware_lists(self) -> tuple[list[str], list[str]]:
        start = [
            itf
            for a in self.activate
            for itf in self.cm.command_interface_names(self.cm.controllers[a])
            if self.rm.hardware_of_interface(itf) is not None
        ]
        stop = [
            loan.name
            for d in self.deactivate
            for loan in self.cm.controllers[d].controller.command_interfaces
            if self.rm.hardware_of_interface(loan.name) is not None
        ]
        return start, stop

    # ----------------------------------------------------------------- execution (steps 9-11)
    def execute(self) -> SwitchResult:
        start, stop = self.hardware_lists()
        if not self.rm.perform_command_mode_switch(start, stop):
            raise SwitchError([f"the hardware failed to perform the command mode switch: {self.rm.last_switch_error}"])
        result = SwitchResult(skipped=list(self.skipped))
        self.was_chained = {
            n: self.cm.controllers[n].controller.is_in_chained_mode()
            for n in {*self.deactivate, *self.to_chained, *self.from_chained}
            if self.cm.controllers[n].controller.is_chainable()
        }
        for name in reversed(self.dependency_order(self.deactivate)):  # users before the controllers they use
            self.cm._deactivate_now(name)
            result.deactivated.append(name)
        for name in sorted(self.to_chained):
            if not self.cm.controllers[name].controller.set_chained_mode(True):  # type: ignore[attr-defined]
                _log.error("controller '%s' refused to enter chained mode", name)
        for name in sorted(self.from_chained):
            if self.state(name) is not State.ACTIVE:
                self.cm.controllers[name].controller.set_chained_mode(False)  # type: ignore[attr-defined]
        failures: list[str] = []
        for name in self.dependency_order(self.activate):  # exporters before the controllers that use them
            reason = self.cm._activate_now(name)
            if reason:
                failures.append(reason)
                if self.strict:
                    break
            else:
                result.activated.append(name)
        if failures and self.strict:
            self.rollback(result)
            raise SwitchError(failures)
        still_active = [d for d in self.deactivate if d not in self.activate and self.state(d) is State.ACTIVE]
        failures += [f"controller '{d}' is still active after deactivation" for d in still_active]
        if failures:
            raise SwitchError(failures, partial=bool(result.activated or result.deactivated))
        return result

    def rollback(self, result: SwitchResult) -> None:
        """Strict mode: undo a switch whose activation failed while it ran.

        Jazzy only deactivates the controllers this switch activated; here the controllers it
        deactivated are also brought back, so a failed strict switch leaves the system as it was.
        """
        for name in reversed(self.dependency_order(result.activated)):
            self.cm._deactivate_now(name)
        for name, chained in self.was_chained.items():
            ctrl = self.cm.controllers[name].controller
            if ctrl.get_lifecycle_state() is not State.ACTIVE and ctrl.is_in_chained_mode() != chained:
                ctrl.set_chained_mode(chained)  # type: ignore[attr-defined]
        for name in self.dependency_order(result.deactivated):
            if self.state(name) is State.INACTIVE:
                reason = self.cm._activate_now(name)
                if reason:
                    _log.error("rollback could not re-activate '%s': %s", name, reason)
        start, stop = self.hardware_lists()
        self.rm.perform_command_mode_switch(stop, start)


def switch_controllers(
    cm: ControllerManager, activate: Iterable[str], deactivate: Iterable[str], strictness: str | int
) -> SwitchResult:
    """Plan and run one switch on ``cm`` (see the module docstring).

    Raises:
        SwitchError: If the switch is rejected (nothing changed) or a requested activation or
            deactivation did not happen; ``reasons`` lists every problem.
        ControllerError: If ``strictness`` is unknown.
    """
    switch = _Switch(cm, list(activate), list(deactivate), normalize_strictness(strictness))
    if not switch.plan():
        for line in switch.skipped:
            _log.warning("switch_controllers (best effort) skipped: %s", line)
        return SwitchResult(skipped=switch.skipped)
    for line in switch.skipped:
        _log.warning("switch_controllers (best effort) skipped: %s", line)
    return switch.execute()
