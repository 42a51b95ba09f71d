"""Chain order: which controllers update before which, and which are chained together.

:class:`ChainGraph` owns one manager's update order and works it out.

A controller that claims another's reference interfaces updates before it (it writes the
references the other reads in the same cycle); a controller that reads another's exported state
interfaces updates after it, unless it also claims that controller's references (a diff drive that
commands wheel PIDs and reads the velocities they export): the claim wins and the state read is the
previous cycle's. Controllers that use each other's interfaces, in either direction, form a chain
group, which fails and stops together. Only a true loop (A claims B's references and B claims A's,
possibly through others; or states read round in a circle) is reported as a chaining loop.
"""

from __future__ import annotations

import heapq
import logging
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING

from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.middleware.lifecycle import State

if TYPE_CHECKING:
    from rrbot_workshop.hardware_interface.resource_manager import ResourceManager

__all__ = ["ChainGraph"]

# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")


class ChainGraph:
    """The update order of one controller manager's controllers, and the chains between them.

    It owns the order (preceding controllers first, ties in load order) and is told when it changes: a controller
    loaded or unloaded, or configured or cleaned up (which adds or removes exported interfaces, so the order is worked
    out again). :attr:`version` counts the changes, for the plans built on the order (the controller loop's).

    Args:
        rm: The resource manager that knows which controller exports which interface.
        claims: Which interfaces each controller uses.
        controllers: The manager's loaded controllers by name (the live mapping).
    """

    def __init__(self, rm: ResourceManager, claims: InterfaceClaims, controllers: Mapping[str, ControllerSpec]) -> None:
        self._rm = rm
        self._claims = claims
        self._controllers = controllers
        self._order: list[str] = []
        #: Number of changes of the order so far.
        self.version = 0

    @property
    def order(self) -> list[str]:
        """Controller names in update order (the graph's own list: read it, do not change it)."""
        return self._order

    def loaded(self, name: str) -> None:
        """A controller was loaded: it updates last until its interfaces are known."""
        self._order.append(name)
        self.version += 1

    def unloaded(self, name: str) -> None:
        """A controller was unloaded."""
        self._order.remove(name)
        self.version += 1

    def rebuild(self) -> None:
        """Work the order out again (after a configure or a cleanup)."""
        self._order = self._work_out_order()
        self.version += 1

    def _work_out_order(self) -> list[str]:
        """Controller names in topological order, preceding controllers first; ties keep load order.

        Every loaded controller is in it; the members of a chaining loop (logged) keep their load order.
        """
        rm, required, controllers = self._rm, self._claims.required, self._controllers
        names = list(controllers)
        if not rm.has_controller_exports():  # nothing chains: load order, without asking every controller
            return names
        before: dict[str, set[str]] = {n: set() for n in names}  # n -> controllers that must run before n
        claims: set[tuple[str, str]] = set()  # (preceding, following): the first claims the second's references
        for name in names:
            for itf in required(controllers[name], "command"):
                owner = rm.controller_of_interface(itf)
                if owner in before and owner != name:
                    before[owner].add(name)  # name claims owner's reference: name runs first
                    claims.add((name, owner))
        for name in names:
            for itf in required(controllers[name], "state"):
                owner = rm.controller_of_interface(itf)
                # name reads owner's exported state: owner runs first, unless name also claims owner's references.
                # Then the claim sets the order and the state is the one owner exported last cycle (a diff drive
                # over wheel PIDs reads their velocities: Jazzy's chain puts the diff drive first).
                if owner in before and owner != name and (name, owner) not in claims:
                    before[name].add(owner)
        # Kahn's algorithm; of the controllers that may run next, the one loaded first (a heap on the load index)
        index = {n: k for k, n in enumerate(names)}
        waiting = {n: len(before[n]) for n in names}
        after: dict[str, list[str]] = {n: [] for n in names}
        for n in names:
            for first in before[n]:
                after[first].append(n)
        ready = [index[n] for n in names if not waiting[n]]
        heapq.heapify(ready)
        order: list[str] = []
        while ready:
            name = names[heapq.heappop(ready)]
            order.append(name)
            for n in after[name]:
                waiting[n] -= 1
                if not waiting[n]:
                    heapq.heappush(ready, index[n])
        if len(order) < len(names):
            placed = set(order)
            remaining = [n for n in names if n not in placed]
            _log.error("controllers %s form a chaining loop; keeping their load order", remaining)
            order += remaining
        return order

    def group(self, names: Iterable[str]) -> list[str]:
        """``names`` and every active controller chained to them (either direction), in update order."""
        rm, required, controllers, order = self._rm, self._claims.required, self._controllers, self._order
        active = [n for n in order if controllers[n].state is State.ACTIVE]
        links: dict[str, set[str]] = {n: set() for n in active}
        for n in active:
            spec = controllers[n]
            for itf in [*required(spec, "command"), *required(spec, "state")]:
                owner = rm.controller_of_interface(itf)
                if owner in links and owner != n:
                    links[n].add(owner)
                    links[owner].add(n)
        group = set(names)
        todo = [n for n in group if n in links]
        while todo:
            for other in links[todo.pop()]:
                if other not in group:
                    group.add(other)
                    todo.append(other)
        return [n for n in order if n in group]
