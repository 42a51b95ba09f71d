"""Course tracks: whether the learner's files (``exercises/``) or the finished ones (``solutions/``) are used.

Every task keeps its files at the same relative path in ``exercises/taskNN_<name>/`` and
``solutions/taskNN_<name>/``. The track is chosen by the ``RRBOT_WORKSHOP_TRACK`` environment variable
(default ``exercises``) or by :func:`set_track` in code. Graders and notebooks find a task's files with
:func:`task_dir`, so the same grader grades either track, and a copy of the course without ``solutions/``
still grades.

The plugin names of the original ROSCon 2022 workshop, ``controlko_hardware_interface/RRBotHardwareInterface``
and ``controlko_controllers/DisplacementController``, resolve to the class in the selected track's task
folder (see :data:`TRACK_PLUGINS`), so the original's files run on the learner's own classes. While that class is
unfinished (its file is missing or does not import, the class is not in it, or a function in it is still a stub:
it raises ``NotImplementedError`` or only returns ERROR under a TODO), the name cannot be loaded, as a C++ plugin
whose library was not built yet: :class:`~rrbot_workshop.exceptions.UnfinishedExercise` (a ``PluginNotFound``)
says which task, file and line, and what to do instead (finish the task, use the library's class under its own
name, mock the hardware, or the solutions track). A bringup therefore fails with that one message, and lint
reports it as one finding. Only where the course has no such task folder at all (the library used without the
course) do the names mean the library's reference implementation.
"""

from __future__ import annotations

import ast
import functools
import importlib
import importlib.util
import logging
import os
import re
import sys
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import ControllerError, CourseError, HardwareError, UnfinishedExercise
from rrbot_workshop.middleware import plugins

__all__ = [
    "TRACKS",
    "TRACK_ENV",
    "ROOT_ENV",
    "TASK_ROOT_ENV",
    "EXERCISES_ENV",
    "TrackPlugin",
    "TRACK_PLUGINS",
    "current_track",
    "set_track",
    "course_root",
    "task_names",
    "task_name",
    "task_dir",
    "load_track_class",
    "unfinished_problem",
    "file_stubs",
    "install",
]

logger = logging.getLogger(__name__)

#: The two tracks, in the order they are listed in messages.
TRACKS = ("exercises", "solutions")
#: Environment variable that selects the track.
TRACK_ENV = "RRBOT_WORKSHOP_TRACK"
#: Environment variable that points at the course folder (the one holding ``exercises/`` and ``tests/tasks/``).
ROOT_ENV = "RRBOT_WORKSHOP_ROOT"
#: Environment variable that points at a folder of ``taskNN_*`` folders used instead of the track's folder
#: (to grade a copy, e.g. an instructor grading a learner's upload).
TASK_ROOT_ENV = "RRBOT_WORKSHOP_TASK_ROOT"
#: Environment variable that points at a folder used as the ``exercises`` track instead of ``exercises/`` (the course's
#: test command points it at the exercises as committed, so tests see them untouched whatever the learner changed).
EXERCISES_ENV = "RRBOT_WORKSHOP_EXERCISES"

_TASK_RE = re.compile(r"^task(\d{2})_([A-Za-z0-9_]+)$")
_GRADER_RE = re.compile(r"^test_task(\d{2})_([A-Za-z0-9_]+)\.py$")

_track_override: str | None = None


def _check_track(name: str, source: str) -> str:
    if name not in TRACKS:
        raise CourseError("track", name, f"unknown course track '{name}' (from {source})", TRACKS)
    return name


def current_track() -> str:
    """The selected track: the one given to :func:`set_track`, else ``$RRBOT_WORKSHOP_TRACK``, else ``exercises``.

    Raises:
        CourseError: If the environment variable holds something other than ``exercises`` or ``solutions``.
    """
    if _track_override is not None:
        return _track_override
    value = os.environ.get(TRACK_ENV, "").strip()
    if not value:
        return TRACKS[0]
    return _check_track(value, f"${TRACK_ENV}")


def set_track(name: str | None) -> None:
    """Select the track for this process (``None`` goes back to the environment variable).

    Graders started from this process with :func:`rrbot_workshop.course.grading.check` use the same track.

    Args:
        name: ``"exercises"``, ``"solutions"`` or ``None``.

    Raises:
        CourseError: If ``name`` is not a track.
    """
    global _track_override
    _track_override = None if name is None else _check_track(name, "set_track()")


def _is_course(path: Path) -> bool:
    return (path / "tests" / "tasks").is_dir()


def course_root() -> Path:
    """The course folder: the one that holds ``exercises/``, ``solutions/`` and ``tests/tasks/``.

    Looked up in order: ``$RRBOT_WORKSHOP_ROOT``; the current folder or one of its parents (a notebook runs in
    ``notebooks/``); the folder above the installed package (an editable install).

    Raises:
        CourseError: If no such folder is found.
    """
    override = os.environ.get(ROOT_ENV)
    if override:
        path = Path(override).expanduser().resolve()
        if not path.is_dir():
            raise CourseError("folder", str(path), f"${ROOT_ENV} points at '{path}', which is not a folder")
        return path
    cwd = Path.cwd().resolve()
    for candidate in (cwd, *cwd.parents):
        if _is_course(candidate):
            return candidate
    package_parent = Path(__file__).resolve().parents[2]  # course/ -> rrbot_workshop/ -> the checkout
    if _is_course(package_parent):
        return package_parent
    raise CourseError(
        "folder", str(cwd), f"no course folder (one with tests/tasks/) at or above '{cwd}'; set ${ROOT_ENV}"
    )


def task_names() -> dict[int, str]:
    """Every task of the course: number -> folder name (``{1: "task01_description", ...}``), sorted.

    A task exists if it has a folder in ``exercises/`` or ``solutions/``, or a grader in ``tests/tasks/``.
    """
    root = course_root()
    found: dict[int, str] = {}
    for track in TRACKS:
        folder = root / track
        if folder.is_dir():
            for child in folder.iterdir():
                match = _TASK_RE.match(child.name)
                if match and child.is_dir():
                    found.setdefault(int(match.group(1)), child.name)
    graders = root / "tests" / "tasks"
    if graders.is_dir():
        for child in graders.iterdir():
            match = _GRADER_RE.match(child.name)
            if match:
                found.setdefault(int(match.group(1)), f"task{match.group(1)}_{match.group(2)}")
    return dict(sorted(found.items()))


def task_name(task: int) -> str:
    """Folder name of a task, e.g. ``task_name(1) == "task01_description"``.

    Raises:
        CourseError: If the course has no such task; the message lists the tasks that exist.
    """
    names = task_names()
    if task not in names:
        raise CourseError("task", task, f"there is no task {task} in {course_root()}", names.values())
    return names[task]


def task_dir(task: int, track: str | None = None) -> Path:
    """Folder of a task's files on a track, e.g. ``exercises/task01_description``.

    If ``$RRBOT_WORKSHOP_TASK_ROOT`` is set, the task folder is looked up there instead (the track does not
    matter then): this grades a copy of the files. ``$RRBOT_WORKSHOP_EXERCISES`` replaces the ``exercises/`` folder
    of the exercises track only (the test command points it at the exercises as committed).

    Args:
        task: Task number (1-12).
        track: ``"exercises"`` or ``"solutions"``; default :func:`current_track`.

    Raises:
        CourseError: If the task does not exist, or the track's folder is not part of this copy of the course.
    """
    name = task_name(task)
    override = os.environ.get(TASK_ROOT_ENV)
    if override:
        return Path(override).expanduser().resolve() / name
    chosen = _check_track(track, "task_dir()") if track is not None else current_track()
    exercises = os.environ.get(EXERCISES_ENV)
    if chosen == "exercises" and exercises:
        return Path(exercises).expanduser().resolve() / name
    folder = course_root() / chosen
    if not folder.is_dir():
        raise CourseError(
            "track", chosen, f"this copy of the course has no '{chosen}/' folder; choose another track", [
                t for t in TRACKS if (course_root() / t).is_dir()
            ]
        )
    return folder / name


# --------------------------------------------------------------------------------------------- track plugins


@dataclass(frozen=True)
class TrackPlugin:
    """A plugin name whose class comes from the selected track's task folder.

    Attributes:
        kind: Plugin kind, ``"hardware"`` or ``"controller"``.
        type_name: The type string used in URDF ``<plugin>`` tags or controller YAML.
        task: Task number whose folder holds the learner's module.
        file_name: Module file searched for anywhere under the task folder.
        class_name: Class defined by that module.
        reference: ``"module:Class"`` of the library's reference implementation, used where the course has no
            such task folder.
        library_name: The plugin name of that reference in the library, never re-mapped to a learner's file.
    """

    kind: str
    type_name: str
    task: int
    file_name: str
    class_name: str
    reference: str
    library_name: str = ""


#: The original workshop's plugin names, resolved per track.
TRACK_PLUGINS: tuple[TrackPlugin, ...] = (
    TrackPlugin(
        kind="hardware",
        type_name="controlko_hardware_interface/RRBotHardwareInterface",
        task=7,
        file_name="rrbot_hardware_interface.py",
        class_name="RRBotHardwareInterface",
        reference="rrbot_workshop.hardware.rrbot:RRBotHardwareInterface",
        library_name="rrbot_workshop/RRBotHardwareInterface",
    ),
    TrackPlugin(
        kind="controller",
        type_name="controlko_controllers/DisplacementController",
        task=8,
        file_name="displacement_controller.py",
        class_name="DisplacementController",
        reference="rrbot_workshop.controllers.displacement:DisplacementController",
        library_name="rrbot_workshop/DisplacementController",
    ),
    # the original's master branch exports the same class as displacement_controller/DisplacementController
    TrackPlugin(
        kind="controller",
        type_name="displacement_controller/DisplacementController",
        task=8,
        file_name="displacement_controller.py",
        class_name="DisplacementController",
        reference="rrbot_workshop.controllers.displacement:DisplacementController",
        library_name="rrbot_workshop/DisplacementController",
    ),
    # MyRobot's arm (notebook 15); the library has no worked answer of task 15: without the course it is mock hardware
    TrackPlugin(
        kind="hardware",
        type_name="my_robot/MyRobotHardware",
        task=15,
        file_name="my_robot_hardware.py",
        class_name="MyRobotHardware",
        reference="rrbot_workshop.hardware.mock:GenericSystem",
    ),
)


def _import_file(path: Path, module_name: str) -> Any:
    """Execute a Python file as a fresh module (its folder is importable while it runs)."""
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load '{path}' as a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    folder = str(path.parent)
    sys.path.insert(0, folder)
    try:
        spec.loader.exec_module(module)
    except BaseException:
        sys.modules.pop(module_name, None)
        raise
    finally:
        try:
            sys.path.remove(folder)
        except ValueError:
            pass
    return module


def _reference(plugin: TrackPlugin) -> Any:
    module, _, attr = plugin.reference.partition(":")
    return getattr(importlib.import_module(module), attr)


def _task_folder(plugin: TrackPlugin, track: str) -> Path | None:
    """The task's folder on ``track``, or ``None`` where this course has none (the library without the course)."""
    try:
        folder = task_dir(plugin.task, track)
    except CourseError:
        return None
    return folder if folder.is_dir() else None


def _find_module_file(plugin: TrackPlugin, track: str) -> Path | None:
    folder = _task_folder(plugin, track)
    if folder is None:
        return None
    matches = sorted(p for p in folder.rglob(plugin.file_name) if "__pycache__" not in p.parts)
    return matches[0] if matches else None


def _raises_not_implemented(node: ast.AST) -> bool:
    if not isinstance(node, ast.Raise) or node.exc is None:
        return False
    exc = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
    return isinstance(exc, ast.Name) and exc.id == "NotImplementedError"


def _todo_message(node: ast.Raise) -> str:
    """The message a stub raises (``TODO(task 7.2): on_configure``), if it is a plain string."""
    if isinstance(node.exc, ast.Call) and node.exc.args and isinstance(node.exc.args[0], ast.Constant):
        value = node.exc.args[0].value
        return value if isinstance(value, str) else ""
    return ""


def _is_failing_stub(function: ast.FunctionDef | ast.AsyncFunctionDef, lines: list[str]) -> bool:
    """A function left as a TODO that only answers ERROR or FAILURE (or nothing): not written yet."""
    body = list(function.body)
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        body = body[1:]  # the docstring
    if len(body) != 1:
        return False
    only = body[0]
    failing = isinstance(only, ast.Pass) or (
        isinstance(only, ast.Expr) and isinstance(only.value, ast.Constant) and only.value.value is Ellipsis
    ) or (
        isinstance(only, ast.Return) and (
            only.value is None
            or (isinstance(only.value, ast.Attribute) and only.value.attr in ("ERROR", "FAILURE"))
        )
    )
    end = function.end_lineno or function.lineno
    return failing and any("TODO" in line for line in lines[function.lineno - 1:end])


def _stubs(tree: ast.Module, lines: list[str]) -> list[tuple[int, str, str]]:
    """``(line, function, what it does)`` of every function of the file still left as a stub, in file order."""
    found: dict[int, tuple[int, str, str]] = {}

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                visit(child, f"{prefix}{child.name}.")
            elif isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                name = f"{prefix}{child.name}"
                for sub in ast.walk(child):
                    if isinstance(sub, ast.Raise) and _raises_not_implemented(sub) and sub.lineno not in found:
                        message = _todo_message(sub)
                        found[sub.lineno] = (sub.lineno, name, f"raises NotImplementedError({message!r})"
                                             if message else "raises NotImplementedError")
                if _is_failing_stub(child, lines) and child.lineno not in found:
                    found[child.lineno] = (child.body[-1].lineno, name, "only answers ERROR under its TODO")
                visit(child, f"{name}.")

    visit(tree, "")
    return [found[k] for k in sorted(found)]


def file_stubs(path: Path) -> list[tuple[int, str, str]]:
    """The functions of a Python file still left as stubs, without running it: ``(line, function, what it does)``.

    A stub raises ``NotImplementedError``, or only answers ERROR/FAILURE (or nothing) under a TODO. A file that does
    not parse or read has none to report (:func:`unfinished_problem` says why it is unfinished).
    """
    try:
        source = path.read_text(encoding="utf-8")
        return _stubs(ast.parse(source, filename=str(path)), source.splitlines())
    except (SyntaxError, OSError, UnicodeDecodeError, ValueError):
        return []


def unfinished_problem(path: Path, class_name: str) -> tuple[int | None, str, Any]:
    """Whether the learner's file ``path`` holds a finished ``class_name``, without running any of its methods.

    Unfinished: the file does not parse or import, has no class of that name, or a function in it is still a stub
    (``raise NotImplementedError``, or a TODO that only returns ERROR/FAILURE). The file is parsed before it is
    imported, so a file full of stubs is never executed.

    Args:
        path: The learner's Python file.
        class_name: The class the plugin name stands for.

    Returns:
        ``(line, problem, cls)``: ``problem`` is ``""`` and ``cls`` the class when it is finished; otherwise
        ``problem`` says what is unfinished (with the file's name and line) and ``cls`` is ``None``.
    """
    try:
        source = path.read_text(encoding="utf-8")
        tree = ast.parse(source, filename=str(path))
    except SyntaxError as exc:
        return exc.lineno, f"SyntaxError: {exc.msg} ({path.name}, line {exc.lineno})", None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        return None, f"{path.name} cannot be read ({type(exc).__name__}: {exc})", None
    stubs = _stubs(tree, source.splitlines())
    if stubs:
        line, function, what = stubs[0]
        more = f"; {len(stubs) - 1} more stub(s) after it" if len(stubs) > 1 else ""
        return line, f"{function}() is not written yet: it {what} ({path.name}, line {line}){more}", None
    module_name = f"rrbot_workshop_track_{path.parent.parent.name}_{path.parent.name}_{path.stem}"
    try:
        module = _import_file(path, module_name)
    except Exception as exc:  # noqa: BLE001 - any error in a learner's file means "not usable yet"
        frames = [f for f in _traceback_frames(exc) if Path(f.filename) == path]
        return (frames[-1].lineno if frames else None), f"it does not import: {short_error(exc, path)}", None
    cls = getattr(module, class_name, None)
    if not isinstance(cls, type):
        return None, f"{path.name} defines no class {class_name}", None
    return None, "", cls


def _traceback_frames(exc: BaseException) -> list[Any]:
    import traceback

    return list(traceback.extract_tb(exc.__traceback__))


def _shown(path: Path) -> str:
    try:
        return shown(path)
    except CourseError:
        return path.as_posix()


def _instead(plugin: TrackPlugin) -> str:
    """What a learner can do while the class is unfinished, for the error message."""
    options = [f"finish task {plugin.task} (`rrbot-workshop grade {plugin.task}`)"]
    if plugin.library_name:
        options.append(f"name the library's '{plugin.library_name}' instead")
    if plugin.kind == "hardware":
        options.append('mock it (use_mock_hardware:=true, or mock_hardware="unknown")')
    try:
        if (course_root() / TRACKS[1]).is_dir():  # a student copy has no solutions to offer
            options.append(f"use the solutions track ({TRACK_ENV}={TRACKS[1]})")
    except CourseError:
        pass
    return ", ".join(options[:-1]) + ", or " + options[-1]


def _unfinished(plugin: TrackPlugin, track: str, path: Path | None, line: int | None, problem: str) -> UnfinishedExercise:
    where = _shown(path) if path is not None else f"task {plugin.task}'s folder"
    message = (f"'{plugin.type_name}' is the workshop's name for your task {plugin.task} class {plugin.class_name} in "
               f"{where}, which is unfinished: {problem}. To run anyway: {_instead(plugin)}.")
    return UnfinishedExercise(plugin.type_name, plugin.kind, plugin.task, path, line, problem, message,
                              plugins.available(plugin.kind))


def load_track_class(plugin: TrackPlugin, track: str | None = None) -> Any:
    """The class for ``plugin`` on a track: the task folder's module, re-read from disk.

    Args:
        plugin: Which plugin to load.
        track: Track to use; default :func:`current_track`.

    Returns:
        The class defined in the track's module when it is finished (see :func:`unfinished_problem`); the library's
        reference class when the course has no folder for the task on that track (a warning says so).

    Raises:
        UnfinishedExercise: If the task folder exists but the class in it is unfinished (the file is missing, does
            not import, lacks the class, or still has stubs); the message names the file, the line and the options.
        HardwareError: For a hardware plugin when there is no task folder and no reference implementation either.
        ControllerError: For a controller plugin in that case.
    """
    chosen = track if track is not None else current_track()
    folder = _task_folder(plugin, chosen)
    if folder is not None:
        path = _find_module_file(plugin, chosen)
        if path is None:
            raise _unfinished(plugin, chosen, None, None,
                              f"there is no {plugin.file_name} in {_shown(folder)} "
                              f"(`rrbot-workshop reset {plugin.task}` restores the exercise)")
        line, problem, cls = unfinished_problem(path, plugin.class_name)
        if problem:
            raise _unfinished(plugin, chosen, path, line, problem)
        logger.debug("plugin '%s' -> %s from %s", plugin.type_name, plugin.class_name, path)
        return cls
    problem = f"no folder for task {plugin.task} on the '{chosen}' track"
    try:
        cls = _reference(plugin)
    except (ImportError, AttributeError) as exc:
        error = HardwareError if plugin.kind == "hardware" else ControllerError
        raise error(
            f"plugin '{plugin.type_name}': {problem}, and the library has no reference implementation "
            f"'{plugin.reference}' ({type(exc).__name__}: {exc})"
        ) from exc
    logger.warning(
        "plugin '%s': %s; using the library's reference implementation '%s' instead",
        plugin.type_name, problem, plugin.reference,
    )
    return cls


_installed = False


def install() -> None:
    """Register the track resolvers of :data:`TRACK_PLUGINS` with :mod:`rrbot_workshop.middleware.plugins` (idempotent)."""
    global _installed
    if _installed:
        return
    _installed = True
    for plugin in TRACK_PLUGINS:
        plugins.register_resolver(plugin.kind, plugin.type_name, functools.partial(load_track_class, plugin))


def shown(path: Path) -> str:
    """``path`` as the learner knows it: relative to the course folder (``exercises/task02_.../bringup.py``).

    The same text whatever folder the track really reads (the test command may point the exercises track at a
    temporary copy), so a notebook's output does not depend on it.
    """
    path = Path(path).resolve()
    exercises = os.environ.get(EXERCISES_ENV)
    if exercises and path.is_relative_to(Path(exercises).resolve()):
        return (Path("exercises") / path.relative_to(Path(exercises).resolve())).as_posix()
    root = course_root()
    return path.relative_to(root).as_posix() if path.is_relative_to(root) else path.as_posix()


def short_error(exc: BaseException, path: Path | None = None) -> str:
    """One line for ``exc`` and, when the error is in the learner's file ``path``, where in it.

    Frames inside the library, importlib and Python are left out: the learner sees their own line.
    """
    text = f"{type(exc).__name__}: {exc}"
    if isinstance(exc, SyntaxError) and exc.filename and exc.lineno:
        return f"{text} ({Path(exc.filename).name}, line {exc.lineno})"
    if path is not None:
        frames = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename) == path]
        if frames:
            last = frames[-1]
            code = f": {last.line.strip()}" if last.line else ""
            return f"{text} (in {path.name}, line {last.lineno}{code})"
    return text
