"""The ros2_control architecture diagram of a running system, as SVG.

The controller manager, with its controllers in chain order, is drawn above the resource manager, with
its hardware components and their interfaces; arrows between the two rows are the claims and reads
that join controllers to hardware, arcs above the controllers join chained ones.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rrbot_workshop.viz.chains_diagram import chain_ranks
from rrbot_workshop.viz.diagram_boxes import (
    COMMAND_EDGE,
    REQUIRED_EDGE,
    STATE_EDGE,
    Box,
    draw_box,
    draw_legend,
    measure_box,
)
from rrbot_workshop.viz.snapshot import controller_claims, take_loaned_snapshot
from rrbot_workshop.viz.svg import FONT_SIZE, LINE_HEIGHT, SvgCanvas, SvgDiagram, text_width

__all__ = ["architecture"]


def architecture(
    source: Any = None, *, controllers: Sequence[Any] | None = None, components: Sequence[Any] | None = None
) -> SvgDiagram:
    """The ros2_control architecture of a running system.

    The controller manager (with its controllers, in chain order) sits above the resource manager (with
    its hardware components and their command and state interfaces; claimed ones are marked). Arrows
    join each controller to the components whose interfaces it claims (solid) or reads (purple dashed),
    and chained controllers to each other; an inactive controller is joined by a grey dashed arrow to
    the components whose command interfaces it requires but has not claimed.

    Args:
        source: A running ``System`` or its ``ControllerManager``.
        controllers: ``list_controllers()`` entries, instead of asking ``source``.
        components: ``list_hardware_components()`` entries, instead of asking ``source``.

    Raises:
        TypeError: If neither a source nor both lists are given.
    """
    snap = take_loaned_snapshot(source, controllers=controllers, components=components)
    refs = snap.reference_owners()
    owner_of = snap.component_of()
    ranks = chain_ranks(snap)
    ordered = sorted(snap.controllers, key=lambda c: (ranks[c.name], c.name))
    margin, inner, spacing = 16.0, 16.0, 24.0

    # Measure both rows first, so that the two manager boxes share one width and rows are centred.
    ctrl_size = {c.name: measure_box(c.name, c.type, [("", f"state: {c.state}", "in")], 140.0) for c in ordered}
    comp_rows: dict[str, list[tuple[str, str, str]]] = {}
    comp_size: dict[str, tuple[float, float]] = {}
    for comp in snap.components:
        rows = [(f"c:{n}", f"{'●' if claimed else '○'} {n} (cmd)", "in") for n, claimed in comp.command_interfaces]
        rows += [(f"s:{n}", f"  {n} (state)", "in") for n in comp.state_interfaces]
        comp_rows[comp.name] = rows
        comp_size[comp.name] = measure_box(comp.name, f"{comp.type} | {comp.plugin_name}", rows, 160.0)

    def row_width(sizes: list[tuple[float, float]]) -> float:
        return sum(w for w, _ in sizes) + spacing * max(len(sizes) - 1, 0)

    ctrl_w, comp_w = row_width(list(ctrl_size.values())), row_width(list(comp_size.values()))
    inner_w = max(ctrl_w, comp_w, 560.0)
    total_w = inner_w + 2 * inner
    canvas = SvgCanvas()

    # Controller manager with its controllers; chained controllers are joined by arcs above them.
    cm_y = margin
    row_y = cm_y + 2 * LINE_HEIGHT + 10 + (34.0 if refs else 0.0)
    ctrl_h = max([h for _, h in ctrl_size.values()] or [LINE_HEIGHT])
    cm_h = row_y - cm_y + ctrl_h + 16.0
    canvas.rect(margin, cm_y, total_w, cm_h, fill="#f3f7fb", stroke="#37474f", rx=10, back=True)
    rate = f"update_rate: {snap.update_rate} Hz | " if snap.update_rate else ""
    canvas.text(margin + inner, cm_y + LINE_HEIGHT + 2, "controller_manager", bold=True)
    canvas.text(margin + inner + text_width("controller_manager") + 12, cm_y + LINE_HEIGHT + 2,
                f"{rate}each cycle: read() -> update() in chain order -> write()", size=FONT_SIZE - 2, color="#555555")
    boxes: dict[str, Box] = {}
    x = margin + inner + (inner_w - ctrl_w) / 2
    for c in ordered:
        w, _ = ctrl_size[c.name]
        boxes[c.name] = draw_box(canvas, x, row_y, c.name, c.type, [("state", f"state: {c.state}", "in")], c.state,
                                 width=w, min_width=140.0, height=ctrl_h)
        x += w + spacing

    # Resource manager with the hardware components.
    rm_y = cm_y + cm_h + 100.0
    comp_h = max([h for _, h in comp_size.values()] or [LINE_HEIGHT])
    rm_h = 2 * LINE_HEIGHT + 10 + comp_h + 16.0
    canvas.rect(margin, rm_y, total_w, rm_h, fill="#f7f3fb", stroke="#37474f", rx=10, back=True)
    canvas.text(margin + inner, rm_y + LINE_HEIGHT + 2, "resource_manager", bold=True)
    canvas.text(margin + inner + text_width("resource_manager") + 12, rm_y + LINE_HEIGHT + 2,
                "owns the hardware components and one value per interface; ● = claimed",
                size=FONT_SIZE - 2, color="#555555")
    comp_boxes: dict[str, Box] = {}
    x = margin + inner + (inner_w - comp_w) / 2
    for comp in snap.components:
        w, _ = comp_size[comp.name]
        comp_boxes[comp.name] = draw_box(canvas, x, rm_y + 2 * LINE_HEIGHT + 10, comp.name,
                                         f"{comp.type} | {comp.plugin_name}", comp_rows[comp.name], comp.state,
                                         width=w, min_width=160.0)
        x += w + spacing

    # Links: (controller, component, kind); endpoints spread along the box edges.
    links: list[tuple[str, str, str]] = []
    for c in ordered:
        claimed, would_claim = controller_claims(c)
        for comp_name in sorted({owner_of[i] for i in claimed if i in owner_of}):
            links.append((c.name, comp_name, "claimed"))
        for comp_name in sorted({owner_of[i] for i in would_claim if i in owner_of}):
            links.append((c.name, comp_name, "required"))
        for comp_name in sorted({owner_of[i] for i in c.required_state_interfaces if i in owner_of}):
            links.append((c.name, comp_name, "state"))
    at_ctrl: dict[str, list[int]] = {}
    at_comp: dict[str, list[int]] = {}
    for k, (ctrl, comp_name, _) in enumerate(links):
        at_ctrl.setdefault(ctrl, []).append(k)
        at_comp.setdefault(comp_name, []).append(k)

    def spread(box: Box, ends: list[int], k: int) -> float:
        return box.x + box.w * (ends.index(k) + 1) / (len(ends) + 1)

    for k, (ctrl, comp_name, kind) in enumerate(links):
        top, bottom = boxes[ctrl], comp_boxes[comp_name]
        x_top, x_bottom = spread(top, at_ctrl[ctrl], k), spread(bottom, at_comp[comp_name], k)
        if kind == "claimed":
            canvas.curve(x_top, top.y + top.h, x_bottom, bottom.y, horizontal=False, color=COMMAND_EDGE)
        elif kind == "required":
            canvas.curve(x_top, top.y + top.h, x_bottom, bottom.y, horizontal=False, color=REQUIRED_EDGE,
                         dash=True, head=REQUIRED_EDGE)
        else:
            canvas.curve(x_bottom, bottom.y, x_top, top.y + top.h, horizontal=False, color=STATE_EDGE, dash=True)
    for c in ordered:
        for owner in sorted({refs[i][0] for i in c.required_command_interfaces if i in refs}):
            a, b = boxes[c.name], boxes[owner]
            canvas.arc(a.x + a.w / 2, a.y, b.x + b.w / 2, b.y, rise=28.0, label="reference")
    draw_legend(canvas, margin, rm_y + rm_h + 28.0, required=any(kind == "required" for *_, kind in links))
    return SvgDiagram(canvas.document("ros2_control architecture"), "ros2_control architecture")
