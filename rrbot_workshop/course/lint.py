"""``rrbot-workshop lint``: check a controllers YAML (and a description) against what ROS 2 Jazzy accepts.

A learner's files are meant to carry over to a real robot unchanged, so the checks are the ones a Jazzy
``controller_manager`` and the ``ros2_controllers`` would make when the file is loaded there, reported all at
once instead of one at a time at bringup:

* the file parses and has the ``<node>: ros__parameters:`` layout;
* ``controller_manager`` parameters are known to Jazzy, with their types (unknown names get the closest valid one);
* each controller has a known ``type`` (the closest known type is suggested);
* each controller's parameters: unknown or misspelt names, wrong types, missing required values, failed
  validations (as generate_parameter_library checks them);
* keys removed or with changed defaults between Humble and Jazzy;
* with a description: every interface a controller claims or reads exists in the ``<ros2_control>`` tags
  (or is a reference interface of another controller in the file);
* a description's ``<hardware>`` holds exactly one ``<plugin>`` (Jazzy's parser would silently take the first).

:func:`lint_controllers` returns :class:`Finding` records; the CLI prints them as ``FILE:LINE: level: message``.
This module reads the files and checks the types and the interfaces; the checks of parameter values are in
:mod:`rrbot_workshop.course.lint_parameters`.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from rrbot_workshop.course.lint_parameters import (
    CONTROLLER_MANAGER_PARAMETERS,
    check_parameters,
    closest,
    manager_findings,
)
from rrbot_workshop.exceptions import DescriptionError, ParameterError, PluginNotFound, RRBotWorkshopError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.controllers_yaml import load_controllers_yaml
from rrbot_workshop.middleware.params import ParameterSchema
from rrbot_workshop.middleware.text_files import MAX_DEPTH, SAFE_LOADER, nesting_depth, paused_gc, read_text

__all__ = ["Finding", "CONTROLLER_MANAGER_PARAMETERS", "lint_controllers", "lint_description", "format_findings"]


@dataclass(frozen=True)
class Finding:
    """One problem found in a file.

    Attributes:
        level: ``"error"`` (Jazzy would refuse the file or the controller), ``"warning"`` (it loads, but
            probably not as meant) or ``"note"`` (a default that changed between Humble and Jazzy is relied on).
        source: File the finding is about.
        line: 1-based line in that file, or 0 when unknown.
        where: The element at fault (``"joint_trajectory_controller.gains.joint1.p"``).
        message: What is wrong and what would be valid.
    """

    level: str
    source: str
    line: int
    where: str
    message: str

    def __str__(self) -> str:
        line = f":{self.line}" if self.line else ""
        return f"{self.source}{line}: {self.level}: {self.where}: {self.message}"


class _Lines:
    """Line numbers of the keys of a YAML document, by path of keys."""

    def __init__(self, text: str) -> None:
        self._text = text
        self._lines: dict[tuple[str, ...], int] = {}
        self._nodes: dict[str, str] = {}  # node name -> its first top-level key (an index: lookups stay O(1))
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
        for key in self._lines:
            if len(key) == 1:
                self._nodes.setdefault(key[0].strip("/").split("/")[-1], key[0])

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

    def node_key(self, name: str) -> str | None:
        """The top-level key naming node ``name`` (``name``, ``/name`` or ``/**/name``)."""
        if not self._built:
            self._build()
        return self._nodes.get(name)


def _interfaces_of(infos: Sequence[Any]) -> tuple[set[str], set[str]]:
    commands: set[str] = set()
    states: set[str] = set()
    for info in infos:
        for component in [*info.joints, *info.sensors, *info.gpios]:
            commands.update(f"{component.name}/{i.name}" for i in component.command_interfaces)
            states.update(f"{component.name}/{i.name}" for i in component.state_interfaces)
    return commands, states


def _controller_interfaces(
    cls: Any, name: str, values: Mapping[str, Any], urdf: str
) -> tuple[list[str], list[str], list[str]]:
    """Command, state and reference interface names the controller asks for once configured."""
    from rrbot_workshop.controller_interface.base import ChainableControllerInterface, InterfaceConfigurationType
    from rrbot_workshop.testing import ControllerHarness

    controller = cls()
    harness = ControllerHarness(controller, name, values, state_values={}, command_values={}, robot_description=urdf)
    harness.configure()

    def names(config: Any) -> list[str]:
        if config is None or config.type is not InterfaceConfigurationType.INDIVIDUAL:
            return []
        return list(config.names)

    references: list[str] = []
    if isinstance(controller, ChainableControllerInterface):
        references = [handle.name for handle in controller.export_reference_interfaces()]
    return (
        names(controller.command_interface_configuration()),
        names(controller.state_interface_configuration()),
        references,
    )


@contextlib.contextmanager
def _quiet() -> Any:
    """The library logs what it ignores while the checks run; the findings say it instead."""
    logger = logging.getLogger("rrbot_workshop")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        logger.setLevel(level)


def lint_controllers(path: str | Path, description: str | Path | None = None,
                     xacro_args: Mapping[str, Any] | None = None) -> list[Finding]:
    """Check a controllers YAML, and, with ``description``, the interfaces its controllers use.

    Args:
        path: The controllers YAML file.
        description: A URDF or xacro file whose ``<ros2_control>`` tags declare the interfaces, or None.
        xacro_args: Arguments for the xacro file.

    Returns:
        Every finding, errors and warnings, in file order.
    """
    with _quiet():
        return _lint_controllers(path, description, xacro_args)


def _lint_controllers(path: str | Path, description: str | Path | None,
                      xacro_args: Mapping[str, Any] | None) -> list[Finding]:
    source = str(path)
    text, problem = read_text(path)
    if problem:
        return [Finding("error", source, 0, "file", problem)]
    findings: list[Finding] = []
    try:
        with paused_gc():
            data = yaml.load(text, Loader=SAFE_LOADER)  # noqa: S506 - a safe loader
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark is not None else 0
        column = f", column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc)
        return [Finding("error", source, line, "YAML", f"does not parse (line {line}{column}): {problem}")]
    except RecursionError:
        data = None
        problem = "is nested too deeply to read"
    else:
        problem = "is nested too deeply to read" if nesting_depth(data) > MAX_DEPTH else ""
    if problem:
        return [Finding("error", source, 0, "YAML", f"{problem} (more than {MAX_DEPTH} levels)")]
    try:
        cfg = load_controllers_yaml(data if isinstance(data, Mapping) else text)
        cfg.source = source
    except ParameterError as exc:
        if exc.parameter == "<string>":  # about the whole file: say it as the other file problems are said
            return [Finding("error", source, 0, "file", str(exc).split("': ", 1)[-1])]
        return [Finding("error", source, 0, exc.parameter.replace("<string>: ", ""), str(exc).replace("<string>", source))]
    lines = _Lines(text)  # line numbers are worked out when the first finding needs one

    def at(node: str, *keys: str) -> Any:
        def report(level: str, where: str, message: str) -> None:
            path = [*keys, *where.split(".")] if where else list(keys)
            line = lines.find(lines.node_key(node) or node, "ros__parameters", *path)
            findings.append(Finding(level, source, line, ".".join([node, *path]), message))

        return report

    manager_findings(cfg, at("controller_manager"))
    known_types = plugins.available("controller")
    classes: dict[str, Any] = {}
    for name, ctype in cfg.controller_types.items():
        report = at("controller_manager", name)
        try:
            classes[name] = plugins.resolve("controller", ctype)
        except PluginNotFound:
            report("error", "type", f"unknown controller type '{ctype}'{closest(ctype, known_types)}")
        except RRBotWorkshopError as exc:
            report("error", "type", f"type '{ctype}' cannot be loaded: {exc}")
    for node in cfg.controller_parameters:
        if node != "/**" and node not in cfg.controller_types:
            line = lines.find(lines.node_key(node) or node)
            manager_key = lines.node_key("controller_manager") or "controller_manager"
            findings.append(Finding(
                "warning", source, line, node,
                f"parameters for '{node}', but '{manager_key}' declares no controller of that name with a 'type'"
                f"{closest(node, cfg.controller_types)}",
            ))
    infos: list[Any] = []
    urdf: str | None = None
    if description is not None:
        urdf, infos, problems = _parse_description(description, xacro_args or {})
        findings.extend(problems)
    interfaces: dict[str, tuple[list[str], list[str], list[str]]] = {}
    failed_parameters: set[str] = set()  # controllers with an error among their parameters (one lookup each)
    schemas: dict[str, ParameterSchema] = {}  # parsed once per type, not once per controller
    for name, cls in classes.items():
        values = cfg.parameters_for(name)
        schema_text = getattr(cls, "PARAMETERS", None)
        if schema_text:
            schema = schemas.get(schema_text)
            if schema is None:
                schema = schemas[schema_text] = ParameterSchema(schema_text)
            errors_before = len(findings)
            check_parameters(name, cfg.controller_types[name], schema, values, at(name))
            if any(f.level == "error" for f in findings[errors_before:]):
                failed_parameters.add(name)
        if urdf is not None:
            try:
                interfaces[name] = _controller_interfaces(cls, name, values, urdf)
            except RRBotWorkshopError as exc:
                if name not in failed_parameters:
                    at(name)("error", "", f"cannot be configured with these parameters: {exc}")
    if urdf is not None and description is not None:
        findings.extend(_interface_findings(source, Path(description).name, infos, interfaces, lines))
    return sorted(findings, key=lambda f: (f.line == 0, f.line))


def _interface_findings(source: str, description: str, infos: Sequence[Any],
                        interfaces: Mapping[str, tuple[list[str], list[str], list[str]]], lines: _Lines) -> list[Finding]:
    commands, states = _interfaces_of(infos)
    references = {ref for (_, _, refs) in interfaces.values() for ref in refs}
    out = []
    for name, (cmds, sts, _) in interfaces.items():
        line = lines.find(lines.node_key(name) or name)
        for itf in cmds:
            if itf not in commands and itf not in references:
                out.append(Finding("error", source, line, name,
                                   f"claims command interface '{itf}', which {description} does not declare"
                                   f"{closest(itf, commands | references)}"))
        for itf in sts:
            if itf not in states:
                out.append(Finding("error", source, line, name,
                                   f"reads state interface '{itf}', which {description} does not declare"
                                   f"{closest(itf, states)}"))
    return out


def _parse_description(
    description: str | Path, xacro_args: Mapping[str, Any]
) -> tuple[str | None, list[Any], list[Finding]]:
    """URDF text and hardware infos of a description, or the finding that says why it cannot be read."""
    from rrbot_workshop.description import parse_ros2_control, process_xacro

    source = str(description)
    try:
        urdf = process_xacro(description, **xacro_args)
        return urdf, parse_ros2_control(urdf, source=source), _plugin_findings(source, urdf)
    except DescriptionError as exc:
        return None, [], [Finding("error", source, 0, exc.element or "description", str(exc))]


def _plugin_findings(source: str, urdf: str) -> list[Finding]:
    """A ``<hardware>`` with more than one ``<plugin>``: Jazzy's parser takes the first and says nothing."""
    import xml.etree.ElementTree as ET

    from rrbot_workshop.description.urdf_model import local_name

    out = []
    for tag in ET.fromstring(urdf.lstrip()):
        if not isinstance(tag.tag, str) or local_name(tag) != "ros2_control":
            continue
        for hardware in (c for c in tag if isinstance(c.tag, str) and local_name(c) == "hardware"):
            names = [(p.text or "").strip() for p in hardware if isinstance(p.tag, str) and local_name(p) == "plugin"]
            if len(names) > 1:
                out.append(Finding(
                    "error", source, 0, f"<ros2_control name='{tag.get('name', '')}'><hardware>",
                    f"holds {len(names)} <plugin> tags ({', '.join(names)}); a <hardware> block takes exactly one. "
                    f"Jazzy's parser would silently use the first ({names[0]}) and ignore the rest. With "
                    "<xacro:if>/<xacro:unless>, check that exactly one branch is taken for every value of its "
                    "argument",
                ))
    return out


def lint_description(path: str | Path, xacro_args: Mapping[str, Any] | None = None) -> list[Finding]:
    """Check a URDF or xacro file's ``<ros2_control>`` tags as ros2_control's parser does."""
    return _parse_description(path, xacro_args or {})[2]


def format_findings(findings: Sequence[Finding]) -> str:
    """One line per finding and a closing count, as a linter prints them."""
    errors = sum(f.level == "error" for f in findings)
    warnings = sum(f.level == "warning" for f in findings)
    body = "\n".join(str(f) for f in findings)
    tail = f"{errors} error(s), {warnings} warning(s)" if errors or warnings else "no problems found"
    return f"{body}\n{tail}" if body else tail
