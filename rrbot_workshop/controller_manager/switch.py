"""``switch_controllers``: ros2_control's ``switch_controller`` rules, step by step.

The steps follow ``controller_manager.cpp`` (Jazzy):

1. unknown names: STRICT rejects, BEST_EFFORT drops them per list (rejects if a list has no known name left);
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

This module holds the :class:`Switcher`, which the manager hands its controllers, chain graph, claims and resource
manager, and the :class:`SwitchRequest` it plans (steps 1-8); the chaining checks of steps 3-4 are the
:class:`~rrbot_workshop.controller_manager.switch_chaining.ChainingRules` the switcher builds and hands each request;
running and rolling back (steps 9-11) are in :mod:`~rrbot_workshop.controller_manager.switch_execution`, which takes
the planned request.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from rrbot_workshop.controller_manager.chains import ChainGraph
from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import ControllerSpec, SwitchResult
from rrbot_workshop.controller_manager.switch_chaining import ChainingRules
from rrbot_workshop.controller_manager.switch_execution import execute
from rrbot_workshop.exceptions import ControllerError, SwitchError
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.lifecycle import State

__all__ = ["STRICTNESS", "SwitchCall", "SwitchRequest", "Switcher", "normalize_strictness", "name_list"]

_log = logging.getLogger(__name__)

#: A switch asked as the manager's ``switch_controllers`` takes it (``activate=``, ``deactivate=``, ``strictness=``): how
#: the collaborators that must switch (``set_state``, the fallbacks of a failed controller) go back through the manager.
SwitchCall = Callable[..., SwitchResult]

#: Accepted strictness values (``controller_manager_msgs/SwitchController``: 1 BEST_EFFORT, 2 STRICT,
#: 3 AUTO and 4 FORCE_AUTO act as BEST_EFFORT in Jazzy).
STRICTNESS = {"best_effort": "best_effort", "strict": "strict", "auto": "best_effort", "force_auto": "best_effort",
              1: "best_effort", 2: "strict", 3: "best_effort", 4: "best_effort"}


def name_list(names: Any, what: str) -> list[str]:
    """``names`` as a list of controller names (any iterable of strings but a string itself).

    Raises:
        ControllerError: If it is not such an iterable (None, a number, a list holding a non-string).
    """
    if isinstance(names, str | bytes | Mapping) or not isinstance(names, Iterable):
        raise ControllerError(f"{what} takes a list of controller names (strings), got {names!r}")
    out = list(names)
    bad = [n for n in out if not isinstance(n, str)]
    if bad:
        raise ControllerError(f"{what} takes a list of controller names (strings); {bad[0]!r} is not a string")
    return out


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


class SwitchRequest:
    """One switch request: what is asked, what planning dropped, and which followers change chained mode.

    It is planned against what it is handed (the :class:`Switcher` builds it), and carries them on to the execution.

    Args:
        controllers: The loaded controllers by name.
        rules: The chaining checks over them.
        claims: Which interfaces each controller requires; claiming them.
        rm: The resource manager (interfaces, holders, the hardware's mode switch).
        activate: Controllers to activate.
        deactivate: Controllers to deactivate.
        strictness: ``"strict"`` or ``"best_effort"``.
    """

    def __init__(self, controllers: Mapping[str, ControllerSpec], rules: ChainingRules, claims: InterfaceClaims,
                 rm: ResourceManager, activate: list[str], deactivate: list[str], strictness: str) -> None:
        self.controllers = controllers
        self.rules = rules
        self.claims = claims
        self.rm = rm
        self.strict = strictness == "strict"
        self.activate = _dedupe(activate)
        self.deactivate = _dedupe(deactivate)
        self.skipped: list[str] = []
        self.to_chained: set[str] = set()
        self.from_chained: set[str] = set()
        #: Followers whose references an active controller claims after the switch: in chained mode then.
        self.must_chain: set[str] = set()

    def state(self, name: str) -> State:
        """Lifecycle state of loaded controller ``name``."""
        return self.controllers[name].state

    # ----------------------------------------------------------------- planning
    def plan(self, ask_hardware: bool = True) -> bool:
        """Steps 1-8. Returns False if there is nothing to do. Raises SwitchError on rejection.

        Args:
            ask_hardware: Ask the components in step 8 (their ``prepare_command_mode_switch``); a dry run checks the
                resource manager's rules only, since a driver may keep what it prepared for the ``perform`` that
                follows.
        """
        loaded = self.controllers
        if not self.activate and not self.deactivate:
            _log.info("switch_controllers: empty activate and deactivate lists, nothing to do")
            return False
        unknown = [n for n in [*self.activate, *self.deactivate] if n not in loaded]
        if unknown:
            lines = [f"controller '{n}' is not loaded (loaded: {sorted(loaded) or 'none'})" for n in _dedupe(unknown)]
            if self.strict:
                raise SwitchError(lines, controllers=unknown)
            self.skipped += lines
            kept_activate = [n for n in self.activate if n in loaded]
            kept_deactivate = [n for n in self.deactivate if n in loaded]
            # best effort forgives unknown names one list at a time: a list none of whose names exists fails the
            # whole request (the switch would otherwise do only the other half of what was asked)
            emptied = [what for what, asked, kept in (("activate", self.activate, kept_activate),
                                                       ("deactivate", self.deactivate, kept_deactivate))
                       if asked and not kept]
            if emptied:
                raise SwitchError(lines + [f"no controller of the {what} list exists; nothing was switched"
                                           for what in emptied], controllers=unknown)
            self.activate, self.deactivate = kept_activate, kept_deactivate

        # steps 3-4, repeated until no best-effort drop changes the picture
        while True:
            self.to_chained, self.from_chained = set(), set()
            for d in self.deactivate:  # step 2
                if self.state(d) is State.ACTIVE:
                    for follower, _itf, kind in self.rules.followers(d):
                        if kind == "reference" and loaded[follower].controller.is_in_chained_mode():
                            self.from_chained.add(follower)
            problems: dict[str, list[str]] = {}
            for a in self.activate:
                reasons, chained = self.rules.check_activation(a, self.activate, self.deactivate)
                if reasons:
                    problems[a] = reasons
                else:
                    self.to_chained |= chained
            if problems and not self.strict:
                # as Jazzy, best effort drops the activations that fail first, then checks the deactivations against
                # what is still activated (a follower whose new preceding controller was dropped can stop)
                self.skipped += [r for rs in problems.values() for r in rs]
                self.activate = [n for n in self.activate if n not in problems]
                continue
            for d in self.deactivate:
                reasons = self.rules.check_deactivation(d, self.activate, self.deactivate)
                if reasons:
                    problems.setdefault(d, []).extend(reasons)
            if not problems:
                break
            all_reasons = [r for rs in problems.values() for r in rs]
            if self.strict:
                raise SwitchError(all_reasons, controllers=list(problems))
            self.skipped += all_reasons
            self.activate = [n for n in self.activate if n not in problems]
            self.deactivate = [n for n in self.deactivate if n not in problems]
        # to_chained holds every follower whose references an activated controller claims; only those not yet in
        # chained mode change, and a follower that stays claimed (a chain head restarted) does not leave it.
        self.must_chain = set(self.to_chained)
        self.from_chained -= self.must_chain
        self.to_chained = {f for f in self.must_chain if not loaded[f].controller.is_in_chained_mode()}
        if not self.activate and not self.deactivate:  # step 5
            return False

        for f in sorted(self.to_chained | self.from_chained):  # step 6: restart to change chained mode
            if self.state(f) is State.ACTIVE and f not in self.deactivate:
                self.deactivate.append(f)
                self.activate.append(f)

        self.check_interfaces()  # step 7
        start, stop = self.hardware_lists()
        if not ask_hardware:  # the resource manager's rules only, the components are not asked
            refused = self.rm.check_command_mode_switch(start, stop)
            if refused:
                raise SwitchError([f"the hardware rejected the command mode switch: {refused}"])
            return True
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
        involved: list[str] = []  # controllers the reasons are about
        interfaces: list[str] = []  # interfaces the reasons are about
        requested: dict[str, str] = {}
        for a in self.activate:
            spec = self.controllers[a]
            for itf in self.claims.command_interface_names(spec):
                if not self.rm.command_interface_exists(itf):
                    reasons.append(
                        f"controller '{a}' needs command interface '{itf}', which does not exist "
                        f"(available: {self.rm.available_command_interfaces()})"
                    )
                    involved.append(a)
                    interfaces.append(itf)
                    continue
                if not ((self.rm.command_interface_is_available(itf) and itf not in lost) or itf in coming_cmd):
                    reasons.append(f"controller '{a}' needs command interface '{itf}', which is not available{self._why(itf)}")
                    involved.append(a)
                    interfaces.append(itf)
                holder = self.rm.command_interface_holder(itf)
                if holder is not None and holder not in self.deactivate:
                    reasons.append(
                        f"command interface '{itf}' is already claimed by '{holder or 'someone'}'; '{a}' cannot claim "
                        f"it unless '{holder}' is deactivated in the same switch"
                    )
                    involved += [a, holder] if holder else [a]
                    interfaces.append(itf)
                if itf in requested:
                    reasons.append(
                        f"controllers '{requested[itf]}' and '{a}' both claim command interface '{itf}'; "
                        "a command interface can have one owner only"
                    )
                    involved += [requested[itf], a]
                    interfaces.append(itf)
                requested.setdefault(itf, a)
            for itf in self.claims.state_interface_names(spec):
                if not self.rm.state_interface_exists(itf):
                    reasons.append(
                        f"controller '{a}' needs state interface '{itf}', which does not exist "
                        f"(available: {self.rm.available_state_interfaces()})"
                    )
                    involved.append(a)
                    interfaces.append(itf)
                elif not ((self.rm.state_interface_is_available(itf) and itf not in lost) or itf in coming_state):
                    reasons.append(f"controller '{a}' needs state interface '{itf}', which is not available{self._why(itf)}")
                    involved.append(a)
                    interfaces.append(itf)
        if reasons:
            raise SwitchError(reasons, controllers=involved, interfaces=interfaces)

    def _why(self, itf: str) -> str:
        hw = self.rm.hardware_of_interface(itf)
        if hw is not None:
            return f" (hardware component '{hw}' is '{self.rm.get_component(hw).get_lifecycle_state().label}')"
        ctrl = self.rm.controller_of_interface(itf)
        if ctrl is not None:
            return f" (controller '{ctrl}' that exports it is '{self.state(ctrl).label}')"
        return ""

    def hardware_lists(self) -> tuple[list[str], list[str]]:
        """Hardware command interfaces the activations claim and those the deactivations release."""
        start = [
            itf
            for a in self.activate
            for itf in self.claims.command_interface_names(self.controllers[a])
            if self.rm.hardware_of_interface(itf) is not None
        ]
        stop = [
            loan.name
            for d in self.deactivate
            for loan in self.controllers[d].controller.command_interfaces
            if self.rm.hardware_of_interface(loan.name) is not None
        ]
        return start, stop


class Switcher:
    """The manager's switch logic: plans requests against the live controllers and runs them.

    It owns the chaining rules and the manager's default strictness; the states it changes are the controllers' and the
    resource manager's.

    Args:
        controllers: The manager's loaded controllers by name (the live mapping).
        chains: The manager's chain graph (the update order).
        claims: Which interfaces each controller requires; claiming and releasing them.
        rm: The resource manager.
        default_strictness: What a switch asked with strictness None or 0 gets
            (``defaults.switch_controller.strictness``).
    """

    def __init__(self, controllers: Mapping[str, ControllerSpec], chains: ChainGraph, claims: InterfaceClaims,
                 rm: ResourceManager, default_strictness: str = "best_effort") -> None:
        self._controllers = controllers
        self._claims = claims
        self._rm = rm
        #: The chaining checks of steps 3-4, and the order of execution.
        self.rules = ChainingRules(controllers, chains, claims, rm)
        self.default_strictness = default_strictness

    def request(self, activate: Iterable[str], deactivate: Iterable[str], strictness: str) -> SwitchRequest:
        """A request to plan (``strictness`` is ``"strict"`` or ``"best_effort"``)."""
        return SwitchRequest(self._controllers, self.rules, self._claims, self._rm, list(activate), list(deactivate),
                             strictness)

    def switch(self, activate: Iterable[str], deactivate: Iterable[str], strictness: str | int | None) -> SwitchResult:
        """Plan and run one switch (see the module docstring); None or 0 take the default strictness.

        Raises:
            SwitchError: If the switch is rejected (nothing changed) or a requested activation or
                deactivation did not happen; ``reasons`` lists every problem.
            ControllerError: If ``strictness`` is unknown.
        """
        if strictness is None or strictness == 0:
            strictness = self.default_strictness
        asked = list(activate), list(deactivate)  # read before the strictness is checked, as the manager always did
        switch = self.request(*asked, normalize_strictness(strictness))
        planned = switch.plan()
        for line in switch.skipped:
            _log.warning("switch_controllers (best effort) skipped: %s", line)
        if not planned:
            return SwitchResult(skipped=switch.skipped)
        return execute(switch)
