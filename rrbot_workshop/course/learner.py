"""The learner's files, as a notebook cell uses them: found on the current track, loaded fresh, never fatal.

A notebook cell should be about ros2_control, not about importlib. These helpers load a task's Python file
from the current track (``exercises/`` by default), call the functions the learner writes, and turn any
failure into one short, readable message instead of a traceback through the library::

    answers = rw.course.load_module(3, "answers.py")          # None (and a message) if it does not import
    rw.course.ask(answers, "roles_of", "rrbot_description.urdf.xacro")
    start_rrbot = rw.course.function(2, "rrbot_bringup/bringup.py", "start_rrbot")
    system = rw.course.run(start_rrbot, robot_controller="forward_position_controller")  # None if it fails
    xacro = rw.course.mine_or_reference(1, "rrbot_description/urdf/rrbot.urdf.xacro",
                                        "rrbot/urdf/rrbot.urdf.xacro", check=problem_of, what="description")
    rw.course.step("configure", harness.configure)   # "configure: ..." and, if it raised, where in your file

Each load re-reads the file from disk, so a learner edits, saves and re-runs the cell.
"""

from __future__ import annotations

import logging
import pprint
import re
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

from rrbot_workshop.course import tracks
from rrbot_workshop.course.tracks import short_error, shown

_log = logging.getLogger(__name__)

__all__ = ["task_file", "shown", "load_module", "function", "ask", "short_error", "mine_or_reference", "run", "step"]

#: The tag of a TODO message (``TODO(task 3.1)``): enough to find it in the file, without its hint.
_TODO = re.compile(r"TODO\(task [0-9.]+\)")


def task_file(task: int, relpath: str, track: str | None = None) -> Path:
    """Path of ``relpath`` inside task ``task``'s folder on ``track`` (default: the current track)."""
    return tracks.task_dir(task, track) / relpath


def load_module(task: int, relpath: str, *, track: str | None = None, quiet: bool = False) -> ModuleType | None:
    """Import the learner's ``relpath`` of ``task`` afresh, or return ``None`` and say why.

    Args:
        task: Task number.
        relpath: File inside the task folder, e.g. ``"answers.py"`` or ``"rrbot_bringup/bringup.py"``.
        track: ``"exercises"`` or ``"solutions"``; default the current track.
        quiet: Do not print anything when the file cannot be imported.

    Returns:
        The module, or ``None`` when the file is missing or raises while importing (a half-written file is
        normal while working on a task; the message tells what to fix).
    """
    path = task_file(task, relpath, track)
    if not path.is_file():
        if not quiet:
            print(f"{relpath} is not in task {task}'s folder ({path.parent}); run `rrbot-workshop reset {task}`?")
        return None
    name = f"rrbot_workshop_learner_task{task:02d}_{Path(relpath).with_suffix('').as_posix().replace('/', '_')}"
    try:
        return tracks._import_file(path, name)
    except Exception as exc:  # noqa: BLE001 - any error in a learner's file means "not usable yet"
        if not quiet:
            print(f"{relpath} cannot be imported yet ({short_error(exc, path)}); fix it, save and run this cell again.")
        # a grader asks quietly; it still learns why (its rubric shows the learner's line, see grading.learner_errors)
        _log.debug("%s cannot be imported: %s", relpath, short_error(exc, path), exc_info=exc)
        return None
    finally:
        sys.modules.pop(name, None)


def function(task: int, relpath: str, name: str, *, track: str | None = None) -> Callable[..., Any] | None:
    """The function ``name`` from the learner's file, or ``None`` (with a message) if it is not usable yet."""
    module = load_module(task, relpath, track=track)
    if module is None:
        return None
    fn = getattr(module, name, None)
    if not callable(fn):
        print(f"{relpath} has no function {name}() yet.")
        return None
    return fn


def ask(
    module: ModuleType | None, question: str, *args: Any, show: bool = True, default: Any = None,
    label: str | None = None,
) -> Any:
    """Call the learner's ``question(*args)`` from ``module`` and print the answer; never raises.

    ``NotImplementedError`` reads "not written yet"; any other exception one short line that names the learner's
    file, line, function and exception. Returns the answer, or ``default`` when there is none. ``label`` names the
    question in the printed line (default its name).
    """
    if module is None:
        if show:
            print(f"{label or question}: the file does not load yet")
        return default
    fn = getattr(module, question, None)
    if not callable(fn):
        if show:
            print(f"{label or question}: not defined in {Path(module.__file__ or '?').name}")
        return default
    try:
        answer = fn(*args)
    except NotImplementedError as exc:
        if show:
            todo = _TODO.search(str(exc))
            print(f"{label or question}: not written yet" + (f" ({todo.group(0) if todo else exc})" if str(exc) else ""))
        return default
    except Exception as exc:  # noqa: BLE001 - a half-written answer must not stop the notebook
        path = Path(module.__file__) if module.__file__ else None
        if show:
            where = _where(exc)
            print(f"{label or question}: {where}" if where else f"{label or question}: raised {short_error(exc, path)}")
        return default
    if show:
        print(f"{label or question}:", pprint.pformat(answer, compact=True, width=110))
    return answer


def _where(exc: BaseException) -> str:
    """``"your <file>, line N, in <function>: <Type>: <message>"`` when ``exc`` passed through the learner's files,
    else ``""``."""
    from rrbot_workshop.course.grading.learner_errors import learner_location, learner_root

    return learner_location(exc, learner_root()) or ""


def _shown(path: Path) -> str:
    """``path`` from its task folder on (``task01_description/...``): the track is not the learner's concern."""
    parts = Path(shown(path)).parts
    return Path(*parts[1:]).as_posix() if len(parts) > 2 and parts[1].startswith("task") else Path(*parts).as_posix()


def mine_or_reference(
    task: int,
    relpath: str,
    reference: str | Path,
    *,
    check: Callable[[Path], str] | None = None,
    what: str = "file",
    track: str | None = None,
) -> Path:
    """The learner's file if it is usable yet, else the library's reference file; one line says which.

    Args:
        task: Task number.
        relpath: The learner's file inside the task folder.
        reference: The file to use instead: a path, or one relative to the library's ``descriptions/``.
        check: ``check(path)`` returns ``""`` when the file is usable, else what is missing; an exception it
            raises (a library error, a syntax error in the file) counts as the problem.
        what: What the file is, for the message (``"description"``, ``"controllers YAML"``).
        track: ``"exercises"`` or ``"solutions"``; default the current track.

    Returns:
        The path to use.
    """
    from rrbot_workshop.description import descriptions_root

    mine = task_file(task, relpath, track)
    fallback = Path(reference)
    if not fallback.is_absolute():
        fallback = descriptions_root() / fallback
    if not mine.is_file():
        problem = f"{relpath} is not in the task folder; `rrbot-workshop reset {task}` restores it"
    else:
        try:
            problem = check(mine) if check is not None else ""
        except Exception as exc:  # noqa: BLE001 - any error in a learner's file means "not usable yet"
            problem = short_error(exc, mine)
    if problem:
        print(f"Your {what} is not finished yet ({problem}); this notebook uses {_shown_reference(fallback)} instead.")
        return fallback
    print(f"Using your {what}: {_shown(mine)}")
    return mine


def _shown_reference(path: Path) -> str:
    from rrbot_workshop.description import descriptions_root

    root = descriptions_root()
    return f"descriptions/{path.relative_to(root).as_posix()}" if path.is_relative_to(root) else path.as_posix()


def run(
    fn: Callable[..., Any] | None,
    *args: Any,
    check: Callable[[Any], str] | None = None,
    what: str | None = None,
    instead: str = "",
    **kwargs: Any,
) -> Any:
    """Call the learner's ``fn(*args, **kwargs)``; on failure say why in one line and return ``None``.

    Systems that ``fn`` brought up before failing are shut down, so the cell can bring up its own.

    Args:
        fn: The learner's function (``None`` when :func:`function` could not load it: returns ``None`` silently,
            :func:`function` has already said why).
        check: ``check(result)`` returns ``""`` when the result is right, else what is wrong.
        what: How to name ``fn`` in the message (default ``name()``).
        instead: What the notebook does instead, appended to the message (``"rw.bringup"``).

    Returns:
        The result, or ``None``.
    """
    if fn is None:
        return None
    from rrbot_workshop.bringup import systems

    before = {id(system) for system in systems().values()}
    label = what or f"{getattr(fn, '__name__', 'your function')}()"
    path = Path(fn.__code__.co_filename) if hasattr(fn, "__code__") else None
    try:
        result = fn(*args, **kwargs)
        problem = check(result) if check is not None else ""
    except NotImplementedError as exc:
        todo = _TODO.search(str(exc))
        problem = "not written yet" + (f": {todo.group(0) if todo else exc}" if str(exc) else "")
    except Exception as exc:  # noqa: BLE001 - the learner's code may fail in any way while being written
        problem = _where(exc) or short_error(exc, path)
    if not problem:
        return result
    for system in systems().values():
        if id(system) not in before and system.running:
            system.shutdown()
    print(f"Your {label} does not run yet ({problem})" + (f"; this notebook uses {instead} instead." if instead else "."))
    return None


def step(label: str, call: Callable[[], Any]) -> Any:
    """Run one step of the learner's code for a notebook cell and say in a line what came of it; never raises.

    The line is the step's result (``done`` for ``None``), with the last error the library logged in brackets (what it
    did: "on_configure ... did not succeed"); then, when the learner's code raised, whether the library caught it or it
    came through, where: ``Your code raised: your displacement_controller.py, line 77, in on_configure: KeyError: ...``
    (see :class:`~rrbot_workshop.course.tracebacks.LearnerErrors`).

    Args:
        label: What the step is, at the start of the line (``"configure"``).
        call: The step, without arguments (``harness.configure``, ``lambda: ...``).

    Returns:
        The result, ``True`` for a step that returned ``None``, or ``None`` when it raised.
    """
    from rrbot_workshop.course.tracebacks import LearnerErrors

    outcome = ""
    result: Any = None
    with LearnerErrors() as errors:
        try:
            result = call()
        except NotImplementedError as exc:
            todo = _TODO.search(str(exc))
            where = _where(exc).split(": NotImplementedError", 1)[0]
            outcome = "not written yet" + (f" ({todo.group(0) if todo else exc})" if str(exc) else "") + (
                f": {where}" if where else "")
        except Exception as exc:  # noqa: BLE001 - the learner's half-written code must not stop the notebook
            outcome = f"raised {type(exc).__name__}"
            errors.note(exc)
    if not outcome:
        shown_result = pprint.pformat(result, compact=True, width=110) if isinstance(
            result, list | tuple | dict | set) else str(result)
        outcome = "done" if result is None else shown_result
    print(f"{label}: {outcome}" + (f" ({errors.reason})" if errors.reason else ""))
    errors.report()
    if outcome.startswith(("not written yet", "raised ")):
        return None
    return True if result is None else result
