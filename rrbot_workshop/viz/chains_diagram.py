"""The controller chains diagram: what ``ros2 control view_controller_chains`` draws, as SVG.

Hardware state interfaces stand on the left, controllers in columns by chain rank (preceding controllers
first, see :func:`chain_ranks`), hardware command interfaces on the right. Every interface a controller
reads or writes is a row of its box, and an arrow joins it to where it comes from or goes to: the hardware,
or another controller's reference or exported state interface.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rrbot_workshop.viz.diagram_boxes import COMMAND_EDGE, REQUIRED_EDGE, STATE_EDGE, Box, draw_box, draw_legend
from rrbot_workshop.viz.snapshot import ControllerView, Snapshot, controller_claims, take_loaned_snapshot
from rrbot_workshop.viz.svg import SvgCanvas, SvgDiagram

__all__ = ["controller_chains", "chain_ranks"]

_GAP_X = 130.0
_GAP_Y = 22.0


def chain_ranks(snapshot: Snapshot) -> dict[str, int]:
    """Column of each controller: 0 for controllers nothing precedes, else one more than their predecessors.

    A controller that claims another's reference interface precedes it; a controller that reads another's
    exported state interface follows it (the update order of ros2_control's chained controllers).
    """
    refs, exps = snapshot.reference_owners(), snapshot.exported_state_owners()
    before: dict[str, set[str]] = {c.name: set() for c in snapshot.controllers}
    for c in snapshot.controllers:
        for i in c.required_command_interfaces:
            if i in refs and refs[i][0] != c.name:
                before[refs[i][0]].add(c.name)
        for i in c.required_state_interfaces:
            if i in exps and exps[i][0] != c.name:
                before[c.name].add(exps[i][0])
    rank = {name: 0 for name in before}
    for _ in range(len(rank)):  # longest path; a cycle (invalid anyway) stops after n rounds
        changed = False
        for name, preds in before.items():
            best = max((rank[p] + 1 for p in preds), default=0)
            if best > rank[name]:
                rank[name], changed = best, True
        if not changed:
            break
    return rank


def _controller_rows(c: ControllerView, refs: dict[str, Any], exps: dict[str, Any]) -> list[tuple[str, str, str]]:
    rows: list[tuple[str, str, str]] = []
    for i in sorted(c.required_state_interfaces):
        rows.append((f"in:{i}", f"{i} ({'exp state' if i in exps else 'state'})", "in"))
    for r in sorted(c.reference_interfaces):
        rows.append((f"ref:{r}", f"{r} (ref)", "in"))
    for i in sorted({*c.required_command_interfaces, *c.claimed_interfaces}):
        rows.append((f"out:{i}", f"{i} (cmd)", "out"))
    for e in sorted(c.exported_state_interfaces):
        rows.append((f"exp:{e}", f"{e} (exp state)", "out"))
    return rows


def controller_chains(
    source: Any = None, *, controllers: Sequence[Any] | None = None, components: Sequence[Any] | None = None
) -> SvgDiagram:
    """The controller chains and interface claims of a system (``ros2 control view_controller_chains``).

    Args:
        source: A running ``System`` or its ``ControllerManager``.
        controllers: ``list_controllers()`` entries, instead of asking ``source``.
        components: ``list_hardware_components()`` entries, instead of asking ``source``.

    Returns:
        The diagram. Solid arrows: command interfaces an active controller has claimed (from
        ``claimed_interfaces``; to hardware or to a following controller's reference); grey dashed arrows:
        command interfaces an inactive controller requires, not claimed; purple dashed arrows: state
        interfaces read (an active controller's loans when ``source`` is a running system).

    Raises:
        TypeError: If neither a source nor both lists are given.
    """
    snap = take_loaned_snapshot(source, controllers=controllers, components=components)
    refs, exps = snap.reference_owners(), snap.exported_state_owners()
    hw_states = {s for comp in snap.components for s in comp.state_interfaces}
    hw_commands = {n for comp in snap.components for n, _ in comp.command_interfaces}
    for c in snap.controllers:  # interfaces a controller names but no component lists (still draw them)
        hw_states |= {i for i in c.required_state_interfaces if i not in exps}
        hw_commands |= {i for i in (*c.required_command_interfaces, *c.claimed_interfaces) if i not in refs}

    canvas = SvgCanvas()
    top = 16.0
    state_rows = [(f"s:{s}", s, "out") for s in sorted(hw_states)]
    state_box = draw_box(canvas, 16.0, top, "hardware", "state interfaces", state_rows, "unknown")

    ranks = chain_ranks(snap)
    columns: dict[int, list[ControllerView]] = {}
    for c in sorted(snap.controllers, key=lambda c: c.name):
        columns.setdefault(ranks[c.name], []).append(c)
    boxes: dict[str, Box] = {}
    x = state_box.x + state_box.w + _GAP_X
    for rank in sorted(columns):
        y = top
        widest = 0.0
        for c in columns[rank]:
            box = draw_box(canvas, x, y, c.name, f"{c.type.rsplit('/', 1)[-1] or 'controller'} | {c.state}",
                           _controller_rows(c, refs, exps), c.state)
            boxes[c.name] = box
            y += box.h + _GAP_Y
            widest = max(widest, box.w)
        x += widest + _GAP_X
    if not columns:
        x = state_box.x + state_box.w + _GAP_X
    command_rows = [(f"c:{i}", i, "in") for i in sorted(hw_commands)]
    command_box = draw_box(canvas, x, top, "hardware", "command interfaces", command_rows, "unknown")

    for c in snap.controllers:
        box = boxes[c.name]
        for i in c.required_state_interfaces:
            if i in exps:
                owner, exported = exps[i]
                src = boxes[owner]
                x1, y1 = src.x + src.w, src.rows[f"exp:{exported}"]
            else:
                x1, y1 = state_box.x + state_box.w, state_box.rows[f"s:{i}"]
            canvas.curve(x1, y1, box.x, box.rows[f"in:{i}"], color=STATE_EDGE, dash=True)
        claimed, would_claim = controller_claims(c)
        for i, is_claimed in [*((i, True) for i in claimed), *((i, False) for i in would_claim)]:
            x1, y1 = box.x + box.w, box.rows[f"out:{i}"]
            if i in refs:
                owner, reference = refs[i]
                dst = boxes[owner]
                x2, y2 = dst.x, dst.rows[f"ref:{reference}"]
            else:
                x2, y2 = command_box.x, command_box.rows[f"c:{i}"]
            if is_claimed:
                canvas.curve(x1, y1, x2, y2, color=COMMAND_EDGE)
            else:
                canvas.curve(x1, y1, x2, y2, color=REQUIRED_EDGE, dash=True, head=REQUIRED_EDGE)
    required = any(controller_claims(c)[1] for c in snap.controllers)
    draw_legend(canvas, 16.0, canvas.height + 24.0, required=required)
    return SvgDiagram(canvas.document("controller chains"), "controller chains")
