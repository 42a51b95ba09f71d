"""``export --ros2`` with hostile input: controller names never become code in the launch file (they are refused
unless they are ROS node names, and the template writes them as literals anyway), and hostile targets get one clear
CourseError (exit 2 through the CLI) with nothing written."""

from __future__ import annotations

import ast
import os
import shutil
from pathlib import Path

import pytest

from rrbot_workshop import cli
from rrbot_workshop.course import tracks
from rrbot_workshop.course.ros2_export import export_ros2
from rrbot_workshop.exceptions import CourseError
from rrbot_workshop.tools.ros2_package import launch_file as _launch_file

INJECTIONS = [
    'a" + str(__import__("os").system("echo pwned")) + "b',
    "a' + str(__import__('os').system('echo pwned')) + 'b",
    'a"""\nimport os\nos.system("echo pwned")\n"""',
    "a'''\nimport os\n'''",
    "ends_with_backslash\\",
    "new\nline",
    "x" * 300,
    "{robot_controller}",
]


def _literal_list(tree: ast.Module, name: str) -> list[str]:
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name for t in node.targets):
            return ast.literal_eval(node.value)
    raise AssertionError(f"{name} not assigned")


@pytest.mark.parametrize("name", INJECTIONS, ids=repr)
def test_the_launch_template_writes_any_name_as_a_literal(name: str) -> None:
    """The escaping layer alone (names not validated): the file compiles, the names come back as the same strings,
    and no call other than the template's own appears."""
    text = _launch_file("rrbot_controllers.yaml", [name, "other"], [name + "_jsb"])
    tree = ast.parse(text)
    compile(text, "rrbot.launch.py", "exec")
    assert _literal_list(tree, "ROBOT_CONTROLLERS") == [name, "other"]
    assert _literal_list(tree, "BROADCASTERS") == [name + "_jsb"]
    called = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
    assert "__import__" not in called and "system" not in text.split("ROBOT_CONTROLLERS = ")[0]
    defaults = [kw.value for n in ast.walk(tree) if isinstance(n, ast.Call)
                for kw in n.keywords if kw.arg == "default_value"]
    assert any(isinstance(v, ast.Constant) and v.value == name for v in defaults)


@pytest.fixture
def task_root(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A copy of the solutions' tasks 1-2 as the graded task root (its controllers YAML can be edited)."""
    solutions = tracks.course_root() / "solutions"
    if not solutions.is_dir():
        pytest.skip("this copy of the course has no solutions/")
    root = tmp_path / "tasks"
    for task in (1, 2):
        name = tracks.task_name(task)
        shutil.copytree(solutions / name, root / name)
    monkeypatch.setenv(tracks.TASK_ROOT_ENV, str(root))
    return root


def _yaml(task_root: Path) -> Path:
    return task_root / tracks.task_name(2) / "rrbot_bringup" / "config" / "rrbot_controllers.yaml"


def _rename(task_root: Path, old: str, new: str) -> None:
    path = _yaml(task_root)
    import yaml

    data = yaml.safe_load(path.read_text())
    cm = data["controller_manager"]["ros__parameters"]
    cm[new] = cm.pop(old)
    data[new] = data.pop(old, {"ros__parameters": {}})
    path.write_text(yaml.safe_dump(data))


@pytest.mark.parametrize("name", INJECTIONS, ids=repr)
def test_a_name_that_is_not_a_node_name_is_refused_before_anything_is_written(
        name: str, task_root: Path, tmp_path: Path) -> None:
    _rename(task_root, "forward_position_controller", name)
    target = tmp_path / "ws"
    with pytest.raises(CourseError, match="is not a valid ROS node name") as info:
        export_ros2(target)
    assert "ASCII letters, digits and underscores" in str(info.value)
    assert not target.exists()


def test_valid_names_come_out_of_the_launch_file_as_literals(task_root: Path, tmp_path: Path) -> None:
    export_ros2(tmp_path / "ws")
    text = (tmp_path / "ws" / "controlko_bringup" / "launch" / "rrbot.launch.py").read_text()
    tree = ast.parse(text)
    compile(text, "rrbot.launch.py", "exec")
    assert _literal_list(tree, "ROBOT_CONTROLLERS") == ["forward_position_controller", "joint_trajectory_controller"]
    assert _literal_list(tree, "BROADCASTERS") == ["joint_state_broadcaster"]


@pytest.mark.parametrize("target", ["", "   ", None, 3, "a\nb", "a\x00b"], ids=repr)
def test_an_empty_or_wrong_typed_target_is_refused(target: object, task_root: Path) -> None:
    before = sorted(os.listdir("."))
    with pytest.raises(CourseError, match="export target|folder"):
        export_ros2(target)  # type: ignore[arg-type]
    assert sorted(os.listdir(".")) == before


def test_a_file_as_target_is_refused(task_root: Path, tmp_path: Path) -> None:
    f = tmp_path / "file.txt"
    f.write_text("keep")
    with pytest.raises(CourseError, match="is a file, not a folder"):
        export_ros2(f)
    assert f.read_text() == "keep"


def test_a_target_under_proc_is_refused(task_root: Path) -> None:
    if not Path("/proc").is_dir():
        pytest.skip("no /proc here")
    with pytest.raises(CourseError, match="cannot be written|cannot be used|writing failed"):
        export_ros2("/proc/rrbot_workshop_export")
    assert not Path("/proc/rrbot_workshop_export").exists()


def test_a_folder_name_too_long_is_refused(task_root: Path, tmp_path: Path) -> None:
    target = tmp_path / ("x" * 300)
    with pytest.raises(CourseError, match="at most 255|too long"):
        export_ros2(target)
    assert list(tmp_path.iterdir()) == [task_root]


def test_an_unwritable_parent_is_refused(task_root: Path, tmp_path: Path) -> None:
    if os.geteuid() == 0:
        pytest.skip("root writes anywhere")
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        with pytest.raises(CourseError, match="cannot be written"):
            export_ros2(locked / "ws")
        assert list(locked.iterdir()) == []
    finally:
        locked.chmod(0o700)


@pytest.mark.parametrize("target", ["", "/proc/x", "x" * 300], ids=repr)
def test_the_cli_answers_a_hostile_target_with_one_line_and_exit_2(
        target: str, task_root: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path,
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert cli.main(["export", "--ros2", target]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rrbot-workshop: error:") and "Traceback" not in err and len(err.splitlines()) == 1


def test_the_cli_refuses_an_injected_name_with_exit_2(task_root: Path, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    _rename(task_root, "forward_position_controller", INJECTIONS[0])
    assert cli.main(["export", "--ros2", str(tmp_path / "ws")]) == 2
    assert "not a valid ROS node name" in capsys.readouterr().err
    assert not (tmp_path / "ws").exists()


# ------------------------------------------------------------------------------------------ package.xml and plugin names
def _set_plugin(task_root: Path, plugin_xml_text: str) -> None:
    """The hardware plugin of the real-hardware branch of task 2's description (``plugin_xml_text`` as written in the
    xacro, so ``&lt;`` there is ``<`` in the name)."""
    path = task_root / tracks.task_name(2) / "rrbot_description" / "urdf" / "rrbot" / "rrbot_macro.ros2_control.xacro"
    text = path.read_text()
    assert "controlko_hardware_interface/RRBotHardwareInterface" in text
    path.write_text(text.replace("controlko_hardware_interface/RRBotHardwareInterface", plugin_xml_text))


HOSTILE_PLUGINS = [
    "x&lt;?evil pi?&gt;/Driver",
    "&lt;![CDATA[x]]&gt;/Driver",
    "ab/C&lt;/exec_depend&gt;&lt;exec_depend&gt;evil",
    "my_driver/Driver&#10;second line",
    "My_Driver/Driver",
    "my__driver/Driver",
    "no_slash_at_all",
    "a/b/Driver",
    "pkg/1Driver",
    "x" * 600 + "/Driver",
]


@pytest.mark.parametrize("plugin", HOSTILE_PLUGINS, ids=lambda p: p[:30])
def test_a_hardware_plugin_that_is_not_a_plugin_name_is_refused_with_one_line_and_exit_2(
        plugin: str, task_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    _set_plugin(task_root, plugin)
    monkeypatch.chdir(tmp_path)
    assert cli.main(["export", "--ros2", str(tmp_path / "ws"), "--task", "2"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert "not a plugin name" in err and "'<package>/<Class>'" in err and len(err) < 1500
    assert not (tmp_path / "ws").exists()


def test_a_plugin_name_refused_by_default_choice_too(task_root: Path, tmp_path: Path) -> None:
    """Without --task, a task with a bad name is not exported (and when no task is left, the refusal names it)."""
    _set_plugin(task_root, "x&lt;?evil?&gt;/Driver")
    with pytest.raises(CourseError, match="export refused, nothing was written: .*not a plugin name"):
        export_ros2(tmp_path / "ws")
    assert not (tmp_path / "ws").exists()


def test_a_valid_plugin_of_another_package_becomes_an_exec_depend_read_back_from_the_xml(
        task_root: Path, tmp_path: Path) -> None:
    from rrbot_workshop.tools.ros2_package import package_xml_values

    _set_plugin(task_root, "my_robot_driver/MyDriver")
    result = export_ros2(tmp_path / "ws", task=2)
    values = package_xml_values((tmp_path / "ws" / "controlko_bringup" / "package.xml").read_text())
    assert "my_robot_driver" in values["exec_depend"] == result.exec_depends["controlko_bringup"]
    assert values["name"] == ["controlko_bringup"]


@pytest.mark.parametrize("depend", ["a<b", "x?>", "]]>", "Upper", "a__b", "", "a"], ids=repr)
def test_package_xml_refuses_a_dependency_that_is_not_a_package_name(depend: str) -> None:
    from rrbot_workshop.tools.ros2_package import package_xml

    with pytest.raises(CourseError, match="is not a ROS package name"):
        package_xml("controlko_bringup", "d", "ament_cmake", ["xacro", depend])


def test_package_xml_escapes_every_value_through_the_xml_library() -> None:
    from rrbot_workshop.tools.ros2_package import package_xml, package_xml_values

    description = "a <b> & c ]]> <?pi?> <!-- x --> \"q\""
    text = package_xml("controlko_bringup", description, "ament_cmake", ["xacro"])
    assert package_xml_values(text)["description"] == [description]
    assert "<?pi?>" not in text and "<!--" not in text.split("?>", 2)[-1]


def test_a_processing_instruction_in_a_package_xml_body_is_caught_by_the_check() -> None:
    from rrbot_workshop.tools.ros2_package import check_generated

    with pytest.raises(CourseError, match="processing instruction or comment"):
        check_generated("package.xml", "<?xml version='1.0'?><package><name>a<?evil?></name></package>")
