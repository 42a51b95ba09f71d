"""Which robot description each controller manager of a controllers YAML is checked against.

A launch file starts each ``ros2_control_node`` with its own ``robot_description``: ros2_control_demos' example 15 runs
``/rrbot_1/controller_manager`` on example 1's RRBot (``prefix:=rrbot_1_``) and ``/rrbot_2/controller_manager`` on
example 5's (``prefix:=rrbot_2_``), both from one YAML. :class:`ManagerDescriptions` holds what lint was given:

* one description for every manager (``--description FILE``), as a launch file with one robot;
* a description for the managers of one namespace, or for one manager (``--description /rrbot_1=FILE``,
  ``--description /rrbot_1/controller_manager=FILE``), each with its own xacro arguments if it needs them.

The most specific one applies: the manager's full name, then its namespace, then the one for every manager. Each
file is expanded once per set of arguments.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from rrbot_workshop.tools.lint.layout import Manager, normal_namespace
from rrbot_workshop.tools.lint.urdf import parse_description

__all__ = ["DescriptionSpec", "ManagerDescriptions", "EVERY_MANAGER", "split_description_option"]

#: A description file, or a file with its own xacro arguments (they override the shared ones).
DescriptionSpec = str | Path | tuple[str | Path, Mapping[str, Any]]

#: The key of the description for every manager that no other key names.
EVERY_MANAGER = ""

_NODE_PATH = re.compile(r"^/(?:[A-Za-z_][A-Za-z0-9_]*(?:/[A-Za-z_][A-Za-z0-9_]*)*)?$")


def split_description_option(value: str) -> tuple[str, str]:
    """``--description [WHO=]FILE`` -> ``(who, file)``; ``who`` is :data:`EVERY_MANAGER` for a plain file.

    ``WHO`` is a namespace (``/rrbot_1``, ``/`` for the root) or a manager's full name
    (``/rrbot_1/controller_manager``). A value that names an existing file is a file, whatever it holds.
    """
    who, sep, file = value.partition("=")
    if not sep or Path(value).exists() or not _NODE_PATH.match(normal_namespace(who)) or not who.startswith("/"):
        return EVERY_MANAGER, value
    return normal_namespace(who), file


class ManagerDescriptions:
    """The descriptions given to one lint run, by the managers they belong to.

    Args:
        description: One file (or file with arguments) for every manager, or a mapping from a namespace, a manager's
            full name or :data:`EVERY_MANAGER` to one; None: no description.
        xacro_args: Arguments every description is expanded with.
        package_path: Folders searched for the packages a description names.
    """

    def __init__(self, description: DescriptionSpec | Mapping[str, DescriptionSpec] | None,
                 xacro_args: Mapping[str, Any], package_path: Sequence[str | Path]) -> None:
        if description is None:
            specs: dict[str, DescriptionSpec] = {}
        elif isinstance(description, Mapping):
            specs = {(k if k == EVERY_MANAGER else normal_namespace(str(k))): v for k, v in description.items()}
        else:
            specs = {EVERY_MANAGER: description}
        self._specs = specs
        self._xacro_args = dict(xacro_args)
        self._package_path = package_path
        self._parsed: dict[tuple[str, tuple[tuple[str, str], ...]], tuple[str | None, list[Any]]] = {}
        self.problems: list[tuple[str, str, str, str]] = []  # (file, level, where, message), each file's once

    def keys(self) -> list[str]:
        """The namespaces and manager names descriptions are given for (:data:`EVERY_MANAGER` for all)."""
        return list(self._specs)

    def key_for(self, manager: Manager) -> str | None:
        """The key of the description ``manager`` is checked against, or None if it has none."""
        for key in (manager.fqn, manager.namespace, EVERY_MANAGER):
            if key in self._specs:
                return key
        return None

    def unused(self, managers: Sequence[Manager]) -> list[str]:
        """Keys that name a namespace or manager the file does not configure (none applies to any manager)."""
        used = {self.key_for(m) for m in managers}
        return [k for k in self._specs if k != EVERY_MANAGER and k not in used]

    def for_manager(self, manager: Manager) -> tuple[str | None, list[Any], str]:
        """``(urdf, hardware_infos, file name)`` for ``manager``: ``(None, [], "")`` when it has no description."""
        key = self.key_for(manager)
        if key is None:
            return None, [], ""
        return self.parse(key)

    def parse(self, key: str) -> tuple[str | None, list[Any], str]:
        """``(urdf, hardware_infos, file name)`` of the description given for ``key``; its problems go to
        :attr:`problems` the first time.

        Raises:
            KeyError: If no description is given for ``key``.
        """
        spec = self._specs[key]
        path, own_args = (spec if isinstance(spec, tuple) else (spec, {}))
        args = {**self._xacro_args, **own_args}
        cache_key = (str(path), tuple(sorted((str(k), str(v)) for k, v in args.items())))
        if cache_key not in self._parsed:
            urdf, infos, problems = parse_description(path, args, self._package_path)
            self._parsed[cache_key] = (urdf, infos)
            self.problems.extend((str(path), level, where, message) for level, where, message in problems)
        urdf, infos = self._parsed[cache_key]
        return urdf, infos, Path(path).name
