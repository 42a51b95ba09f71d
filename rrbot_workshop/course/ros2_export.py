"""``rrbot-workshop export --ros2 DIR [--task N]``: the learner's work as ROS 2 packages, laid out as the original
workshop's.

What a learner wrote in the course is meant to run on a real ROS 2 Jazzy install. This writes two ament packages
next to each other, named as the ROSCon 2022 workshop named them:

``controlko_description``
    ``urdf/`` with the learner's xacro files, copied byte for byte from the exported task's
    ``rrbot_description/urdf/``; ``package.xml`` and ``CMakeLists.txt`` (ament_cmake, installs ``urdf/``).
``controlko_bringup``
    ``config/`` with the same task's controllers YAML (``rrbot_bringup/config/``), byte for byte;
    ``launch/rrbot.launch.py``, the equivalent of the learner's ``bringup.py`` (xacro -> ``robot_state_publisher``,
    ``ros2_control_node`` with the YAML, spawners for the broadcasters and the chosen robot controller, the other
    robot controllers spawned ``--inactive``); ``package.xml`` and ``CMakeLists.txt``.

**Which task.** Every task whose folder holds both a description (``rrbot_description/urdf/rrbot.urdf.xacro``) and a
bringup (``rrbot_bringup/config/*.yaml``) can be exported (:func:`export_sources`). ``task=N`` chooses one; by
default the most advanced task that is ready is exported, and :class:`Ros2Export` says which.

**Ready** means the files the packages are made from are finished for what the packages do, checked in about a
second without running the robot (:func:`export_problems`): the xacro declares the two arguments the launch file
hands it (``use_mock_hardware``, ``mock_sensor_commands``) and expands with both values of the switch; with
``use_mock_hardware:=true`` every ``<ros2_control>`` tag names ``mock_components/GenericSystem``; the controllers
YAML loads, declares at least one robot controller (the launch argument ``robot_controller`` needs a choice) and
lints with no error against the expanded description; and no plugin exists only in this library. An export that is
not ready is refused with every problem, and writes nothing.

**Names.** Every name that reaches a generated file must be one ROS takes: each controller name a node name, each
plugin (the hardware plugin the description names, each controller type) of pluginlib's ``<package>/<Class>`` form,
and each package found by the description (``$(find pkg)``, ``package://pkg``) a package name (REP 144). A name that
is not is refused in one line naming the file and the name, before anything is written. ``package.xml`` is then built
with :mod:`xml.etree.ElementTree` (every value escaped by the library) and read back to check that it holds no
processing instruction or comment; the launch file holds names only as Python literals (``repr``) and is parsed.

**Manifests.** The ``exec_depend`` lists are derived from the files: the packages the generated launch file uses
(its ``Node(package=...)``, ``FindPackageShare``, ``FindExecutable``, the ``launch`` modules it imports, and
``ros2launch`` that runs it), the packages of the controller types in the YAML and of the hardware plugins the
description can name (``mock_components`` is in ``hardware_interface``), and for the description ``xacro`` plus
any package its files find (``$(find pkg)``, ``package://pkg``). The workshop's own plugins (task 7's driver,
task 8's controller) are not dependencies: they remain to be written in C++, as the generated README says.

A ``README.md`` at the top says how to build it with colcon and what stays to be written in C++ (the learner's
Python versions of tasks 7 and 8 are copied to ``python_reference/`` to port from). Nothing here needs ROS to run:
the generated files are checked to parse (XML, Python), and every ``DeclareLaunchArgument`` to be one that
``ros2 launch`` accepts (a name, a text default, and choices that are not empty and hold the default).
"""

from __future__ import annotations

import shutil
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError, DescriptionError, ParameterError, RRBotWorkshopError
from rrbot_workshop.middleware.names import NODE_NAME_RULE, node_name_problem
from rrbot_workshop.middleware.params import load_controllers_yaml
from rrbot_workshop.tools.ros2_package import (
    PACKAGE_NAME_RULE,
    PLUGIN_NAME_RULE,
    Created,
    check_generated,
    check_target,
    cmakelists,
    description_packages,
    launch_argument_problem,
    launch_file,
    launch_packages,
    package_name_problem,
    package_xml,
    plugin_name_problem,
)

__all__ = ["Ros2Export", "ExportSource", "export_sources", "export_problems", "export_ros2", "launch_argument_problem"]

#: Broadcaster types: spawned first, never the "robot controller".
_BROADCASTER_SUFFIXES = ("Broadcaster",)
#: Where a task keeps the files that are exported.
_DESCRIPTION = Path("rrbot_description") / "urdf"
_XACRO = "rrbot.urdf.xacro"
_BRINGUP_CONFIG = Path("rrbot_bringup") / "config"
_PREFERRED_YAML = "rrbot_controllers.yaml"
#: The xacro arguments the generated launch file hands to the description, with the values it can give.
_LAUNCH_XACRO_ARGS = {"use_mock_hardware": ("true", "false"), "mock_sensor_commands": ("false",)}
_MOCK = "mock_components/GenericSystem"
#: Plugin prefixes whose ROS 2 package has another name (Jazzy builds mock_components in hardware_interface).
_PLUGIN_PACKAGES = {"mock_components": "hardware_interface"}
#: Plugin prefixes of this library alone: ROS 2 has no such plugin.
_LIBRARY_ONLY = ("rrbot_workshop",)


@dataclass
class ExportSource:
    """A task whose description and bringup can be exported.

    Attributes:
        task: Task number.
        folder: The task's folder on the track.
        urdf: Its ``rrbot_description/urdf`` folder (the xacro files).
        controllers: Its controllers YAML.
    """

    task: int
    folder: Path
    urdf: Path
    controllers: Path

    @property
    def shown(self) -> str:
        """The task folder as the learner knows it (``exercises/task05_simulation``)."""
        from rrbot_workshop.course.learner import shown

        try:
            return shown(self.folder)
        except CourseError:
            return self.folder.as_posix()


@dataclass
class Ros2Export:
    """What :func:`export_ros2` wrote.

    Attributes:
        root: The output folder.
        task: The task whose files were exported.
        task_folder: That task's folder, as the learner knows it (``exercises/task05_simulation``).
        ready_tasks: Every task that was ready to export (the learner may choose another with ``task=``).
        copied: Learner files copied byte for byte: destination -> source.
        generated: Files written from templates.
        robot_controllers: Controllers the launch file can start as the robot controller, the default first.
        exec_depends: Package name -> its ``exec_depend`` entries, as written in its ``package.xml``.
        to_port: The workshop's plugins the files name that remain to be written in C++.
    """

    root: Path
    task: int = 0
    task_folder: str = ""
    ready_tasks: list[int] = field(default_factory=list)
    copied: dict[Path, Path] = field(default_factory=dict)
    generated: list[Path] = field(default_factory=list)
    robot_controllers: list[str] = field(default_factory=list)
    exec_depends: dict[str, list[str]] = field(default_factory=dict)
    to_port: list[str] = field(default_factory=list)


def _readme(result: Ros2Export, references: list[str]) -> str:
    robot_controllers = result.robot_controllers
    ported = "\n".join(f"- {r}" for r in references) or "- (none of tasks 7 and 8 written yet)"
    plugins = ", ".join(f"`{p}`" for p in result.to_port) or "none"
    return f"""# Your RRBot, as ROS 2 packages

Written by `rrbot-workshop export --ros2` from your course files of task {result.task} (`{result.task_folder}`). The
xacro files and the controllers YAML are yours, unchanged; the package manifests, CMake files and the launch file
were generated to match them.

## Build and run (ROS 2 Jazzy)

```bash
mkdir -p ~/ws/src && cp -r controlko_description controlko_bringup ~/ws/src/
cd ~/ws && rosdep install --from-paths src -i -y && colcon build --symlink-install
source install/setup.bash
ros2 launch controlko_bringup rrbot.launch.py robot_controller:={robot_controllers[0] if robot_controllers else "..."}
```

Robot controllers the launch file accepts: {", ".join(f"`{c}`" for c in robot_controllers) or "none found"}.
With `use_mock_hardware:=true` (the default) `mock_components/GenericSystem` stands in for the robot, exactly
as in the course.

## What remains C++

Plugins your files name that no ROS 2 package provides yet: {plugins}. The course's Python hardware interface
(task 7, `controlko_hardware_interface/RRBotHardwareInterface`, used with `use_mock_hardware:=false`) and the
displacement controller (task 8, `controlko_controllers/DisplacementController`) are plugins: on a real robot
they are C++ classes exported with `pluginlib`. Port them method by method (the names are the same,
`on_configure`, `read`, `write`, `update`, ...), then build them as `controlko_hardware_interface` and
`controlko_controllers`, and add them to `controlko_bringup/package.xml` as `exec_depend`. Your Python versions,
to port from:

{ported}
"""


def _controllers_yaml(folder: Path) -> Path | None:
    if not folder.is_dir():
        return None
    found = sorted(p for p in folder.iterdir() if p.suffix in (".yaml", ".yml") and p.is_file())
    preferred = [p for p in found if p.name == _PREFERRED_YAML]
    return (preferred or found)[0] if found else None


def export_sources(track: str | None = None) -> list[ExportSource]:
    """Every task of the course that has a description and a bringup to export, in task order.

    A task qualifies when its folder on the track holds ``rrbot_description/urdf/rrbot.urdf.xacro`` and a controllers
    YAML in ``rrbot_bringup/config/`` (``rrbot_controllers.yaml`` if there are several).

    Args:
        track: ``"exercises"`` or ``"solutions"``; default the current track.
    """
    found: list[ExportSource] = []
    for task in tracks.task_names():
        try:
            folder = tracks.task_dir(task, track)
        except CourseError:
            continue
        yaml_path = _controllers_yaml(folder / _BRINGUP_CONFIG)
        if (folder / _DESCRIPTION / _XACRO).is_file() and yaml_path is not None:
            found.append(ExportSource(task, folder, folder / _DESCRIPTION, yaml_path))
    return found


def _plugin_package(type_name: str) -> str:
    return _PLUGIN_PACKAGES.get(type_name.split("/", 1)[0], type_name.split("/", 1)[0])


def _workshop_prefixes() -> set[str]:
    return {p.type_name.split("/", 1)[0] for p in tracks.TRACK_PLUGINS}


@dataclass
class _Plan:
    """What checking a source found out: its problems, and what the packages need."""

    problems: list[str] = field(default_factory=list)
    invalid_names: list[str] = field(default_factory=list)
    robot_controllers: list[str] = field(default_factory=list)
    broadcasters: list[str] = field(default_factory=list)
    plugin_packages: list[str] = field(default_factory=list)
    to_port: list[str] = field(default_factory=list)


def _declared_xacro_args(xacro: Path) -> set[str] | None:
    try:
        root = ET.parse(xacro).getroot()
    except (ET.ParseError, OSError):
        return None
    return {e.get("name", "") for e in root.iter() if isinstance(e.tag, str) and e.tag.rsplit("}", 1)[-1] == "arg"}


def _plugin(plan: _Plan, type_name: str, where: str) -> None:
    if plugin_name_problem(type_name):
        plan.invalid_names.append(f"{where} names {_shown_name(type_name)}, not a plugin name")
        return
    prefix = type_name.split("/", 1)[0]
    if prefix in _LIBRARY_ONLY:
        plan.problems.append(f"{where} names '{type_name}', which exists only in this library: ROS 2 has no such "
                             "plugin (use the workshop's name or a ROS 2 package's)")
    elif prefix in _workshop_prefixes():
        if type_name not in plan.to_port:
            plan.to_port.append(type_name)
    elif "/" in type_name:
        package = _plugin_package(type_name)
        if package not in plan.plugin_packages:
            plan.plugin_packages.append(package)


def _check(source: ExportSource) -> _Plan:
    """Everything :func:`export_problems` checks, and what the manifests need (nothing is written)."""
    from rrbot_workshop.description import parse_ros2_control, process_xacro
    from rrbot_workshop.tools.lint import lint_controllers

    plan = _Plan()
    xacro = source.urdf / _XACRO
    shown_xacro = f"{source.shown}/{_DESCRIPTION.as_posix()}/{_XACRO}"
    shown_yaml = f"{source.shown}/{_BRINGUP_CONFIG.as_posix()}/{source.controllers.name}"
    declared = _declared_xacro_args(xacro)
    if declared is None:
        plan.problems.append(f"{shown_xacro} does not parse as XML")
        return plan
    missing = [a for a in _LAUNCH_XACRO_ARGS if a not in declared]
    if missing:
        plan.problems.append(f"{shown_xacro} declares no xacro argument {', '.join(repr(m) for m in missing)}, which "
                             "the launch file sets (<xacro:arg name=... default=.../>, handed to the macro)")
    description_ok = not missing
    for mock in _LAUNCH_XACRO_ARGS["use_mock_hardware"] if description_ok else ():
        args = {"use_mock_hardware": mock, "mock_sensor_commands": "false"}
        try:
            infos = parse_ros2_control(process_xacro(xacro, **args), source=str(xacro))
        except (DescriptionError, RRBotWorkshopError, OSError) as exc:
            plan.problems.append(f"{shown_xacro} with use_mock_hardware:={mock}: {str(exc).splitlines()[0]}")
            description_ok = False
            continue
        if not infos:
            plan.problems.append(f"{shown_xacro} has no <ros2_control> tag with use_mock_hardware:={mock}")
            description_ok = False
        for info in infos:
            plugin = info.hardware_plugin_name or ""
            if mock == "true" and plugin != _MOCK:
                plan.problems.append(f"{shown_xacro}: with use_mock_hardware:=true, <ros2_control name="
                                     f"{_shown_name(info.name)}> names {_shown_name(plugin or 'no plugin')}, not "
                                     f"{_MOCK}: the switch is not finished")
            elif plugin:
                _plugin(plan, plugin, f"{shown_xacro} (<ros2_control name={_shown_name(info.name)}>)")
    try:
        config = load_controllers_yaml(source.controllers)
    except ParameterError as exc:
        if exc.parameter == "type" or exc.parameter.endswith(".type"):  # a controller type that is no plugin name
            where = exc.parameter if exc.parameter != "type" else f"{exc.owner}.type"
            plan.invalid_names.append(f"{shown_yaml}: {_shown_name(where)} is not a plugin name")
        else:
            plan.problems.append(f"{shown_yaml} does not load: {exc}")
        return plan
    for name, type_name in config.controller_types.items():
        problem = node_name_problem(name)
        if problem:
            plan.invalid_names.append(f"{shown_yaml}: controller name {_shown_name(name)} is not a valid ROS node "
                                      f"name ({problem})")
            continue
        _plugin(plan, type_name, f"{shown_yaml} (controller '{name}')")
    for package in description_packages(sorted(p for p in source.urdf.rglob("*") if p.is_file()), ""):
        if package_name_problem(package):
            plan.invalid_names.append(f"{source.shown}/{_DESCRIPTION.as_posix()} finds package "
                                      f"{_shown_name(package)} ($(find ...) or package://), not a ROS package name")
    plan.broadcasters = [n for n, t in config.controller_types.items() if t.endswith(_BROADCASTER_SUFFIXES)]
    plan.robot_controllers = [n for n in config.controller_types if n not in plan.broadcasters]
    if not plan.robot_controllers:
        only = f" (only {', '.join(plan.broadcasters)})" if plan.broadcasters else ""
        plan.problems.append(f"{shown_yaml} declares no robot controller{only}: the launch file's robot_controller "
                             "needs at least one to choose from")
    if description_ok:
        args = {"use_mock_hardware": "true", "mock_sensor_commands": "false"}
        for finding in lint_controllers(source.controllers, xacro, args):
            if finding.level == "error":
                line = f":{finding.line}" if finding.line else ""
                plan.problems.append(f"{shown_yaml}{line}: {finding.where}: {finding.message} (lint)")
    return plan


def export_problems(source: ExportSource) -> list[str]:
    """Why ``source`` is not ready to export, one sentence per problem naming the file; empty when it is ready.

    Checked without running anything (about a second): see the module's documentation for the list (names ROS
    would not take come first).
    """
    plan = _check(source)
    return plan.invalid_names + plan.problems


def _choose(task: int | None) -> tuple[ExportSource, _Plan, list[int]]:
    """The source to export: ``task``'s, or the most advanced ready one; and the tasks that are ready.

    Raises:
        CourseError: If ``task`` has nothing to export, or the chosen source is not ready (every problem listed).
    """
    sources = export_sources()
    if not sources:
        raise CourseError("task", task, f"no task on the '{tracks.current_track()}' track has a description "
                          f"({_DESCRIPTION.as_posix()}/{_XACRO}) and a bringup ({_BRINGUP_CONFIG.as_posix()}/*.yaml) "
                          "to export; nothing was written")
    if task is not None:
        chosen = [s for s in sources if s.task == task]
        if not chosen:
            raise CourseError("task", task, f"task {task} has no description and bringup to export; nothing was "
                              "written", [s.task for s in sources])
        plan = _check(chosen[0])
        if plan.invalid_names:
            raise CourseError("task", task, _refused_names([plan]))
        if plan.problems:
            raise CourseError("task", task, _not_ready([(chosen[0], plan)], chosen=True, tasks=[s.task for s in sources]))
        return chosen[0], plan, [task]
    plans = [(s, _check(s)) for s in sources]
    ready = [(s, p) for s, p in plans if not p.problems and not p.invalid_names]
    if not ready and any(p.invalid_names for _, p in plans):
        raise CourseError("task", None, _refused_names([p for _, p in plans]))
    if not ready:
        raise CourseError("task", None, _not_ready(list(reversed(plans)), chosen=False, tasks=[s.task for s in sources]))
    source, plan = ready[-1]
    return source, plan, [s.task for s, _ in ready]


def _shown_name(name: object, limit: int = 60) -> str:
    """A name from a learner's file as it goes into a message: quoted, escaped (no line break or control character
    reaches the terminal) and cut to ``limit`` characters."""
    text = repr(str(name))
    return text if len(text) <= limit else text[: limit - 4] + "...'"


def _refused_names(plans: list[_Plan]) -> str:
    """One line: every name that is not what ROS takes, and the rules they break."""
    names = [n for plan in plans for n in plan.invalid_names]
    rules = [rule for word, rule in (("plugin name", PLUGIN_NAME_RULE), ("node name", NODE_NAME_RULE),
                                     ("package name", PACKAGE_NAME_RULE)) if any(word in n for n in names)]
    return f"export refused, nothing was written: {'; '.join(names)}. Rules: {'; '.join(rules)}"


def _not_ready(plans: list[tuple[ExportSource, _Plan]], *, chosen: bool, tasks: list[int]) -> str:
    lines = []
    if chosen:
        source, plan = plans[0]
        lines.append(f"task {source.task} ({source.shown}) is not finished for export; nothing was written:")
        lines += [f"  - {p}" for p in plan.problems]
        others = [str(t) for t in tasks if t != source.task]
        lines.append(f"Finish task {source.task} and export again (`rrbot-workshop grade {source.task}` checks it)"
                     + (f", or export another task with --task N (these have a description and bringup: "
                        f"{', '.join(others)})." if others else "."))
    else:
        lines.append(f"none of the tasks with a description and bringup ({', '.join(map(str, tasks))}) is finished "
                     "for export; nothing was written:")
        for source, plan in plans:
            lines.append(f"  task {source.task} ({source.shown}):")
            lines += [f"    - {p}" for p in plan.problems]
        lines.append("Finish one of them and export again (`rrbot-workshop grade N` checks task N).")
    return "\n".join(lines)


def export_ros2(target: str | Path, *, force: bool = False, task: int | None = None) -> Ros2Export:
    """Write the learner's description and bringup of one task as ROS 2 packages under ``target``.

    Everything is checked and prepared before the first file is written (the target, the task's files, the controller
    names, the generated files parsing, every launch argument), so a refused export leaves the disk as it was; an
    error while writing removes what this call created.

    Args:
        target: Output folder; it must not exist yet, or be empty, unless ``force``.
        force: Write into an existing non-empty folder (files of the same name are replaced). It does not export
            unfinished work.
        task: The task whose files are exported (see :func:`export_sources`); default the most advanced one that is
            ready.

    Returns:
        What was exported (which task) and what was copied and generated.

    Raises:
        CourseError: If ``target`` is empty, a file, not writable or a non-empty folder (and not ``force``); no task
            has files to export, or ``task`` has none; a name in the chosen task's files is not one ROS takes (one
            line, see the module's documentation); the chosen task's files are not ready (every problem is listed,
            see :func:`export_problems`); or writing fails.
    """
    root = check_target(target)
    if root.is_dir() and any(root.iterdir()) and not force:
        raise CourseError("export target", str(root), "is not empty; choose a new folder (or pass --force)")
    source, plan, ready = _choose(task)
    result = Ros2Export(root=root, task=source.task, task_folder=source.shown, ready_tasks=ready,
                        robot_controllers=plan.robot_controllers, to_port=plan.to_port)
    description = root / "controlko_description"
    bringup = root / "controlko_bringup"

    # ---- plan: what is copied from where, and what is generated (nothing is written yet)
    copies: dict[Path, Path] = {}
    urdf_files = sorted(p for p in source.urdf.rglob("*") if p.is_file() and "__pycache__" not in p.parts)
    for src in urdf_files:
        copies[description / "urdf" / src.relative_to(source.urdf)] = src
    copies[bringup / "config" / source.controllers.name] = source.controllers

    references: list[str] = []
    for ported, relative in ((7, "controlko_hardware_interface"), (8, "controlko_controllers")):
        try:
            folder = tracks.task_dir(ported)
        except CourseError:
            continue
        for src in sorted(folder.rglob("*.py")):
            dst = root / "python_reference" / relative / src.relative_to(folder)
            copies[dst] = src
            stubs = tracks.file_stubs(src)
            note = (f" (unfinished: {len(stubs)} stub(s) left, the first {stubs[0][1]}() at line {stubs[0][0]}; "
                    f"finish task {ported} first)") if stubs else ""
            references.append(f"`python_reference/{dst.relative_to(root / 'python_reference').as_posix()}`{note}")

    launch = launch_file(source.controllers.name, plan.robot_controllers, plan.broadcasters)
    # checked again where the names are written: none reaches a manifest unless ROS takes it
    refused = [_shown_name(d) for d in [*plan.plugin_packages, *description_packages(urdf_files, "")] if package_name_problem(d)]
    if refused:
        raise CourseError("task", source.task, f"export refused, nothing was written: {', '.join(refused)} would be "
                          f"written as package dependencies; {PACKAGE_NAME_RULE}")
    result.exec_depends = {
        "controlko_description": description_packages(urdf_files, "controlko_description"),
        "controlko_bringup": sorted((set(launch_packages(launch)) | set(plan.plugin_packages)) - {"controlko_bringup"}),
    }
    files = {
        description / "package.xml": package_xml(
            "controlko_description", "RRBot description (xacro, ros2_control tag), from rrbot_workshop.",
            "ament_cmake", result.exec_depends["controlko_description"],
        ),
        description / "CMakeLists.txt": cmakelists("controlko_description", ["urdf"]),
        bringup / "package.xml": package_xml(
            "controlko_bringup", "RRBot bringup: controllers YAML and launch file, from rrbot_workshop.",
            "ament_cmake", result.exec_depends["controlko_bringup"],
        ),
        bringup / "CMakeLists.txt": cmakelists("controlko_bringup", ["config", "launch"]),
        bringup / "launch" / "rrbot.launch.py": launch,
        root / "README.md": _readme(result, references),
    }
    for path, text in files.items():
        check_generated(path.name, text)

    # ---- write
    created = Created()
    try:
        created.folder(root)
        for dst, src in copies.items():
            created.folder(dst.parent)
            shutil.copyfile(src, dst)
            created.files.append(dst)
            result.copied[dst] = src
        for path, text in files.items():
            created.folder(path.parent)
            path.write_text(text)
            created.files.append(path)
            result.generated.append(path)
    except OSError as exc:
        created.undo()
        raise CourseError("export target", str(root), f"writing failed ({exc.strerror or exc}); what this export "
                          "had written was removed") from exc
    return result
