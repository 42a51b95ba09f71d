"""ROS 2 packages written from files: ``package.xml``, ``CMakeLists.txt``, a launch file, and the checks they pass.

:mod:`rrbot_workshop.course.ros2_export` uses these to write the learner's work as ament packages. Every generated
file is checked to parse before anything is written (:func:`check_generated`), every ``DeclareLaunchArgument`` to
be one that ``ros2 launch`` accepts (:func:`launch_argument_problem`), and :class:`Created` takes back what a
failed write had made.
"""

from __future__ import annotations

import ast
import os
import re
import shutil
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path

from rrbot_workshop.exceptions import CourseError

__all__ = ["package_xml", "package_xml_values", "package_name_problem", "plugin_name_problem", "PACKAGE_NAME_RULE",
           "PLUGIN_NAME_RULE", "cmakelists", "launch_file", "check_generated", "launch_argument_problem",
           "check_target", "launch_packages", "description_packages", "Created"]

_MAINTAINER = "learner@example.com"
#: The longest file or folder name most file systems take, in bytes.
_NAME_MAX = 255
#: Executables the generated launch file finds, and the package that installs each.
_EXECUTABLE_PACKAGES = {"xacro": "xacro"}
_COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)
_FIND = re.compile(r"\$\(find\s+([A-Za-z0-9_]+)\)|package://([A-Za-z0-9_]+)/")


#: The rule of REP 144 for a ROS package name, in one sentence for error messages.
PACKAGE_NAME_RULE = ("a ROS package name (REP 144) is at least two characters: lowercase letters, digits and "
                     "underscores, starting with a letter, never two underscores in a row (e.g. 'controlko_bringup')")
#: The form of a plugin name as pluginlib looks it up, in one sentence for error messages.
PLUGIN_NAME_RULE = ("a plugin name is '<package>/<Class>': a ROS package name, one '/', and a C++ class name of "
                    "letters, digits and underscores not starting with a digit (e.g. 'mock_components/GenericSystem')")
_PACKAGE_NAME = re.compile(r"[a-z](?:[a-z0-9]|_(?!_))*\Z")
_CLASS_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
#: The longest name checked [characters]; anything longer is refused without being matched.
_NAME_MAX_CHARS = 255


def package_name_problem(name: object) -> str:
    """Why ``name`` is not a valid ROS package name (REP 144), or ``""`` if it is."""
    if not isinstance(name, str):
        return f"it is a {type(name).__name__}, not text"
    if len(name) > _NAME_MAX_CHARS:
        return f"it has {len(name)} characters, more than {_NAME_MAX_CHARS}"
    if len(name) < 2 or not _PACKAGE_NAME.match(name):
        return f"{name!r} is not one"
    return ""


def plugin_name_problem(name: object) -> str:
    """Why ``name`` is not a plugin name of the ``<package>/<Class>`` form pluginlib looks up, or ``""`` if it is."""
    if not isinstance(name, str):
        return f"it is a {type(name).__name__}, not text"
    if len(name) > 2 * _NAME_MAX_CHARS:
        return f"it has {len(name)} characters, more than {2 * _NAME_MAX_CHARS}"
    package, slash, cls = name.partition("/")
    if not slash or package_name_problem(package) or not _CLASS_NAME.match(cls):
        return f"{name!r} is not of that form"
    return ""


#: The prolog of every package.xml: constant text, no value of the package's is ever formatted into it.
_PACKAGE_XML_PROLOG = ('<?xml version="1.0"?>\n<?xml-model href="http://download.ros.org/schema/package_format3.xsd" '
                       'schematypens="http://www.w3.org/2001/XMLSchema"?>\n')


def package_xml(name: str, description: str, build_type: str, exec_depends: list[str]) -> str:
    """A ``package.xml`` (format 3), built with :mod:`xml.etree.ElementTree`: every value is an element's text,
    escaped by the library.

    Args:
        name: The package's name.
        description: One sentence.
        build_type: ``ament_cmake`` or ``ament_python``.
        exec_depends: The packages it needs at run time.

    Raises:
        CourseError: If ``name`` or a dependency is not a ROS package name (:func:`package_name_problem`).
    """
    for role, value in [("package name", name), *(("exec_depend", d) for d in exec_depends)]:
        problem = package_name_problem(value)
        if problem:
            raise CourseError("package.xml", value, f"package.xml not written: its {role} {str(value)[:80]!r} is not "
                              f"a ROS package name ({problem}); {PACKAGE_NAME_RULE}")
    package = ET.Element("package", {"format": "3"})
    for tag, text in (("name", name), ("version", "0.1.0"), ("description", description)):
        ET.SubElement(package, tag).text = text
    ET.SubElement(package, "maintainer", {"email": _MAINTAINER}).text = "rrbot_workshop learner"
    ET.SubElement(package, "license").text = "Apache-2.0"
    ET.SubElement(package, "buildtool_depend").text = "ament_cmake"
    for dependency in exec_depends:
        ET.SubElement(package, "exec_depend").text = dependency
    ET.SubElement(ET.SubElement(package, "export"), "build_type").text = build_type
    ET.indent(package, space="  ")
    return _PACKAGE_XML_PROLOG + ET.tostring(package, encoding="unicode") + "\n"


def package_xml_values(text: str) -> dict[str, list[str]]:
    """The text of each element of a ``package.xml`` by tag (``{"name": [...], "exec_depend": [...]}``), read back
    with a parser that keeps processing instructions and comments.

    Raises:
        CourseError: If the text does not parse, or holds a processing instruction or comment after its prolog.
    """
    builder = ET.TreeBuilder(insert_comments=True, insert_pis=True)
    try:
        parser = ET.XMLParser(target=builder)
        parser.feed(text)
        root = parser.close()
    except ET.ParseError as exc:
        raise CourseError("package.xml", text[:80], f"the generated package.xml does not parse ({exc})") from exc
    values: dict[str, list[str]] = {}
    for element in root.iter():
        if not isinstance(element.tag, str):
            raise CourseError("package.xml", text[:80], "the generated package.xml holds a processing instruction "
                              "or comment in its body")
        values.setdefault(element.tag, []).append(element.text or "")
    return values


def cmakelists(name: str, folders: list[str]) -> str:
    return f"""cmake_minimum_required(VERSION 3.16)
project({name})

find_package(ament_cmake REQUIRED)

install(
  DIRECTORY {" ".join(folders)}
  DESTINATION share/${{PROJECT_NAME}}
)

ament_package()
"""


def launch_file(controllers_file: str, robot_controllers: list[str], broadcasters: list[str]) -> str:
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
        DeclareLaunchArgument("robot_controller", default_value={default!r}, choices={others}),
        DeclareLaunchArgument("use_mock_hardware", default_value="true"),
        DeclareLaunchArgument("mock_sensor_commands", default_value="false"),
        OpaqueFunction(function=_nodes),
    ])
'''


def check_generated(name: str, text: str) -> None:
    """Generated files must parse, or the export fails here (before anything is written) instead of in colcon."""
    if name == "package.xml":
        package_xml_values(text)
    try:
        if name.endswith(".xml"):
            ET.fromstring(text)
        elif name.endswith(".py"):
            compile(text, name, "exec", flags=ast.PyCF_ONLY_AST)
    except (SyntaxError, ValueError, ET.ParseError) as exc:  # our template failed: say so, write nothing
        raise CourseError("export", name, f"the generated {name} does not parse ({exc}); nothing was written") from exc
    if name.endswith(".launch.py"):
        problem = launch_argument_problem(text)
        if problem:
            raise CourseError("export", name, f"the generated {name} would be refused by ros2 launch ({problem}); "
                              "nothing was written")


def launch_argument_problem(text: str) -> str:
    """Why ``ros2 launch`` would refuse a ``DeclareLaunchArgument`` of the launch file ``text``, or ``""``.

    Every call must give the name and ``default_value`` as text literals; ``choices``, when given, a non-empty list
    of text literals that holds the default (launch raises on an empty ``choices`` and on a default outside them).
    """
    for node in ast.walk(ast.parse(text)):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "DeclareLaunchArgument"):
            continue
        if not node.args or not isinstance(node.args[0], ast.Constant) or not isinstance(node.args[0].value, str):
            return f"a DeclareLaunchArgument at line {node.lineno} has no literal name"
        name = node.args[0].value
        keywords = {k.arg: k.value for k in node.keywords}
        default = keywords.get("default_value")
        if not isinstance(default, ast.Constant) or not isinstance(default.value, str):
            return f"launch argument '{name}' has no text default_value"
        if "choices" in keywords:
            try:
                choices = ast.literal_eval(keywords["choices"])
            except ValueError:
                return f"launch argument '{name}': choices must be a literal list"
            if not isinstance(choices, list) or not choices or not all(isinstance(c, str) for c in choices):
                return f"launch argument '{name}' has choices={choices!r}: launch refuses an empty or non-text list"
            if default.value not in choices:
                return f"launch argument '{name}': its default {default.value!r} is not among its choices {choices}"
    return ""


def check_target(target: object) -> Path:
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


def _unique(items: Iterable[str]) -> list[str]:
    return list(dict.fromkeys(items))


def _text(node: ast.expr | None) -> str | None:
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


def launch_packages(text: str) -> list[str]:
    """The packages a launch file needs at run time, read from its code."""
    found: list[str | None] = []
    tree = ast.parse(text)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.append(node.module.split(".", 1)[0])
        elif isinstance(node, ast.Import):
            found += [alias.name.split(".", 1)[0] for alias in node.names]
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            keywords = {k.arg: k.value for k in node.keywords}
            if node.func.id == "Node":
                found.append(_text(keywords.get("package")))
            elif node.func.id == "FindPackageShare" and node.args:
                found.append(_text(node.args[0]))
            elif node.func.id == "FindExecutable":
                executable = _text(keywords.get("name"))
                found.append(_EXECUTABLE_PACKAGES.get(executable, executable) if executable else None)
    return _unique(["ros2launch", *(f for f in found if f)])  # ros2launch: the `ros2 launch` command that runs it


def description_packages(files: Iterable[Path], own: str) -> list[str]:
    found = ["xacro"]
    for path in files:
        if path.suffix in (".xacro", ".urdf"):
            text = _COMMENT.sub("", path.read_text(encoding="utf-8", errors="replace"))
            for match in _FIND.finditer(text):
                found.append(match.group(1) or match.group(2))
    return sorted(set(found) - {own})


class Created:
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
