"""The original workshop's plugin names on a learner's classes: finished ones load, unfinished ones say so once.

``controlko_hardware_interface/RRBotHardwareInterface`` (task 7) and ``displacement_controller/DisplacementController``
(task 8) stand for the learner's classes. Each test points the exercises track at a copy of those two task folders
(``$RRBOT_WORKSHOP_EXERCISES``), as committed (unfinished) or with the finished file put in.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import systems
from rrbot_workshop.course import tracks
from rrbot_workshop.description import descriptions_root
from rrbot_workshop.exceptions import ControllerError, HardwareError, PluginNotFound, UnfinishedExercise
from rrbot_workshop.middleware import plugins
from rrbot_workshop.msgs import Float64MultiArray
from rrbot_workshop.tools.lint import lint_controllers

DRIVER = "controlko_hardware_interface/RRBotHardwareInterface"
CONTROLLER = "displacement_controller/DisplacementController"
TASK7, TASK8 = "task07_hardware_interface", "task08_write_a_controller"
DRIVER_FILE, CONTROLLER_FILE = "rrbot_hardware_interface.py", "displacement_controller.py"
XACRO = descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro"
YAML = """
controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    displacement_controller:
      type: {type}
displacement_controller:
  ros__parameters:
    joints: [joint1, joint2]
    interface_name: position
"""


def _course_file(track: str, task: str, name: str) -> Path:
    return tracks.course_root() / track / task / name


@pytest.fixture
def exercises(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """Tasks 7 and 8 of the exercises track, as committed, in a folder of their own."""
    for name in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV):
        monkeypatch.delenv(name, raising=False)
    tracks.set_track(None)
    folder = tmp_path / "exercises"
    for task in (TASK7, TASK8):
        source = _course_file("exercises", task, "")
        if not source.is_dir():
            pytest.skip("this copy of the course has no exercises/")
        shutil.copytree(source, folder / task)
    monkeypatch.setenv(tracks.EXERCISES_ENV, str(folder))
    yield folder
    for running in list(systems().values()):
        running.shutdown()


def _finish(folder: Path, task: str, name: str) -> None:
    source = _course_file("solutions", task, name)
    if not source.is_file():
        pytest.skip("this copy of the course has no solutions/")
    shutil.copyfile(source, folder / task / name)


def _line_of(path: Path, text: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), start=1) if text in line)


def _urdf() -> str:
    return rw.description.process_xacro(XACRO, use_mock_hardware=False)


# ------------------------------------------------------------------------------------------- resolution


def test_unfinished_driver_is_refused_with_task_file_line_and_options(exercises: Path) -> None:
    path = exercises / TASK7 / DRIVER_FILE
    with pytest.raises(UnfinishedExercise) as info:
        plugins.resolve("hardware", DRIVER)
    error = info.value
    assert isinstance(error, PluginNotFound)  # whoever handles an unknown plugin handles this one
    assert (error.task, error.kind, error.plugin, error.path) == (7, "hardware", DRIVER, path)
    assert error.line == _line_of(path, 'raise NotImplementedError("TODO(task 7.1)')
    text = str(error)
    assert text.startswith(f"'{DRIVER}' is the workshop's name for your task 7 class RRBotHardwareInterface in "
                           f"exercises/{TASK7}/{DRIVER_FILE}, which is unfinished: RRBotHardwareInterface.on_init()")
    assert f"({DRIVER_FILE}, line {error.line})" in text
    offered = ["finish task 7", "'rrbot_workshop/RRBotHardwareInterface'", "use_mock_hardware:=true",
               'mock_hardware="unknown"']
    solutions = "RRBOT_WORKSHOP_TRACK=solutions"  # offered where the course has solutions/ (not in a student copy)
    for option in offered:
        assert option in text, option
    assert (solutions in text) == (tracks.course_root() / "solutions").is_dir(), text


def test_finished_driver_resolves_to_the_learners_class(exercises: Path) -> None:
    _finish(exercises, TASK7, DRIVER_FILE)
    cls = plugins.resolve("hardware", DRIVER)
    assert cls.__name__ == "RRBotHardwareInterface" and cls.__module__.startswith("rrbot_workshop_track_")
    assert plugins.describe_unfinished(DRIVER) is None


def test_a_file_with_stubs_is_not_executed(exercises: Path, tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    path = exercises / TASK7 / DRIVER_FILE
    path.write_text(f"from pathlib import Path\nPath({str(marker)!r}).write_text('ran')\n" + path.read_text())
    with pytest.raises(UnfinishedExercise):
        plugins.resolve("hardware", DRIVER)
    assert not marker.exists()


@pytest.mark.parametrize(("source", "expected", "line"), [
    ("class RRBotHardwareInterface(:\n", "SyntaxError: invalid syntax (rrbot_hardware_interface.py, line 1)", 1),
    ("X = 1\nraise RuntimeError('half written')\n",
     "it does not import: RuntimeError: half written (in rrbot_hardware_interface.py, line 2", 2),
    ("class Other:\n    pass\n", "rrbot_hardware_interface.py defines no class RRBotHardwareInterface", None),
    ("RRBotHardwareInterface = 3\n", "defines no class RRBotHardwareInterface", None),
    ("from rrbot_workshop.middleware.lifecycle import CallbackReturn\n\n\nclass RRBotHardwareInterface:\n"
     "    def on_init(self, info):\n        # TODO(task 7.1): check the description\n"
     "        return CallbackReturn.ERROR\n",
     "RRBotHardwareInterface.on_init() is not written yet: it only answers ERROR under its TODO "
     "(rrbot_hardware_interface.py, line 7)", 7),
    ("class RRBotHardwareInterface:\n    def read(self, time, period):\n        raise NotImplementedError\n",
     "RRBotHardwareInterface.read() is not written yet: it raises NotImplementedError "
     "(rrbot_hardware_interface.py, line 3)", 3),
])
def test_every_kind_of_unfinished_file_is_named(exercises: Path, source: str, expected: str, line: int | None) -> None:
    (exercises / TASK7 / DRIVER_FILE).write_text(source)
    with pytest.raises(UnfinishedExercise) as info:
        plugins.resolve("hardware", DRIVER)
    assert expected in info.value.problem and info.value.line == line


def test_a_finished_function_that_kept_its_todo_comment_is_finished(exercises: Path) -> None:
    (exercises / TASK7 / DRIVER_FILE).write_text(
        "from rrbot_workshop.middleware.lifecycle import CallbackReturn\n\n\nclass RRBotHardwareInterface:\n"
        "    def on_activate(self, previous_state):\n        # TODO(task 7.2): enable movement\n"
        "        return CallbackReturn.SUCCESS\n"
    )
    assert plugins.resolve("hardware", DRIVER).__name__ == "RRBotHardwareInterface"


def test_a_missing_file_says_how_to_get_it_back(exercises: Path) -> None:
    (exercises / TASK7 / DRIVER_FILE).unlink()
    with pytest.raises(UnfinishedExercise, match=r"there is no rrbot_hardware_interface.py in .*rrbot-workshop reset 7"):
        plugins.resolve("hardware", DRIVER)


def test_describe_unfinished_for_tools_that_report(exercises: Path) -> None:
    text = plugins.describe_unfinished(CONTROLLER)
    assert text is not None and "your task 8 class DisplacementController" in text
    assert plugins.describe_unfinished(CONTROLLER, "controller") == text
    assert plugins.describe_unfinished("joint_state_broadcaster/JointStateBroadcaster") is None
    assert plugins.describe_unfinished("no_such_package/NoSuchController") is None
    _finish(exercises, TASK8, CONTROLLER_FILE)
    assert plugins.describe_unfinished(CONTROLLER) is None


# ------------------------------------------------------------------------------------------- bringup


def test_bringup_on_the_unfinished_driver_raises_one_error_with_the_message(exercises: Path) -> None:
    with pytest.raises(HardwareError) as info:
        rw.bringup(_urdf(), descriptions_root() / "rrbot" / "config" / "rrbot_controllers.yaml", name="names_unfinished")
    text = str(info.value)
    assert text.startswith("hardware component 'rrbot': "), text
    assert "your task 7 class RRBotHardwareInterface" in text and "line" in text
    assert isinstance(info.value.__cause__, UnfinishedExercise)
    assert "names_unfinished" not in systems()


def test_bringup_on_the_finished_driver_moves_the_robot(exercises: Path) -> None:
    _finish(exercises, TASK7, DRIVER_FILE)
    system = rw.bringup(_urdf(), descriptions_root() / "rrbot" / "config" / "rrbot_controllers.yaml", spawn=["joint_state_broadcaster",
                                                                   "forward_position_controller"], name="names_done")
    with system:
        component = system.resource_manager.get_component("rrbot")
        assert component.get_lifecycle_state().label == "active"
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.3, 0.3]))
        system.spin(1.0)
        position = system.latest("/joint_states").position
        assert position[0] > 0.25 and position[1] > 0.25  # from 0.1 rad at 0.5 rad/s


def test_mock_hardware_does_not_need_the_driver(exercises: Path) -> None:
    system = rw.bringup("rrbot", "rrbot_controllers.yaml", xacro_args={"use_mock_hardware": True},
                        spawn=["joint_state_broadcaster"], name="names_mock")
    with system:
        assert system.resource_manager.get_component("rrbot").get_lifecycle_state().label == "active"


def test_spawning_the_unfinished_controller_raises_one_error(exercises: Path) -> None:
    with pytest.raises(ControllerError) as info:
        rw.bringup("rrbot", YAML.format(type=CONTROLLER), spawn=["joint_state_broadcaster", "displacement_controller"],
                   name="names_ctrl")
    assert "your task 8 class DisplacementController" in str(info.value)
    assert isinstance(info.value.__cause__, UnfinishedExercise)


def test_spawning_the_finished_controller_works(exercises: Path) -> None:
    _finish(exercises, TASK8, CONTROLLER_FILE)
    system = rw.bringup("rrbot", YAML.format(type=CONTROLLER), spawn=["joint_state_broadcaster",
                                                                      "displacement_controller"], name="names_ctrl_ok")
    with system:
        states = {c.name: c.state for c in system.controller_manager.list_controllers()}
        assert states["displacement_controller"] == "active"
        assert type(system.controller_manager.controllers["displacement_controller"].controller).__module__ \
            .startswith("rrbot_workshop_track_")


# ------------------------------------------------------------------------------------------- lint


def test_lint_reports_the_unfinished_controller_without_crashing(exercises: Path, tmp_path: Path) -> None:
    yaml = tmp_path / "controllers.yaml"
    yaml.write_text(YAML.format(type=CONTROLLER))
    findings = lint_controllers(yaml, XACRO)  # with the description: lint asks the class for its interfaces
    errors = [f for f in findings if f.level == "error"]
    assert len(errors) == 1 and CONTROLLER in errors[0].message, [str(f) for f in findings]


def test_lint_of_the_finished_controller_has_no_error(exercises: Path, tmp_path: Path) -> None:
    _finish(exercises, TASK8, CONTROLLER_FILE)
    yaml = tmp_path / "controllers.yaml"
    yaml.write_text(YAML.format(type=CONTROLLER))
    assert [f for f in lint_controllers(yaml, XACRO) if f.level == "error"] == []
