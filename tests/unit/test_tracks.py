"""Course tracks: track selection, task folders, and the original workshop's plugin names per track."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError, HardwareError, UnfinishedExercise
from rrbot_workshop.middleware import plugins

_CONTROLLER = '''
class DisplacementController:
    VERSION = {version}
'''


@pytest.fixture(autouse=True)
def _clean_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    for name in (tracks.TRACK_ENV, tracks.ROOT_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(name, raising=False)
    tracks.set_track(None)
    yield
    tracks.set_track(None)


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A tiny course: task 8 with a learner's controller module on both tracks, a grader for task 3."""
    root = tmp_path / "course"
    (root / "tests" / "tasks").mkdir(parents=True)
    (root / "tests" / "tasks" / "test_task03_components.py").write_text("")
    for version, track in enumerate(tracks.TRACKS, start=1):
        folder = root / track / "task08_write_controller" / "controlko_controllers"
        folder.mkdir(parents=True)
        (folder / "displacement_controller.py").write_text(_CONTROLLER.format(version=version))
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    return root


def _plugin(kind: str = "controller", reference: str = "rrbot_workshop.middleware.lifecycle:State") -> tracks.TrackPlugin:
    return tracks.TrackPlugin(kind, "test/Thing", 8, "displacement_controller.py", "DisplacementController",
                              reference)


# ------------------------------------------------------------------------------------------- track selection


def test_default_track_is_exercises() -> None:
    assert tracks.current_track() == "exercises"


def test_environment_selects_the_track(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(tracks.TRACK_ENV, "solutions")
    assert tracks.current_track() == "solutions"


def test_invalid_environment_track_lists_valid_tracks(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(tracks.TRACK_ENV, "answers")
    with pytest.raises(CourseError, match="'answers'.*valid: 'exercises', 'solutions'"):
        tracks.current_track()


def test_set_track_overrides_environment_until_cleared(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(tracks.TRACK_ENV, "exercises")
    tracks.set_track("solutions")
    assert tracks.current_track() == "solutions"
    tracks.set_track(None)
    assert tracks.current_track() == "exercises"


def test_set_track_rejects_unknown_track() -> None:
    with pytest.raises(CourseError, match="unknown course track 'final'"):
        tracks.set_track("final")


# ------------------------------------------------------------------------------------------- folders


def test_course_root_from_environment(course: Path) -> None:
    assert tracks.course_root() == course.resolve()


def test_course_root_environment_must_be_a_folder(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv(tracks.ROOT_ENV, str(tmp_path / "nope"))
    with pytest.raises(CourseError, match="not a folder"):
        tracks.course_root()


def test_course_root_found_from_a_subfolder(course: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A notebook runs in notebooks/: the course is found by walking up."""
    monkeypatch.delenv(tracks.ROOT_ENV)
    (course / "notebooks").mkdir()
    monkeypatch.chdir(course / "notebooks")
    assert tracks.course_root() == course.resolve()


def test_course_root_missing_is_a_course_error(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(tracks, "__file__", str(tmp_path / "pkg" / "rrbot_workshop" / "tracks.py"))
    with pytest.raises(CourseError, match="no course folder"):
        tracks.course_root()


def test_task_names_merge_folders_and_graders(course: Path) -> None:
    assert tracks.task_names() == {3: "task03_components", 8: "task08_write_controller"}


def test_task_dir_follows_the_track(course: Path) -> None:
    assert tracks.task_dir(8) == course.resolve() / "exercises" / "task08_write_controller"
    tracks.set_track("solutions")
    assert tracks.task_dir(8) == course.resolve() / "solutions" / "task08_write_controller"
    assert tracks.task_dir(8, "exercises").parent.name == "exercises"


def test_task_dir_unknown_task_lists_existing_tasks(course: Path) -> None:
    with pytest.raises(CourseError, match="no task 9.*'task03_components', 'task08_write_controller'"):
        tracks.task_dir(9)


def test_task_dir_missing_track_folder(course: Path) -> None:
    import shutil

    shutil.rmtree(course / "solutions")
    with pytest.raises(CourseError, match="no 'solutions/' folder.*valid: 'exercises'"):
        tracks.task_dir(8, "solutions")


def test_task_root_environment_redirects_task_dir(course: Path, monkeypatch: pytest.MonkeyPatch,
                                                  tmp_path: Path) -> None:
    monkeypatch.setenv(tracks.TASK_ROOT_ENV, str(tmp_path / "upload"))
    assert tracks.task_dir(8) == (tmp_path / "upload").resolve() / "task08_write_controller"


def test_real_course_task01_folders() -> None:
    """The repository's task 1 exists on every track this copy has (a student copy has no solutions/), same path."""
    assert tracks.task_name(1) == "task01_description"
    for track in [t for t in tracks.TRACKS if (tracks.course_root() / t).is_dir()]:
        assert (tracks.task_dir(1, track) / "rrbot_description" / "urdf" / "rrbot.urdf.xacro").is_file()


# ------------------------------------------------------------------------------------------- track plugins


def test_track_class_comes_from_the_selected_track(course: Path) -> None:
    assert tracks.load_track_class(_plugin()).VERSION == 1
    tracks.set_track("solutions")
    assert tracks.load_track_class(_plugin()).VERSION == 2


def test_track_class_is_reread_after_an_edit(course: Path) -> None:
    path = course / "exercises" / "task08_write_controller" / "controlko_controllers" / "displacement_controller.py"
    assert tracks.load_track_class(_plugin()).VERSION == 1
    path.write_text(_CONTROLLER.format(version=7))
    assert tracks.load_track_class(_plugin()).VERSION == 7


def test_unfinished_learner_file_is_refused_naming_its_line(course: Path) -> None:
    path = course / "exercises" / "task08_write_controller" / "controlko_controllers" / "displacement_controller.py"
    path.write_text("class DisplacementController(:\n")
    with pytest.raises(UnfinishedExercise, match=r"task 8 class DisplacementController in .*SyntaxError.*line 1") as info:
        tracks.load_track_class(_plugin())
    assert info.value.task == 8 and info.value.line == 1 and info.value.path == path


def test_missing_class_is_refused(course: Path) -> None:
    path = course / "exercises" / "task08_write_controller" / "controlko_controllers" / "displacement_controller.py"
    path.write_text("X = 1\n")
    with pytest.raises(UnfinishedExercise, match="defines no class DisplacementController"):
        tracks.load_track_class(_plugin())


def test_no_learner_file_and_no_reference_raises_hardware_error(course: Path) -> None:
    plugin = tracks.TrackPlugin("hardware", "test/Hw", 7, "rrbot_hardware_interface.py", "RRBotHardwareInterface",
                                "rrbot_workshop.no_such_module:Driver")
    with pytest.raises(HardwareError, match="no folder for task 7.*no reference implementation"):
        tracks.load_track_class(plugin)


def test_original_plugin_names_are_registered() -> None:
    assert "controlko_hardware_interface/RRBotHardwareInterface" in plugins.available("hardware")
    assert "controlko_controllers/DisplacementController" in plugins.available("controller")


def test_original_controller_name_resolves_to_the_learners_class(course: Path) -> None:
    cls = plugins.resolve("controller", "controlko_controllers/DisplacementController")
    assert cls.VERSION == 1
