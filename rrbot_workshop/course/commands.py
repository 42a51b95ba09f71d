"""The course's commands of ``rrbot-workshop``: grade, progress, tasks, reset and export.

:func:`add_commands` adds them to the tool's parser (see :mod:`rrbot_workshop.cli`) and returns their handlers.
Output carries no wall-clock times, so notebook cells that call them give the same output every run.
"""

from __future__ import annotations

import argparse
import json
import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError, GradingError

if TYPE_CHECKING:
    from rrbot_workshop.course.grading.rubric import Rubric

__all__ = ["add_commands"]

_TASK_FOLDER = re.compile(r"^task\d{2}_[A-Za-z0-9_]+$")


def add_commands(sub: Any) -> dict[str, Callable[[argparse.Namespace], int]]:
    """Add grade, progress, tasks, reset and export to ``sub`` (argparse's sub-parsers); return their handlers."""
    from rrbot_workshop.course.grading.runner import DEFAULT_CHECK_TIMEOUT

    def add_grading_options(p: argparse.ArgumentParser) -> None:
        p.add_argument("--json", action="store_true", help="print JSON instead of a rubric")
        p.add_argument("--track", choices=tracks.TRACKS, help="track to grade (default: $RRBOT_WORKSHOP_TRACK)")
        p.add_argument("--root", metavar="DIR", help="grade the taskNN_* folders in DIR instead of the track's")
        p.add_argument("--timeout", type=float, default=DEFAULT_CHECK_TIMEOUT, metavar="S",
                       help=f"time limit per check in seconds (default {DEFAULT_CHECK_TIMEOUT:g})")

    grade = sub.add_parser("grade", help="grade one task and print its rubric")
    grade.add_argument("task", type=int, help="task number")
    add_grading_options(grade)

    progress = sub.add_parser("progress", help="grade every task that has a grader")
    add_grading_options(progress)

    sub.add_parser("tasks", help="list the course's tasks and the current track")

    reset = sub.add_parser("reset", help="restore an exercise (your files are backed up first)")
    reset.add_argument("task", type=int, help="task number")

    export = sub.add_parser("export", help="write a copy of the course for learners, or your work as ROS 2 packages")
    target = export.add_mutually_exclusive_group(required=True)
    target.add_argument("--student", metavar="DIR", help="new folder for a copy of the course (no solutions/)")
    target.add_argument("--ros2", metavar="DIR",
                        help="new folder for your description and bringup as ROS 2 packages (controlko_description, "
                             "controlko_bringup), from one task of the current track")
    export.add_argument("--task", type=int, metavar="N",
                        help="with --ros2: the task whose description and bringup are exported (default: the most "
                             "advanced one that is finished); unfinished files are refused, nothing is written")
    export.add_argument("--force", action="store_true", help="with --ros2: write into a folder that is not empty")
    export.add_argument("--package-path", action="append", default=[], metavar="DIR",
                        help="a folder with ROS packages (source or installed trees) to find $(find pkg) and "
                             "package:// in (repeatable; searched before $RRBOT_WORKSHOP_PACKAGE_PATH)")
    export.add_argument("--withhold-references", action="store_true",
                        help="with --student: replace the library's worked answers (task 7's driver, task 8's "
                             "controller, task 13's planner) by stand-ins; the copy's README says what they do")
    return {"grade": _cmd_grade, "progress": _cmd_progress, "tasks": _cmd_tasks, "reset": _cmd_reset,
            "export": _cmd_export}


def _check_grading_options(args: argparse.Namespace) -> None:
    """``--timeout`` a finite number of seconds above 0; ``--root`` an existing folder holding taskNN_* folders.

    Raises:
        CourseError: Saying which option is wrong and what it accepts.
    """
    timeout = args.timeout
    if not math.isfinite(timeout) or timeout <= 0:
        raise CourseError("--timeout", timeout, f"--timeout must be a number of seconds above 0 (e.g. 30), not {timeout:g}")
    if args.root is None:
        return
    if not args.root.strip() or "\x00" in args.root or "\n" in args.root:
        raise CourseError("--root", args.root, "--root must be the path of a folder that holds taskNN_* folders")
    try:
        root = Path(args.root).expanduser().resolve()
        is_dir, exists = root.is_dir(), root.exists()
        tasks = [p.name for p in root.iterdir() if p.is_dir() and _TASK_FOLDER.match(p.name)] if is_dir else []
    except (OSError, RuntimeError) as exc:
        raise CourseError("--root", args.root, f"--root cannot be read: {getattr(exc, 'strerror', None) or exc}") from exc
    if not exists:
        raise CourseError("--root", args.root, f"--root '{root}' does not exist; give a folder that holds taskNN_* folders")
    if not is_dir:
        raise CourseError("--root", args.root, f"--root '{root}' is a file; give a folder that holds taskNN_* folders")
    if not tasks:
        raise CourseError("--root", args.root, f"--root '{root}' holds no taskNN_* folder (such as task01_description) to "
                          "grade")


def _cmd_grade(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.grading.runner import grade

    _check_grading_options(args)

    rubric = grade(args.task, track=args.track, task_root=args.root, check_timeout=args.timeout)
    print(rubric.to_json() if args.json else rubric.format())
    return 0


def _checks_line(rubric: Rubric) -> str:
    """``"3 of 21 checks"``: the learner's checks passed. A given check (the exercise satisfied it when handed out) is
    not the learner's work and is not counted; one that fails now is named, as it says something was broken."""
    scored = [c for c in rubric.checks if not c.given]
    broken = [c.name for c in rubric.checks if c.given and not c.passed]
    line = f"{sum(c.passed for c in scored)} of {len(scored)} checks"
    return line + (f"; given, failing now: {', '.join(broken)}" if broken else "")


def _cmd_progress(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.grading import attempts
    from rrbot_workshop.course.grading.pytest_process import warm_up
    from rrbot_workshop.course.grading.runner import grade, graded_tasks

    _check_grading_options(args)
    warm_up()  # every task is graded: the later ones fork from a process that has imported what graders use
    track = args.track or tracks.current_track()
    results: list[dict[str, Any]] = []
    lines = [f"Progress on the {track} track" if args.root is None else f"Progress of {args.root}"]
    names = tracks.task_names()
    score = max_score = 0.0
    for task in graded_tasks():
        label = names.get(task, f"task{task:02d}")
        try:
            rubric = grade(task, track=track, task_root=args.root, check_timeout=args.timeout, record=False)
        except (CourseError, GradingError) as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            results.append({"task": task, "score": 0.0, "max_score": 0.0, "checks": [], "error": first})
            lines.append(f"  {label:<32} not graded: {first}")
            continue
        entry = rubric.to_dict()
        if track == "exercises":
            # the learner's own checks: how many, and how long from the first to a full score (for the instructor)
            entry["attempts"] = attempts.summary(task, args.root)
        results.append(entry)
        score += rubric.score
        max_score += rubric.max_score
        lines.append(f"  {label:<32} {rubric.score:>5g}/{rubric.max_score:<5g} ({_checks_line(rubric)})")
    lines.append(f"Total: {score:g}/{max_score:g} points")
    if args.json:
        print(json.dumps({"track": track, "score": score, "max_score": max_score, "tasks": results}))
    else:
        print("\n".join(lines))
    return 0


def _cmd_tasks(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.grading.runner import graded_tasks

    root = tracks.course_root()
    graded = set(graded_tasks())
    print(f"Course folder: {root}")
    print(f"Track: {tracks.current_track()}")
    for task, name in tracks.task_names().items():
        have = [t for t in tracks.TRACKS if (root / t / name).is_dir()]
        grader = "grader" if task in graded else "no grader"
        print(f"  {task:>2}  {name:<32} {grader:<10} {', '.join(have) or 'no files'}")
    return 0


def _cmd_reset(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.grading.course import reset_exercise

    result = reset_exercise(args.task)
    root = tracks.course_root()
    if result.backup is not None:
        print(f"Your files are saved in {result.backup.relative_to(root)}")
    print(f"Restored {result.folder.relative_to(root)} ({result.files} files, from {result.source})")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.grading.course import export_student_copy, uncommitted_changes

    if args.ros2 is not None:
        from rrbot_workshop.course.ros2_export import export_ros2

        if args.withhold_references:
            raise CourseError("--withhold-references", "--ros2", "only applies to a student copy (--student DIR)")

        from rrbot_workshop.description.packages import use_package_path

        with use_package_path(args.package_path):
            result = export_ros2(args.ros2, force=args.force, task=args.task)
        others = [t for t in result.ready_tasks if t != result.task]
        print(f"Exporting task {result.task} ({result.task_folder}): its description and bringup"
              + (f" (also ready: task {', '.join(map(str, others))}; choose with --task N)." if others else "."))
        print(f"Wrote ROS 2 packages to {result.root}: {len(result.copied)} file(s) of yours copied as they are, "
              f"{len(result.generated)} generated (package.xml, CMakeLists.txt, launch file, README.md).")
        if result.to_port:
            print(f"Still to write in C++ before use_mock_hardware:=false runs: {', '.join(result.to_port)}.")
        print(f"Read {result.root / 'README.md'} for what to build with colcon and what remains to write in C++.")
        return 0
    if args.task is not None:
        raise CourseError("--task", args.task, "--task only applies to --ros2 (a student copy holds every task)")

    if not args.student.strip():
        raise CourseError("export target", args.student, "--student is empty; give the path of a new folder for the copy")
    left_out = uncommitted_changes(tracks.course_root())
    target = export_student_copy(args.student, withhold_references=args.withhold_references)
    print(f"Wrote a student copy of the course as committed (without solutions/) to {target}")
    if args.withhold_references:
        print("The library's references for tasks 7, 8 and 13 are replaced by stand-ins (see the copy's README and "
              "WITHHELD.json).")
    if left_out:
        print(f"Not in the copy: uncommitted changes to {len(left_out)} file(s), e.g. {', '.join(left_out[:3])}; "
              "commit them first if learners should get them.")
    return 0
