"""``rrbot-workshop export --ros2 DIR``: the learner's work as ROS 2 packages, laid out as the original workshop's.

What a learner wrote in the course is meant to run on a real ROS 2 Jazzy install. This writes two ament packages
next to each other, named as the ROSCon 2022 workshop named them:

``controlko_description``
    ``urdf/`` with the learner's xacro files, copied byte for byte from the latest task that has them
    (task 2's description, which has the hardware switch, else task 1's); ``package.xml`` and
    ``CMakeLists.txt`` (ament_cmake, installs ``urdf/``).
``controlko_bringup``
    ``config/`` with the learner's controllers YAML, byte for byte; ``launch/rrbot.launch.py``, the
    equivalent of the learner's ``bringup.py`` (xacro -> ``robot_state_publisher``, ``ros2_control_node``
    with the YAML, spawners for the joint state broadcaster and the chosen robot controller, the other robot
    controllers spawned ``--inactive``); ``package.xml`` and ``CMakeLists.txt``.

A ``README.md`` at the top says how to build it with colcon and what stays to be written in C++ (the hardware
interface of task 7 and the controller of task 8: their Python versions are copied to ``python_reference/`` to
port from). Nothing here needs ROS to run: the generated files are checked to parse as XML and Python.
"""

from __future__ import annotations

import ast
import os
import shutil
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError, ParameterError
from rrbot_workshop.middleware.names import NODE_NAME_RULE, node_name_problem
from rrbot_workshop.middleware.params import load_controllers_yaml

__all__ = ["Ros2Export", "export_ros2"]

_MAINTAINER = "learner@example.com"
#: Broadcaster types: spawned first, never the "robot controller".
_BROADCASTER_SUFFIXES = ("Broadcaster",)
#: The longest file or folder name most file systems take, in bytes.
_NAME_MAX = 255


@dataclass
class Ros2Export:
    """What :func:`export_ros2` wrote.

    Attributes:
        root: The output folder.
        copied: Learner files copied byte for byte: destination -> source.
        generated: Files written from templates.
        robot_controllers: Controllers the launch file can start as the robot controller, the default first.
    """

    root: Path
    copied: dict[Path, Path] = field(default_factory=dict)
    generated: list[Path] = field(default_factory=list)
    robot_controllers: list[str] = field(default_factory=list)


def _package_xml(name: str, description: str, build_type: str, exec_depends: list[str]) -> str:
    depends = "\n".join(f"  <exec_depend>{d}</exec_depend>" for d in exec_depends)
    return f"""<?xml version="1.0"?>
<?xml-model href="http://download.ros.org/schema/package_format3.xsd" schematypens="http://www.w3.org/2001/XMLSchema"?>
<package format="3">
  <name>{name}</name>
  <version>0.1.0</version>
  <description>{description}</description>
  <maintainer email="{_MAINTAINER}">rrbot_workshop learner</maintainer>
  <license>Apache-2.0</license>

  <buildtool_depend>ament_cmake</buildtool_depend>

{depends}

  <export>
    <build_type>{build_type}</build_type>
  </export>
</package>
"""


def _cmakelists(name: str, folders: list[str]) -> str:
    return f"""cmake_minimum_required(VERSION 3.16)
project({name})

find_package(ament_cmake REQUIRED)

install(
  DIRECTORY {" ".join(folders)}
  DESTINATION share/${{PROJECT_NAME}}
)

ament_package()
"""


def _launch_file(controllers_file: str, robot_controllers: list[str], broadcasters: list[str]) -> str:
    # Names enter the code only as Python literals (repr), never inside a docstring or a string being written:
    # whatever a name holds, it stays data. (They are also checked as ROS node names before anything is written.)
    default = robot_controllers[0] if robot_controllers else ""
    others = repr(list(robot_controllers))
    return f'''"""Bring RRBot up: the launch file equivalent to the course's ``bringup.py``.

Arguments: ``robot_controller`` (one of ROBOT_CONTROLLERS below, default the first), ``use_mock_hardware``
(default true), ``mock_sensor_commands`` (default false). The broadcasters start first; the robot
controller once they are active; the other robot controllers are loaded and configured, inactive.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.substitutions import Command, FindExecutable, LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

ROBOT_CONTROLLERS = {others}
BROADCASTERS = {list(broadcasters)!r}


def _spawner(arguments):
    return Node(
        package="controller_manager",
        executable="spawner",
        arguments=[*arguments, "--controller-manager", "/controller_manager", "--param-file", CONTROLLERS],
    )


CONTROLLERS = PathJoinSubstitution([FindPackageShare("controlko_bringup"), "config", {controllers_file!r}])


def _nodes(context):
    robot_controller = LaunchConfiguration("robot_controller").perform(context)
    if robot_controller not in ROBOT_CONTROLLERS:
        raise RuntimeError(f"robot_controller must be one of {{ROBOT_CONTROLLERS}}, not '{{robot_controller}}'")
    description = ParameterValue(
        Command([
            PathJoinSubstitution([FindExecutable(name="xacro")]), " ",
            PathJoinSubstitution([FindPackageShare("controlko_description"), "urdf", "rrbot.urdf.xacro"]),
            " use_mock_hardware:=", LaunchConfiguration("use_mock_hardware"),
            " mock_sensor_commands:=", LaunchConfiguration("mock_sensor_commands"),
        ]),
        value_type=str,
    )
    nodes = [
        Node(package="robot_state_publisher", executable="robot_state_publisher",
             parameters=[{{"robot_description": description}}]),
        # Jazzy's controller manager reads the description from robot_state_publisher's topic.
        Node(package="controller_manager", executable="ros2_control_node", parameters=[CONTROLLERS],
             remappings=[("~/robot_description", "/robot_description")], output="both"),
    ]
    broadcasters = [_spawner([name]) for name in BROADCASTERS]
    robot = [_spawner([robot_controller])]
    robot += [_spawner([other, "--inactive"]) for other in ROBOT_CONTROLLERS if other != robot_controller]
    nodes += broadcasters
    if broadcasters:  # the robot controller starts once the joint states are published
        nodes.append(RegisterEventHandler(OnProcessExit(target_action=broadcasters[-1], on_exit=robot)))
    else:
        nodes += robot
    return nodes


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("robot_controller", default_value={default!r}, choices=ROBOT_CONTROLLERS),
        DeclareLaunchArgument("use_mock_hardware", default_value="true"),
        DeclareLaunchArgument("mock_sensor_commands", default_value="false"),
        OpaqueFunction(function=_nodes),
    ])
'''


def _readme(robot_controllers: list[str], references: list[str]) -> str:
    ported = "\n".join(f"- `python_reference/{r}`" for r in references) or "- (none of tasks 7 and 8 written yet)"
    return f"""# Your RRBot, as ROS 2 packages

Written by `rrbot-workshop export --ros2` from your course files. The xacro files and the controllers YAML are
yours, unchanged; the package manifests, CMake files and the launch file were generated to match them.

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

The course's Python hardware interface (task 7, `controlko_hardware_interface/RRBotHardwareInterface`) and the
displacement controller (task 8, `controlko_controllers/DisplacementController`) are plugins: on a real robot
they are C++ classes exported with `pluginlib`. Port them method by method (the names are the same,
`on_configure`, `read`, `write`, `update`, ...), then build them as `controlko_hardware_interface` and
`controlko_controllers`. Your Python versions, to port from:

{ported}
"""


def _check_generated(name: str, text: str) -> None:
    """Generated files must parse, or the export fails here (before anything is written) instead of in colcon."""
    try:
        if name.endswith(".xml"):
            ET.fromstring(text.split("?>", 2)[-1] if text.startswith("<?xml") else text)
        elif name.endswith(".py"):
            compile(text, name, "exec", flags=ast.PyCF_ONLY_AST)
    except (SyntaxError, ValueError, ET.ParseError) as exc:  # our template failed: say so, write nothing
        raise CourseError("export", name, f"the generated {name} does not parse ({exc}); nothing was written") from exc


def _check_target(target: object) -> Path:
    """The output folder, resolved, or one clear CourseError (empty, a file, not writable, a name too long)."""
    if not isinstance(target, str | os.PathLike):
        raise CourseError("export target", target, f"must be a folder path, got {type(target).__name__}")
    text = os.fspath(target)
    if not isinstance(text, str) or not text.strip():
        raise CourseError("export target", text, "the target folder is empty text; give the path of a new folder to write into")
    if "\x00" in text or "\n" in text or "\r" in text:
        raise CourseError("export target", text, "contains a NUL or line break; give an ordinary folder path")
    try:
        root = Path(text).expanduser().resolve()
        exists, is_dir = root.exists(), root.is_dir()
        if is_dir:
            non_empty = any(root.iterdir())
    except (OSError, RuntimeError) as exc:
        raise CourseError("export target", text, f"cannot be used: {getattr(exc, 'strerror', None) or exc}") from exc
    if exists and not is_dir:
        raise CourseError("export target", str(root), "is a file, not a folder; choose a new folder")
    too_long = [part for part in root.parts if len(part.encode()) > _NAME_MAX]
    if too_long:
        raise CourseError("export target", str(root), f"has a folder name of {len(too_long[0].encode())} bytes; "
                                                      f"file systems allow at most {_NAME_MAX}")
    if exists and non_empty:
        return root
    parent = root if exists else next((p for p in root.parents if p.exists()), root.anchor and Path(root.anchor))
    if not isinstance(parent, Path) or not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
        raise CourseError("export target", str(root), f"cannot be written: {parent} is not a writable folder")
    return root


def _description_source() -> Path:
    for task in (2, 1):
        try:
            folder = tracks.task_dir(task) / "rrbot_description" / "urdf"
        except CourseError:
            continue
        if (folder / "rrbot.urdf.xacro").is_file():
            return folder
    raise CourseError("task", 1, "no rrbot_description/urdf/rrbot.urdf.xacro in task 2 or task 1 to export")


def export_ros2(target: str | Path, *, force: bool = False) -> Ros2Export:
    """Write the learner's description and bringup as ROS 2 packages under ``target``.

    Everything is checked and prepared before the first file is written (the target, the learner's files, the
    controller names, the generated files parsing), so a refused export leaves the disk as it was; an error while
    writing removes what this call created.

    Args:
        target: Output folder; it must not exist yet, or be empty, unless ``force``.
        force: Write into an existing non-empty folder (files of the same name are replaced).

    Returns:
        What was copied and generated.

    Raises:
        CourseError: If ``target`` is empty, a file, not writable or a non-empty folder (and not ``force``); the
            learner's description or controllers YAML is missing or unreadable; a controller name in it is not a
            valid ROS node name; or writing fails.
    """
    root = _check_target(target)
    if root.is_dir() and any(root.iterdir()) and not force:
        raise CourseError("export target", str(root), "is not empty; choose a new folder (or pass --force)")
    result = Ros2Export(root=root)
    description = root / "controlko_description"
    bringup = root / "controlko_bringup"

    # ---- plan: what is copied from where, and what is generated (nothing is written yet)
    copies: dict[Path, Path] = {}
    urdf_src = _description_source()
    for src in sorted(p for p in urdf_src.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        copies[description / "urdf" / src.relative_to(urdf_src)] = src
    yaml_src = tracks.task_dir(2) / "rrbot_bringup" / "config" / "rrbot_controllers.yaml"
    if not yaml_src.is_file():
        raise CourseError("task", 2, f"no controllers YAML at {yaml_src} to export")
    copies[bringup / "config" / yaml_src.name] = yaml_src
    try:
        config = load_controllers_yaml(yaml_src)
    except ParameterError as exc:
        raise CourseError("controllers file", str(yaml_src), f"cannot be exported: {exc}") from exc
    for name in config.controller_types:
        problem = node_name_problem(name)
        if problem:
            raise CourseError("controller", name, f"{yaml_src}: controller name {name!r} is not a valid ROS node name: "
                              f"{problem}; {NODE_NAME_RULE}. Rename it; nothing was written")
    broadcasters = [n for n, t in config.controller_types.items() if t.endswith(_BROADCASTER_SUFFIXES)]
    result.robot_controllers = [n for n in config.controller_types if n not in broadcasters]

    references: list[str] = []
    for task, relative in ((7, "controlko_hardware_interface"), (8, "controlko_controllers")):
        try:
            folder = tracks.task_dir(task)
        except CourseError:
            continue
        for src in sorted(folder.rglob("*.py")):
            dst = root / "python_reference" / relative / src.relative_to(folder)
            copies[dst] = src
            references.append(str(dst.relative_to(root / "python_reference")))

    files = {
        description / "package.xml": _package_xml(
            "controlko_description", "RRBot description (xacro, ros2_control tag), from rrbot_workshop.",
            "ament_cmake", ["xacro", "robot_state_publisher"],
        ),
        description / "CMakeLists.txt": _cmakelists("controlko_description", ["urdf"]),
        bringup / "package.xml": _package_xml(
            "controlko_bringup", "RRBot bringup: controllers YAML and launch file, from rrbot_workshop.",
            "ament_cmake",
            ["controlko_description", "controller_manager", "ros2_controllers", "robot_state_publisher", "xacro"],
        ),
        bringup / "CMakeLists.txt": _cmakelists("controlko_bringup", ["config", "launch"]),
        bringup / "launch" / "rrbot.launch.py": _launch_file(yaml_src.name, result.robot_controllers, broadcasters),
        root / "README.md": _readme(result.robot_controllers, references),
    }
    for path, text in files.items():
        _check_generated(path.name, text)

    # ---- write
    created = _Created()
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


class _Created:
    """What an export created, to remove it again if writing fails half-way."""

    def __init__(self) -> None:
        self.folders: list[Path] = []
        self.files: list[Path] = []

    def folder(self, path: Path) -> None:
        missing = [p for p in (path, *path.parents) if not p.exists()]
        for p in reversed(missing):
            p.mkdir()
            self.folders.append(p)

    def undo(self) -> None:
        for f in reversed(self.files):
            f.unlink(missing_ok=True)
        for d in reversed(self.folders):
            shutil.rmtree(d, ignore_errors=True)
