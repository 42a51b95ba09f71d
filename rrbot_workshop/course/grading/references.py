"""What the library itself contains that answers the course's tasks, and how a student copy can leave it out.

The course runs on a library that implements ros2_control, so some of its modules are, by nature, worked answers:
the RRBot driver a learner writes in task 7, the displacement controller of task 8, the jerk-limited planner of task
13; and the robot descriptions under ``descriptions/`` answer tasks 1, 2, 5, 10 and 11. :data:`REFERENCES` lists them
all, with what each answers; a student copy's README lists them (:func:`readme_section`).

``rrbot-workshop export --student DIR --withhold-references`` leaves out the Python references. The mechanism, and
why: each module is replaced in the copy by a *stand-in* of the same name (:data:`STAND_INS`), so every import keeps
working and no later notebook stops; what the stand-in does instead is documented per module:

* the driver (task 7) behaves as ``mock_components/GenericSystem`` (commands become states at once, no device, no
  modes): notebook 06, which runs before task 7, still brings the RRBot up on it;
* the displacement controller (task 8) and the planner (task 13) refuse, with a message, to be used: nothing after
  their own notebooks uses them (a test keeps it so), and the course's plugin names resolve to the learner's own class.

The descriptions are kept: every notebook from 02 on brings the RRBot up from them, so they cannot be left out
without leaving out the course; the README says so. A copy made this way records what it left out in
``WITHHELD.json``; its test command then runs the notebooks whose stored outputs came from a reference without
comparing those outputs, leaves out the reference's own unit tests, and the graders' checks that compare a learner's
code with a withheld reference are shown as GIVEN (the rule-by-rule checks still judge every stated rule).
"""

from __future__ import annotations

import fnmatch
import json
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

__all__ = ["LibraryReference", "REFERENCES", "STAND_INS", "MANIFEST", "WITHHELD_SKIP", "INSTRUCTOR_ONLY", "readme_section",
           "withheld", "is_withheld", "reference_or_skip", "write_withheld_copy", "instructor_only", "README_MARK",
           "README_END"]

#: What no student copy holds, with or without ``--withhold-references`` (course-relative POSIX patterns; a pattern
#: ending in ``/`` is a folder): the graders' own wrong and right solutions. Each is written from ``solutions/`` or is a
#: complete answer written another way, so pasted into an exercise it would score; they test the graders, which the
#: instructor's copy does.
INSTRUCTOR_ONLY: tuple[str, ...] = (
    "tests/unit/grader_variants.py",
    "tests/unit/test_grader_task[0-9][0-9].py",
    "tests/unit/task[0-9][0-9]_alternatives/",
    # the task-16 grader's hidden wrong controllers: a copy grades against its public ones
    "tests/tasks/task16_mutants/",
)


def instructor_only(rel: str) -> bool:
    """True for a course-relative path that no student copy holds (see :data:`INSTRUCTOR_ONLY`)."""
    path = PurePosixPath(rel)
    for pattern in INSTRUCTOR_ONLY:
        if pattern.endswith("/"):
            depth = len(PurePosixPath(pattern).parts)
            if len(path.parts) > depth and fnmatch.fnmatchcase(PurePosixPath(*path.parts[:depth]).as_posix(),
                                                               pattern.rstrip("/")):
                return True
        elif fnmatch.fnmatchcase(path.as_posix(), pattern):
            return True
    return False

#: How a grader's check that needs a withheld reference skips; the rubric shows it as GIVEN (no points either way).
WITHHELD_SKIP = "withheld:"

#: Written at the root of a copy made with ``--withhold-references``: what it left out.
MANIFEST = "WITHHELD.json"
#: Around the sections :func:`readme_section` writes into a copy's README (a copy of a copy replaces them).
README_MARK, README_END = "\n<!-- student copy -->", "<!-- /student copy -->\n"


@dataclass(frozen=True)
class LibraryReference:
    """A file of the library or of ``descriptions/`` that answers a task.

    Attributes:
        path: Course-relative POSIX path (a file or a folder).
        tasks: The tasks it answers.
        answers: What it gives away, in a few words.
        module: The Python module, for references a copy can withhold (``""`` for descriptions, which are kept).
        tests: Unit tests of the reference itself, left out of a copy that withholds it.
        notebooks: Notebooks whose stored outputs were made with it: a withholding copy runs them without comparing.
        kept: Why a copy keeps it (references that are not withheld).
    """

    path: str
    tasks: tuple[int, ...]
    answers: str
    module: str = ""
    tests: tuple[str, ...] = ()
    notebooks: tuple[str, ...] = ()
    kept: str = ""


REFERENCES: tuple[LibraryReference, ...] = (
    LibraryReference("rrbot_workshop/hardware/rrbot.py", (7,),
                     "a complete RRBotHardwareInterface driver over the RRBot device",
                     module="rrbot_workshop.hardware.rrbot", tests=("tests/unit/test_rrbot_driver.py",),
                     notebooks=("notebooks/06_lifecycle.ipynb", "notebooks/07_hardware_interface.ipynb")),
    LibraryReference("rrbot_workshop/controllers/displacement.py", (8,),
                     "a complete DisplacementController with its parameter validator",
                     module="rrbot_workshop.controllers.displacement",
                     tests=("tests/unit/test_displacement_controller.py",),
                     # notebook 16 runs the learner's task-8 class, or this one while it is unfinished
                     notebooks=("notebooks/08_write_a_controller.ipynb", "notebooks/16_test_your_controller.ipynb")),
    LibraryReference("rrbot_workshop/motion.py", (13,),
                     "jerk_limited_trajectory(): limits, ruckig planning and sampling as a JointTrajectory",
                     module="rrbot_workshop.motion", tests=("tests/unit/test_motion.py",),
                     notebooks=("notebooks/13_jerk_limited_trajectories.ipynb",)),
    LibraryReference("descriptions/rrbot/", (1, 2, 5, 7, 9),
                     "the RRBot xacro macros with their <ros2_control> tag, the mock and simulation switches, and the "
                     "controllers YAML files (mock, simulation, the incompatible JTC, the PID chain)",
                     kept="every notebook from 02 on brings the RRBot up from these files"),
    LibraryReference("descriptions/rrbot_on_diffbot/", (10,), "RRBot on DiffBot: the composed xacro and its YAML",
                     kept="notebook 10 runs on them until your own files of task 10 are complete"),
    LibraryReference("descriptions/multi_rrbot/", (11,), "two prefixed RRBots: the xacro and the controllers YAML",
                     kept="notebook 11 runs on them until your own files of task 11 are complete"),
    LibraryReference("descriptions/my_robot/", (15,),
                     "MyRobot's package: its <ros2_control> tags and a controllers YAML in Jazzy's layout (other "
                     "controllers than task 15.4 asks for)",
                     kept="notebook 15 brings MyRobot up from these files"),
    LibraryReference("rrbot_workshop/joint_limits/", (15,),
                     "Jazzy's joint limiters, which your write of task 15 applies (the grader compares with them)",
                     kept="they are ros2_control's joint_limits, which task 15 asks you to call; notebook 15 runs them"),
    LibraryReference("rrbot_workshop/ (any running system)", (6, 14),
                     "what each request of task 6 and each fault of task 14 does, for anyone who runs it before "
                     "predicting",
                     kept="it is ros2_control; the self-checks grade each prediction as it was when notebook 06 or 14 "
                          "first showed its outcome"),
)

_WITHHELD_NOTE = ('"""Withheld from this copy of the course: the library\'s reference for task {task} ({answers}).\n\n'
                  "An instructor exported this copy with --withhold-references; {fallback}\n"
                  '"""\n\n')

#: Module path -> the text that replaces it in a copy that withholds it.
STAND_INS: dict[str, str] = {
    "rrbot_workshop/hardware/rrbot.py": _WITHHELD_NOTE.format(
        task=7, answers="the RRBot driver",
        fallback="in its place the plugin\nrrbot_workshop/RRBotHardwareInterface behaves as mock_components/"
                 "GenericSystem (commands become states at once;\nno device, no control modes). The course's name "
                 "controlko_hardware_interface/RRBotHardwareInterface\nis your class from task 7.") + '''\
from __future__ import annotations

import logging

from rrbot_workshop.hardware.mock import GenericSystem

__all__ = ["RRBotHardwareInterface"]

_log = logging.getLogger(__name__)


class RRBotHardwareInterface(GenericSystem):
    """Stand-in for the withheld RRBot driver: mock hardware under the driver's name."""

    def on_init(self, info):  # type: ignore[no-untyped-def]
        _log.warning("the library's RRBot driver is withheld from this copy (the answer to task 7); '%s' runs as "
                     "mock_components/GenericSystem instead", info.name)
        return super().on_init(info)
''',
    "rrbot_workshop/controllers/displacement.py": _WITHHELD_NOTE.format(
        task=8, answers="the displacement controller",
        fallback="the course's names\ncontrolko_controllers/DisplacementController and displacement_controller/"
                 "DisplacementController are\nyour class from task 8, and nothing after notebook 08 needs this one.")
    + '''\
from __future__ import annotations

from rrbot_workshop.controller_interface.base import ControllerInterface
from rrbot_workshop.exceptions import ControllerError

__all__ = ["DisplacementController", "forbidden_interface_name_prefix"]

_WHY = ("the library's DisplacementController is withheld from this copy (the answer to task 8); finish "
        "exercises/task08_write_a_controller/displacement_controller.py and the course uses yours")


def forbidden_interface_name_prefix(value: str, prefix: str = "blup_") -> str | None:
    """Stand-in for the withheld validator: always refuses, saying why."""
    return _WHY


class DisplacementController(ControllerInterface):
    """Stand-in for the withheld controller: cannot be loaded."""

    def on_init(self):  # type: ignore[no-untyped-def]
        raise ControllerError(_WHY)
''',
    "rrbot_workshop/motion.py": _WITHHELD_NOTE.format(
        task=13, answers="the jerk-limited planner",
        fallback="finish\nexercises/task13_jerk_limited_trajectories/jerk_limited.py: nothing after notebook 13 "
                 "needs this one.") + '''\
from __future__ import annotations

from typing import Any

from rrbot_workshop.exceptions import ParameterError

__all__ = ["jerk_limited_trajectory"]


def jerk_limited_trajectory(*args: Any, **kwargs: Any) -> Any:
    """Stand-in for the withheld planner: refuses, saying why."""
    raise ParameterError("jerk_limited_trajectory", "reference",
                         "is withheld from this copy (the answer to task 13); use plan() from your "
                         "exercises/task13_jerk_limited_trajectories/jerk_limited.py")
''',
}


def withheld(root: Path) -> dict[str, list[str]]:
    """What a copy of the course left out: ``{"modules": [...], "tests": [...], "notebooks": [...]}`` (empty lists for
    a complete course)."""
    try:
        data = json.loads((root / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        data = {}
    return {key: [str(v) for v in data.get(key, [])] if isinstance(data, dict) else [] for key in
            ("modules", "tests", "notebooks")}


def is_withheld(module: str, root: Path | None = None) -> bool:
    """True if this copy of the course replaced the library module ``module`` by its stand-in."""
    from rrbot_workshop.course import tracks

    folder = root if root is not None else tracks.course_root()
    path = module.replace(".", "/") + ".py"
    return path in withheld(folder)["modules"]


def reference_or_skip(module: str) -> object:
    """For a grader's check that compares the learner's code with a reference: the module, or skip the check (shown
    as GIVEN) in a copy that withheld it."""
    import importlib

    import pytest

    if is_withheld(module):
        pytest.skip(f"{WITHHELD_SKIP} this copy of the course has no {module} to compare your code with; the other "
                    "checks judge the task's rules")
    return importlib.import_module(module)


def readme_section(withhold: bool) -> str:
    """The student README's sections on what this copy leaves out and what the library contains that answers tasks."""
    lines = ["", "## What this copy leaves out", "",
             "- `solutions/`: the finished files of every task.",
             "- The graders' own wrong and right solutions, which test the graders in the instructor's copy: "
             + ", ".join(f"`{p}`" for p in INSTRUCTOR_ONLY) + ".",
             ]
    if withhold:
        lines.append("- The library's Python references for tasks 7, 8 and 13 (below) and their unit tests: "
                     + ", ".join(f"`{t}`" for ref in REFERENCES for t in ref.tests) + ".")
    lines += ["", "The graders in `tests/tasks/` stay: they are the self-checks. Each check's hints come one level at "
              "a time (the idea, the API, then the code), and only for the first cause of a failure.",
              "", "## What the library contains that answers tasks", "",
              "The course runs on a library that implements ros2_control, so some of its files are worked answers to "
              "tasks:", ""]
    for ref in REFERENCES:
        tasks = ", ".join(str(t) for t in ref.tasks)
        if ref.module:
            state = " **Withheld from this copy.**" if withhold else ""
        else:
            state = f" Kept in every copy: {ref.kept}."
        lines.append(f"- `{ref.path}` (task{'s' if len(ref.tasks) > 1 else ''} {tasks}): {ref.answers}.{state}")
    lines.append("")
    if withhold:
        lines.append("In this copy the Python references are replaced by stand-ins of the same names: the RRBot "
                     "driver runs as mock hardware, the displacement controller and the planner refuse to run; the "
                     "course's plugin names use your own classes. The notebooks of those tasks run without "
                     "comparing their outputs, and the graders' checks that compare your code with a reference are "
                     "shown as GIVEN.")
    else:
        lines.append("An instructor can leave the Python references out of a copy: `rrbot-workshop export --student "
                     "DIR --withhold-references`.")
    return README_MARK + "\n".join(lines) + "\n" + README_END


def write_withheld_copy(target: Path) -> list[str]:
    """Replace the Python references in the copy at ``target`` by their stand-ins, leave out their tests, and write
    :data:`MANIFEST`; returns the course-relative paths replaced."""
    modules: list[str] = []
    tests: list[str] = []
    notebooks: list[str] = []
    for ref in REFERENCES:
        if not ref.module:
            continue
        (target / ref.path).write_text(STAND_INS[ref.path], encoding="utf-8")
        modules.append(ref.path)
        for test in ref.tests:
            (target / test).unlink(missing_ok=True)
            tests.append(test)
        notebooks.extend(n for n in ref.notebooks if n not in notebooks)
    manifest = {"modules": modules, "tests": tests, "notebooks": notebooks}
    (target / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    return modules
