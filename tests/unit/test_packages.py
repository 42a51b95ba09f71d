"""Packages found as ROS finds them: the package path, package.xml names, CMake install rules, installed trees.

The packages under tests/unit/data/packages/src are this project's own, in the layouts ROS 2 packages use (see the
README there): ``tinybot_description`` (urdf/ and meshes/) and ``tinybot_example`` in the folder ``example_tiny``
(description/urdf, description/ros2_control, bringup/config, moved by install rules).
"""

from __future__ import annotations

import logging
import os
import shutil
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import systems
from rrbot_workshop.bringup.inputs import description_to_urdf
from rrbot_workshop.description import packages, process_xacro, resolve_package_uri
from rrbot_workshop.description.packages import PACKAGE_PATH_ENV, parse_install_rules
from rrbot_workshop.exceptions import DescriptionError, ParameterError
from rrbot_workshop.msgs import Float64MultiArray

SRC = Path(__file__).resolve().parent / "data" / "packages" / "src"
EXAMPLE = SRC / "example_tiny"
DESCRIPTION = SRC / "tinybot_description"
CONTROLLERS = ["joint_state_broadcaster", "position_controller", "wrist_ft_broadcaster"]


@pytest.fixture(autouse=True)
def _clean(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(PACKAGE_PATH_ENV, raising=False)
    packages.clear_cache()
    for system in list(systems().values()):
        system.shutdown()


def _package_xml(name: str) -> str:
    return (f'<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n  <version>0.0.1</version>\n'
            "  <description>test</description>\n  <license>Apache-2.0</license>\n</package>\n")


def _make_package(folder: Path, name: str, files: dict[str, str] | None = None, cmake: str | None = None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(_package_xml(name))
    if cmake is not None:
        (folder / "CMakeLists.txt").write_text(cmake)
    for rel, text in (files or {}).items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_text(text)
    return folder


def _install(tmp_path: Path) -> Path:
    """An install prefix made as colcon would, by hand from the two packages' install rules."""
    prefix = tmp_path / "install"
    share = prefix / "share" / "tinybot_description"
    shutil.copytree(DESCRIPTION / "urdf", share / "urdf")
    shutil.copytree(DESCRIPTION / "meshes", share / "meshes")
    shutil.copy(DESCRIPTION / "package.xml", share / "package.xml")
    share = prefix / "share" / "tinybot_example"
    shutil.copytree(EXAMPLE / "description" / "urdf", share / "urdf")
    shutil.copytree(EXAMPLE / "description" / "ros2_control", share / "ros2_control")
    shutil.copytree(EXAMPLE / "bringup" / "config", share / "config")
    shutil.copy(EXAMPLE / "bringup" / "notes.txt", share / "NOTES")
    shutil.copy(EXAMPLE / "package.xml", share / "package.xml")
    (prefix / "include" / "tinybot_example").mkdir(parents=True)
    return prefix


# ============================================================================ finding packages
def test_packages_are_found_by_the_name_in_package_xml_and_ignored_folders_are_skipped() -> None:
    """``example_tiny/`` is the package ``tinybot_example``; the copy below attic/COLCON_IGNORE is never found;
    the course's descriptions stay at the end of the path."""
    index = packages.package_index([SRC])
    assert {"tinybot_description", "tinybot_example", "rrbot"} <= set(index.names())
    example = index.packages["tinybot_example"]
    assert example.path == EXAMPLE and example.layout == "source"
    assert "tinybot_example" not in index.shadowed  # the ignored copy is not even a loser
    assert index.entries[0] == SRC and index.entries[-1] == rw.description.descriptions_root()
    assert index.packages["rrbot"].layout == "descriptions"


def test_hidden_folders_are_not_crawled(tmp_path: Path) -> None:
    """Folders starting with a dot (.git, .venv) are skipped, as colcon skips them."""
    _make_package(tmp_path / ".hidden" / "secret", "secret_pkg")
    _make_package(tmp_path / "visible", "visible_pkg")
    names = packages.package_index([tmp_path]).names()
    assert "visible_pkg" in names and "secret_pkg" not in names


def test_the_environment_variable_adds_folders_after_the_given_ones(tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """``RRBOT_WORKSHOP_PACKAGE_PATH`` is os.pathsep-separated, as ROS_PACKAGE_PATH, and comes after package_path."""
    other = _make_package(tmp_path / "ws" / "other", "other_pkg")
    monkeypatch.setenv(PACKAGE_PATH_ENV, f"{tmp_path / 'ws'}{os.pathsep}{SRC}")
    (tmp_path / "first").mkdir()
    entries = packages.package_path([tmp_path / "first"])
    assert entries[:3] == (tmp_path / "first", tmp_path / "ws", SRC)
    assert packages.find_package("other_pkg").path == other
    assert packages.resolve("tinybot_example", "config/tinybot_controllers.yaml").is_file()


def test_two_packages_with_one_name_the_first_on_the_path_wins_and_a_warning_says_so(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """As in ROS: the first folder of the path wins; the log names both."""
    first = _make_package(tmp_path / "a" / "twin", "twin_pkg", {"urdf/x.txt": "first"})
    second = _make_package(tmp_path / "b" / "twin", "twin_pkg", {"urdf/x.txt": "second"})
    with caplog.at_level(logging.WARNING, logger="rrbot_workshop.description.packages"):
        index = packages.package_index([tmp_path / "a", tmp_path / "b"])
    assert index.packages["twin_pkg"].path == first
    assert [p.path for p in index.shadowed["twin_pkg"]] == [second]
    assert "twin_pkg" in caplog.text and str(first) in caplog.text and str(second) in caplog.text
    assert "first on the package path wins" in caplog.text
    assert packages.resolve("twin_pkg", "urdf/x.txt", [tmp_path / "a", tmp_path / "b"]).read_text() == "first"
    assert packages.resolve("twin_pkg", "urdf/x.txt", [tmp_path / "b", tmp_path / "a"]).read_text() == "second"


def test_a_malformed_package_xml_is_named_with_its_line(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """A broken manifest is skipped with a warning naming the file; looking for the package names it again."""
    broken = tmp_path / "broken_pkg" / "package.xml"
    broken.parent.mkdir()
    broken.write_text('<?xml version="1.0"?>\n<package format="3">\n  <name>broken_pkg</nam>\n</package>\n')
    (tmp_path / "nameless" ).mkdir()
    (tmp_path / "nameless" / "package.xml").write_text('<package format="3"><version>1</version></package>')
    with caplog.at_level(logging.WARNING, logger="rrbot_workshop.description.packages"):
        index = packages.package_index([tmp_path])
    assert str(broken) in caplog.text and "line 3" in caplog.text
    with pytest.raises(DescriptionError) as info:
        packages.find_package("broken_pkg", [tmp_path])
    text = str(info.value)
    assert "unknown package 'broken_pkg'" in text and str(broken) in text and "malformed package.xml" in text
    assert str(tmp_path / "nameless" / "package.xml") in text and "no <name>" in text
    assert "broken_pkg" not in index.names()


def test_an_unknown_package_lists_the_known_ones_and_the_path_searched(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError) as info:
        packages.resolve("no_such_pkg", "urdf/x.xacro", [SRC])
    text = str(info.value)
    assert "unknown package 'no_such_pkg'" in text
    assert "tinybot_description" in text and "tinybot_example" in text and "rrbot" in text
    assert f"package path searched: {SRC}, {rw.description.descriptions_root()}" in text
    assert "--package-path" in text and PACKAGE_PATH_ENV in text


def test_the_root_and_the_home_folder_are_refused_and_missing_folders_named(tmp_path: Path) -> None:
    """The crawl never walks / or $HOME by accident."""
    for bad in (Path("/"), Path.home()):
        with pytest.raises(DescriptionError, match="file system root or the home folder"):
            packages.package_index([bad])
    with pytest.raises(DescriptionError, match=f"package path folder '{tmp_path / 'nope'}' does not exist"):
        packages.package_index([tmp_path / "nope"])


def test_a_package_added_after_the_first_crawl_is_found(tmp_path: Path) -> None:
    """The index is cached per path; an unknown name crawls once more before failing."""
    assert "late_pkg" not in packages.package_index([tmp_path]).names()
    late = _make_package(tmp_path / "late", "late_pkg")
    assert packages.find_package("late_pkg", [tmp_path]).path == late


# ============================================================================ install rules
def test_install_rules_follow_cmake(tmp_path: Path) -> None:
    """Trailing slash = contents; several DIRECTORY entries; multi-line; comments; ${PROJECT_NAME}, project(),
    set(); FILES with RENAME; destinations outside share/<pkg> and commented rules are not rules."""
    rules, complete = parse_install_rules(EXAMPLE / "CMakeLists.txt", "tinybot_example")
    assert complete
    got = [(r.kind, str(r.installed_as), r.source.relative_to(EXAMPLE).as_posix()) for r in rules]
    assert got == [
        ("directory", "urdf", "description/urdf"),
        ("directory", "ros2_control", "description/ros2_control"),
        ("contents", "config", "bringup/config"),
        ("file", "NOTES", "bringup/notes.txt"),
    ]
    cmake = tmp_path / "CMakeLists.txt"
    cmake.write_text('project(renamed_pkg)\ninstall(DIRECTORY "launch" meshes/ DESTINATION share/${PROJECT_NAME}/sub)\n'
                     "install(DIRECTORY ${UNKNOWN_VAR}/x DESTINATION share/${PROJECT_NAME})\n"
                     "install(DIRECTORY cfg DESTINATION share/other_pkg)\n")
    rules, complete = parse_install_rules(cmake, "renamed_pkg")
    assert not complete  # ${UNKNOWN_VAR}: the source folder is searched too
    assert [(r.kind, str(r.installed_as)) for r in rules] == [("directory", "sub/launch"), ("contents", "sub")]


def test_a_source_tree_resolves_as_its_installed_form_would() -> None:
    """share/<pkg>/ros2_control/x is description/ros2_control/x; config/ is bringup/config's contents."""
    assert packages.resolve("tinybot_example", "ros2_control/tinybot.ros2_control.xacro", [SRC]) == (
        EXAMPLE / "description" / "ros2_control" / "tinybot.ros2_control.xacro")
    assert packages.resolve("tinybot_example", "config/tinybot_controllers.yaml", [SRC]) == (
        EXAMPLE / "bringup" / "config" / "tinybot_controllers.yaml")
    assert packages.resolve("tinybot_example", "NOTES", [SRC]) == EXAMPLE / "bringup" / "notes.txt"
    assert packages.resolve("tinybot_example", "package.xml", [SRC]) == EXAMPLE / "package.xml"
    assert packages.resolve("tinybot_description", "meshes/tiny_link.stl", [SRC]) == (
        DESCRIPTION / "meshes" / "tiny_link.stl")


def test_a_missing_file_names_every_place_looked_for() -> None:
    with pytest.raises(DescriptionError) as info:
        packages.resolve("tinybot_example", "config/missing.yaml", [SRC])
    text = str(info.value)
    assert "file 'config/missing.yaml' of package 'tinybot_example'" in text
    assert str(EXAMPLE / "bringup" / "config" / "missing.yaml") in text
    assert "description/urdf -> share/tinybot_example/urdf" in text  # the rules it went through


def test_a_file_that_no_rule_installs_is_not_found_and_the_message_says_why() -> None:
    """description/old/README exists in the source tree, but no rule installs it: ROS would not find it either."""
    with pytest.raises(DescriptionError) as info:
        packages.resolve("tinybot_example", "description/old/README", [SRC])
    assert "no install(... DESTINATION share/tinybot_example...) rule" in str(info.value)
    assert str(EXAMPLE / "description" / "old" / "README") in str(info.value)


def test_a_package_without_install_rules_resolves_from_its_folder(tmp_path: Path) -> None:
    """ament_python packages (setup.py data_files) and rule-less ones: share/<pkg>/x is <src>/x."""
    pkg = _make_package(tmp_path / "py_pkg", "py_pkg", {"setup.py": "", "config/c.yaml": "{}"})
    assert packages.resolve("py_pkg", "config/c.yaml", [tmp_path]) == pkg / "config" / "c.yaml"
    assert packages.share_directory("py_pkg", [tmp_path]) == pkg


# ============================================================================ xacro and package://
def test_xacro_expands_the_example_from_its_source_tree() -> None:
    """$(find tinybot_description) and $(find tinybot_example)/ros2_control/... from the clone as it is, with a
    relative include inside the other package."""
    with packages.use_package_path([SRC]):
        urdf = process_xacro(EXAMPLE / "description" / "urdf" / "tinybot.urdf.xacro")
    assert '<ros2_control name="TinyBotShoulder" type="system">' in urdf
    assert "tinybot_example/TinyElbowDrive" in urdf and 'material name="tiny_grey"' in urdf
    assert "package://tinybot_description/meshes/tiny_link.stl" in urdf


def test_find_gives_a_folder_that_looks_installed() -> None:
    """The share folder of a source tree is a view: its entries are the installed names."""
    share = packages.share_directory("tinybot_example", [SRC])
    assert share.name == "tinybot_example" and share.parent.name == "share"
    assert sorted(p.name for p in share.iterdir()) == ["NOTES", "config", "package.xml", "ros2_control", "urdf"]
    assert (share / "config" / "tinybot_controllers.yaml").read_text() == (
        EXAMPLE / "bringup" / "config" / "tinybot_controllers.yaml").read_text()
    # installed and rule-less packages need no view
    assert packages.share_directory("rrbot", [SRC]) == rw.description.descriptions_root() / "rrbot"


def test_a_missing_include_in_xacro_lists_every_place_looked_for(tmp_path: Path) -> None:
    top = tmp_path / "top.urdf.xacro"
    top.write_text('<?xml version="1.0"?>\n<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                   '  <xacro:include filename="$(find tinybot_example)/ros2_control/gone.xacro"/>\n</robot>\n')
    with packages.use_package_path([SRC]), pytest.raises(DescriptionError) as info:
        process_xacro(top)
    text = str(info.value)
    assert "file 'ros2_control/gone.xacro' of package 'tinybot_example'" in text
    assert str(EXAMPLE / "description" / "ros2_control" / "gone.xacro") in text
    assert str(top) in text


def test_package_uris_resolve_through_the_path() -> None:
    """Meshes: package:// goes through the same rules; an unknown package still raises."""
    with packages.use_package_path([SRC]):
        assert resolve_package_uri("package://tinybot_description/meshes/tiny_link.stl") == (
            DESCRIPTION / "meshes" / "tiny_link.stl")
        with pytest.raises(DescriptionError, match="unknown package 'nobody'"):
            resolve_package_uri("package://nobody/meshes/x.stl")
    assert packages.resolve_uri("$(find tinybot_example)/config/tinybot_controllers.yaml", [SRC]).is_file()


# ============================================================================ bringup
def test_bringup_from_the_source_tree_with_package_references_moves_as_commanded() -> None:
    """Description and controllers as package:// and $(find ...); the shoulder and elbow follow the command."""
    system = rw.bringup("package://tinybot_example/urdf/tinybot.urdf.xacro",
                        "$(find tinybot_example)/config/tinybot_controllers.yaml",
                        package_path=[SRC], mock_hardware="unknown", spawn=CONTROLLERS)
    with system:
        system.publish("/position_controller/commands", Float64MultiArray(data=[0.5, -0.4]))
        system.spin(0.05)
        state = system.latest("/joint_states")
        positions = dict(zip(state.name, state.position, strict=True))
        assert positions == {"shoulder": 0.5, "elbow": -0.4}
        assert system.latest("/wrist_ft_broadcaster/wrench").wrench.force.z == 1.5


def test_bringup_takes_a_bare_controllers_file_name_from_the_packages_config() -> None:
    """A file name alone is looked up in share/<pkg>/config of the description's package (here bringup/config)."""
    with rw.bringup(EXAMPLE / "description" / "urdf" / "tinybot.urdf.xacro", "tinybot_controllers.yaml",
                    package_path=[SRC], mock_hardware="unknown", spawn=["joint_state_broadcaster"]) as system:
        assert system.controller_manager.controllers["joint_state_broadcaster"].state.label == "active"
    with pytest.raises(ParameterError) as info:
        rw.bringup(EXAMPLE / "description" / "urdf" / "tinybot.urdf.xacro", "nope.yaml", package_path=[SRC],
                   mock_hardware="unknown")
    assert str(EXAMPLE / "bringup" / "config" / "nope.yaml") in str(info.value)
    assert "tinybot_controllers.yaml" in str(info.value)  # what is there


def test_bringup_from_an_installed_tree(tmp_path: Path) -> None:
    """The same robot from install/share/<pkg> (only the prefix is on the path)."""
    prefix = _install(tmp_path)
    index = packages.package_index([prefix])
    assert index.packages["tinybot_example"].layout == "installed"
    assert index.packages["tinybot_example"].path == prefix / "share" / "tinybot_example"
    system = rw.bringup("$(find tinybot_example)/urdf/tinybot.urdf.xacro", "package://tinybot_example/config/"
                        "tinybot_controllers.yaml", package_path=[prefix], mock_hardware="unknown", spawn=CONTROLLERS)
    with system:
        system.publish("/position_controller/commands", Float64MultiArray(data=[-0.3, 0.7]))
        system.spin(0.05)
        state = system.latest("/joint_states")
        assert dict(zip(state.name, state.position, strict=True)) == {"shoulder": -0.3, "elbow": 0.7}
    assert packages.resolve("tinybot_description", "meshes/tiny_link.stl", [prefix]) == (
        prefix / "share" / "tinybot_description" / "meshes" / "tiny_link.stl")


def test_the_description_package_alone_expands_with_meshes_by_package_uri() -> None:
    """A description package's own xacro ($(find self)) and its package:// meshes."""
    urdf, package, _ = description_to_urdf("package://tinybot_description/urdf/tinybot.urdf.xacro", {"prefix": "l_"},
                                        [SRC])
    assert package == "tinybot_description" and 'joint name="l_shoulder"' in urdf
    with packages.use_package_path([SRC]):
        mesh = resolve_package_uri("package://tinybot_description/meshes/tiny_link.stl")
    assert mesh.read_text().startswith("solid tiny_link")


def test_existing_descriptions_keep_working_without_a_package_path() -> None:
    """The course's own robots by name, as before."""
    with rw.bringup("rrbot", "rrbot_controllers.yaml", xacro_args={"use_mock_hardware": True}) as system:
        assert system.hardware_infos and system.mocked_hardware == {}


def test_a_file_added_to_an_installed_folder_shows_in_the_next_find(tmp_path: Path) -> None:
    """The installed tree is worked out on every share_directory(): a new file gives a new view, an unchanged tree
    the same one; nothing is written in the package."""
    pkg = _make_package(tmp_path / "grow", "grow_pkg", {"config/a.yaml": "a: 1\n"},
                        "install(DIRECTORY config DESTINATION share/${PROJECT_NAME})\n")
    first = packages.share_directory("grow_pkg", [tmp_path])
    assert packages.share_directory("grow_pkg", [tmp_path]) == first
    (pkg / "config" / "b.yaml").write_text("b: 1\n")
    second = packages.share_directory("grow_pkg", [tmp_path])
    assert second != first and (second / "config" / "b.yaml").read_text() == "b: 1\n"
    assert sorted(p.name for p in (pkg / "config").iterdir()) == ["a.yaml", "b.yaml"]
