"""The chaining checks of a controller switch (steps 3 and 4 of :mod:`rrbot_workshop.controller_manager.switch`).

A controller *follows* another when the other uses its exported interfaces: references it
claims, or exported states it reads. A follower must be active, or activated in the same switch,
while a controller that uses it is active; it is in chained mode while its references are claimed.
:class:`ChainingRules` reads the controllers, the interfaces they require and who exports them, and the
``activate`` / ``deactivate`` lists of a request; it changes nothing.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from rrbot_workshop.controller_interface.base import InterfaceConfigurationType
from rrbot_workshop.controller_manager.chains import ChainGraph
from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.lifecycle import State

__all__ = ["ChainingRules"]


class ChainingRules:
    """Who follows whom among the loaded controllers, and the chaining checks of steps 3 and 4.

    Args:
        controllers: The manager's loaded controllers by name (the live mapping).
        chains: The manager's chain graph (the update order, for ties).
        claims: Which interfaces each controller requires.
        rm: The resource manager that knows which controller exports which interface.
    """

    def __init__(self, controllers: Mapping[str, ControllerSpec], chains: ChainGraph, claims: InterfaceClaims,
                 rm: ResourceManager) -> None:
        self._controllers = controllers
        self._chains = chains
        self._claims = claims
        self._rm = rm

    def _names_for_chaining(self, spec: ControllerSpec, kind: str) -> list[str]:
        """The interfaces a controller *names*: chain links come from these only.

        As in Jazzy (``get_following_controller_names`` reads ``interface_configuration().names``), a controller
        configured for ``ALL`` interfaces, such as the joint state broadcaster, names none, so it never precedes a
        chainable controller even when it reads that controller's exported states.
        """
        controller = spec.controller
        try:
            cfg = (controller.command_interface_configuration() if kind == "command"
                   else controller.state_interface_configuration())
        except Exception:  # noqa: BLE001 - reported where the interfaces are resolved
            return []
        if cfg.type in (InterfaceConfigurationType.ALL, InterfaceConfigurationType.NONE):
            return []
        return self._claims.required(spec, kind)

    def followers(self, name: str) -> list[tuple[str, str, str]]:
        """``(follower, interface, "reference"|"state")`` for each exported interface controller ``name`` uses."""
        rm = self._rm
        spec = self._controllers[name]
        out = []
        for itf in self._names_for_chaining(spec, "command"):
            owner = rm.controller_of_interface(itf)
            if owner is not None and owner != name and itf in rm.get_controller_reference_interface_names(owner):
                out.append((owner, itf, "reference"))
        for itf in self._names_for_chaining(spec, "state"):
            owner = rm.controller_of_interface(itf)
            if owner is not None and owner != name and itf in rm.get_controller_exported_state_interface_names(owner):
                out.append((owner, itf, "state"))
        return out

    def preceding(self, name: str) -> list[tuple[str, str]]:
        """``(controller, interface)`` for each configured controller that uses an interface ``name`` exports."""
        rm = self._rm
        refs = set(rm.get_controller_reference_interface_names(name))
        exps = set(rm.get_controller_exported_state_interface_names(name))
        out = []
        for other, spec in self._controllers.items():
            if other == name or spec.state not in (State.INACTIVE, State.ACTIVE):
                continue
            for itf in self._names_for_chaining(spec, "command"):
                if itf in refs:
                    out.append((other, itf))
            for itf in self._names_for_chaining(spec, "state"):
                if itf in exps:
                    out.append((other, itf))
        return out

    def dependency_order(self, names: Iterable[str]) -> list[str]:
        """``names`` ordered so that a controller comes after every controller whose interfaces it uses
        (references or exported states); ties keep the update order."""
        order = list(self._chains.order)
        todo = sorted(set(names), key=order.index)
        deps = {n: {f for f, _i, _k in self.followers(n) if f in todo and f != n} for n in todo}
        out: list[str] = []
        while todo:
            ready = next((n for n in todo if deps[n] <= set(out)), todo[0])
            out.append(ready)
            todo.remove(ready)
        return out

    def check_activation(self, name: str, activate: list[str], deactivate: list[str]) -> tuple[list[str], set[str]]:
        """Step 3 for one controller of ``activate``.

        Returns:
            Why ``name`` cannot be activated (empty if it can), and the followers it would put in chained mode.
        """
        controllers = self._controllers
        state = controllers[name].state
        if state is State.UNCONFIGURED:
            return [f"controller '{name}' is unconfigured; configure it before activating it"], set()
        if state is State.ACTIVE and name not in deactivate:
            return [f"controller '{name}' is already active"], set()
        if state not in (State.INACTIVE, State.ACTIVE):
            return [f"controller '{name}' is '{state.label}' and cannot be activated (it must be inactive)"], set()
        reasons: list[str] = []
        chained: set[str] = set()
        self._check_followers(name, activate, deactivate, reasons, chained, visited={name})
        for fb in controllers[name].fallback_controllers:
            if fb not in controllers:
                reasons.append(f"fallback controller '{fb}' of '{name}' is not loaded")
            elif (fb_state := controllers[fb].state) not in (State.INACTIVE, State.ACTIVE):
                reasons.append(f"fallback controller '{fb}' of '{name}' is '{fb_state.label}'; it must be configured")
        return reasons, chained

    def _check_followers(
        self,
        name: str,
        activate: list[str],
        deactivate: list[str],
        reasons: list[str],
        chained: set[str],
        visited: set[str],
    ) -> None:
        controllers = self._controllers
        uses_all = controllers[name].controller.command_interface_configuration().type is InterfaceConfigurationType.ALL
        for follower, itf, kind in self.followers(name):
            fstate = controllers[follower].state
            staying = fstate is State.ACTIVE and (follower not in deactivate or follower in activate)
            coming = fstate is State.INACTIVE and follower in activate
            leaving = fstate is State.ACTIVE and follower in deactivate and follower not in activate
            if not (staying or coming or (leaving and uses_all)):
                what = "being deactivated" if leaving else f"'{fstate.label}' and not activated in this switch"
                reasons.append(
                    f"controller '{name}' uses {kind} interface '{itf}' of controller '{follower}', which is {what}; "
                    f"activate '{follower}' first or in the same switch"
                )
                continue
            if kind == "reference":  # it must be in chained mode after the switch (it may be already)
                chained.add(follower)
            if coming and follower not in visited:
                visited.add(follower)
                self._check_followers(follower, activate, deactivate, reasons, chained, visited)

    def check_deactivation(self, name: str, activate: list[str], deactivate: list[str]) -> list[str]:
        """Step 4 for one controller of ``deactivate``: why it cannot be deactivated (empty if it can)."""
        controllers = self._controllers
        state = controllers[name].state
        if state is not State.ACTIVE:
            return [f"controller '{name}' is not active (it is '{state.label}'); it cannot be deactivated"]
        reasons = []
        for other, itf in self.preceding(name):
            ostate = controllers[other].state
            if ostate is State.INACTIVE and other in activate:
                reasons.append(
                    f"cannot deactivate '{name}': preceding controller '{other}' is being activated and uses its "
                    f"interface '{itf}'"
                )
            elif ostate is State.ACTIVE and other not in deactivate:
                reasons.append(
                    f"cannot deactivate '{name}': preceding controller '{other}' stays active and uses its "
                    f"interface '{itf}'; deactivate '{other}' too (or first)"
                )
        return reasons
