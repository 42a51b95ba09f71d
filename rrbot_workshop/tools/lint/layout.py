"""How ``rrbot-workshop lint`` reads a controllers YAML as Jazzy's nodes would: launch arguments, node keys, managers.

A ros2_control parameter file is read by several parties in Jazzy:

* ``ros2 launch`` substitutes ``$(var name)`` in it (a ``ParameterFile`` with ``allow_substs``) before anyone
  parses it (:func:`substitute`);
* every node takes the sections whose key matches its fully qualified name, as rclcpp does: a key without a
  leading ``/`` is taken from the root, ``/*`` stands for one namespace or name token and ``/**`` for any number
  of them (:func:`key_matches`); keys may also be nested (``rrbot_1: controller_manager: ros__parameters:``);
* the spawner reads a controller's ``type`` from the controller's own section and hands it to the controller
  manager as ``<name>.type``, next to the manager's own ``<name>: {type: ...}`` entries.

:func:`read_layout` turns a parsed file into the controller managers it configures (:class:`Manager`), each with
its controllers (:class:`Controller`), and the sections no node of the file takes.
"""

from __future__ import annotations

import copy
import functools
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import yaml

from rrbot_workshop.middleware.text_files import SAFE_LOADER, paused_gc

__all__ = ["KeyLines", "Section", "Controller", "Manager", "Layout", "substitute", "key_matches", "read_layout",
           "normal_namespace", "MANAGER_ENTRY_KEYS"]

#: ``$(var name)`` as ros2 launch writes a launch configuration in a substituted file.
_VAR = re.compile(r"\$\(\s*var\s+([A-Za-z_][A-Za-z0-9_]*)\s*\)")

#: Keys of a controller's entry in the controller manager's section (``<name>.<key>``) that Jazzy's manager reads.
MANAGER_ENTRY_KEYS = ("type", "params_file", "fallback_controllers", "node_options_args")


def substitute(text: str, launch_args: Mapping[str, str]) -> tuple[str, list[str]]:
    """``text`` with every ``$(var name)`` replaced by its value, and the names that have no value, in order.

    A variable without a value stays as written, so the file still parses and its line numbers do not move.
    """
    missing: list[str] = []

    def value(match: re.Match[str]) -> str:
        name = match.group(1)
        if name in launch_args:
            return str(launch_args[name])
        if name not in missing:
            missing.append(name)
        return match.group(0)

    return _VAR.sub(value, text), missing


def unresolved(value: Any) -> bool:
    """True if ``value`` (or an item of a list value) still holds a ``$(var ...)``."""
    if isinstance(value, str):
        return _VAR.search(value) is not None
    if isinstance(value, list):
        return any(unresolved(v) for v in value)
    return False


def _absolute(key: str) -> str:
    return key if key.startswith("/") else "/" + key


@functools.lru_cache(maxsize=4096)
def _key_pattern(key: str) -> re.Pattern[str]:
    return re.compile(re.escape(_absolute(key)).replace(r"/\*\*", r"(?:/\w+)*").replace(r"/\*", r"(?:/\w+)"))


def key_matches(key: str, fqn: str) -> bool:
    """Whether the section key ``key`` applies to the node ``fqn`` (``/ns/name``), as rclcpp matches them."""
    return _key_pattern(key).fullmatch(fqn) is not None


class _Applying:
    """The sections that apply to a node, in file order: exact keys looked up, only wildcard keys matched.

    A file with thousands of controllers would otherwise match every key against every node.
    """

    def __init__(self, sections: list[Section]) -> None:
        self._sections = sections
        self._exact: dict[str, list[int]] = {}
        self._wild: list[int] = []
        for index, section in enumerate(sections):
            if "*" in section.key:
                self._wild.append(index)
            else:
                self._exact.setdefault(_absolute(section.key), []).append(index)

    def __call__(self, fqn: str) -> list[Section]:
        found = self._exact.get(fqn, []) + [i for i in self._wild if key_matches(self._sections[i].key, fqn)]
        return [self._sections[i] for i in sorted(found)]


@dataclass
class Section:
    """One ``<node key>: ros__parameters:`` block.

    Attributes:
        key: The node key, nested keys joined with ``/`` (``/rrbot_1/controller_manager``, ``/**``).
        path: The YAML keys that lead to ``ros__parameters``, as written (for line numbers).
        params: Its ``ros__parameters`` mapping.
    """

    key: str
    path: tuple[str, ...]
    params: dict[str, Any]

    @property
    def name(self) -> str:
        """The last token of the key (``controller_manager``, ``*``, ``**``)."""
        return _absolute(self.key).rsplit("/", 1)[-1]

    @property
    def wildcard_name(self) -> bool:
        """The key names no node in particular (``/**``, ``/**/*``)."""
        return "*" in self.name

    @property
    def namespace(self) -> str | None:
        """The namespace the key names (``/`` for the root), or None when it holds a wildcard."""
        ns = _absolute(self.key).rsplit("/", 1)[0] or "/"
        return None if "*" in ns else ns


@dataclass
class Controller:
    """A controller a manager would load from this file.

    Attributes:
        name: Its name (``forward_position_controller``).
        fqn: Its node's fully qualified name (``/rrbot_1/forward_position_controller``).
        type: Its type string (from the controller's own section, or the manager's ``<name>.type``).
        type_sections: Where the type was given: ``(section, key path inside ros__parameters)``.
        sections: The sections that apply to it, in file order.
        manager_entry: Its entry in the manager's section (``type`` and the other keys there).
    """

    name: str
    fqn: str
    type: Any = None
    type_sections: list[tuple[Section, tuple[str, ...]]] = field(default_factory=list)
    sections: list[Section] = field(default_factory=list)
    manager_entry: dict[str, Any] = field(default_factory=dict)

    def parameters(self) -> dict[str, Any]:
        """Its ``ros__parameters``, the sections merged in file order (later sections win, maps merge)."""
        merged: dict[str, Any] = {}
        for section in self.sections:
            _merge(merged, section.params)
        return merged

    def specific_sections(self) -> list[Section]:
        """The sections that name this controller (not the ``/**`` ones shared by every node)."""
        return [s for s in self.sections if not s.wildcard_name]


@dataclass
class Manager:
    """A controller manager the file configures.

    Attributes:
        fqn: Its fully qualified name (``/controller_manager``, ``/rrbot_1/controller_manager``).
        sections: The sections that apply to it, in file order.
        controllers: Its controllers by name, in file order.
    """

    fqn: str
    sections: list[Section] = field(default_factory=list)
    controllers: dict[str, Controller] = field(default_factory=dict)

    @property
    def namespace(self) -> str:
        return self.fqn.rsplit("/", 1)[0] or "/"

    def parameters(self) -> dict[str, Any]:
        """Its own parameters merged in file order, without the controllers' entries."""
        merged: dict[str, Any] = {}
        for section in self.sections:
            _merge(merged, section.params)
        return {k: v for k, v in merged.items() if k not in self.controllers}


@dataclass
class Layout:
    """What a parameter file configures: managers, and the sections that no manager or controller takes."""

    sections: list[Section]
    managers: list[Manager]
    unclaimed: list[Section]


def _merge(into: dict[str, Any], values: Mapping[str, Any]) -> None:
    for key, value in values.items():
        if isinstance(value, Mapping) and isinstance(into.get(key), dict):
            _merge(into[key], value)
        else:
            into[key] = copy.deepcopy(dict(value)) if isinstance(value, Mapping) else copy.deepcopy(value)


def _flatten_lists_of_maps(value: Any) -> Any:
    """A list whose items are all mappings becomes one mapping of their keys, as Jazzy's parameter parser reads
    it (``interfaces`` under ``- interfaces: [...]`` is the parameter ``<parent>.interfaces``)."""
    if isinstance(value, Mapping):
        return {k: _flatten_lists_of_maps(v) for k, v in value.items()}
    if isinstance(value, list) and value and all(isinstance(v, Mapping) for v in value):
        merged: dict[str, Any] = {}
        for item in value:
            _merge(merged, _flatten_lists_of_maps(item))
        return merged
    return value


def read_sections(data: Mapping[str, Any]) -> tuple[list[Section], list[tuple[tuple[str, ...], str]]]:
    """Every ``ros__parameters`` block of a parsed file, and the keys that lead to none (with why)."""
    sections: list[Section] = []
    problems: list[tuple[tuple[str, ...], str]] = []
    stack: list[tuple[tuple[str, ...], Any]] = [((str(k),), v) for k, v in reversed(list(data.items()))]
    while stack:
        path, body = stack.pop()
        if not isinstance(body, Mapping):
            problems.append((path, "each node key needs a 'ros__parameters:' mapping under it"))
            continue
        if "ros__parameters" in body:
            params = body["ros__parameters"]
            if params is None:
                params = {}
            if not isinstance(params, Mapping):
                problems.append(((*path, "ros__parameters"), "must be a mapping of parameter names to values"))
                continue
            params = _flatten_lists_of_maps(params)
            key = "/".join(p.strip("/") for p in path)
            key = ("/" if path[0].startswith("/") else "") + key
            sections.append(Section(key, path, dict(params)))
            others = [k for k in body if k != "ros__parameters"]
            stack.extend(((*path, str(k)), body[k]) for k in reversed(others))
        elif not body:
            problems.append((path, "each node key needs a 'ros__parameters:' mapping under it"))
        else:
            stack.extend(((*path, str(k)), v) for k, v in reversed(list(body.items())))
    return sections, problems


def _is_manager_name(name: str) -> bool:
    return name.endswith("controller_manager")


def normal_namespace(namespace: str) -> str:
    """``rrbot_1``, ``/rrbot_1/`` -> ``/rrbot_1``; the root is ``/`` (as a launch file's ``namespace=`` is read)."""
    return "/" + namespace.strip().strip("/")


def read_layout(sections: list[Section], namespaces: list[str] | None = None) -> Layout:
    """The controller managers (and their controllers) that ``sections`` configure.

    A manager is any node named ``*controller_manager`` in a key, in each namespace the file names (or the root
    when it names none); where no key names a manager but controllers carry a ``type``, the default
    ``controller_manager`` of that namespace is meant. A controller belongs to a manager when its type is given
    in the manager's ``<name>.type`` or in a section that applies to ``<namespace>/<name>``.

    Args:
        sections: The file's sections (:func:`read_sections`).
        namespaces: The namespaces the managers run in, as a launch file gives ``ros2_control_node`` one; None: every
            namespace the file names. With namespaces given, a section for a node of another namespace is left out
            of :attr:`Layout.unclaimed` (another launch's node takes it).
    """
    given = None if namespaces is None else [normal_namespace(ns) for ns in namespaces]
    if given is not None:
        namespaces = list(dict.fromkeys(given))
    else:
        namespaces = []
        for section in sections:
            ns = section.namespace
            if ns is not None and not section.wildcard_name and ns not in namespaces:
                namespaces.append(ns)
    if not namespaces:
        namespaces = ["/"]
    manager_names = [s.name for s in sections if _is_manager_name(s.name)] or ["controller_manager"]
    manager_names = list(dict.fromkeys(manager_names))
    # a controller typed in its own section is spawned into the default manager (the first one otherwise)
    primary = "controller_manager" if "controller_manager" in manager_names else manager_names[0]
    node_names = list(dict.fromkeys(s.name for s in sections if not s.wildcard_name
                                    and not _is_manager_name(s.name)))
    managers: list[Manager] = []
    claimed: set[int] = set()
    applying_to = _Applying(sections)
    for ns in namespaces:
        for manager_name in manager_names:
            fqn = f"{ns.rstrip('/')}/{manager_name}"
            manager = Manager(fqn, applying_to(fqn))
            named = any(not s.wildcard_name for s in manager.sections)
            for section in manager.sections:
                for pname, pval in section.params.items():
                    if isinstance(pval, Mapping) and "type" in pval:
                        entry = manager.controllers.setdefault(
                            str(pname), Controller(str(pname), f"{ns.rstrip('/')}/{pname}"))
                        entry.manager_entry.update(pval)
                        entry.type = pval["type"]
                        entry.type_sections.append((section, (str(pname), "type")))
            for name in node_names:
                cfqn = f"{ns.rstrip('/')}/{name}"
                applying = applying_to(cfqn)
                typed = [s for s in applying if "type" in s.params] if manager_name == primary else []
                if not typed and name not in manager.controllers:
                    continue
                entry = manager.controllers.setdefault(name, Controller(name, cfqn))
                for section in typed:
                    entry.type = section.params["type"]
                    entry.type_sections.append((section, ("type",)))
            for entry in manager.controllers.values():
                entry.sections = applying_to(entry.fqn)
                claimed.update(id(s) for s in entry.specific_sections())
            if named or manager.controllers:
                managers.append(manager)
                claimed.update(id(s) for s in manager.sections if not s.wildcard_name)
    unclaimed = [s for s in sections if id(s) not in claimed and not s.wildcard_name
                 and (given is None or s.namespace is None or s.namespace in namespaces)]
    return Layout(sections, managers, unclaimed)


class KeyLines:
    """Line numbers of the keys of a YAML document, by path of keys."""

    def __init__(self, text: str) -> None:
        self._text = text
        self._lines: dict[tuple[str, ...], int] = {}
        self._built = False

    def _build(self) -> None:
        """Compose the document once, when the first finding needs a line (a clean file never pays for it)."""
        self._built = True
        try:
            with paused_gc():
                node = yaml.compose(self._text, Loader=SAFE_LOADER)
        except (yaml.YAMLError, RecursionError):
            node = None
        if node is not None:
            self._walk(node, ())

    def _walk(self, node: yaml.Node, path: tuple[str, ...]) -> None:
        stack = [(node, path)]  # iterative: a deep file must not exhaust Python's recursion
        while stack:
            current, prefix = stack.pop()
            if isinstance(current, yaml.MappingNode):
                for key, value in reversed(current.value):
                    child = (*prefix, str(key.value))
                    self._lines.setdefault(child, key.start_mark.line + 1)
                    stack.append((value, child))

    def find(self, *path: str) -> int:
        """Line of the deepest key of ``path`` that exists (0 if none)."""
        if not self._built:
            self._build()
        for end in range(len(path), 0, -1):
            if path[:end] in self._lines:
                return self._lines[path[:end]]
        return 0

    def exact(self, *path: str) -> int:
        """Line of the key ``path`` (0 if it is not in the file)."""
        if not self._built:
            self._build()
        return self._lines.get(path, 0)
