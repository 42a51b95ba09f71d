"""Helpers of the package-path tests: the state of a folder tree (to prove a tool left it untouched), small packages
written in a test's tmp folder, and a check that an install view is made of real folders and links to files only."""

from __future__ import annotations

import hashlib
import os
import stat
from pathlib import Path

PACKAGE_XML = ('<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n  <version>0.0.1</version>\n'
               "  <description>test</description>\n  <license>Apache-2.0</license>\n"
               "  <buildtool_depend>ament_cmake</buildtool_depend>\n</package>\n")

#: A one-joint robot whose ros2_control tag comes from ``$(find <name>)/urdf/control.xacro``.
URDF = """<?xml version="1.0"?>
<robot name="{name}" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find {name})/urdf/control.xacro"/>
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <link name="arm"/>
  <xacro:control/>
</robot>
"""
CONTROL = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="control">
    <ros2_control name="Arm" type="system">
      <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
      <joint name="j1"><command_interface name="position"/><state_interface name="position"/></joint>
    </ros2_control>
  </xacro:macro>
</robot>
"""
#: Controllers YAML whose update rate [Hz] tells which file a lookup found.
CONTROLLERS = """controller_manager:
  ros__parameters:
    update_rate: {rate}
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
"""


def tree_state(root: Path) -> dict[str, tuple[object, ...]]:
    """Every entry below ``root`` and ``root`` itself, links not followed: its type and mode, and the SHA-256 of a
    file's content or a link's target text."""
    state: dict[str, tuple[object, ...]] = {}

    def record(path: str) -> None:
        info = os.lstat(path)
        rel = os.path.relpath(path, root)
        mode = stat.S_IMODE(info.st_mode)
        if stat.S_ISLNK(info.st_mode):
            state[rel] = ("link", os.readlink(path))
        elif stat.S_ISDIR(info.st_mode):
            state[rel] = ("folder", mode)
        elif stat.S_ISREG(info.st_mode):
            with open(path, "rb") as handle:
                state[rel] = ("file", mode, hashlib.sha256(handle.read()).hexdigest())
        else:
            state[rel] = ("other", stat.S_IFMT(info.st_mode), mode)

    record(str(root))
    for folder, dirs, files in os.walk(root, followlinks=False):
        for name in dirs + files:
            record(os.path.join(folder, name))
    return state


def write_package(folder: Path, name: str, files: dict[str, str], cmake: str | None = None) -> Path:
    """A package ``name`` in ``folder``: ``package.xml``, ``CMakeLists.txt`` (if given) and ``files``."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(PACKAGE_XML.format(name=name))
    if cmake is not None:
        (folder / "CMakeLists.txt").write_text(cmake)
    for rel, text in files.items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_text(text)
    return folder


def view_files(view: Path) -> dict[str, bytes]:
    """Installed path -> content of every file of an install view, after checking how it is built: every folder a real
    folder, every link a link to a file (an AssertionError names the entry that is not)."""
    out: dict[str, bytes] = {}
    for folder, dirs, files in os.walk(view, followlinks=False):
        for name in dirs:
            path = os.path.join(folder, name)
            assert not os.path.islink(path), f"{path} is a link to a folder"
        for name in files:
            path = os.path.join(folder, name)
            assert os.path.isfile(path), f"{path} is not a file, nor a link to one"
            out[os.path.relpath(path, view)] = Path(path).read_bytes()
    return out
