"""The tools' commands of ``rrbot-workshop``: lint and bringup, for anybody's ROS files.

:func:`add_commands` adds them to the tool's parser (see :mod:`rrbot_workshop.cli`) and returns their handlers.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import stat
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import CourseError, RRBotWorkshopError

__all__ = ["add_commands", "LINT_ERRORS", "USAGE_ERROR", "BRINGUP_MAX_SECONDS", "BRINGUP_MAX_CYCLES"]

#: Exit status of ``lint`` when it found at least one error (warnings alone exit 0).
LINT_ERRORS = 1
#: Exit status of a command given a file or value it cannot use.
USAGE_ERROR = 2
#: The longest ``bringup --seconds`` [s of simulated time], and the most control cycles it may run (seconds times the
#: controller manager's update rate): the work of one command stays bounded whatever the YAML's update_rate says.
BRINGUP_MAX_SECONDS = 3600.0
BRINGUP_MAX_CYCLES = 1_000_000

_XACRO_ARG_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def add_commands(sub: Any) -> dict[str, Callable[[argparse.Namespace], int]]:
    """Add lint and bringup to ``sub`` (argparse's sub-parsers); return their handlers."""
    lint = sub.add_parser("lint", help="check controllers YAML files and descriptions against what Jazzy accepts")
    lint.add_argument("files", nargs="+", metavar="FILE",
                      help="controllers YAML (.yaml/.yml) or description (.urdf/.xacro) files")
    lint.add_argument("--description", action="append", default=[], metavar="[NS=]URDF",
                      help="a URDF or xacro file: also check that every interface a controller uses exists in it. "
                           "With several controller managers in the YAML, give each its own: NS=URDF, NS being the "
                           "manager's namespace (/rrbot_1) or full name (/rrbot_1/controller_manager); a plain URDF "
                           "is for every manager not named (repeatable)")
    lint.add_argument("--namespace", metavar="NS", default=None,
                      help="the controller manager's namespace (/rrbot_1), as the launch file gives ros2_control_node: "
                           "check only that manager, with the YAML's /rrbot_1/... and /**/... sections")
    lint.add_argument("--arg", action="append", default=[], metavar="NAME:=VALUE",
                      help="a launch argument: a xacro argument of the description(s) and the value of $(var NAME) "
                           "in the YAML files, as a launch file passes its arguments to both (repeatable; the same "
                           "as bringup --arg)")
    lint.add_argument("--xacro-arg", action="append", default=[], metavar="NAME:=VALUE",
                      help="an argument for the xacro file(s) only, as xacro takes it; it wins over an --arg of the "
                           "same name (repeatable)")
    lint.add_argument("--package-path", action="append", default=[], metavar="DIR",
                      help="a folder holding ROS packages (source or install trees) where the description's "
                           "$(find pkg) and package:// are looked up (repeatable)")
    _add_bringup_parser(sub)
    return {"lint": _cmd_lint, "bringup": _cmd_bringup}


def _add_bringup_parser(sub: Any) -> None:
    """``bringup DESCRIPTION [--controllers YAML] [--package-path DIR]... [--mock-hardware unknown|all]
    [--arg NAME:=VALUE]... [--spawn NAME]... [--inactive NAME]... [--seconds S]``."""
    up = sub.add_parser("bringup", help="bring a robot up on the simulated clock, spawn controllers, spin, and print "
                                        "its hardware, controllers and joint states")
    up.add_argument("description", metavar="DESCRIPTION",
                    help="a .urdf/.xacro file, package://pkg/path, $(find pkg)/path, or a package name (files are "
                         "read only if they are regular files: never a FIFO or a device)")
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
                    help=f"simulated seconds to spin after spawning (default 1; at most {BRINGUP_MAX_SECONDS:g}, and at "
                         f"most {BRINGUP_MAX_CYCLES:,} control cycles at the controller manager's update rate)")


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
    from rrbot_workshop.tools.lint import format_findings, lint_controllers, lint_description

    launch_args = _xacro_args(args.arg, "--arg", "joint_prefix:=rrbot_")
    xacro_args = {**launch_args, **_xacro_args(args.xacro_arg)}
    package_path = [str(Path(p).expanduser()) for p in args.package_path]
    descriptions = _lint_descriptions(args.description)
    namespace = None if args.namespace is None else _namespace("--namespace", args.namespace)
    findings = []
    for name in args.files:
        if Path(name).suffix.lower() in (".yaml", ".yml"):
            findings += lint_controllers(name, descriptions or None, xacro_args, launch_args=launch_args,
                                         package_path=package_path, namespace=namespace)
        else:
            findings += lint_description(name, xacro_args, package_path=package_path)
    print(format_findings(findings))
    return LINT_ERRORS if any(f.level == "error" for f in findings) else 0


def _namespace(option: str, value: str) -> str:
    """A namespace or manager name given on the command line, as ``/a/b``.

    Raises:
        CourseError: If it is not ``/`` or ``/``-separated names of letters, digits and underscores.
    """
    tokens = value.strip().strip("/").split("/")
    if value.strip().strip("/") and not all(_XACRO_ARG_NAME.match(t) for t in tokens):
        raise CourseError(option, value, f"{option} {value!r} is not a ROS namespace: names of letters, digits and "
                          "underscores separated by '/'", ["/rrbot_1", "/rrbot_1/controller_manager", "/"])
    return "/" + "/".join(t for t in tokens if t)


def _lint_descriptions(values: Sequence[str]) -> dict[str, str]:
    """``--description [NS=]URDF`` values -> ``{namespace or manager name, or "" for every manager: file}``.

    Raises:
        CourseError: If a value has no file, or two values are for the same managers.
    """
    from rrbot_workshop.tools.lint.descriptions import EVERY_MANAGER, split_description_option

    out: dict[str, str] = {}
    for value in values:
        who, file = split_description_option(value)
        if who != EVERY_MANAGER:
            who = _namespace("--description", who)
        if not file:
            raise CourseError("--description", value, f"--description {value!r} names no file; give NS=URDF or URDF",
                              ["/rrbot_1=rrbot.urdf.xacro", "rrbot.urdf.xacro"])
        if who in out:
            whom = f"the managers of '{who}'" if who else "every manager"
            raise CourseError("--description", value, f"--description is given twice for {whom} ({out[who]!r} and "
                              f"{file!r}); give each manager its own with NS=URDF", ["/rrbot_1=a.xacro",
                                                                                     "/rrbot_2=b.xacro"])
        out[who] = file
    return out


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


def _regular_file(option: str, value: str | None) -> None:
    """Refuse a path given on the command line that is not a regular file (a FIFO would block the read forever, a
    device would never end); a package reference, a package name or text is resolved and checked by the reader.

    Raises:
        CourseError: If ``value`` names an existing path that is not a regular file.
    """
    if value is None or "\n" in value or value.lstrip().startswith("<") or value.startswith(("package://", "$(")):
        return
    try:
        mode = os.stat(value).st_mode  # a link is followed: what counts is what would be read
    except (OSError, ValueError):
        return  # missing (or not a path): bringup says where it looked
    if not stat.S_ISREG(mode):
        kind = ("a folder" if stat.S_ISDIR(mode) else "a FIFO (named pipe)" if stat.S_ISFIFO(mode)
                else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "not a regular file")
        raise CourseError(option, value, f"{option} {value!r} is {kind}; give a regular file (.urdf, .xacro or "
                          "controllers .yaml), package://pkg/path or $(find pkg)/path")


def _cmd_bringup(args: argparse.Namespace) -> int:
    """Bring up, spawn, spin ``--seconds`` and print what runs; any failure is one line and exit status 2."""
    import logging

    from rrbot_workshop.bringup import bringup

    seconds = args.seconds
    if not math.isfinite(seconds) or seconds < 0:
        raise CourseError("--seconds", seconds, f"--seconds must be a number of seconds of 0 or more, not {seconds:g}")
    if seconds > BRINGUP_MAX_SECONDS:
        raise CourseError("--seconds", seconds, f"--seconds {seconds:g} is more than the {BRINGUP_MAX_SECONDS:g} "
                          "simulated seconds one bringup may spin; give less, or drive a longer run from Python "
                          "(rrbot_workshop.bringup(...).spin(seconds))")
    _regular_file("description", args.description)
    _regular_file("--controllers", args.controllers)
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
        cycles = seconds / system.period
        if cycles > BRINGUP_MAX_CYCLES:
            rate = 1.0 / system.period
            raise CourseError("--seconds", seconds, f"--seconds {seconds:g} at this controller manager's update rate "
                              f"({rate:g} Hz) is {cycles:,.0f} control cycles, more than the {BRINGUP_MAX_CYCLES:,} "
                              f"one bringup may run; give at most {BRINGUP_MAX_CYCLES * system.period:g} s")
        try:
            system.spin(seconds)
        except RRBotWorkshopError:
            raise
        except Exception as exc:  # noqa: BLE001 - a plugin's own bug while running: one message, not a traceback
            raise CourseError("bringup", args.description, f"the system failed while spinning: "
                              f"{type(exc).__name__}: {exc}") from exc
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
