"""``rrbot-workshop``: grade tasks, show progress, reset an exercise, hand out a student copy, lint controllers YAML
and descriptions, export the learner's work as ROS 2 packages.

Exit status: 0 when the command ran (a low score is still a successful grading), 1 when a grader could not
run or ``lint`` found an error, 2 for a usage error (unknown task, unknown track, bad folder). Output carries no wall-clock times, so
notebook cells that call it give the same output every run.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError, GradingError, RRBotWorkshopError

__all__ = ["main", "build_parser"]

USAGE_ERROR = 2
GRADER_ERROR = 1
#: Exit status of ``lint`` when it found at least one error (warnings alone exit 0).
LINT_ERRORS = 1

_TASK_FOLDER = re.compile(r"^task\d{2}_[A-Za-z0-9_]+$")
_XACRO_ARG_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class _Parser(argparse.ArgumentParser):
    """argparse, with a usage error said in one line (and where to find the usage) instead of the whole usage."""

    def error(self, message: str) -> NoReturn:
        self.exit(USAGE_ERROR, f"{self.prog}: error: {message.splitlines()[0] if message else 'bad arguments'} "
                               f"(see: {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``rrbot-workshop`` (sub-commands grade, progress, tasks, reset, export)."""
    from rrbot_workshop.course.grading.runner import DEFAULT_CHECK_TIMEOUT

    parser = _Parser(
        prog="rrbot-workshop", description="Self-checks and instructor tools for the rrbot_workshop course."
    )
    parser.add_argument("--course", metavar="DIR", help="course folder (default: found from the current folder)")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

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

    init = sub.add_parser("init", help="make (or update) a learner's workspace from the course installed for a room")
    init.add_argument("workspace", nargs="?", metavar="DIR", help="the workspace (default ~/rrbot_workshop)")
    init.add_argument("--from", dest="source", metavar="COURSE",
                      help="the installed course folder (default: the one this library belongs to)")
    single = sub.add_parser("singleuser", help="JupyterHub's single-user server for a learner: init ~/rrbot_workshop, "
                                               "then start jupyterhub-singleuser there (set it as the spawner's cmd)")
    single.add_argument("args", nargs=argparse.REMAINDER, help="passed on to jupyterhub-singleuser")

    room = sub.add_parser("class-report", help="the instructor's view of a room: every learner's progress from their "
                                              "attempt logs, as JSON, CSV and HTML")
    room.add_argument("workspaces", nargs="*", metavar="WORKSPACE",
                      help="learners' course folders or homes, or globs of them ('/home/*')")
    room.add_argument("--hub", metavar="URL", help="take the learners from this JupyterHub's user list (an API token "
                                                   "allowed to list users in $JUPYTERHUB_API_TOKEN)")
    room.add_argument("--home-template", metavar="PATH", default="/home/jupyter-{username}",
                      help="with --hub: a learner's home (default TLJH's '/home/jupyter-{username}')")
    room.add_argument("--out", metavar="DIR", required=True, help="folder for report.json, report.csv, report.html")

    lint = sub.add_parser("lint", help="check controllers YAML files and descriptions against what Jazzy accepts")
    lint.add_argument("files", nargs="+", metavar="FILE",
                      help="controllers YAML (.yaml/.yml) or description (.urdf/.xacro) files")
    lint.add_argument("--description", metavar="URDF",
                      help="a URDF or xacro file: also check that every interface a controller uses exists in it")
    lint.add_argument("--xacro-arg", action="append", default=[], metavar="NAME:=VALUE",
                      help="an argument for the xacro file(s), as xacro takes it (repeatable)")
    lint.add_argument("--arg", action="append", default=[], metavar="NAME:=VALUE",
                      help="a launch argument: its value replaces $(var NAME) in the YAML files, as ros2 launch "
                           "substitutes a parameter file (repeatable)")
    lint.add_argument("--package-path", action="append", default=[], metavar="DIR",
                      help="a folder holding ROS packages (source or install trees) where the description's "
                           "$(find pkg) and package:// are looked up (repeatable)")
    _add_bringup_parser(sub)
    return parser


def _add_bringup_parser(sub: Any) -> None:
    """``bringup DESCRIPTION [--controllers YAML] [--package-path DIR]... [--mock-hardware unknown|all]
    [--arg NAME:=VALUE]... [--spawn NAME]... [--inactive NAME]... [--seconds S]``."""
    up = sub.add_parser("bringup", help="bring a robot up on the simulated clock, spawn controllers, spin, and print "
                                        "its hardware, controllers and joint states")
    up.add_argument("description", metavar="DESCRIPTION",
                    help="a .urdf/.xacro file, package://pkg/path, $(find pkg)/path, or a package name")
    up.add_argument("--controllers", metavar="YAML",
                    help="controllers YAML: a path, package://pkg/path, $(find pkg)/path or a file name in the "
                         "description package's config/")
    up.add_argument("--package-path", action="append", default=[], metavar="DIR",
                    help="a folder with ROS packages, source or installed trees (repeatable; searched before "
                         "$RRBOT_WORKSHOP_PACKAGE_PATH and the course's descriptions/)")
    up.add_argument("--mock-hardware", choices=("unknown", "all"),
                    help="unknown: every hardware plugin the library does not have becomes the mock of its "
                         "component's type; all: every component does")
    up.add_argument("--arg", action="append", default=[], metavar="NAME:=VALUE",
                    help="a launch argument: a xacro argument of the description and the value of $(var NAME) in "
                         "the controllers YAML, as a launch file passes its arguments to both (repeatable)")
    up.add_argument("--namespace", metavar="NS", default=None,
                    help="the controller manager's namespace (/rrbot_1): its services and controllers' topics, and the "
                         "YAML's /rrbot_1/... and /**/... sections")
    up.add_argument("--spawn", action="append", default=[], metavar="NAME",
                    help="a controller to load, configure and activate (repeatable; all in one strict switch)")
    up.add_argument("--inactive", action="append", default=[], metavar="NAME",
                    help="a controller to load and configure only, as the spawner's --inactive (repeatable)")
    up.add_argument("--seconds", type=float, default=1.0, metavar="S",
                    help="simulated seconds to spin after spawning (default 1)")


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


def _cmd_progress(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.grading import attempts
    from rrbot_workshop.course.grading.runner import grade, graded_tasks

    _check_grading_options(args)
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
        passed = len(rubric.checks) - len(rubric.failed())
        lines.append(f"  {label:<32} {rubric.score:>5g}/{rubric.max_score:<5g} ({passed} of {len(rubric.checks)} checks)")
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


def _xacro_args(pairs: Sequence[str], option: str = "--xacro-arg",
                example: str = "use_mock_hardware:=true") -> dict[str, str]:
    """``NAME:=VALUE`` pairs of ``option`` as a mapping (the last value of a name wins).

    Raises:
        CourseError: For a pair without ``:=``, a name that is not an identifier, or a value on several lines.
    """
    what = "xacro" if option == "--xacro-arg" else "ros2 launch"
    out: dict[str, str] = {}
    for pair in pairs:
        name, sep, value = pair.partition(":=")
        if not sep or not name:
            raise CourseError(option, pair, f"{option} {pair!r} must be NAME:=VALUE, as {what} takes it", [example])
        if not _XACRO_ARG_NAME.match(name):
            raise CourseError(option, pair, f"{option} {pair!r} has the name {name!r}; an argument name is letters, "
                              "digits and underscores, not starting with a digit", [example])
        if any(c in value for c in "\n\r\x00"):
            raise CourseError(option, pair, f"{option} {pair!r} has a line break or NUL in the value of {name!r}; give "
                              "a value on one line", [example])
        out[name] = value
    return out


def _cmd_lint(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.lint import format_findings, lint_controllers, lint_description

    xacro_args = _xacro_args(args.xacro_arg)
    launch_args = _xacro_args(args.arg, "--arg", "joint_prefix:=rrbot_")
    package_path = [str(Path(p).expanduser()) for p in args.package_path]
    findings = []
    for name in args.files:
        if Path(name).suffix.lower() in (".yaml", ".yml"):
            findings += lint_controllers(name, args.description, xacro_args, launch_args=launch_args,
                                         package_path=package_path)
        else:
            findings += lint_description(name, xacro_args, package_path=package_path)
    print(format_findings(findings))
    return LINT_ERRORS if any(f.level == "error" for f in findings) else 0


def _bringup_args(pairs: Sequence[str]) -> dict[str, str]:
    """``--arg NAME:=VALUE`` pairs of ``bringup`` -> a mapping (xacro arguments).

    Raises:
        CourseError: If a pair is not ``NAME:=VALUE`` with a xacro argument name.
    """
    out: dict[str, str] = {}
    for pair in pairs:
        name, sep, value = pair.partition(":=")
        if not sep or not _XACRO_ARG_NAME.match(name) or any(c in value for c in "\n\r\x00"):
            raise CourseError("--arg", pair, f"--arg {pair!r} must be NAME:=VALUE on one line, as xacro and "
                              "ros2 launch take it, with NAME letters, digits and underscores",
                              ["use_mock_hardware:=true"])
        out[name] = value
    return out


def _format_value(value: Any) -> str:
    return f"{value:.4f}" if isinstance(value, float) else str(value)


def _cmd_bringup(args: argparse.Namespace) -> int:
    """Bring up, spawn, spin ``--seconds`` and print what runs; any failure is one line and exit status 2."""
    import logging

    from rrbot_workshop.bringup import bringup

    seconds = args.seconds
    if not math.isfinite(seconds) or seconds < 0:
        raise CourseError("--seconds", seconds, f"--seconds must be a number of seconds of 0 or more, not {seconds:g}")
    xacro_args = _bringup_args(args.arg)
    if not logging.getLogger().handlers:  # bringup's INFO lines (what was mocked) and every warning, on stderr
        logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        system = bringup(args.description, args.controllers, xacro_args=xacro_args, spawn=args.spawn,
                         inactive=args.inactive, package_path=args.package_path, mock_hardware=args.mock_hardware,
                         clock="sim", launch_args=xacro_args, namespace=args.namespace)
    except RRBotWorkshopError as exc:  # the whole message: a rejected switch lists its reasons on the next lines
        print(f"rrbot-workshop: error: {str(exc).strip() or type(exc).__name__}", file=sys.stderr)
        return USAGE_ERROR
    except Exception as exc:  # noqa: BLE001 - a plugin's own bug: one message, not a traceback
        raise CourseError("bringup", args.description, f"bringup failed: {type(exc).__name__}: {exc}") from exc
    try:
        system.spin(seconds)
        _print_system(system)
    finally:
        system.shutdown()
    return 0


def _print_system(system: Any) -> None:
    """The hardware components (plugins, mocks), controllers and joint states of a running system."""
    cm, rm = system.controller_manager, system.resource_manager
    print(f"System '{system.name}' at t = {system.time:.3f} s (simulated clock, {round(1 / system.period)} Hz)")
    print("Hardware components:")
    for comp in cm.list_hardware_components():
        mocked = system.mocked_hardware.get(comp.name)
        note = f"  [mock, replaces {mocked or '(no plugin)'}]" if mocked is not None else ""
        print(f"  {comp.name}  {comp.type}  {comp.plugin_name}  {comp.state.label}{note}")
    print("Controllers:")
    listed = cm.list_controllers()
    for ctrl in listed:
        print(f"  {ctrl.name}  {ctrl.type}  {ctrl.state}")
    if not listed:
        print("  (none loaded; spawn them with --spawn NAME)")
    print("Joint states:")
    msg = system.latest("/joint_states")
    if msg is not None and getattr(msg, "name", None):
        for i, joint in enumerate(msg.name):
            values = [(field, getattr(msg, field)) for field in ("position", "velocity", "effort")]
            text = "  ".join(f"{field} {_format_value(v[i])}" for field, v in values if i < len(v))
            print(f"  {joint}  {text}")
        return
    shown = False
    for info in system.hardware_infos:
        for joint in info.joints:
            parts = []
            for itf in joint.state_interfaces:
                try:
                    parts.append(f"{itf.name} {_format_value(rm.get_interface_value(f'{joint.name}/{itf.name}'))}")
                except Exception:  # noqa: BLE001 - an interface that is not exported: leave it out
                    continue
            print(f"  {joint.name}  {'  '.join(parts)}")
            shown = True
    if not shown:
        print("  (no joints)")
    else:
        print("  (read from the state interfaces: no joint_state_broadcaster publishes /joint_states)")


def _cmd_init(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.workspace import init_workspace

    result = init_workspace(args.workspace, args.source)
    what = "made" if result.created else "updated"
    print(f"Workspace {what}: {result.workspace} ({len(result.added)} exercise file(s) added, "
          f"{len(result.updated)} updated)")
    for rel in result.kept:
        print(f"  {rel}: you changed it and so did the course; yours is kept, the course's is beside it as "
              f"{Path(rel).name}.course-update")
    for line in result.notebooks:
        print(f"  {line}")
    if result.created:
        print(f"Work in {result.workspace}: open my_notebooks/00_intro.ipynb; in a terminal, cd there first.")
    return 0


def _cmd_singleuser(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.workspace import init_workspace, singleuser_command

    result = init_workspace()
    command = singleuser_command(result.workspace, list(args.args))
    os.execvp(command[0], command)  # the server takes this process's place: the spawner's signals reach it
    return 0  # pragma: no cover - execvp does not return


def _cmd_class_report(args: argparse.Namespace) -> int:
    from rrbot_workshop.course.class_report import build_report, hub_homes, write_report

    patterns = list(args.workspaces)
    if args.hub:
        patterns += hub_homes(args.hub, os.environ.get("JUPYTERHUB_API_TOKEN", ""), args.home_template)
    if not patterns:
        raise CourseError("class-report", "", "name the learners' workspaces ('/home/*') or a hub (--hub URL)")
    report = build_report(patterns, missing_ok=bool(args.hub))
    paths = write_report(report, Path(args.out))
    stuck = report.stuck()
    print(f"{len(report.learners)} learner(s); wrote {', '.join(str(p) for p in paths)}")
    if stuck:
        top = stuck[0]
        print(f"Most learners stuck on: task {top['task']} {top['check']} ({top['learners_failing']} learner(s))")
    for note in report.notes:
        print(f"note: {note}")
    return 0


_COMMANDS = {
    "grade": _cmd_grade,
    "progress": _cmd_progress,
    "tasks": _cmd_tasks,
    "reset": _cmd_reset,
    "export": _cmd_export,
    "lint": _cmd_lint,
    "bringup": _cmd_bringup,
    "class-report": _cmd_class_report,
    "init": _cmd_init,
    "singleuser": _cmd_singleuser,
}


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``rrbot-workshop`` with ``argv`` (default ``sys.argv[1:]``) and return the exit status."""
    parser = build_parser()
    given = list(sys.argv[1:] if argv is None else argv)
    if given[:1] == ["singleuser"] and not {"-h", "--help"} & set(given[1:2]):
        # everything after the command is the spawner's, options included (argparse would take them as ours)
        return _cmd_singleuser(argparse.Namespace(args=given[1:]))
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help (0) or a usage error (2)
        return int(exc.code) if isinstance(exc.code, int) else USAGE_ERROR
    previous_root = os.environ.get(tracks.ROOT_ENV)
    if args.course:
        os.environ[tracks.ROOT_ENV] = os.path.abspath(args.course)
    try:
        return _COMMANDS[args.command](args)
    except CourseError as exc:
        print(f"rrbot-workshop: error: {exc}", file=sys.stderr)
        return USAGE_ERROR
    except GradingError as exc:
        print(f"rrbot-workshop: the grader could not run: {exc}", file=sys.stderr)
        return GRADER_ERROR
    except (RRBotWorkshopError, OSError) as exc:  # a file or value the command could not use: one line, usage error
        text = str(exc).strip().splitlines()
        print(f"rrbot-workshop: error: {text[0] if text else type(exc).__name__}", file=sys.stderr)
        return USAGE_ERROR
    finally:
        if previous_root is None:
            os.environ.pop(tracks.ROOT_ENV, None)
        else:
            os.environ[tracks.ROOT_ENV] = previous_root


if __name__ == "__main__":
    sys.exit(main())
