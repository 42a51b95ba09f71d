"""The classroom's commands of ``rrbot-workshop``: init, singleuser, class-report, class-service and room.

:func:`add_commands` adds them to the tool's parser (see :mod:`rrbot_workshop.cli`) and returns their handlers.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import CourseError

__all__ = ["add_commands"]


def add_commands(sub: Any) -> dict[str, Callable[[argparse.Namespace], int]]:
    """Add init, singleuser, class-report, class-service and room to ``sub`` (argparse's sub-parsers); return their
    handlers."""
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
                                                   "allowed to list users in $JUPYTERHUB_API_TOKEN); names are taken "
                                                   "literally")
    room.add_argument("--home-template", metavar="PATH", default="tljh",
                      help="with --hub: a learner's home, a path with {username} ('/home/{username}'), or 'tljh' for "
                           "The Littlest JupyterHub's homes (/home/jupyter-<name>, long names cut as TLJH does; the "
                           "default)")
    room.add_argument("--stuck-after", metavar="MINUTES", type=float, default=10.0,
                      help="a learner is stuck on a task when the same check has failed in every self-check of their "
                           "own work for this long (default 10)")
    room.add_argument("--course", metavar="COURSE", help="the course the workspaces were made from, whose exercises "
                                                        "as handed out are not a start (default: the installed one)")
    room.add_argument("--out", metavar="DIR", required=True, help="folder for report.json, report.csv, report.html")

    service = sub.add_parser("class-service", help="the instructor's live view of a room on a JupyterHub: a hub "
                                                   "service that learners' self-checks report to (see deploy/)")
    service.add_argument("--state", metavar="FILE", help="keep the results in this JSON-lines file (read back at "
                                                         "start); default: in memory only")
    service.add_argument("--ip", help="address to listen on (default: the one in $JUPYTERHUB_SERVICE_URL, else "
                                      "127.0.0.1)")
    service.add_argument("--port", type=int, help="port (default: the one in $JUPYTERHUB_SERVICE_URL, else 10101)")
    service.add_argument("--group", default="instructors",
                         help="members of this hub group see the room too (hub admins always do; default "
                              "'instructors')")
    service.add_argument("--name", default="rrbot-class", help="the service's name on the hub (default "
                                                                "'rrbot-class'; $JUPYTERHUB_SERVICE_NAME wins)")
    service.add_argument("--stuck-after", metavar="MINUTES", type=float, default=10.0,
                         help="a learner is stuck on a task when the same check has failed in every self-check of "
                              "their own work for this long (default 10, as class-report)")

    room_cmd = sub.add_parser("room", help="the workshop room on a JupyterHub: 'room warm' starts every learner's "
                                           "server before the workshop")
    room_sub = room_cmd.add_subparsers(dest="room_command", required=True, metavar="{warm}")
    warm = room_sub.add_parser("warm", help="make the learners (if missing) and start their servers through the "
                                            "hub's API, a few at a time (an admin's token in $JUPYTERHUB_API_TOKEN)")
    warm.add_argument("--hub", metavar="URL", required=True, help="the hub's URL")
    who = warm.add_mutually_exclusive_group(required=True)
    who.add_argument("--learners", nargs="+", metavar="NAME", help="the learners' user names")
    who.add_argument("--learners-file", metavar="FILE", help="a file with one user name per line")
    who.add_argument("--count", type=int, metavar="N", help="N learners named PREFIX01, PREFIX02, ...")
    warm.add_argument("--prefix", default="learner", help="with --count: the names' prefix (default 'learner')")
    warm.add_argument("--stagger", type=float, default=2.0, metavar="S",
                      help="seconds between two starts (default 2)")
    warm.add_argument("--at-once", type=int, default=4, metavar="N",
                      help="most servers starting at the same time (default 4)")
    warm.add_argument("--timeout", type=float, default=900.0, metavar="S",
                      help="longest wait for the whole room (default 900 s)")
    return {"init": _cmd_init, "singleuser": _cmd_singleuser, "class-report": _cmd_class_report,
            "class-service": _cmd_class_service, "room": _cmd_room}


def _report_lines(result: Any) -> list[str]:
    """What ``init`` did, one line each: the problems met and dealt with, kept files, notebooks."""
    lines = [f"note: {note}" for note in result.notes]
    lines += [f"{rel}: you changed it and so did the course; yours is kept, the course's is beside it as "
              f"{Path(rel).name}.course-update" for rel in result.kept]
    return lines + list(result.notebooks)


def _cmd_init(args: argparse.Namespace) -> int:
    from rrbot_workshop.classroom.workspace import init_workspace

    result = init_workspace(args.workspace, args.source)
    what = "made" if result.created else "updated"
    print(f"Workspace {what}: {result.workspace} from {result.source} ({len(result.added)} exercise file(s) added, "
          f"{len(result.updated)} updated)")
    for line in _report_lines(result):
        print(f"  {line}")
    if result.created:
        print(f"Work in {result.workspace}: open my_notebooks/00_intro.ipynb; in a terminal, cd there first.")
    return 0


#: Exit status of ``singleuser`` when the learner's workspace cannot be used (the server is not started).
WORKSPACE_UNUSABLE = 2
#: Exit status of ``singleuser`` when ``jupyterhub-singleuser`` cannot be started (as a shell says of a command).
SERVER_MISSING = 127


def _log(message: str) -> None:
    """One line in the single-user server's log (JupyterHub keeps the spawned process's stderr)."""
    print(f"rrbot-workshop singleuser: {' '.join(str(message).split())}", file=sys.stderr, flush=True)


def _cmd_singleuser(args: argparse.Namespace) -> int:
    """Make or update ``~/rrbot_workshop`` and start the server there; every problem is one line on stderr.

    The server starts whenever the workspace is usable, even when the update met a problem (the learner keeps working
    on what is there; the next start tries again). When it is not usable, the line says what to do and the exit
    status is :data:`WORKSPACE_UNUSABLE`.
    """
    from rrbot_workshop.classroom.workspace import default_workspace, init_workspace, is_workspace, singleuser_command

    try:
        workspace = default_workspace()
    except RuntimeError as exc:  # no home folder: nowhere to make a workspace
        _log(f"the learner has no home folder ({exc}); give the user a home, then start the server again")
        return WORKSPACE_UNUSABLE
    try:
        result = init_workspace(workspace)
    except CourseError as exc:
        _log(f"the workspace was not updated: {exc}")
    except Exception as exc:  # noqa: BLE001 - the server must still start when the workspace is usable
        _log(f"the workspace was not updated: {type(exc).__name__}: {exc}")
    else:
        _log(f"workspace {'made' if result.created else 'updated'}: {workspace} from {result.source}")
        for line in _report_lines(result):
            _log(line)
    if not is_workspace(workspace) or not os.access(workspace, os.R_OK | os.W_OK | os.X_OK):
        _log(f"{workspace} is not a workspace this server can open. Move it away or free the name (as the learner or "
             f"an admin: `mv {workspace} {workspace}.old`), check the home folder is writable, then start the "
             "server again: the next start makes a new workspace")
        return WORKSPACE_UNUSABLE
    command = singleuser_command(workspace, list(args.args))
    try:
        os.execvp(command[0], command)  # the server takes this process's place: the spawner's signals reach it
    except OSError as exc:
        _log(f"{command[0]} could not be started ({exc.strerror or exc}); install JupyterHub's single-user server "
             "in this environment (pip install 'rrbot_workshop[hub]', or jupyterhub)")
        return SERVER_MISSING
    return 0  # pragma: no cover - execvp does not return


def _cmd_class_report(args: argparse.Namespace) -> int:
    from rrbot_workshop.classroom.class_report import build_report, hub_users, hub_workspaces
    from rrbot_workshop.classroom.class_report_page import write_report
    from rrbot_workshop.classroom.learner_logs import shown

    if not args.workspaces and not args.hub:
        raise CourseError("class-report", "", "name the learners' workspaces ('/home/*') or a hub (--hub URL)")
    if not 0 <= args.stuck_after <= 10_000:  # also refuses nan
        raise CourseError("--stuck-after", args.stuck_after, f"--stuck-after {args.stuck_after:g}: give a number of "
                          "minutes from 0 to 10000")
    notes: list[str] = []
    found = []
    if args.hub:
        names = hub_users(args.hub, os.environ.get("JUPYTERHUB_API_TOKEN", ""))
        found = hub_workspaces(names, args.home_template, notes)
    report = build_report(list(args.workspaces), missing_ok=bool(args.hub), workspaces=found, notes=notes,
                          stuck_after=args.stuck_after * 60.0,
                          course=Path(args.course).expanduser() if args.course else None)
    paths = write_report(report, Path(args.out))
    print(f"{len(report.learners)} learner(s); wrote {', '.join(str(p) for p in paths)}")
    top = next(iter(report.stuck()), None)
    if top is not None and top["learners_stuck"]:
        print(f"Most learners stuck on: task {top['task']} {shown(top['check'])} ({top['learners_stuck']} "
              f"learner(s) for {args.stuck_after:g} min or more)")
    for note in report.notes:
        print(f"note: {note}")
    return 0


def _cmd_class_service(args: argparse.Namespace) -> int:
    import logging

    from rrbot_workshop.classroom.service import serve

    logging.basicConfig(level=logging.INFO, format="[%(levelname)s %(asctime)s %(name)s] %(message)s")
    if not 0 <= args.stuck_after <= 10_000:  # also refuses nan
        raise CourseError("--stuck-after", args.stuck_after, f"--stuck-after {args.stuck_after:g}: give a number of "
                          "minutes from 0 to 10000")
    try:
        serve(Path(args.state) if args.state else None, args.ip, args.port, args.group, args.name,
              args.stuck_after * 60.0)
    except KeyboardInterrupt:  # the hub stops its services with SIGINT
        pass
    return 0


def _learner_names(args: argparse.Namespace) -> list[str]:
    if args.count is not None:
        if not 1 <= args.count <= 1000:
            raise CourseError("--count", args.count, "a room has 1 to 1000 learners")
        return [f"{args.prefix}{i:02d}" for i in range(1, args.count + 1)]
    if args.learners_file:
        try:
            text = Path(args.learners_file).read_text()
        except OSError as exc:
            raise CourseError("--learners-file", args.learners_file, f"cannot read {args.learners_file}: {exc}") from exc
        return [line.strip() for line in text.splitlines() if line.strip() and not line.startswith("#")]
    return list(args.learners)


def _cmd_room(args: argparse.Namespace) -> int:
    from rrbot_workshop.classroom.hub import HubAPI, warm_room

    token = os.environ.get("JUPYTERHUB_API_TOKEN", "")
    if not token:
        raise CourseError("JUPYTERHUB_API_TOKEN", "", "room warm needs an admin's API token in $JUPYTERHUB_API_TOKEN "
                          "(the hub's token page, /hub/token, logged in as the instructor)")
    names = _learner_names(args)
    if not names:
        raise CourseError("learners", "", "no learner named")
    if args.stagger < 0 or args.at_once < 1 or args.timeout <= 0:
        raise CourseError("room warm", "", "--stagger must be 0 or more, --at-once 1 or more, --timeout above 0")
    states = warm_room(HubAPI(args.hub, token), names, args.stagger, args.at_once, args.timeout)
    not_ready = sorted(n for n in names if states.get(n) is None or states[n].state != "ready")
    if not_ready:
        print(f"not ready: {', '.join(not_ready)}")
    return 1 if not_ready else 0
