"""A tiny SVG writer: enough boxes, text and arrows for the course's diagrams, no graphviz needed.

Text is set in a monospace font so that its width can be computed without a renderer; every number is
rounded, so the same system always gives byte-identical SVG.
"""

from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import escape

__all__ = ["SvgDiagram", "SvgCanvas", "text_width", "FONT_SIZE", "LINE_HEIGHT", "FIT_STYLE"]

FONT_SIZE = 12
LINE_HEIGHT = 18
_CHAR_WIDTH = 0.61 * FONT_SIZE  # monospace advance width, generous
_FONT = "DejaVu Sans Mono, Menlo, Consolas, monospace"

#: Style of every diagram's root element: natural size when the cell is wide enough, scaled down
#: (keeping its proportions, thanks to the viewBox) to the cell's width when it is not.
FIT_STYLE = "max-width: 100%; height: auto"

#: Fill and stroke colours of lifecycle states.
STATE_COLORS: dict[str, tuple[str, str]] = {
    "active": ("#dcf3dc", "#2e7d32"),
    "inactive": ("#fff4d1", "#b8860b"),
    "unconfigured": ("#eeeeee", "#757575"),
    "finalized": ("#e0e0e0", "#424242"),
    "unknown": ("#ffffff", "#9e9e9e"),
}


def text_width(text: str, size: float = FONT_SIZE) -> float:
    """Width of ``text`` in [px] at font ``size`` (monospace estimate)."""
    return len(text) * 0.61 * size


def _n(value: float) -> str:
    rounded = round(value, 1)
    return str(int(rounded)) if rounded == int(rounded) else f"{rounded:.1f}"


class SvgDiagram:
    """An SVG picture that notebooks display inline and that can be written to a file.

    Args:
        svg: The SVG document text.
        title: What the diagram shows.
    """

    def __init__(self, svg: str, title: str = "") -> None:
        self.svg = svg
        self.title = title

    def _repr_svg_(self) -> str:
        return self.svg

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the SVG to ``path``.

        Returns:
            The path written.
        """
        out = Path(path)
        out.write_text(self.svg, encoding="utf-8")
        return out

    def __str__(self) -> str:
        return self.svg

    def __repr__(self) -> str:
        return f"<SvgDiagram {self.title!r} ({len(self.svg)} characters)>"


class SvgCanvas:
    """Collects SVG elements and writes the document, sized to what was drawn."""

    def __init__(self) -> None:
        self._layers: dict[str, list[str]] = {"back": [], "edges": [], "front": []}
        self._items = self._layers["front"]
        self._heads: dict[str, str] = {}  # extra arrowhead marker id -> fill colour
        self.width = 0.0
        self.height = 0.0

    def _grow(self, x: float, y: float) -> None:
        self.width = max(self.width, x)
        self.height = max(self.height, y)

    def rect(
        self, x: float, y: float, w: float, h: float, *, fill: str = "#ffffff", stroke: str = "#333333",
        rx: float = 6.0, dash: bool = False, stroke_width: float = 1.2, back: bool = False,
    ) -> None:
        """A rounded rectangle with its top-left corner at (x, y); ``back`` puts it behind the arrows."""
        extra = ' stroke-dasharray="5,3"' if dash else ""
        self._layers["back" if back else "front"].append(
            f'<rect x="{_n(x)}" y="{_n(y)}" width="{_n(w)}" height="{_n(h)}" rx="{_n(rx)}" '
            f'fill="{fill}" stroke="{stroke}" stroke-width="{_n(stroke_width)}"{extra}/>'
        )
        self._grow(x + w, y + h)

    def text(
        self, x: float, y: float, text: str, *, anchor: str = "start", size: float = FONT_SIZE,
        bold: bool = False, color: str = "#212121", italic: bool = False,
    ) -> None:
        """Text whose baseline starts (or is centred / ends, per ``anchor``) at (x, y)."""
        style = (' font-weight="bold"' if bold else "") + (' font-style="italic"' if italic else "")
        self._items.append(
            f'<text x="{_n(x)}" y="{_n(y)}" text-anchor="{anchor}" font-size="{_n(size)}"{style} '
            f'fill="{color}">{escape(text)}</text>'
        )
        width = text_width(text, size)
        right = x + (width if anchor == "start" else width / 2 if anchor == "middle" else 0)
        self._grow(right, y + size / 3)

    def curve(
        self, x1: float, y1: float, x2: float, y2: float, *, color: str = "#455a64", dash: bool = False,
        horizontal: bool = True, label: str = "", head: str | None = None,
    ) -> None:
        """An arrow from (x1, y1) to (x2, y2), bent as an S (horizontal or vertical tangents).

        ``head`` colours the arrowhead; None keeps the default head (dark when solid, purple when dashed).
        """
        if horizontal:
            bend = max(abs(x2 - x1) / 2.0, 30.0)
            c1, c2 = (x1 + bend, y1), (x2 - bend, y2)
        else:
            bend = max(abs(y2 - y1) / 2.0, 20.0)
            sign = 1.0 if y2 >= y1 else -1.0
            c1, c2 = (x1, y1 + sign * bend), (x2, y2 - sign * bend)
        extra = ' stroke-dasharray="5,3"' if dash else ""
        marker = "arrow-dash" if dash else "arrow"
        if head is not None:
            marker = "arrow-" + "".join(ch for ch in head if ch.isalnum())
            self._heads[marker] = head
        self._layers["edges"].append(
            f'<path d="M {_n(x1)} {_n(y1)} C {_n(c1[0])} {_n(c1[1])}, {_n(c2[0])} {_n(c2[1])}, {_n(x2)} {_n(y2)}" '
            f'fill="none" stroke="{color}" stroke-width="1.3"{extra} marker-end="url(#{marker})"/>'
        )
        if label:
            self.text((x1 + x2) / 2 + 4, (y1 + y2) / 2 - 4, label, size=FONT_SIZE - 2, color=color, italic=True)
        self._grow(max(x1, x2), max(y1, y2))

    def arc(self, x1: float, y1: float, x2: float, y2: float, *, rise: float = 30.0, color: str = "#455a64",
            label: str = "") -> None:
        """An arrow from (x1, y1) to (x2, y2) that bulges ``rise`` [px] upwards."""
        top = min(y1, y2) - rise
        self._layers["edges"].append(
            f'<path d="M {_n(x1)} {_n(y1)} C {_n(x1)} {_n(top)}, {_n(x2)} {_n(top)}, {_n(x2)} {_n(y2)}" '
            f'fill="none" stroke="{color}" stroke-width="1.3" marker-end="url(#arrow)"/>'
        )
        if label:
            self.text((x1 + x2) / 2, top + 0.25 * rise - 2, label, anchor="middle", size=FONT_SIZE - 2, color=color,
                      italic=True)
        self._grow(max(x1, x2), max(y1, y2))

    def line(self, x1: float, y1: float, x2: float, y2: float, *, color: str = "#455a64", label: str = "") -> None:
        """A straight arrow from (x1, y1) to (x2, y2)."""
        self._layers["edges"].append(
            f'<line x1="{_n(x1)}" y1="{_n(y1)}" x2="{_n(x2)}" y2="{_n(y2)}" stroke="{color}" '
            f'stroke-width="1.3" marker-end="url(#arrow)"/>'
        )
        if label:
            self.text((x1 + x2) / 2, (y1 + y2) / 2 - 5, label, anchor="middle", size=FONT_SIZE - 1, color=color,
                      italic=True)
        self._grow(max(x1, x2), max(y1, y2))

    def document(self, title: str, margin: float = 16.0) -> str:
        """The SVG document text."""
        w, h = self.width + margin, self.height + margin
        defs = (
            "<defs>"
            '<marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" '
            'orient="auto-start-reverse"><path d="M 0 0 L 10 5 L 0 10 z" fill="#455a64"/></marker>'
            '<marker id="arrow-dash" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" '
            'orient="auto-start-reverse"><path d="M 0 0 L 10 5 L 0 10 z" fill="#8e24aa"/></marker>'
            + "".join(
                f'<marker id="{marker}" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" '
                f'orient="auto-start-reverse"><path d="M 0 0 L 10 5 L 0 10 z" fill="{fill}"/></marker>'
                for marker, fill in sorted(self._heads.items())
            )
            + "</defs>"
        )
        body = "\n".join([*self._layers["back"], *self._layers["edges"], *self._layers["front"]])
        return (
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{_n(w)}" height="{_n(h)}" '
            f'viewBox="0 0 {_n(w)} {_n(h)}" style="{FIT_STYLE}" font-family="{_FONT}">\n'
            f"<title>{escape(title)}</title>\n{defs}\n"
            f'<rect x="0" y="0" width="{_n(w)}" height="{_n(h)}" fill="#ffffff"/>\n{body}\n</svg>\n'
        )
