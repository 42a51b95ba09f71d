"""XML helpers of the ``<ros2_control>`` parser: element labels, error context, ``<param>`` lists, booleans."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from rrbot_workshop.description.urdf_model import local_name
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["parse_bool", "label", "XmlContext", "children", "text_of", "parameters"]


def parse_bool(text: str) -> bool:
    """``"true"``/``"false"`` in any letter case, as ros2_control's ``parse_bool``; raises ValueError otherwise."""
    lowered = text.strip().lower()
    if lowered == "true":
        return True
    if lowered == "false":
        return False
    raise ValueError(text)


def label(element: ET.Element) -> str:
    """``<tag name='x'>`` (or ``<tag>``), how messages name an element."""
    name = element.get("name")
    tag = local_name(element)
    return f"<{tag} name='{name}'>" if name is not None else f"<{tag}>"


class XmlContext:
    """Error helper: knows the source and the chain of enclosing elements."""

    def __init__(self, source: str | None, path: tuple[str, ...] = ()) -> None:
        self.source = source
        self.path = path

    def enter(self, element: ET.Element) -> XmlContext:
        """The context one element deeper."""
        return XmlContext(self.source, (*self.path, label(element)))

    @property
    def where(self) -> str:
        """Innermost element first: ``<joint name='j1'> of <ros2_control name='rrbot'>``."""
        return " of ".join(reversed(self.path)) if self.path else "the document"

    def error(self, message: str, attribute: str | None = None) -> DescriptionError:
        """A DescriptionError carrying the source and the innermost element."""
        return DescriptionError(message, source=self.source, element=self.path[-1] if self.path else None,
                                attribute=attribute)

    def required(self, element: ET.Element, attribute: str) -> str:
        """Value of a required attribute of ``element`` (a child of this context); raises DescriptionError."""
        value = element.get(attribute)
        if value is None:
            raise self.error(f"missing attribute '{attribute}' in {self.enter(element).where}", attribute)
        return value

    def boolean(self, element: ET.Element, attribute: str, value: str) -> bool:
        """``value`` of ``element``'s boolean attribute; raises DescriptionError unless true/false."""
        try:
            return parse_bool(value)
        except ValueError:
            raise self.error(
                f"invalid {attribute}='{value}' in {self.enter(element).where} (valid: true, false)", attribute
            ) from None


def children(element: ET.Element, name: str) -> list[ET.Element]:
    """Direct children with the given tag name (namespaces ignored)."""
    return [child for child in element if local_name(child) == name]


def text_of(element: ET.Element) -> str:
    """Element text, stripped (``""`` when empty)."""
    return (element.text or "").strip()


def parameters(element: ET.Element, ctx: XmlContext, owner: str) -> dict[str, str]:
    """``<param name="...">value</param>`` children of ``element``; values stripped, empty allowed.

    ``owner`` is the named thing the parameters belong to (hardware, joint, sensor, GPIO, transmission).
    """
    params: dict[str, str] = {}
    for param in children(element, "param"):
        name = param.get("name")
        if name is None:
            raise ctx.error(
                f"no parameter name attribute set in param tag for '{owner}' ({ctx.enter(element).where})", "name"
            )
        params[name] = text_of(param)
    return params
