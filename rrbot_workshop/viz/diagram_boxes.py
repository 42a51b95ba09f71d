"""The drawing pieces the diagrams share: titled boxes with interface rows, arrow styles and their legend.

Every box of :mod:`~rrbot_workshop.viz.diagrams` (a controller, a hardware component, a lifecycle state)
is a rounded rectangle coloured by lifecycle state, with a bold title, an italic subtitle and a white panel
of one-line rows. :func:`draw_box` remembers where each row sits so that arrows can start and end on it.
Arrows come in three styles, each with its colour here and an entry in :func:`draw_legend`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from rrbot_workshop.viz.svg import FONT_SIZE, LINE_HEIGHT, STATE_COLORS, SvgCanvas, text_width

__all__ = [
    "STATE_EDGE",
    "COMMAND_EDGE",
    "REQUIRED_EDGE",
    "Box",
    "state_colors",
    "measure_box",
    "draw_box",
    "draw_legend",
]

_PAD = 10.0
#: Arrow colour of a state interface read.
STATE_EDGE = "#8e24aa"
#: Arrow colour of a claimed command or reference interface.
COMMAND_EDGE = "#455a64"
#: Arrow colour of a command interface an inactive controller requires but has not claimed.
REQUIRED_EDGE = "#9e9e9e"
_REQUIRED_LABEL = "required (not claimed: controller inactive)"


@dataclass
class Box:
    """Where a box was drawn, in [px].

    Attributes:
        x: Left edge.
        y: Top edge.
        w: Width.
        h: Height.
        rows: Row key -> y of the row's middle.
    """

    x: float
    y: float
    w: float
    h: float
    rows: dict[str, float]


def state_colors(state: str) -> tuple[str, str]:
    """``(fill, stroke)`` of a lifecycle state; unknown states get the colours of ``"unknown"``."""
    return STATE_COLORS.get(state, STATE_COLORS["unknown"])


def measure_box(
    title: str, subtitle: str, rows: Sequence[tuple[str, str, str]], min_width: float = 150.0
) -> tuple[float, float]:
    """``(width, height)`` in [px] of the box :func:`draw_box` would draw for these texts."""
    width = max([min_width, text_width(title) + 2 * _PAD, text_width(subtitle, FONT_SIZE - 2) + 2 * _PAD,
                 *(text_width(text) + 2 * _PAD for _, text, _ in rows)])
    height = 2 * LINE_HEIGHT + 6 + len(rows) * LINE_HEIGHT + (6 if rows else 0)
    return width, height


def draw_box(
    canvas: SvgCanvas, x: float, y: float, title: str, subtitle: str, rows: Sequence[tuple[str, str, str]],
    state: str, width: float | None = None, min_width: float = 150.0, height: float | None = None,
) -> Box:
    """A titled box whose rows are ``(key, text, side)``; side "in" aligns left, "out" right.

    Args:
        canvas: Where to draw.
        x: Left edge in [px].
        y: Top edge in [px].
        title: Bold first line.
        subtitle: Smaller italic second line.
        rows: One line each, in order.
        state: Lifecycle state that picks the colours.
        width: Least width in [px] (the texts may need more).
        min_width: Least width in [px] when measuring the texts.
        height: Least height in [px].
    """
    w, h = measure_box(title, subtitle, rows, min_width)
    w, h = max(w, width or 0.0), max(h, height or 0.0)
    fill, stroke = state_colors(state)
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
    return Box(x, y, w, h, positions)


def draw_legend(canvas: SvgCanvas, x: float, y: float, required: bool = False) -> None:
    """Arrow styles and state colours; the grey "required" entry only when such arrows are drawn."""
    canvas.curve(x, y, x + 40, y, color=COMMAND_EDGE)
    canvas.text(x + 48, y + 4, "command (claimed command or reference interface)", size=FONT_SIZE - 1)
    canvas.curve(x, y + 18, x + 40, y + 18, color=STATE_EDGE, dash=True)
    canvas.text(x + 48, y + 22, "state interface read", size=FONT_SIZE - 1)
    if required:
        canvas.curve(x, y + 36, x + 40, y + 36, color=REQUIRED_EDGE, dash=True, head=REQUIRED_EDGE)
        canvas.text(x + 48, y + 40, _REQUIRED_LABEL, size=FONT_SIZE - 1)
    cx = x + 420
    for state in ("active", "inactive", "unconfigured"):
        fill, stroke = state_colors(state)
        canvas.rect(cx, y - 8, 14, 14, fill=fill, stroke=stroke, rx=3)
        canvas.text(cx + 20, y + 4, state, size=FONT_SIZE - 1)
        cx += 30 + text_width(state, FONT_SIZE - 1)
