"""What the diagrams draw: a snapshot of a controller manager's introspection answers.

The diagrams read only the public introspection calls (``list_controllers``,
``list_hardware_components``, ``list_hardware_interfaces``), as ``ros2 control view_controller_chains``
reads the services of the same names, and normalise their answers here so that drawing code does not
care whether a field is a lifecycle ``State`` or a string, a ``HardwareInterface`` or a bare name.
:func:`take_loaned_snapshot` makes the one exception the diagrams allow (an active controller's loans), and
:func:`controller_claims` says which command interfaces a controller holds or would hold.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from rrbot_workshop.exceptions import ControllerNotFound

__all__ = [
    "ControllerView",
    "ComponentView",
    "Snapshot",
    "take_snapshot",
    "take_loaned_snapshot",
    "controller_claims",
]


def _label(state: Any) -> str:
    label = getattr(state, "label", None)
    return str(label if label is not None else state).lower()


def _get(obj: Any, name: str, default: Any = None) -> Any:
    if isinstance(obj, dict):
        return obj.get(name, default)
    return getattr(obj, name, default)


@dataclass(frozen=True)
class ControllerView:
    """One loaded controller, as ``list_controllers`` reports it (exports without the name prefix)."""

    name: str
    state: str
    type: str
    required_command_interfaces: tuple[str, ...] = ()
    required_state_interfaces: tuple[str, ...] = ()
    claimed_interfaces: tuple[str, ...] = ()
    is_chainable: bool = False
    is_chained: bool = False
    reference_interfaces: tuple[str, ...] = ()
    exported_state_interfaces: tuple[str, ...] = ()


@dataclass(frozen=True)
class ComponentView:
    """One hardware component: its interfaces as ``(name, is_claimed)`` pairs."""

    name: str
    state: str
    type: str
    plugin_name: str
    command_interfaces: tuple[tuple[str, bool], ...] = ()
    state_interfaces: tuple[str, ...] = ()


@dataclass
class Snapshot:
    """Controllers and hardware components of one controller manager at one instant."""

    controllers: list[ControllerView] = field(default_factory=list)
    components: list[ComponentView] = field(default_factory=list)
    update_rate: int | None = None

    def reference_owners(self) -> dict[str, tuple[str, str]]:
        """Full reference interface name -> (exporting controller, exported name)."""
        return {f"{c.name}/{r}": (c.name, r) for c in self.controllers for r in c.reference_interfaces}

    def exported_state_owners(self) -> dict[str, tuple[str, str]]:
        """Full exported state interface name -> (exporting controller, exported name)."""
        return {f"{c.name}/{s}": (c.name, s) for c in self.controllers for s in c.exported_state_interfaces}

    def component_of(self) -> dict[str, str]:
        """Hardware interface name (command or state) -> component name."""
        owner: dict[str, str] = {}
        for comp in self.components:
            for name, _ in comp.command_interfaces:
                owner[name] = comp.name
            for name in comp.state_interfaces:
                owner[name] = comp.name
        return owner


def _names(items: Iterable[Any]) -> tuple[str, ...]:
    return tuple(str(_get(i, "name", i)) for i in items or ())


def controller_view(c: Any) -> ControllerView:
    """Normalise one ``ControllerState``-like object or dict."""
    return ControllerView(
        name=str(_get(c, "name")),
        state=_label(_get(c, "state", "unknown")),
        type=str(_get(c, "type", "")),
        required_command_interfaces=tuple(_get(c, "required_command_interfaces", ()) or ()),
        required_state_interfaces=tuple(_get(c, "required_state_interfaces", ()) or ()),
        claimed_interfaces=tuple(_get(c, "claimed_interfaces", ()) or ()),
        is_chainable=bool(_get(c, "is_chainable", False)),
        is_chained=bool(_get(c, "is_chained", False)),
        reference_interfaces=tuple(_get(c, "reference_interfaces", ()) or ()),
        exported_state_interfaces=tuple(_get(c, "exported_state_interfaces", ()) or ()),
    )


def component_view(c: Any, claimed: set[str] | None = None) -> ComponentView:
    """Normalise one ``HardwareComponentState``-like object or dict."""
    commands = []
    for item in _get(c, "command_interfaces", ()) or ():
        name = str(_get(item, "name", item))
        is_claimed = bool(_get(item, "is_claimed", False)) or (claimed is not None and name in claimed)
        commands.append((name, is_claimed))
    return ComponentView(
        name=str(_get(c, "name")),
        state=_label(_get(c, "state", "unknown")),
        type=str(_get(c, "type", "")),
        plugin_name=str(_get(c, "plugin_name", "")),
        command_interfaces=tuple(commands),
        state_interfaces=_names(_get(c, "state_interfaces", ())),
    )


def take_snapshot(
    source: Any = None,
    *,
    controllers: Sequence[Any] | None = None,
    components: Sequence[Any] | None = None,
) -> Snapshot:
    """Read a system's (or controller manager's) introspection answers, or normalise given ones.

    Args:
        source: A ``System`` or ``ControllerManager``; may be None when both lists are given.
        controllers: ``list_controllers()`` entries to use instead of asking ``source``.
        components: ``list_hardware_components()`` entries to use instead of asking ``source``.

    Raises:
        TypeError: If neither a source nor both lists are given.
    """
    cm = getattr(source, "controller_manager", source)
    if cm is None and (controllers is None or components is None):
        raise TypeError("pass a System or ControllerManager, or both controllers= and components=")
    raw_controllers = list(controllers if controllers is not None else cm.list_controllers())
    raw_components = list(components if components is not None else cm.list_hardware_components())
    claimed: set[str] = set()
    if cm is not None and hasattr(cm, "list_hardware_interfaces"):
        listing = cm.list_hardware_interfaces()
        for item in _get(listing, "command_interfaces", ()) or ():
            if _get(item, "is_claimed", False):
                claimed.add(str(_get(item, "name")))
    rate = None
    if cm is not None and hasattr(cm, "get_update_rate"):
        rate = int(cm.get_update_rate())
    return Snapshot(
        controllers=[controller_view(c) for c in raw_controllers],
        components=[component_view(c, claimed) for c in raw_components],
        update_rate=rate,
    )


def take_loaned_snapshot(
    source: Any = None,
    *,
    controllers: Sequence[Any] | None = None,
    components: Sequence[Any] | None = None,
) -> Snapshot:
    """:func:`take_snapshot`, with each active controller's state interfaces replaced by its loans.

    Only when the controllers come from a running ``source``: given ``list_controllers`` entries are
    drawn as they are (their ``required_state_interfaces`` is the best there is).

    Raises:
        TypeError: If neither a source nor both lists are given.
    """
    snap = take_snapshot(source, controllers=controllers, components=components)
    get_controller = getattr(getattr(source, "controller_manager", source), "get_controller", None)
    if controllers is not None or get_controller is None:
        return snap
    views = []
    for c in snap.controllers:
        if c.state == "active":
            try:
                loans = getattr(get_controller(c.name), "state_interfaces", None)
            except ControllerNotFound:  # unloaded between the two calls: keep what list_controllers said
                loans = None
            if loans is not None:
                c = replace(c, required_state_interfaces=tuple(str(loan.name) for loan in loans))
        views.append(c)
    return replace(snap, controllers=views)


def controller_claims(c: ControllerView) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """``(claimed, would_claim)``: the command interfaces an active controller holds, or those an inactive
    controller requires (and would claim once activated). Other states hold and require nothing."""
    if c.state == "active":
        return c.claimed_interfaces, ()
    if c.state == "inactive":
        return (), c.required_command_interfaces
    return (), ()
