"""SVG diagrams of a running system: controller chains, the ros2_control architecture, lifecycle states.

* :func:`controller_chains` draws what ``ros2 control view_controller_chains`` draws: hardware state
  interfaces on the left, controllers in chain order (preceding controllers first), hardware command
  interfaces on the right, and an arrow for every interface a controller writes or reads. Solid arrows
  are claims an active controller holds; an inactive controller's required command interfaces (what it
  would claim once activated) are grey and dashed.
* :func:`architecture` draws the controller manager with its controllers above the resource manager
  with its hardware components and their interfaces, linked by the claims between them.
* :func:`lifecycle_states` places every controller and hardware component in its lifecycle state.

Each returns an :class:`~rrbot_workshop.viz.svg.SvgDiagram` (shown inline by Jupyter, ``.save(path)``).
The input is the system's introspection answers (``list_controllers``, ``list_hardware_components``,
``list_hardware_interfaces``), so the pictures show what a learner can query. One exception: for an
active controller of a running system, the state interfaces drawn are those it holds on loan
(``controller.state_interfaces``, as a learner can also look up). ``list_controllers`` reports an
active controller whose state interface configuration is ALL (``joint_state_broadcaster``) as requiring
every state interface available *now*, including state interfaces that chainable controllers exported
after it was activated and that it never received; ros2_control's own service does the same.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from ..exceptions import ControllerNotFound
from .snapshot import ControllerView, Snapshot, take_snapshot
from .svg import FONT_SIZE, LINE_HEIGHT, STATE_COLORS, SvgCanvas, SvgDiagram, text_width

__all__ = ["controller_chains", "architecture", "lifecycle_states", "chain_ranks"]

_PAD = 10.0
_GAP_X = 130.0
_GAP_Y = 22.0
_STATE_EDGE = "#8e24aa"
_COMMAND_EDGE = "#455a64"
_REQUIRED_EDGE = "#9e9e9e"
_REQUIRED_LABEL = "required (not claimed: controller inactive)"


@dataclass
class _Box:
    x: float
    y: float
    w: float
    h: float
    rows: dict[str, float]  # row key -> y of the row's middle


def _colors(state: str) -> tuple[str, str]:
    return STATE_COLORS.get(state, STATE_COLORS["unknown"])


def _claims(c: ControllerView) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """``(claimed, would_claim)``: the command interfaces an active controller holds, or those an inactive
    controller requires (and would claim once activated). Other states hold and require nothing."""
    if c.state == "active":
        return c.claimed_interfaces, ()
    if c.state == "inactive":
        return (), c.required_command_interfaces
    return (), ()


def _snapshot(source: Any, controllers: Sequence[Any] | None, components: Sequence[Any] | None) -> Snapshot:
    """The introspection snapshot, with each active controller's state interfaces replaced by its loans.

    Only when the controllers come from a running ``source``: given ``list_controllers`` entries are
    drawn as they are (their ``required_state_interfaces`` is the best there is).
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


def _measure(title: str, subtitle: str, rows: Sequence[tuple[str, str, str]], min_width: float = 150.0) -> tuple[float, float]:
    width = max([min_width, text_width(title) + 2 * _PAD, text_width(subtitle, FONT_SIZE - 2) + 2 * _PAD,
                 *(text_width(text) + 2 * _PAD for _, text, _ in rows)])
    height = 2 * LINE_HEIGHT + 6 + len(rows) * LINE_HEIGHT + (6 if rows else 0)
    return width, height


def _draw_box(
    canvas: SvgCanvas, x: float, y: float, title: str, subtitle: str, rows: Sequence[tuple[str, str, str]],
    state: str, width: float | None = None, min_width: float = 150.0, height: float | None = None,
) -> _Box:
    """A titled box whose rows are ``(key, text, side)``; side "in" aligns left, "out" right."""
    w, h = _measure(title, subtitle, rows, min_width)
    w, h = max(w, width or 0.0), max(h, height or 0.0)
    fill, stroke = _colors(state)
    canvas.rect(x, y, w, h, fill=fill, stroke=stroke)
    canvas.text(x + w / 2, y + LINE_HEIGHT, title, anchor="middle", bold=True)
    canvas.text(x + w / 2, y + 2 * LINE_HEIGHT - 2, subtitle, anchor="middle", size=FONT_SIZE - 2, color="#555555",
                italic=True)
    positions: dict[str, float] = {}
    row_y = y + 2 * LINE_HEIGHT + 6
    if rows:
        canvas.rect(x + 4, row_y, w - 8, len(rows) * LINE_HEIGHT + 2, fill="#ffffff", stroke=stroke, rx=3,
                    stroke_width=0.6)
    for key, text, side in rows:
        middle = row_y + LINE_HEIGHT / 2 + 1
        if side == "out":
            canvas.text(x + w - _PAD, middle + FONT_SIZE / 3, text, anchor="end")
        else:
            canvas.text(x + _PAD, middle + FONT_SIZE / 3, text)
        positions[key] = middle
        row_y += LINE_HEIGHT
    return _Box(x, y, w, h, positions)


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
    snap = _snapshot(source, controllers, components)
    refs, exps = snap.reference_owners(), snap.exported_state_owners()
    hw_states = {s for comp in snap.components for s in comp.state_interfaces}
    hw_commands = {n for comp in snap.components for n, _ in comp.command_interfaces}
    for c in snap.controllers:  # interfaces a controller names but no component lists (still draw them)
        hw_states |= {i for i in c.required_state_interfaces if i not in exps}
        hw_commands |= {i for i in (*c.required_command_interfaces, *c.claimed_interfaces) if i not in refs}

    canvas = SvgCanvas()
    top = 16.0
    state_rows = [(f"s:{s}", s, "out") for s in sorted(hw_states)]
    state_box = _draw_box(canvas, 16.0, top, "hardware", "state interfaces", state_rows, "unknown")

    ranks = chain_ranks(snap)
    columns: dict[int, list[ControllerView]] = {}
    for c in sorted(snap.controllers, key=lambda c: c.name):
        columns.setdefault(ranks[c.name], []).append(c)
    boxes: dict[str, _Box] = {}
    x = state_box.x + state_box.w + _GAP_X
    for rank in sorted(columns):
        y = top
        widest = 0.0
        for c in columns[rank]:
            box = _draw_box(canvas, x, y, c.name, f"{c.type.rsplit('/', 1)[-1] or 'controller'} | {c.state}",
                            _controller_rows(c, refs, exps), c.state)
            boxes[c.name] = box
            y += box.h + _GAP_Y
            widest = max(widest, box.w)
        x += widest + _GAP_X
    if not columns:
        x = state_box.x + state_box.w + _GAP_X
    command_rows = [(f"c:{i}", i, "in") for i in sorted(hw_commands)]
    command_box = _draw_box(canvas, x, top, "hardware", "command interfaces", command_rows, "unknown")

    for c in snap.controllers:
        box = boxes[c.name]
        for i in c.required_state_interfaces:
            if i in exps:
                owner, exported = exps[i]
                src = boxes[owner]
                x1, y1 = src.x + src.w, src.rows[f"exp:{exported}"]
            else:
                x1, y1 = state_box.x + state_box.w, state_box.rows[f"s:{i}"]
            canvas.curve(x1, y1, box.x, box.rows[f"in:{i}"], color=_STATE_EDGE, dash=True)
        claimed, would_claim = _claims(c)
        for i, is_claimed in [*((i, True) for i in claimed), *((i, False) for i in would_claim)]:
            x1, y1 = box.x + box.w, box.rows[f"out:{i}"]
            if i in refs:
                owner, reference = refs[i]
                dst = boxes[owner]
                x2, y2 = dst.x, dst.rows[f"ref:{reference}"]
            else:
                x2, y2 = command_box.x, command_box.rows[f"c:{i}"]
            if is_claimed:
                canvas.curve(x1, y1, x2, y2, color=_COMMAND_EDGE)
            else:
                canvas.curve(x1, y1, x2, y2, color=_REQUIRED_EDGE, dash=True, head=_REQUIRED_EDGE)
    required = any(_claims(c)[1] for c in snap.controllers)
    _legend(canvas, 16.0, canvas.height + 24.0, required=required)
    return SvgDiagram(canvas.document("controller chains"), "controller chains")


def _legend(canvas: SvgCanvas, x: float, y: float, required: bool = False) -> None:
    """Arrow styles and state colours; the grey "required" entry only when such arrows are drawn."""
    canvas.curve(x, y, x + 40, y, color=_COMMAND_EDGE)
    canvas.text(x + 48, y + 4, "command (claimed command or reference interface)", size=FONT_SIZE - 1)
    canvas.curve(x, y + 18, x + 40, y + 18, color=_STATE_EDGE, dash=True)
    canvas.text(x + 48, y + 22, "state interface read", size=FONT_SIZE - 1)
    if required:
        canvas.curve(x, y + 36, x + 40, y + 36, color=_REQUIRED_EDGE, dash=True, head=_REQUIRED_EDGE)
        canvas.text(x + 48, y + 40, _REQUIRED_LABEL, size=FONT_SIZE - 1)
    cx = x + 420
    for state in ("active", "inactive", "unconfigured"):
        fill, stroke = _colors(state)
        canvas.rect(cx, y - 8, 14, 14, fill=fill, stroke=stroke, rx=3)
        canvas.text(cx + 20, y + 4, state, size=FONT_SIZE - 1)
        cx += 30 + text_width(state, FONT_SIZE - 1)


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
    snap = _snapshot(source, controllers, components)
    refs = snap.reference_owners()
    owner_of = snap.component_of()
    ranks = chain_ranks(snap)
    ordered = sorted(snap.controllers, key=lambda c: (ranks[c.name], c.name))
    margin, inner, spacing = 16.0, 16.0, 24.0

    # Measure both rows first, so that the two manager boxes share one width and rows are centred.
    ctrl_size = {c.name: _measure(c.name, c.type, [("", f"state: {c.state}", "in")], 140.0) for c in ordered}
    comp_rows: dict[str, list[tuple[str, str, str]]] = {}
    comp_size: dict[str, tuple[float, float]] = {}
    for comp in snap.components:
        rows = [(f"c:{n}", f"{'●' if claimed else '○'} {n} (cmd)", "in") for n, claimed in comp.command_interfaces]
        rows += [(f"s:{n}", f"  {n} (state)", "in") for n in comp.state_interfaces]
        comp_rows[comp.name] = rows
        comp_size[comp.name] = _measure(comp.name, f"{comp.type} | {comp.plugin_name}", rows, 160.0)

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
    boxes: dict[str, _Box] = {}
    x = margin + inner + (inner_w - ctrl_w) / 2
    for c in ordered:
        w, _ = ctrl_size[c.name]
        boxes[c.name] = _draw_box(canvas, x, row_y, c.name, c.type, [("state", f"state: {c.state}", "in")], c.state,
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
    comp_boxes: dict[str, _Box] = {}
    x = margin + inner + (inner_w - comp_w) / 2
    for comp in snap.components:
        w, _ = comp_size[comp.name]
        comp_boxes[comp.name] = _draw_box(canvas, x, rm_y + 2 * LINE_HEIGHT + 10, comp.name,
                                          f"{comp.type} | {comp.plugin_name}", comp_rows[comp.name], comp.state,
                                          width=w, min_width=160.0)
        x += w + spacing

    # Links: (controller, component, kind); endpoints spread along the box edges.
    links: list[tuple[str, str, str]] = []
    for c in ordered:
        claimed, would_claim = _claims(c)
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

    def spread(box: _Box, ends: list[int], k: int) -> float:
        return box.x + box.w * (ends.index(k) + 1) / (len(ends) + 1)

    for k, (ctrl, comp_name, kind) in enumerate(links):
        top, bottom = boxes[ctrl], comp_boxes[comp_name]
        x_top, x_bottom = spread(top, at_ctrl[ctrl], k), spread(bottom, at_comp[comp_name], k)
        if kind == "claimed":
            canvas.curve(x_top, top.y + top.h, x_bottom, bottom.y, horizontal=False, color=_COMMAND_EDGE)
        elif kind == "required":
            canvas.curve(x_top, top.y + top.h, x_bottom, bottom.y, horizontal=False, color=_REQUIRED_EDGE,
                         dash=True, head=_REQUIRED_EDGE)
        else:
            canvas.curve(x_bottom, bottom.y, x_top, top.y + top.h, horizontal=False, color=_STATE_EDGE, dash=True)
    for c in ordered:
        for owner in sorted({refs[i][0] for i in c.required_command_interfaces if i in refs}):
            a, b = boxes[c.name], boxes[owner]
            canvas.arc(a.x + a.w / 2, a.y, b.x + b.w / 2, b.y, rise=28.0, label="reference")
    _legend(canvas, margin, rm_y + rm_h + 28.0, required=any(kind == "required" for *_, kind in links))
    return SvgDiagram(canvas.document("ros2_control architecture"), "ros2_control architecture")


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
    widths = {s: _measure(s, "", members.get(s, []), 170.0)[0] for s in members}
    height = max(_measure(s, "", members.get(s, []))[1] for s in main)
    boxes: dict[str, _Box] = {}
    x = margin
    for state in main:
        subtitle = f"{len(members[state])} here"
        boxes[state] = _draw_box(canvas, x, margin + 20.0, state, subtitle, members[state], state,
                                 width=widths[state], height=height)
        box = boxes[state]
        x += box.w + gap
    fin_w = widths["finalized"]
    mid = boxes["inactive"]
    fin = _draw_box(canvas, mid.x + mid.w / 2 - fin_w / 2, mid.y + height + 110.0, "finalized",
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
