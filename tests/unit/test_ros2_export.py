"""``rrbot-workshop export --ros2``: the learner's files as ROS 2 packages; theirs byte for byte, ours parse."""

from __future__ import annotations

import ast
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.ros2_export import export_ros2
from rrbot_workshop.exceptions import CourseError


@pytest.fixture
def solutions_track():  # noqa: ANN201
    if not (tracks.course_root() / "solutions").is_dir():
        pytest.skip("this copy of the course has no solutions/")
    tracks.set_track("solutions")
    yield
    tracks.set_track(None)


def test_learner_files_are_copied_byte_for_byte(tmp_path: Path, solutions_track: None) -> None:
    result = export_ros2(tmp_path / "ws")
    assert result.copied, "nothing was copied"
    for dst, src in result.copied.items():
        assert dst.read_bytes() == src.read_bytes(), dst
    urdf = tmp_path / "ws" / "controlko_description" / "urdf"
    assert (urdf / "rrbot.urdf.xacro").is_file() and (urdf / "rrbot" / "rrbot_macro.ros2_control.xacro").is_file()
    assert (tmp_path / "ws" / "controlko_bringup" / "config" / "rrbot_controllers.yaml").is_file()


def test_generated_manifests_follow_ament_and_parse(tmp_path: Path, solutions_track: None) -> None:
    export_ros2(tmp_path / "ws")
    for package in ("controlko_description", "controlko_bringup"):
        root = ET.parse(tmp_path / "ws" / package / "package.xml").getroot()
        assert root.get("format") == "3" and root.findtext("name") == package
        assert root.findtext("buildtool_depend") == "ament_cmake"
        assert root.find("export/build_type").text == "ament_cmake"
        cmake = (tmp_path / "ws" / package / "CMakeLists.txt").read_text()
        assert f"project({package})" in cmake and "ament_package()" in cmake


def test_launch_file_parses_and_starts_what_the_bringup_starts(tmp_path: Path, solutions_track: None) -> None:
    result = export_ros2(tmp_path / "ws")
    launch = tmp_path / "ws" / "controlko_bringup" / "launch" / "rrbot.launch.py"
    tree = ast.parse(launch.read_text())
    functions = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    assert "generate_launch_description" in functions
    assert result.robot_controllers == ["forward_position_controller", "joint_trajectory_controller"]
    text = launch.read_text()
    assert "BROADCASTERS = ['joint_state_broadcaster']" in text and '"--inactive"' in text
    assert "ros2_control_node" in text and "~/robot_description" in text and "rrbot_controllers.yaml" in text and "OnProcessExit" in text


def test_readme_says_what_remains_cpp(tmp_path: Path, solutions_track: None) -> None:
    export_ros2(tmp_path / "ws")
    readme = (tmp_path / "ws" / "README.md").read_text()
    assert "colcon build" in readme and "What remains C++" in readme and "RRBotHardwareInterface" in readme


def test_non_empty_target_is_refused_unless_forced(tmp_path: Path, solutions_track: None) -> None:
    target = tmp_path / "ws"
    target.mkdir()
    (target / "mine.txt").write_text("keep")
    with pytest.raises(CourseError, match="is not empty"):
        export_ros2(target)
    assert (target / "mine.txt").read_text() == "keep" and len(list(target.iterdir())) == 1
    export_ros2(target, force=True)
    assert (target / "mine.txt").read_text() == "keep"
