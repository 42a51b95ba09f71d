"""``explain_switch``: why a switch would (not) go through, asked without changing anything.

The answer runs the controller manager's own switch planning (a :class:`~rrbot_workshop.controller_manager.switch.
SwitchRequest` of its :class:`~rrbot_workshop.controller_manager.switch.Switcher`, steps 1-7 of ``switch_controllers``)
twice, once per strictness, on the system as it is, and reports what each would do. Nothing is activated, deactivated,
claimed or asked of the hardware: step 8 (the hardware's ``prepare_command_mode_switch``) only runs in a real switch,
because a driver may keep what it prepared for the ``perform`` call that follows;
:attr:`SwitchExplanation.hardware_not_asked` lists the interfaces it would be asked about.

Each reason comes with the data behind it (:class:`Evidence`): who holds a claimed interface, the state of the
hardware component behind an unavailable one, the state of a chain follower, the closest existing names for an
interface or controller that does not exist.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.controller_manager.switch import Switcher, name_list, normalize_strictness
from rrbot_workshop.exceptions import ControllerError, RRBotWorkshopError, SwitchError
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager

__all__ = ["Evidence", "Outcome", "SwitchExplanation", "explain_switch"]


@dataclass(frozen=True)
class Evidence:
    """One fact behind a reason: ``what`` it is about and what it says (``"interface joint1/position is claimed by
    'forward_position_controller'"``)."""

    what: str
    fact: str


@dataclass
class Outcome:
    """What one strictness would do with the request.

    Attributes:
        strictness: ``"strict"`` or ``"best_effort"``.
        accepted: The switch would go through (under best effort: the part not skipped).
        activate: Controllers that would be activated (restarts of chained followers included).
        deactivate: Controllers that would be deactivated.
        reasons: Why it would be rejected, or (best effort, accepted) what it would skip.
    """

    strictness: str
    accepted: bool
    activate: list[str] = field(default_factory=list)
    deactivate: list[str] = field(default_factory=list)
    reasons: list[str] = field(default_factory=list)


@dataclass
class SwitchExplanation:
    """The answer of :func:`explain_switch`.

    Attributes:
        activate: The activate list as asked.
        deactivate: The deactivate list as asked.
        strict: What a strict switch would do.
        best_effort: What a best-effort switch (Jazzy's default) would do.
        evidence: The facts behind the reasons, each once.
        hardware_not_asked: Hardware command interfaces the hardware would be asked to switch modes for
            (``prepare_command_mode_switch``), which a dry run does not do.
    """

    activate: list[str]
    deactivate: list[str]
    strict: Outcome
    best_effort: Outcome
    evidence: list[Evidence] = field(default_factory=list)
    hardware_not_asked: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True if a strict switch would go through: nothing blocks any part of the request."""
        return self.strict.accepted

    @property
    def reasons(self) -> list[str]:
        """Every reason either strictness gives, each once."""
        return list(dict.fromkeys([*self.strict.reasons, *self.best_effort.reasons]))

    def __str__(self) -> str:
        asked = (
            " and ".join(
                f"{verb} {', '.join(names)}"
                for verb, names in (("activate", self.activate), ("deactivate", self.deactivate))
                if names
            )
            or "nothing"
        )
        lines = [f"Switch: {asked}"]
        for out in (self.strict, self.best_effort):
            if out.accepted:
                done = (
                    " and ".join(
                        f"{verb} {', '.join(names)}"
                        for verb, names in (("activate", out.activate), ("deactivate", out.deactivate))
                        if names
                    )
                    or "change nothing"
                )
                lines.append(f"  {out.strictness:<11}  would go through: {done}")
                lines += [f"               skipping: {r}" for r in out.reasons]
            else:
                lines.append(f"  {out.strictness:<11}  would be rejected, nothing would change:")
                lines += [f"               - {r}" for r in out.reasons]
        if self.evidence:
            lines.append("  Facts:")
            lines += [f"    {e.what}: {e.fact}" for e in self.evidence]
        if self.hardware_not_asked and self.strict.accepted:
            lines.append(
                "  Not checked: the hardware's own answer (prepare_command_mode_switch) for "
                f"{', '.join(self.hardware_not_asked)}; only a real switch asks it."
            )
        return "\n".join(lines)

    def _repr_pretty_(self, printer: object, cycle: bool) -> None:  # IPython shows the text, not the dataclass
        printer.text(str(self))  # type: ignore[attr-defined]


def _closest(name: str, names: Iterable[str]) -> list[str]:
    return difflib.get_close_matches(name, list(names), n=3, cutoff=0.5)


def _outcome(
    switcher: Switcher, activate: list[str], deactivate: list[str], strictness: str, hardware: list[str]
) -> tuple[Outcome, list[str], list[str]]:
    """Plan the request; returns the outcome and the controllers and interfaces its reasons involve."""
    request = switcher.request(activate, deactivate, strictness)
    try:
        if request.plan(ask_hardware=False):
            start, _stop = request.hardware_lists()
            hardware += [i for i in start if i not in hardware]
    except SwitchError as err:
        return (
            Outcome(strictness, False, reasons=list(dict.fromkeys([*request.skipped, *err.reasons]))),
            err.controllers,
            err.interfaces,
        )
    return Outcome(strictness, True, list(request.activate), list(request.deactivate), list(request.skipped)), [], []


def _evidence(loaded: Mapping[str, ControllerSpec], rm: ResourceManager, asked: list[str], controllers: list[str],
              interfaces: list[str]) -> list[Evidence]:
    facts: list[Evidence] = []
    for name in dict.fromkeys([*asked, *controllers]):
        if name in loaded:
            facts.append(Evidence(f"controller '{name}'", f"is '{loaded[name].state.label}'"))
        else:
            close = _closest(name, loaded)
            facts.append(
                Evidence(f"controller '{name}'", "is not loaded" + (f"; did you mean {close}?" if close else ""))
            )
    for itf in interfaces:
        if not (rm.command_interface_exists(itf) or rm.state_interface_exists(itf)):
            known = [*rm.available_command_interfaces(), *rm.available_state_interfaces()]
            close = _closest(itf, dict.fromkeys(known))
            facts.append(Evidence(f"interface '{itf}'", "does not exist" + (f"; closest: {close}" if close else "")))
            continue
        holder = rm.command_interface_holder(itf) if rm.command_interface_exists(itf) else None
        if holder:
            facts.append(Evidence(f"interface '{itf}'", f"is claimed by '{holder}'"))
        hw = rm.hardware_of_interface(itf)
        if hw is not None:
            facts.append(
                Evidence(
                    f"hardware component '{hw}'",
                    f"is '{rm.get_component(hw).get_lifecycle_state().label}' (it provides '{itf}')",
                )
            )
        owner = rm.controller_of_interface(itf)
        if owner is not None and owner in loaded:
            facts.append(
                Evidence(f"controller '{owner}'", f"is '{loaded[owner].state.label}' (it exports '{itf}')")
            )
    return list(dict.fromkeys(facts))


def explain_switch(
    switcher: Switcher,
    controllers: Mapping[str, ControllerSpec],
    rm: ResourceManager,
    activate: Iterable[str] = (),
    deactivate: Iterable[str] = (),
    strictness: str | int | None = None,
) -> SwitchExplanation:
    """Would ``switch_controllers(activate, deactivate, strictness)`` go through, and if not, why?

    Args:
        switcher: The manager's switch logic, whose planning is run.
        controllers: The loaded controllers by name.
        rm: The resource manager (interfaces, holders, hardware components).
        activate: Controllers to activate, as for ``switch_controllers``.
        deactivate: Controllers to deactivate.
        strictness: Accepted for the same call shape; both strictnesses are always explained.

    Returns:
        What a strict and a best-effort switch would do, with the reasons and the facts behind them.

    Raises:
        ControllerError: If ``strictness`` is not valid, or a list is given as a single string.
    """
    if isinstance(activate, str) or isinstance(deactivate, str):
        raise ControllerError("activate and deactivate take lists of controller names, not a single string")
    activate, deactivate = name_list(activate, "activate"), name_list(deactivate, "deactivate")
    if strictness is not None:
        normalize_strictness(strictness)
    act, deact = list(activate), list(deactivate)
    hardware: list[str] = []
    involved: list[str] = []
    interfaces: list[str] = []
    outcomes = []
    for mode in ("strict", "best_effort"):
        try:
            outcome, ctrls, itfs = _outcome(switcher, act, deact, mode, hardware)
        except RRBotWorkshopError as exc:  # a controller whose interface configuration cannot be read, etc.
            outcome, ctrls, itfs = Outcome(mode, False, reasons=[str(exc)]), [], []
        outcomes.append(outcome)
        involved += ctrls
        interfaces += [i for i in itfs if i not in interfaces]
    strict, best = outcomes
    # controllers a reason names (a chain follower, a preceding controller), leaving out "(loaded: [...])" lists
    said = [re.sub(r"\(loaded: [^)]*\)", "", r) for r in [*strict.reasons, *best.reasons]]
    named = [n for n in controllers if any(f"'{n}'" in r for r in said)]
    components = [n for n in rm.component_names() if any(f"component '{n}'" in r for r in said)]
    evidence = _evidence(controllers, rm, [*act, *deact], [*involved, *named], interfaces)
    evidence += [
        Evidence(
            f"hardware component '{n}'", f"is '{rm.get_component(n).get_lifecycle_state().label}'"
        )
        for n in components
    ]
    return SwitchExplanation(act, deact, strict, best, list(dict.fromkeys(evidence)), hardware)
