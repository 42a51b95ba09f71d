"""What the controller manager's ``list_*`` services and ``view_controller_chains`` report.

Pure functions of what they are handed (the controllers, their update order, the claims, the resource manager):
they build the ``controller_manager_msgs``-shaped records of :mod:`rrbot_workshop.controller_manager.spec`, or
graphviz DOT text for the chain diagram.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping

from rrbot_workshop.controller_manager.claims import InterfaceClaims
from rrbot_workshop.controller_manager.spec import (
    ChainConnection,
    ControllerSpec,
    ControllerState,
    HardwareComponentState,
    HardwareInterface,
    HardwareInterfaces,
)
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import State

__all__ = [
    "list_controllers",
    "list_hardware_components",
    "list_hardware_interfaces",
    "list_controller_types",
    "view_controller_chains",
]

_log = logging.getLogger(__name__)


def _strip(prefix: str, names: list[str]) -> list[str]:
    return [n[len(prefix) + 1:] if n.startswith(prefix + "/") else n for n in names]


def list_controllers(controllers: Mapping[str, ControllerSpec], order: Iterable[str], claims: InterfaceClaims,
                     rm: ResourceManager) -> list[ControllerState]:
    """One :class:`ControllerState` per loaded controller, in update order (preceding controllers first).

    Args:
        controllers: The loaded controllers by name.
        order: Their names in update order.
        claims: Which interfaces each controller requires.
        rm: The resource manager (exported interfaces and who exports what).
    """
    out = []
    for name in order:
        spec = controllers[name]
        ctrl = spec.controller
        state = spec.state
        entry = ControllerState(
            name=name,
            state=state.label,
            type=spec.type,
            is_async=bool(ctrl.get_node().get_parameter("is_async", False)),
            update_rate=ctrl.get_update_rate(),
            is_chainable=ctrl.is_chainable(),
            is_chained=ctrl.is_in_chained_mode(),
        )
        if state is State.ACTIVE:
            entry.claimed_interfaces = [loan.name for loan in ctrl.command_interfaces]
        if state in (State.INACTIVE, State.ACTIVE):
            entry.required_command_interfaces = claims.command_interface_names(spec)
            entry.required_state_interfaces = claims.state_interface_names(spec)
            entry.reference_interfaces = _strip(name, rm.get_controller_reference_interface_names(name))
            entry.exported_state_interfaces = _strip(name, rm.get_controller_exported_state_interface_names(name))
            connections: dict[str, list[str]] = {}
            for itf in [*entry.required_command_interfaces, *entry.required_state_interfaces]:
                owner = rm.controller_of_interface(itf)
                if owner is not None and owner != name:
                    connections.setdefault(owner, []).append(itf)
            entry.chain_connections = [ChainConnection(n, refs) for n, refs in connections.items()]
        out.append(entry)
    return out


def list_hardware_components(rm: ResourceManager) -> list[HardwareComponentState]:
    """One :class:`HardwareComponentState` per hardware component of ``rm``, in load order."""
    out = []
    for name, info in rm.get_components_status().items():
        out.append(
            HardwareComponentState(
                name=name,
                type=info.type,
                is_async=info.is_async,
                rw_rate=info.rw_rate,
                plugin_name=info.plugin_name,
                state=info.state,
                command_interfaces=[
                    HardwareInterface(
                        n, rm.interface_data_type(n), rm.command_interface_is_available(n), rm.command_interface_is_claimed(n)
                    )
                    for n in info.command_interfaces
                ],
                state_interfaces=[
                    HardwareInterface(n, rm.interface_data_type(n), rm.state_interface_is_available(n), False)
                    for n in info.state_interfaces
                ],
            )
        )
    return out


def list_hardware_interfaces(rm: ResourceManager) -> HardwareInterfaces:
    """Every command interface (hardware and controller references) and state interface of ``rm``, sorted by name."""
    return HardwareInterfaces(
        command_interfaces=[
            HardwareInterface(
                n, rm.interface_data_type(n), rm.command_interface_is_available(n), rm.command_interface_is_claimed(n)
            )
            for n in rm.command_interface_keys()
        ],
        state_interfaces=[
            HardwareInterface(n, rm.interface_data_type(n), rm.state_interface_is_available(n), False)
            for n in rm.state_interface_keys()
        ],
    )


def list_controller_types() -> list[tuple[str, str]]:
    """``(type, base_class)`` for every controller plugin, sorted by type.

    The base class is ``controller_interface::ChainableControllerInterface`` or
    ``controller_interface::ControllerInterface``; a plugin whose module cannot be imported is listed
    with ``"(not importable)"``.
    """
    from rrbot_workshop.controller_interface.base import ChainableControllerInterface

    out = []
    for type_name in plugins.available("controller"):
        try:
            cls = plugins.resolve("controller", type_name)
        except Exception as exc:  # noqa: BLE001 - a broken plugin must not hide the others
            _log.debug("controller plugin '%s' cannot be imported: %s", type_name, exc)
            out.append((type_name, "(not importable)"))
            continue
        chainable = isinstance(cls, type) and issubclass(cls, ChainableControllerInterface)
        base = "ChainableControllerInterface" if chainable else "ControllerInterface"
        out.append((type_name, f"controller_interface::{base}"))
    return out


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _port(kind: str, name: str) -> str:
    return kind + "_" + "".join(c if c.isalnum() else "_" for c in name)


def _record(title: str, inputs: list[tuple[str, str]], outputs: list[tuple[str, str]]) -> str:
    def esc(t: str) -> str:
        return "".join("\\" + c if c in "{}|<>" else c for c in t)

    cols = ["{" + " | ".join(f"<{p}> {esc(t)}" for p, t in side) + "}" for side in (inputs, outputs) if side]
    return esc(title) + ("|{" + "|".join(cols) + "}" if cols else "")


def view_controller_chains(controllers: list[ControllerState], rm: ResourceManager) -> str:
    """Graphviz DOT text of controllers, their chain connections and the hardware interfaces they use.

    Every configured controller is a record node with its inputs (state and reference interfaces) on
    the left and its outputs (command and exported state interfaces) on the right; edges go from
    whoever writes or exports an interface to whoever reads or claims it, as ``ros2 control
    view_controller_chains`` draws it.

    Args:
        controllers: The records of :func:`list_controllers`.
        rm: The resource manager (who exports an interface).
    """
    lines = [
        "digraph controller_chains {",
        '  graph [rankdir="LR", ranksep="2"];',
        '  node [shape="record", style="rounded"];',
    ]
    hw_cmd: set[str] = set()
    hw_state: set[str] = set()
    edges: list[str] = []
    for entry in controllers:
        if entry.state not in ("inactive", "active"):
            continue
        name = entry.name
        refs = [f"{name}/{r}" for r in entry.reference_interfaces]
        exps = [f"{name}/{e}" for e in entry.exported_state_interfaces]
        inputs = [(_port("state", s), s) for s in sorted(entry.required_state_interfaces)]
        inputs += [(_port("ref", r), r + " (ref)") for r in sorted(refs)]
        outputs = [(_port("cmd", c), c) for c in sorted(entry.required_command_interfaces)]
        outputs += [(_port("exp", e), e + " (exp state)") for e in sorted(exps)]
        label = _record(f"{name} [{entry.state}]", inputs, outputs)
        lines.append(f"  {_quote(name)} [label={_quote(label)}];")
        for c in sorted(entry.required_command_interfaces):
            owner = rm.controller_of_interface(c)
            if owner is not None:
                target = f"{_quote(owner)}:{_port('ref', c)}"
            else:
                hw_cmd.add(c)
                target = f'"hw_command_interfaces":{_port("hw", c)}'
            edges.append(f"  {_quote(name)}:{_port('cmd', c)} -> {target};")
        for s in sorted(entry.required_state_interfaces):
            owner = rm.controller_of_interface(s)
            if owner is not None:
                source = f"{_quote(owner)}:{_port('exp', s)}"
            else:
                hw_state.add(s)
                source = f'"hw_state_interfaces":{_port("hw", s)}'
            edges.append(f"  {source} -> {_quote(name)}:{_port('state', s)};")
    if hw_state:
        label = _record("hw state_interfaces", [(_port("hw", s), s) for s in sorted(hw_state)], [])
        lines.append(f'  "hw_state_interfaces" [label={_quote(label)}];')
    if hw_cmd:
        label = _record("hw command_interfaces", [(_port("hw", c), c) for c in sorted(hw_cmd)], [])
        lines.append(f'  "hw_command_interfaces" [label={_quote(label)}];')
    lines += edges
    lines.append("}")
    return "\n".join(lines) + "\n"
