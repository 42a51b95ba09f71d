"""``rrbot-workshop export --ros2``: one task's files as ROS 2 packages; theirs byte for byte, ours parse, ``ros2
launch`` would accept the launch file, the manifests carry what the files use, and unfinished work is refused."""

from __future__ import annotations

import ast
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from rrbot_workshop import cli
from rrbot_workshop.course import tracks
from rrbot_workshop.course.ros2_export import export_problems, export_ros2, export_sources, launch_argument_problem
from rrbot_workshop.exceptions import CourseError

LAUNCH = Path("controlko_bringup") / "launch" / "rrbot.launch.py"
BRINGUP_DEPENDS = {"ros2launch", "launch", "launch_ros", "xacro", "robot_state_publisher", "controller_manager",
                   "controlko_description", "hardware_interface", "joint_state_broadcaster",
                   "forward_command_controller", "joint_trajectory_controller"}


@pytest.fixture
def solutions_track():  # noqa: ANN201
    if not (tracks.course_root() / "solutions").is_dir():
        pytest.skip("this copy of the course has no solutions/")
    tracks.set_track("solutions")
    yield
    tracks.set_track(None)


@pytest.fixture
def task_root(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The solutions of tasks 2, 5, 7 and 8 as the task root, to be edited by a test."""
    solutions = tracks.course_root() / "solutions"
    if not solutions.is_dir():
        pytest.skip("this copy of the course has no solutions/")
    root = tmp_path / "tasks"
    for task in (2, 5, 7, 8):
        shutil.copytree(solutions / tracks.task_name(task), root / tracks.task_name(task))
    monkeypatch.setenv(tracks.TASK_ROOT_ENV, str(root))
    return root


def _task(root: Path, task: int) -> Path:
    return root / tracks.task_name(task)


def _yaml(root: Path, task: int) -> Path:
    return next((_task(root, task) / "rrbot_bringup" / "config").glob("*.yaml"))


def _edit_yaml(root: Path, task: int, edit) -> None:  # noqa: ANN001
    path = _yaml(root, task)
    data = yaml.safe_load(path.read_text())
    edit(data)
    path.write_text(yaml.safe_dump(data))


def _unfinish(root: Path, task: int) -> None:
    """Put the exercise's files of ``task`` (as committed, unfinished) in place of the solution's."""
    exercise = tracks.course_root() / "exercises" / tracks.task_name(task)
    if not exercise.is_dir():
        pytest.skip("this copy of the course has no exercises/")
    shutil.rmtree(_task(root, task))
    shutil.copytree(exercise, _task(root, task))


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


# ------------------------------------------------------------------------------------------- which task


def test_the_tasks_with_a_description_and_bringup_are_found(solutions_track: None) -> None:
    sources = export_sources()
    assert [s.task for s in sources] == [2, 5]
    assert [s.controllers.name for s in sources] == ["rrbot_controllers.yaml", "rrbot_sim_controllers.yaml"]
    assert all(export_problems(s) == [] for s in sources)


def test_the_default_is_the_most_advanced_ready_task(tmp_path: Path, solutions_track: None) -> None:
    result = export_ros2(tmp_path / "ws")
    assert (result.task, result.task_folder, result.ready_tasks) == (5, "solutions/task05_simulation", [2, 5])
    assert (tmp_path / "ws" / "controlko_bringup" / "config" / "rrbot_sim_controllers.yaml").is_file()
    assert "task 5 (`solutions/task05_simulation`)" in (tmp_path / "ws" / "README.md").read_text()


@pytest.mark.parametrize(("task", "yaml_name"), [(2, "rrbot_controllers.yaml"), (5, "rrbot_sim_controllers.yaml")])
def test_the_learner_chooses_the_task(tmp_path: Path, solutions_track: None, task: int, yaml_name: str) -> None:
    result = export_ros2(tmp_path / "ws", task=task)
    folder = tracks.task_dir(task)
    assert result.task == task and result.task_folder == f"solutions/{folder.name}"
    exported = {src for dst, src in result.copied.items() if "python_reference" not in dst.parts}
    assert exported and all(src.is_relative_to(folder) for src in exported)
    assert (tmp_path / "ws" / "controlko_bringup" / "config" / yaml_name).is_file()
    assert repr(yaml_name) in (tmp_path / "ws" / LAUNCH).read_text()


def test_a_task_without_files_to_export_is_refused(tmp_path: Path, solutions_track: None) -> None:
    with pytest.raises(CourseError, match=r"task 3 has no description and bringup to export.*valid: '2', '5'"):
        export_ros2(tmp_path / "ws", task=3)
    assert not (tmp_path / "ws").exists()


def test_learner_files_are_copied_byte_for_byte(tmp_path: Path, solutions_track: None) -> None:
    result = export_ros2(tmp_path / "ws", task=2)
    assert result.copied, "nothing was copied"
    for dst, src in result.copied.items():
        assert dst.read_bytes() == src.read_bytes(), dst
    urdf = tmp_path / "ws" / "controlko_description" / "urdf"
    assert (urdf / "rrbot.urdf.xacro").is_file() and (urdf / "rrbot" / "rrbot_macro.ros2_control.xacro").is_file()
    assert (tmp_path / "ws" / "controlko_bringup" / "config" / "rrbot_controllers.yaml").is_file()


# ------------------------------------------------------------------------------------------- unfinished work


def test_unfinished_task_is_refused_naming_what_is_unfinished(task_root: Path, tmp_path: Path) -> None:
    _unfinish(task_root, 2)
    target = tmp_path / "ws"
    with pytest.raises(CourseError) as info:
        export_ros2(target, task=2)
    text = str(info.value)
    assert text.startswith("task 2 (") and "is not finished for export; nothing was written" in text
    assert "declares no xacro argument 'use_mock_hardware', 'mock_sensor_commands'" in text
    assert "rrbot_controllers.yaml declares no robot controller (only joint_state_broadcaster)" in text
    assert "--task N (these have a description and bringup: 5)" in text
    assert not target.exists()


def test_refusal_leaves_a_forced_target_untouched(task_root: Path, tmp_path: Path) -> None:
    _unfinish(task_root, 2)
    target = tmp_path / "ws"
    (target / "controlko_bringup").mkdir(parents=True)
    (target / "controlko_bringup" / "package.xml").write_text("mine")
    before = _snapshot(target)
    with pytest.raises(CourseError, match="not finished for export"):
        export_ros2(target, task=2, force=True)  # --force is for a non-empty folder, not for unfinished work
    assert _snapshot(target) == before


def test_the_default_skips_an_unfinished_task(task_root: Path, tmp_path: Path) -> None:
    _edit_yaml(task_root, 5, lambda d: d["controller_manager"]["ros__parameters"]["joint_trajectory_controller"]
               .update(type="joint_trajectory_controller/NoSuchController"))
    assert any("unknown controller type" in p for p in export_problems(export_sources()[1]))
    result = export_ros2(tmp_path / "ws")
    assert (result.task, result.ready_tasks) == (2, [2])


def test_with_nothing_ready_every_task_says_why(task_root: Path, tmp_path: Path) -> None:
    _unfinish(task_root, 2)

    def only_broadcaster(data: dict) -> None:
        cm = data["controller_manager"]["ros__parameters"]
        for name in [n for n, v in cm.items() if isinstance(v, dict) and "Broadcaster" not in v["type"]]:
            del cm[name]
            data.pop(name, None)

    _edit_yaml(task_root, 5, only_broadcaster)
    with pytest.raises(CourseError) as info:
        export_ros2(tmp_path / "ws")
    text = str(info.value)
    assert "none of the tasks with a description and bringup (2, 5) is finished for export" in text
    assert text.index("task 5 (") < text.index("task 2 (")
    assert "rrbot_sim_controllers.yaml declares no robot controller" in text
    assert not (tmp_path / "ws").exists()


def test_a_mock_switch_that_does_not_switch_is_unfinished(task_root: Path, tmp_path: Path) -> None:
    macro = _task(task_root, 2) / "rrbot_description" / "urdf" / "rrbot" / "rrbot_macro.ros2_control.xacro"
    text = macro.read_text()
    macro.write_text(text.replace("<plugin>mock_components/GenericSystem</plugin>",
                                  "<plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>"))
    with pytest.raises(CourseError, match=r"with use_mock_hardware:=true, <ros2_control name='rrbot'> names "
                                          r"'controlko_hardware_interface/RRBotHardwareInterface'"):
        export_ros2(tmp_path / "ws", task=2)


def test_a_plugin_of_this_library_alone_is_refused(task_root: Path, tmp_path: Path) -> None:
    def library_controller(data: dict) -> None:
        data["controller_manager"]["ros__parameters"]["displacement_controller"] = {
            "type": "rrbot_workshop/DisplacementController"}
        data["displacement_controller"] = {"ros__parameters": {"joints": ["joint1", "joint2"],
                                                               "interface_name": "position"}}

    _edit_yaml(task_root, 2, library_controller)
    with pytest.raises(CourseError, match="'rrbot_workshop/DisplacementController', which exists only in this library"):
        export_ros2(tmp_path / "ws", task=2)


def _displacement(data: dict) -> None:
    data["controller_manager"]["ros__parameters"]["displacement_controller"] = {
        "type": "displacement_controller/DisplacementController"}
    data["displacement_controller"] = {"ros__parameters": {"joints": ["joint1", "joint2"], "interface_name": "position"}}


def test_the_workshops_finished_controller_is_exported_as_a_plugin_to_port(task_root: Path, tmp_path: Path) -> None:
    _edit_yaml(task_root, 2, _displacement)
    result = export_ros2(tmp_path / "ws", task=2)
    assert "displacement_controller/DisplacementController" in result.to_port
    assert "displacement_controller" not in result.exec_depends["controlko_bringup"]
    assert "displacement_controller" in result.robot_controllers


def test_the_workshops_unfinished_controller_is_refused(task_root: Path, tmp_path: Path) -> None:
    _edit_yaml(task_root, 2, _displacement)
    _unfinish(task_root, 8)
    with pytest.raises(CourseError, match=r"(?s)not finished for export.*displacement_controller"):
        export_ros2(tmp_path / "ws", task=2)
    assert not (tmp_path / "ws").exists()


# ------------------------------------------------------------------------------------------- generated files


def _declared_arguments(text: str) -> dict[str, dict[str, object]]:
    out = {}
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "DeclareLaunchArgument":
            out[ast.literal_eval(node.args[0])] = {k.arg: ast.literal_eval(k.value) for k in node.keywords}
    return out


@pytest.mark.parametrize("task", [2, 5])
def test_every_launch_argument_is_one_ros2_launch_accepts(tmp_path: Path, solutions_track: None, task: int) -> None:
    result = export_ros2(tmp_path / "ws", task=task)
    text = (tmp_path / "ws" / LAUNCH).read_text()
    arguments = _declared_arguments(text)
    assert set(arguments) == {"robot_controller", "use_mock_hardware", "mock_sensor_commands"}
    for name, keywords in arguments.items():
        assert isinstance(keywords["default_value"], str), name
        if "choices" in keywords:
            choices = keywords["choices"]
            assert isinstance(choices, list) and choices and keywords["default_value"] in choices, name
    assert arguments["robot_controller"]["choices"] == result.robot_controllers
    assert arguments["robot_controller"]["default_value"] == "forward_position_controller"
    assert launch_argument_problem(text) == ""


def test_the_launch_check_finds_what_ros2_launch_refuses() -> None:
    head = "from launch.actions import DeclareLaunchArgument\n"
    assert "choices=[]" in launch_argument_problem(
        head + 'DeclareLaunchArgument("robot_controller", default_value="", choices=[])')
    assert "not among its choices" in launch_argument_problem(
        head + 'DeclareLaunchArgument("robot_controller", default_value="x", choices=["a", "b"])')
    assert "no text default_value" in launch_argument_problem(head + 'DeclareLaunchArgument("flag")')
    assert launch_argument_problem(head + 'DeclareLaunchArgument("flag", default_value="true")') == ""


def test_the_launch_file_starts_what_the_bringup_starts(tmp_path: Path, solutions_track: None) -> None:
    export_ros2(tmp_path / "ws", task=2)
    text = (tmp_path / "ws" / LAUNCH).read_text()
    tree = ast.parse(text)
    assert "generate_launch_description" in {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert "BROADCASTERS = ['joint_state_broadcaster']" in text and '"--inactive"' in text
    assert "ros2_control_node" in text and "~/robot_description" in text and "OnProcessExit" in text


_FORMAT3_ORDER = ["name", "version", "description", "maintainer", "license"]


@pytest.mark.parametrize("task", [2, 5])
def test_manifests_have_the_format_3_essentials(tmp_path: Path, solutions_track: None, task: int) -> None:
    export_ros2(tmp_path / "ws", task=task)
    for package in ("controlko_description", "controlko_bringup"):
        text = (tmp_path / "ws" / package / "package.xml").read_text()
        assert "package_format3.xsd" in text
        root = ET.fromstring(text.split("?>", 2)[-1])
        assert root.tag == "package" and root.get("format") == "3"
        tags = [child.tag for child in root]
        assert tags[:5] == _FORMAT3_ORDER, tags  # the schema's order: name, version, description, maintainer, license
        assert all(root.findtext(t).strip() for t in _FORMAT3_ORDER)
        assert root.findtext("name") == package and root.find("maintainer").get("email")
        assert root.findtext("buildtool_depend") == "ament_cmake"
        assert root.find("export/build_type").text == "ament_cmake"
        assert tags[-1] == "export"
        depends = [e.text for e in root.findall("exec_depend")]
        assert len(depends) == len(set(depends)) and package not in depends
        cmake = (tmp_path / "ws" / package / "CMakeLists.txt").read_text()
        assert f"project({package})" in cmake and "ament_package()" in cmake


def _depends(tmp_path: Path, package: str) -> set[str]:
    root = ET.parse(tmp_path / "ws" / package / "package.xml").getroot()
    return {e.text for e in root.findall("exec_depend")}


def test_manifests_carry_what_a_minimal_install_needs(tmp_path: Path, solutions_track: None) -> None:
    result = export_ros2(tmp_path / "ws", task=2)
    assert _depends(tmp_path, "controlko_bringup") == BRINGUP_DEPENDS
    assert _depends(tmp_path, "controlko_description") == {"xacro"}
    assert "rviz2" not in BRINGUP_DEPENDS  # the launch file starts no RViz
    assert result.to_port == ["controlko_hardware_interface/RRBotHardwareInterface"]  # use_mock_hardware:=false
    assert set(result.exec_depends["controlko_bringup"]) == BRINGUP_DEPENDS


def test_manifests_follow_the_files(task_root: Path, tmp_path: Path) -> None:
    def position_group(data: dict) -> None:
        cm = data["controller_manager"]["ros__parameters"]
        del cm["joint_trajectory_controller"]
        data.pop("joint_trajectory_controller")
        cm["group_position_controller"] = {"type": "position_controllers/JointGroupPositionController"}
        data["group_position_controller"] = {"ros__parameters": {"joints": ["joint1", "joint2"]}}

    _edit_yaml(task_root, 2, position_group)
    xacro = _task(task_root, 2) / "rrbot_description" / "urdf" / "rrbot.urdf.xacro"
    xacro.write_text(xacro.read_text().replace(
        "</robot>", '  <!-- $(find commented_out_pkg) -->\n'
                    '  <xacro:property name="mesh" value="package://rrbot_meshes/meshes/base.stl"/>\n</robot>'))
    export_ros2(tmp_path / "ws", task=2)
    bringup = _depends(tmp_path, "controlko_bringup")
    assert "position_controllers" in bringup and "joint_trajectory_controller" not in bringup
    assert _depends(tmp_path, "controlko_description") == {"xacro", "rrbot_meshes"}


def test_readme_says_what_remains_cpp(tmp_path: Path, solutions_track: None) -> None:
    export_ros2(tmp_path / "ws")
    readme = (tmp_path / "ws" / "README.md").read_text()
    assert "colcon build" in readme and "What remains C++" in readme and "RRBotHardwareInterface" in readme
    assert "python_reference/controlko_hardware_interface/rrbot_hardware_interface.py`\n" in readme
    assert "unfinished" not in readme


def test_readme_says_which_python_reference_is_unfinished(task_root: Path, tmp_path: Path) -> None:
    _unfinish(task_root, 7)
    export_ros2(tmp_path / "ws", task=2)
    readme = (tmp_path / "ws" / "README.md").read_text()
    line = next(x for x in readme.splitlines() if "rrbot_hardware_interface.py" in x)
    assert "(unfinished:" in line and "RRBotHardwareInterface.on_init() at line" in line and "finish task 7" in line
    line = next(x for x in readme.splitlines() if "displacement_controller.py" in x)
    assert "unfinished" not in line


def test_non_empty_target_is_refused_unless_forced(tmp_path: Path, solutions_track: None) -> None:
    target = tmp_path / "ws"
    target.mkdir()
    (target / "mine.txt").write_text("keep")
    with pytest.raises(CourseError, match="is not empty"):
        export_ros2(target)
    assert (target / "mine.txt").read_text() == "keep" and len(list(target.iterdir())) == 1
    export_ros2(target, force=True)
    assert (target / "mine.txt").read_text() == "keep"


# ------------------------------------------------------------------------------------------- the command


def test_the_command_says_which_task_it_exports(tmp_path: Path, solutions_track: None,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["export", "--ros2", str(tmp_path / "ws")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("Exporting task 5 (solutions/task05_simulation): its description and bringup (also ready: "
                          "task 2; choose with --task N).")
    assert cli.main(["export", "--ros2", str(tmp_path / "ws2"), "--task", "2"]) == 0
    assert capsys.readouterr().out.startswith("Exporting task 2 (solutions/task02_mock_hardware): its description "
                                              "and bringup.")


def test_the_command_refuses_unfinished_work_with_exit_2(task_root: Path, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    _unfinish(task_root, 2)
    assert cli.main(["export", "--ros2", str(tmp_path / "ws"), "--task", "2"]) == 2
    err = capsys.readouterr().err
    assert "task 2 (" in err and "declares no robot controller" in err
    assert not (tmp_path / "ws").exists()
    assert cli.main(["export", "--student", str(tmp_path / "copy"), "--task", "2"]) == 2
    assert "--task only applies to --ros2" in capsys.readouterr().err
