"""The lifecycle states diagram: every controller and hardware component in its lifecycle state, as SVG.

The three primary states a component moves between (unconfigured, inactive, active) stand in a row with
their transitions, ``finalized`` below them; each state's box lists who is in it. States outside the
picture (e.g. ``unknown``) are listed underneath.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rrbot_workshop.viz.diagram_boxes import Box, draw_box, measure_box
from rrbot_workshop.viz.snapshot import take_snapshot
from rrbot_workshop.viz.svg import LINE_HEIGHT, SvgCanvas, SvgDiagram

__all__ = ["lifecycle_states"]


def lifecycle_states(
    source: Any = None, *, controllers: Sequence[Any] | None = None, components: Sequence[Any] | None = None
) -> SvgDiagram:
    """The lifecycle state machine with every controller and hardware component placed in its state.

    Args:
        source: A running ``System`` or its ``ControllerManager``.
        controllers: ``list_controllers()`` entries, instead of asking ``source``.
        components: ``list_hardware_components()`` entries, instead of asking ``source``.

    Raises:
        TypeError: If neither a source nor both lists are given.
    """
    snap = take_snapshot(source, controllers=controllers, components=components)
    members: dict[str, list[tuple[str, str, str]]] = {s: [] for s in ("unconfigured", "inactive", "active", "finalized")}
    for comp in sorted(snap.components, key=lambda c: c.name):
        members.setdefault(comp.state, []).append((f"hw:{comp.name}", f"[hw]   {comp.name}", "in"))
    for c in sorted(snap.controllers, key=lambda c: c.name):
        members.setdefault(c.state, []).append((f"ctrl:{c.name}", f"[ctrl] {c.name}", "in"))
    canvas = SvgCanvas()
    margin, gap = 16.0, 150.0
    main = ("unconfigured", "inactive", "active")
    widths = {s: measure_box(s, "", members.get(s, []), 170.0)[0] for s in members}
    height = max(measure_box(s, "", members.get(s, []))[1] for s in main)
    boxes: dict[str, Box] = {}
    x = margin
    for state in main:
        subtitle = f"{len(members[state])} here"
        boxes[state] = draw_box(canvas, x, margin + 20.0, state, subtitle, members[state], state,
                                width=widths[state], height=height)
        box = boxes[state]
        x += box.w + gap
    fin_w = widths["finalized"]
    mid = boxes["inactive"]
    fin = draw_box(canvas, mid.x + mid.w / 2 - fin_w / 2, mid.y + height + 110.0, "finalized",
                   f"{len(members['finalized'])} here", members["finalized"], "finalized", width=fin_w)
    for a, b, label in (("unconfigured", "inactive", "configure"), ("inactive", "active", "activate")):
        src, dst = boxes[a], boxes[b]
        canvas.line(src.x + src.w, src.y + 28, dst.x, dst.y + 28, label=label)
    for a, b, label in (("inactive", "unconfigured", "cleanup"), ("active", "inactive", "deactivate")):
        src, dst = boxes[a], boxes[b]
        canvas.line(src.x, src.y + 64, dst.x + dst.w, dst.y + 64, label=label)
    for k, state in enumerate(main):
        box = boxes[state]
        canvas.curve(box.x + box.w / 2, box.y + box.h, fin.x + fin.w * (k + 1) / 4, fin.y, horizontal=False,
                     color="#757575", label="shutdown" if k == 0 else "")
    others = sorted(set(members) - set(main) - {"finalized"})
    if others:  # e.g. "unknown": listed under the picture
        y = fin.y + fin.h + 30.0
        for state in others:
            names = ", ".join(text.split("] ", 1)[-1].strip() for _, text, _ in members[state])
            canvas.text(margin, y, f"{state}: {names}", color="#b71c1c")
            y += LINE_HEIGHT
    return SvgDiagram(canvas.document("lifecycle states"), "lifecycle states")
