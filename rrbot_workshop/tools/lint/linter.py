"""``rrbot-workshop lint``: check a controllers YAML (and a description) against what ROS 2 Jazzy accepts.

A learner's files are meant to carry over to a real robot unchanged, so the checks are the ones a Jazzy
``controller_manager``, its spawner and the ``ros2_controllers`` would make when the file is loaded there, reported
all at once instead of one at a time at bringup:

* launch arguments (``$(var name)``) are substituted first, as ``ros2 launch`` does; one without a value is
  reported once;
* the file parses and has the ``<node>: ros__parameters:`` layout; node keys apply to nodes as rclcpp matches them
  (``/rrbot_1/controller_manager``, ``/**/controller_manager``, ``/**``), so each controller manager of the file is
  checked with its own controllers (:mod:`rrbot_workshop.tools.lint.layout`);
* ``controller_manager`` parameters are known to Jazzy, with their types (unknown names get the closest valid one);
* each controller has a known ``type``, given in the manager's ``<name>.type`` or in the controller's own section
  (the spawner reads it there); a type that resolves to a learner's unfinished exercise says so;
* each controller's parameters: unknown or misspelt names, wrong types, missing required values, failed
  validations (as generate_parameter_library checks them), the parameters every controller has, deprecated ones
  as notes (:mod:`rrbot_workshop.tools.lint.parameters`);
* with a description: every interface a controller claims or reads exists in the ``<ros2_control>`` tags or is
  exported by a chainable controller of the same manager (reference and state interfaces), and the description's
  ``<hardware>`` blocks are sound (:mod:`rrbot_workshop.tools.lint.urdf`). Each manager is checked against its own
  description where the launch file gives each its own robot (:mod:`rrbot_workshop.tools.lint.descriptions`), and
  with ``namespace`` only the manager of that namespace is checked.

:func:`lint_controllers` returns :class:`Finding` records; the CLI prints them as ``FILE:LINE: level: message``.
"""

from __future__ import annotations

import contextlib
import logging
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from rrbot_workshop.exceptions import PluginNotFound, RRBotWorkshopError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.params import ParameterSchema, flatten
from rrbot_workshop.middleware.text_files import MAX_DEPTH, SAFE_LOADER, nesting_depth, paused_gc, read_text
from rrbot_workshop.tools.lint.classes import (
    Interfaces,
    captured,
    controller_interfaces,
    hardware_interfaces,
    learner_file,
    quiet,
    reason,
    unfinished_exercise,
)
from rrbot_workshop.tools.lint.descriptions import EVERY_MANAGER, DescriptionSpec, ManagerDescriptions
from rrbot_workshop.tools.lint.layout import (
    MANAGER_ENTRY_KEYS,
    Controller,
    KeyLines,
    Manager,
    Section,
    normal_namespace,
    read_layout,
    read_sections,
    substitute,
    unresolved,
)
from rrbot_workshop.tools.lint.parameters import (
    CONTROLLER_MANAGER_PARAMETERS,
    behaviour_findings,
    check_parameters,
    closest,
    manager_findings,
    rate_findings,
)
from rrbot_workshop.tools.lint.urdf import parse_description


def external_plugin(ctype: str, source: str) -> str | None:
    """Where a package declares the pluginlib class ``ctype`` (``pkg/Class``), or None.

    The package is the type's prefix, looked up on the package path or found above the linted file (a demo's YAML
    sits in the package that declares its controller). Its plugin description files (the ``*.xml`` beside its
    ``package.xml``, as ``pluginlib_export_plugin_description_file`` installs them) are read for
    ``<class name="ctype">``.
    """
    import xml.etree.ElementTree as ET

    from rrbot_workshop.description import packages

    prefix = ctype.partition("/")[0]
    folders: list[Path] = []
    with contextlib.suppress(Exception):
        folders.append(packages.find_package(prefix).path)
    for parent in Path(source).resolve().parents:
        manifest = parent / "package.xml"
        if manifest.is_file():
            with contextlib.suppress(Exception):
                if (ET.parse(manifest).getroot().findtext("name") or "").strip() == prefix:
                    folders.append(parent)
            break
    for folder in folders:
        for xml_file in sorted(folder.glob("*.xml")):
            if xml_file.name == "package.xml":
                continue
            with contextlib.suppress(Exception):
                root = ET.parse(xml_file).getroot()
                if any(c.get("name") == ctype for c in root.iter("class")):
                    return f"{prefix}/{xml_file.name}"
    return None


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


def lint_controllers(path: str | Path, description: DescriptionSpec | Mapping[str, DescriptionSpec] | None = None,
                     xacro_args: Mapping[str, Any] | None = None, launch_args: Mapping[str, str] | None = None,
                     package_path: Sequence[str | Path] = (), namespace: str | None = None) -> list[Finding]:
    """Check a controllers YAML, and, with ``description``, the interfaces its controllers use.

    Args:
        path: The controllers YAML file.
        description: A URDF or xacro file whose ``<ros2_control>`` tags declare the interfaces (for every controller
            manager of the file), or a mapping from a namespace (``"/rrbot_1"``) or a manager's full name
            (``"/rrbot_1/controller_manager"``) to the file of the managers there, as a launch file gives each
            ``ros2_control_node`` its own ``robot_description``. A file may come with its own xacro arguments:
            ``("rrbot.urdf.xacro", {"prefix": "rrbot_1_"})``. None: interfaces are not checked.
        xacro_args: Arguments for every xacro file.
        launch_args: Values of the launch arguments the YAML uses as ``$(var name)`` (as ``ros2 launch``
            substitutes them in a parameter file).
        package_path: Folders searched for the packages the description names (``$(find pkg)``,
            ``package://``).
        namespace: The namespace the controller manager runs in (``"/rrbot_1"``), as a launch file gives it to
            ``ros2_control_node``: only that manager is checked, with the sections that apply to it (``/**/...``,
            ``/rrbot_1/...``); sections for other namespaces are left to their own runs. None: every manager the
            file names.

    Returns:
        Every finding (errors, warnings, notes), in file order.
    """
    with quiet():
        return _Linter(str(path), launch_args or {}).run(
            path, ManagerDescriptions(description, xacro_args or {}, package_path), namespace)


class _Linter:
    """One run of :func:`lint_controllers` over one file."""

    def __init__(self, source: str, launch_args: Mapping[str, str]) -> None:
        self.source = source
        self.launch_args = launch_args
        self.findings: list[Finding] = []
        self.lines: KeyLines = KeyLines("")
        self.single = True  # one manager at the root: findings name controllers without their namespace

    def add(self, level: str, line: int, where: str, message: str) -> None:
        self.findings.append(Finding(level, self.source, line, where, message))

    # ----------------------------------------------------------------- reading
    def read(self, path: str | Path) -> list[Section] | None:
        """The file's sections, or None after the finding that says why it cannot be read."""
        text, problem = read_text(path)
        if problem:
            self.add("error", 0, "file", problem)
            return None
        text, missing = substitute(text, self.launch_args)
        for name in missing:
            use = re.compile(r"\$\(\s*var\s+" + re.escape(name) + r"\s*\)")
            line = next((i for i, row in enumerate(text.splitlines(), 1) if use.search(row)), 0)
            self.add("error", line, f"$(var {name})",
                     f"the launch argument '{name}' has no value here; give it as the launch file would "
                     f"(--arg {name}:=VALUE, or launch_args={{'{name}': ...}}). Values that use it are not checked")
        try:
            with paused_gc():
                data = yaml.load(text, Loader=SAFE_LOADER)  # noqa: S506 - a safe loader
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            line = mark.line + 1 if mark is not None else 0
            column = f", column {mark.column + 1}" if mark is not None else ""
            problem = getattr(exc, "problem", None) or str(exc)
            self.add("error", line, "YAML", f"does not parse (line {line}{column}): {problem}")
            return None
        except RecursionError:
            data, problem = None, "is nested too deeply to read"
        else:
            problem = "is nested too deeply to read" if nesting_depth(data) > MAX_DEPTH else ""
        if problem:
            self.add("error", 0, "YAML", f"{problem} (more than {MAX_DEPTH} levels)")
            return None
        if data is None:
            self.add("error", 0, "file", "is empty; it needs a 'controller_manager:' entry with 'ros__parameters:' "
                                         "(update_rate and the controllers' types)")
            return None
        if not isinstance(data, Mapping):
            self.add("error", 0, "file", "must be a mapping of node names to 'ros__parameters'")
            return None
        self.lines = KeyLines(text)
        sections, problems = read_sections(data)
        for keys, message in problems:
            self.add("error", self.lines.find(*keys), ".".join(keys), message)
        return sections

    # ----------------------------------------------------------------- where
    def label(self, controller: Controller | Manager | str) -> str:
        if isinstance(controller, str):
            return controller
        return controller.fqn.rsplit("/", 1)[-1] if self.single else controller.fqn

    def section_of(self, sections: Sequence[Section], key: str) -> Section | None:
        """The last of ``sections`` that gives ``key`` (dotted), or None."""
        parts = key.split(".") if key else []
        for section in reversed(sections):
            if key and (key in flatten(section.params) or parts[0] in section.params):
                return section
        return None

    def line_of(self, sections: Sequence[Section], key: str) -> int:
        """Line of ``key`` (dotted) in the last of ``sections`` that gives it, else of the first section."""
        section = self.section_of(sections, key)
        if section is None:
            return self.lines.find(*sections[0].path) if sections else 0
        parts = key.split(".")
        base = (*section.path, "ros__parameters")
        for cut in range(len(parts), 0, -1):  # 'linear.x.max_velocity' may be one YAML key or three
            line = self.lines.exact(*base, *parts[:cut - 1], ".".join(parts[cut - 1:]))
            if line:
                return line
        return self.lines.find(*base, *parts)

    def reporter(self, controller: Controller) -> Any:
        sections = controller.specific_sections() or controller.sections or [s for s, _ in controller.type_sections]

        def report(level: str, key: str, message: str) -> None:
            section = self.section_of(sections, key)
            # a value from a section every namespace shares ('/**/name') is named by that section's key
            label = section.key if section is not None and section.namespace is None and not self.single \
                else self.label(controller)
            line = self.line_of(sections, key) if sections else 0
            self.add(level, line, ".".join(p for p in (label, key) if p), message)

        return report

    # ----------------------------------------------------------------- checks
    def run(self, path: str | Path, descriptions: ManagerDescriptions, namespace: str | None) -> list[Finding]:
        sections = self.read(path)
        if sections is not None:
            layout = read_layout(sections, None if namespace is None else [namespace])
            self.single = len(layout.managers) == 1 and layout.managers[0].namespace == "/"
            if namespace is not None and not layout.managers:
                named = sorted({s.namespace for s in sections if s.namespace is not None and not s.wildcard_name})
                self.add("warning", 0, f"namespace {normal_namespace(namespace)}",
                         "no section of this file applies to a controller manager in this namespace, so there is "
                         f"nothing to check (the file names {', '.join(named) or 'no namespace'})")
            for key in descriptions.unused(layout.managers):
                valid = sorted({m.namespace for m in layout.managers} | {m.fqn for m in layout.managers})
                self.add("error", 0, f"description for '{key}'",
                         f"no controller manager of this file runs in or is named '{key}', so this description "
                         f"checks nothing (valid: {', '.join(valid) or 'none: the file configures no manager'})")
            for manager in layout.managers:
                urdf, infos, name = descriptions.for_manager(manager)
                self.check_manager(manager, urdf, infos, name)
            if not layout.managers and EVERY_MANAGER in descriptions.keys():
                descriptions.parse(EVERY_MANAGER)  # nothing to check it against: its own problems still count
            if layout.managers:
                names = {n for m in layout.managers for n in m.controllers}
                manager_key = "/".join(layout.managers[0].sections[0].path) if layout.managers[0].sections \
                    else "controller_manager"
                for section in layout.unclaimed:
                    if not (closest(section.name, names) or _controller_like(section.params)):
                        continue  # another node's parameters (a publisher, robot_state_publisher): not lint's business
                    self.add("warning", self.lines.find(*section.path), section.key,
                             f"parameters for '{section.key}', but no controller manager of this file has a controller "
                             f"of that name with a 'type' (in '{manager_key}' or in the section itself)"
                             f"{closest(section.name, names)}")
        self.findings.extend(Finding(level, source, 0, where, message)
                             for source, level, where, message in descriptions.problems)
        unique = list(dict.fromkeys((f.level, f.source, f.line, f.message, f.where) for f in self.findings))
        seen: set[tuple[str, str, int, str]] = set()
        out = []
        for level, source, line, message, where in unique:
            if (level, source, line, message) not in seen:  # a section shared by two managers: said once
                seen.add((level, source, line, message))
                out.append(Finding(level, source, line, where, message))
        return sorted(out, key=lambda f: (f.source != self.source, f.line == 0, f.line))

    def check_manager(self, manager: Manager, urdf: str | None, infos: Sequence[Any], description: str) -> None:
        own = [s for s in manager.sections if not s.wildcard_name]
        label = self.label(manager)

        def report(level: str, key: str, message: str) -> None:
            self.add(level, self.line_of(own, key), f"{label}.{key}", message)

        params = {}
        for section in own:
            params.update({k: v for k, v in section.params.items() if k not in manager.controllers
                           and not (isinstance(v, Mapping) and v and set(v) <= set(MANAGER_ENTRY_KEYS))})
        manager_findings(params, report)
        rate = manager.parameters().get("update_rate", 100)
        exports: dict[str, Interfaces] = {}
        for controller in manager.controllers.values():
            for key in controller.manager_entry:
                if key not in MANAGER_ENTRY_KEYS:
                    report("warning", f"{controller.name}.{key}",
                           f"'{controller.name}.{key}' is a parameter of the controller manager, not of controller "
                           f"'{controller.name}': give it in the controller's own section "
                           f"('{controller.name}: ros__parameters: {key}: ...')")
            interfaces = self.check_controller(controller, rate, urdf, label)
            if interfaces is not None:
                exports[controller.name] = interfaces
        if urdf is not None:
            self.interface_findings(manager, description, infos, exports)

    def check_controller(self, controller: Controller, rate: Any, urdf: str | None,
                         manager_label: str) -> Interfaces | None:
        report = self.reporter(controller)
        section, keys = controller.type_sections[-1]  # the type that counts: the spawner's, else the manager's
        type_line = self.lines.find(*section.path, "ros__parameters", *keys)
        type_where = f"{manager_label}.{controller.name}.type" if len(keys) > 1 else f"{self.label(controller)}.type"

        def report_type(level: str, message: str) -> None:
            self.add(level, type_line, type_where, message)

        types = list(dict.fromkeys(str(t) for s, k in controller.type_sections
                                   for t in [_get(s.params, k)] if t is not None))
        ctype = controller.type
        if len(types) > 1:
            report_type("warning", f"two types are given for '{controller.name}' ({', '.join(types)}); the "
                                   f"spawner sets the one of the controller's own section, '{ctype}'")
        if not isinstance(ctype, str) or "/" not in ctype:
            report_type("error", f"'{ctype}' is not a plugin type string such as 'package/ClassName'")
            return None
        if unresolved(ctype):
            return None
        with captured("rrbot_workshop.course.tracks") as log:
            try:
                cls = plugins.resolve("controller", ctype)
            except PluginNotFound as exc:
                unfinished = unfinished_exercise(exc)
                if unfinished is not None:  # the workshop's name for a learner's class that is not finished
                    report_type("error", f"'{ctype}' resolves to your unfinished {unfinished}")
                    return None
                declared = external_plugin(ctype, self.source)
                if declared is not None:  # a package's own C++ controller: Jazzy loads it, the library cannot
                    report_type("note", f"'{ctype}' is a C++ controller declared in {declared}: Jazzy loads it from "
                                        "that package, this library cannot run it, so its parameters are not checked "
                                        "(to try the package here, bring it up with controller_types={'"
                                        f"{controller.name}': '<a library controller type>'}})")
                    return None
                report_type("error", f"unknown controller type '{ctype}': no controller of that type is available "
                                     f"here{closest(ctype, plugins.available('controller'))}")
                return None
            except RRBotWorkshopError as exc:
                report_type("error", f"type '{ctype}' cannot be loaded: {exc}")
                return None
        for record in log.records:
            report_type("warning", f"'{ctype}' resolves to your unfinished exercise: {record.getMessage()}")
        learner = learner_file(cls)
        try:
            return self.check_class(controller, ctype, cls, rate, urdf, report, report_type)
        except Exception as exc:  # noqa: BLE001 - a class that fails is a finding, never a traceback
            if learner is None:
                raise
            report_type("error", f"'{ctype}' resolves to your unfinished {learner}: {reason(exc)}")
            return None

    def check_class(self, controller: Controller, ctype: str, cls: Any, rate: Any, urdf: str | None,
                    report: Any, report_type: Any) -> Interfaces | None:
        values = controller.parameters()
        flat = flatten(values)
        skip = {k for k, v in flat.items() if unresolved(v)}
        shared = set(flat) - {k for s in controller.specific_sections() for k in flatten(s.params)}
        errors_before = sum(f.level == "error" for f in self.findings)
        rate_findings(values, rate, report)
        schema_text = getattr(cls, "PARAMETERS", None)
        if schema_text:
            check_parameters(controller.name, ctype, ParameterSchema(schema_text), values, report, shared, skip)
        behaviour_findings(ctype, values, report, skip)
        failed = sum(f.level == "error" for f in self.findings) > errors_before
        learner = learner_file(cls)
        if (urdf is None and learner is None) or skip:
            return None
        values.pop("type", None)
        failure: Exception | None = None
        with captured("rrbot_workshop") as log:
            try:
                interfaces = controller_interfaces(cls, controller.name, values, urdf or "",
                                                    rate if isinstance(rate, int) and rate > 0 else 100)
            except Exception as exc:  # noqa: BLE001 - a learner's class may raise anything
                if learner is None and not isinstance(exc, RRBotWorkshopError):
                    raise
                failure = exc
        if learner is not None:
            problems = [r for r in log.records if r.exc_info or r.levelno >= logging.ERROR]
            if problems or failure is not None:
                first = problems[0] if problems else None
                if first is not None and first.exc_info and first.exc_info[1] is not None:
                    why = reason(first.exc_info[1])
                else:
                    why = first.getMessage() if first is not None else reason(failure)  # type: ignore[arg-type]
                report_type("error", f"'{ctype}' resolves to your unfinished {learner}: {why}")
                return None
        if failure is not None:
            if not failed:
                report("error", "", f"cannot be configured with these parameters: {failure}")
            return None
        return interfaces if urdf is not None else None

    def interface_findings(self, manager: Manager, description: str, infos: Sequence[Any],
                           exports: Mapping[str, Interfaces]) -> None:
        commands, states = hardware_interfaces(infos)
        references = {ref for itf in exports.values() for ref in itf.references}
        exported = {state for itf in exports.values() for state in itf.exported_states}
        # a controller that could not be configured exports nothing known: what others take from it is not judged
        unknown = tuple(f"{name}/" for name in manager.controllers if name not in exports)
        for name, itf in exports.items():
            controller = manager.controllers[name]
            sections = controller.specific_sections() or controller.sections
            line = self.lines.find(*sections[0].path) if sections else 0
            label = self.label(controller)
            for item in itf.commands:
                if item not in commands and item not in references and not item.startswith(unknown):
                    self.add("error", line, label,
                             f"claims command interface '{item}', which {description} does not declare and no "
                             f"chainable controller exports{closest(item, commands | references)}")
            for item in itf.states:
                if item not in states and item not in exported and not item.startswith(unknown):
                    self.add("error", line, label,
                             f"reads state interface '{item}', which {description} does not declare and no "
                             f"chainable controller exports{closest(item, states | exported)}")


def _controller_like(params: Mapping[str, Any]) -> bool:
    """Whether a section gives a parameter that some controller type declares (``joints``, ``interface_name``...)."""
    global _DECLARED_TOP_LEVEL
    if _DECLARED_TOP_LEVEL is None:
        names: set[str] = set()
        for ctype in plugins.available("controller"):
            with contextlib.suppress(Exception):  # a type that does not load has nothing to offer here
                text = getattr(plugins.resolve("controller", ctype), "PARAMETERS", None)
                if text:
                    names.update(d.path[0] for d in ParameterSchema(text).declarations)
        _DECLARED_TOP_LEVEL = frozenset(names)
    return any(str(key) in _DECLARED_TOP_LEVEL for key in params)


_DECLARED_TOP_LEVEL: frozenset[str] | None = None


def _get(params: Mapping[str, Any], keys: tuple[str, ...]) -> Any:
    value: Any = params
    for key in keys:
        if not isinstance(value, Mapping):
            return None
        value = value.get(key)
    return value


def lint_description(path: str | Path, xacro_args: Mapping[str, Any] | None = None,
                     package_path: Sequence[str | Path] = ()) -> list[Finding]:
    """Check a URDF or xacro file's ``<ros2_control>`` tags as ros2_control's parser does.

    Args:
        path: The URDF or xacro file.
        xacro_args: Arguments for the xacro file.
        package_path: Folders searched for the packages the file names (``$(find pkg)``, ``package://``).
    """
    with quiet():
        problems = parse_description(path, xacro_args or {}, package_path)[2]
    return [Finding(level, str(path), 0, where, message) for level, where, message in problems]


def format_findings(findings: Sequence[Finding]) -> str:
    """One line per finding and a closing count, as a linter prints them."""
    errors = sum(f.level == "error" for f in findings)
    warnings = sum(f.level == "warning" for f in findings)
    notes = sum(f.level == "note" for f in findings)
    body = "\n".join(str(f) for f in findings)
    tail = f"{errors} error(s), {warnings} warning(s)" if errors or warnings else "no problems found"
    if notes:
        tail += f", {notes} note(s)"
    return f"{body}\n{tail}" if body else tail
