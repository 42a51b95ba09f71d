"""The description checks of ``rrbot-workshop lint``: a URDF or xacro file's ``<ros2_control>`` tags as Jazzy reads them.

* the file expands (xacro) and its ``<ros2_control>`` tags parse;
* a ``<hardware>`` holds exactly one ``<plugin>`` (Jazzy's parser would silently take the first);
* plugins and parameters renamed before Jazzy: ``fake_components/GenericSystem`` is gone (its successor is
  ``mock_components/GenericSystem``), and Jazzy's GenericSystem reads ``mock_sensor_commands`` and
  ``mock_gpio_commands`` only, so the older ``fake_*`` names are ignored there.

:func:`parse_description` is the one place a description is expanded, so package lookup (``package_path``) is
wired in one spot.
"""

from __future__ import annotations

import importlib
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import DescriptionError

__all__ = ["parse_description", "PACKAGE_PATH_ENV"]

#: The package path variable (colon-separated folders, as ``ROS_PACKAGE_PATH``) that package lookup reads.
PACKAGE_PATH_ENV = "RRBOT_WORKSHOP_PACKAGE_PATH"

#: Hardware plugins renamed before Jazzy: old name -> Jazzy's name.
RENAMED_PLUGINS = {"fake_components/GenericSystem": "mock_components/GenericSystem"}

#: ``<hardware><param>`` names of the GenericSystem renamed before Jazzy: old name -> Jazzy's name.
RENAMED_PARAMS = {"fake_sensor_commands": "mock_sensor_commands", "fake_gpio_commands": "mock_gpio_commands"}


def _expand(description: str | Path, xacro_args: Mapping[str, Any], package_path: Sequence[str | Path]) -> str:
    """URDF text of ``description``, with ``package_path`` searched first for ``$(find pkg)`` and ``package://``.

    The one place lint hands its package path to package lookup: through
    ``rrbot_workshop.description.packages.use_package_path`` where the library has it, else by putting the folders in
    front of ``$RRBOT_WORKSHOP_PACKAGE_PATH`` while the file expands. An empty ``package_path`` changes nothing.

    Raises:
        DescriptionError: If the file cannot be expanded (a folder of ``package_path`` that does not exist too).
    """
    from rrbot_workshop.description import process_xacro

    if not package_path:
        return process_xacro(description, **xacro_args)
    try:
        packages: Any = importlib.import_module("rrbot_workshop.description.packages")
    except ImportError:
        packages = None
    use_package_path = getattr(packages, "use_package_path", None)
    if use_package_path is not None:
        with use_package_path([str(p) for p in package_path]):
            return process_xacro(description, **xacro_args)
    before = os.environ.get(PACKAGE_PATH_ENV)
    os.environ[PACKAGE_PATH_ENV] = os.pathsep.join([*(str(p) for p in package_path), *([before] if before else [])])
    try:
        return process_xacro(description, **xacro_args)
    finally:
        if before is None:
            os.environ.pop(PACKAGE_PATH_ENV, None)
        else:
            os.environ[PACKAGE_PATH_ENV] = before


def parse_description(
    description: str | Path, xacro_args: Mapping[str, Any], package_path: Sequence[str | Path] = (),
) -> tuple[str | None, list[Any], list[tuple[str, str, str]]]:
    """URDF text, hardware infos and problems ``(level, where, message)`` of a description.

    Returns:
        ``(None, [], [the error])`` when the file cannot be expanded or parsed.
    """
    from rrbot_workshop.description import parse_ros2_control

    source = str(description)
    try:
        urdf = _expand(description, xacro_args, package_path)
        infos = parse_ros2_control(urdf, source=source)
    except DescriptionError as exc:
        return None, [], [("error", exc.element or "description", str(exc))]
    return urdf, infos, _hardware_findings(urdf)


def _hardware_findings(urdf: str) -> list[tuple[str, str, str]]:
    """Problems of the ``<hardware>`` blocks: several plugins, renamed plugins and parameters."""
    from rrbot_workshop.description.urdf_model import local_name

    def children(element: Any, name: str) -> list[Any]:
        return [c for c in element if isinstance(c.tag, str) and local_name(c) == name]

    out: list[tuple[str, str, str]] = []
    for tag in ET.fromstring(urdf.lstrip()):
        if not isinstance(tag.tag, str) or local_name(tag) != "ros2_control":
            continue
        where = f"<ros2_control name='{tag.get('name', '')}'><hardware>"
        for hardware in children(tag, "hardware"):
            names = [(p.text or "").strip() for p in children(hardware, "plugin")]
            if len(names) > 1:
                out.append(("error", where,
                            f"holds {len(names)} <plugin> tags ({', '.join(names)}); a <hardware> block takes exactly "
                            f"one. Jazzy's parser would silently use the first ({names[0]}) and ignore the rest. With "
                            "<xacro:if>/<xacro:unless>, check that exactly one branch is taken for every value of its "
                            "argument"))
            for name in names[:1]:
                if name in RENAMED_PLUGINS:
                    out.append(("error", f"{where}<plugin>",
                                f"'{name}' does not exist in Jazzy: it was renamed '{RENAMED_PLUGINS[name]}'; write "
                                f"<plugin>{RENAMED_PLUGINS[name]}</plugin>"))
            for param in children(hardware, "param"):
                old = param.get("name", "")
                if old in RENAMED_PARAMS:
                    out.append(("warning", f"{where}<param name='{old}'>",
                                f"Jazzy's GenericSystem does not read '{old}' (it is ignored): it was renamed "
                                f"'{RENAMED_PARAMS[old]}'; write <param name=\"{RENAMED_PARAMS[old]}\">"))
    return out
