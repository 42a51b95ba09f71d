"""A learner's controllers YAML read as ``rrbot-workshop lint`` reads it: the graders of tasks 8, 9 and 10 use it.

Jazzy takes a controller's ``type`` from the controller manager's ``<name>.type`` or from the controller's own
``ros__parameters`` (block or flow style alike); the lint's layout reader (:mod:`rrbot_workshop.tools.lint.layout`)
reads both, and sections that apply to every node (``/**``). A grader asks :func:`read_controllers` for the
controllers of the default manager, each with its type and its merged parameters.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from rrbot_workshop.middleware.text_files import SAFE_LOADER
from rrbot_workshop.tools.lint.layout import read_layout, read_sections

__all__ = ["Declared", "read_controllers", "read_manager"]


@dataclass(frozen=True)
class Declared:
    """What a controllers file gives one controller.

    Attributes:
        type: Its type string, wherever the file gives it (None when it gives none).
        params: Its ``ros__parameters``, every section that applies to it merged in file order (``type`` left out).
        manager_entry: Its entry under the manager's ``ros__parameters`` (``type``, ``update_rate``, ...), if any.
    """

    type: Any
    params: Mapping[str, Any]
    manager_entry: Mapping[str, Any] = field(default_factory=dict)


def read_controllers(path: Path) -> dict[str, Declared] | str:
    """The controllers of ``path``'s default controller manager by name, or why the file cannot be read.

    Args:
        path: The learner's controllers YAML.
    """
    read = read_manager(path)
    return read if isinstance(read, str) else read[1]


def read_manager(path: Path) -> tuple[dict[str, Any], dict[str, Declared]] | str:
    """The default controller manager's own parameters and its controllers by name, or why the file cannot be read.

    Args:
        path: The learner's controllers YAML.
    """
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=SAFE_LOADER)  # noqa: S506 (a safe loader)
    except yaml.YAMLError as exc:
        return f"your {path.name} is not valid YAML: {exc}"
    except (OSError, UnicodeDecodeError) as exc:
        return f"your {path.name} cannot be read: {exc}"
    if not isinstance(data, Mapping):
        return f"your {path.name} is not a mapping of node names to 'ros__parameters'"
    sections, _problems = read_sections(data)
    managers = read_layout(sections).managers
    manager = next((m for m in managers if m.fqn == "/controller_manager"), managers[0] if managers else None)
    if manager is None:
        return {}, {}
    return manager.parameters(), {
        name: Declared(c.type, {k: v for k, v in c.parameters().items() if k != "type"}, dict(c.manager_entry))
        for name, c in manager.controllers.items()}
