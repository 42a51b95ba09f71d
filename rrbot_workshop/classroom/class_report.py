"""The instructor's view of a room: where each learner stands on each task, where the room is stuck, and since when.

``rrbot-workshop class-report WORKSPACE... --out DIR`` reads the attempt logs that each learner's self-checks write
(``exercises/.progress/taskNN.json`` in the learner's workspace, see :mod:`rrbot_workshop.course.grading.attempts`)
and writes ``report.json``, ``report.csv`` and ``report.html``. Each learner × task is not started, working, stuck
or passed (:mod:`rrbot_workshop.classroom.task_status`); the report says when it was made and each learner's last
self-check. It grades nothing and writes nothing in any learner's folder: it reads what their own checks recorded, so
a room of 30 is reported in a second.

Nothing a learner puts in their workspace can stop, hang or skew the report (:mod:`rrbot_workshop.classroom.
learner_logs`): only the learner's own regular files are read, never through a link, within bounds, and every file
left out is one note for that learner. The CSV is safe to open in a spreadsheet (:func:`csv_cell`) and the HTML page
escapes every text.

A workspace is a learner's course folder (the one holding ``exercises/``), or a home folder holding one at
``rrbot_workshop/`` (what ``rrbot-workshop init`` makes); each may be given as a glob (``/home/*``). On a hub, the
learners can come from the hub's user list instead (:func:`hub_users`, :func:`hub_workspaces`): their names are taken
literally, never as patterns.
"""

from __future__ import annotations

import glob
import hashlib
import json
import os
import re
import stat
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rrbot_workshop.classroom.learner_logs import LearnerLogs, read_logs, shown
from rrbot_workshop.classroom.task_status import (
    DEFAULT_STUCK_AFTER_S,
    NOT_STARTED,
    STATUSES,
    STUCK,
    WORKING,
    TaskState,
    classify,
    last_activity,
    local_time,
)
from rrbot_workshop.exceptions import CourseError

__all__ = ["Workspace", "LearnerReport", "RoomReport", "find_workspaces", "hub_users", "hub_workspaces", "tljh_home",
           "untouched_versions", "build_report", "WORKSPACE_NAME",
           "TLJH_HOMES", "MAX_HUB_NAME_CHARS", "MAX_HUB_USERS"]

#: The folder ``rrbot-workshop init`` makes in a learner's home.
WORKSPACE_NAME = "rrbot_workshop"
#: The ``--home-template`` that means The Littlest JupyterHub's homes (see :func:`tljh_home`).
TLJH_HOMES = "tljh"
#: Longest hub user name taken [characters]; a longer one is a note.
MAX_HUB_NAME_CHARS = 255
#: Most hub users listed.
MAX_HUB_USERS = 5000
#: JupyterHub's media type for a paginated answer (JupyterHub 2.0 and later).
_PAGINATION = "application/jupyterhub-pagination+json"
_PAGE = 200  # JupyterHub's largest page by default (api_page_max_limit)
_HUB_MAX_BYTES = 64 * 1024 * 1024
_TASK_DIR = re.compile(r"^task(\d{2})_")


@dataclass(frozen=True)
class Workspace:
    """A learner's workspace, as the report finds it.

    Attributes:
        name: The learner.
        root: The folder the instructor named or the hub gave (a home, or the course folder itself).
        inside: Folders from ``root`` to the workspace: ``()`` or ``("rrbot_workshop",)``; never followed as links.
    """

    name: str
    root: Path
    inside: tuple[str, ...] = ()

    @property
    def path(self) -> Path:
        """The workspace folder."""
        return self.root.joinpath(*self.inside)


def _mode(path: Path) -> int | None:
    """``path``'s type bits, not following a link; None if it cannot be looked at (missing, a name too long...)."""
    try:
        return os.lstat(path).st_mode
    except (OSError, ValueError):
        return None


def _is_dir(path: Path) -> bool:
    mode = _mode(path)
    return mode is not None and stat.S_ISDIR(mode)


def _workspace_in(name: str, folder: Path) -> Workspace | None:
    """The workspace ``folder`` holds (itself, or its ``rrbot_workshop/``, even a link there: reading notes it)."""
    if _is_dir(folder / "exercises"):
        return Workspace(name, folder)
    if _mode(folder / WORKSPACE_NAME) is not None:
        return Workspace(name, folder, (WORKSPACE_NAME,))
    return None


def _key(workspace: Workspace) -> tuple[Path, tuple[str, ...]]:
    """What makes two workspaces the same: the folder they are in, links resolved in the part the instructor named
    and never in the part inside it (the learner's)."""
    if all(_is_dir(workspace.root.joinpath(*workspace.inside[:i + 1])) for i in range(len(workspace.inside))):
        return workspace.path.resolve(), ()
    return workspace.root.resolve(), workspace.inside


def _through_link(match: Path, fixed: int) -> bool:
    """Whether a glob's ``match`` is, or lies in, a link among the names the glob matched (from part ``fixed`` on)."""
    parts = match.parts
    return any(stat.S_ISLNK(_mode(Path(*parts[:i + 1])) or 0) for i in range(fixed, len(parts)))


def find_workspaces(patterns: list[str], notes: list[str] | None = None,
                    missing_ok: bool = False) -> list[Workspace]:
    """Every workspace the patterns (paths or globs) name, sorted by learner.

    A path the instructor wrote is followed even if it is a link; a glob's match that is a link is left out (with a
    note), since a learner could have made it.

    Args:
        patterns: Learners' course folders or homes, or globs of them.
        notes: Where the notes go (links left out; with ``missing_ok``, homes without a workspace).
        missing_ok: A pattern naming no workspace is a note, not an error.

    Raises:
        CourseError: Without ``missing_ok``, if a pattern matches no folder, or nothing matched is a workspace.
    """
    notes = [] if notes is None else notes
    found: dict[tuple[Path, tuple[str, ...]], Workspace] = {}
    for pattern in patterns:
        expanded = os.path.expanduser(pattern)
        is_glob = glob.has_magic(expanded)
        matches = sorted(glob.glob(expanded)) if is_glob else [expanded]
        folders = []
        fixed = next((i for i, part in enumerate(Path(expanded).parts) if glob.has_magic(part)), 0)
        for match in matches:
            if is_glob and _through_link(Path(match), fixed):
                notes.append(f"{shown(match, 300)}: a link (or in one) among the folders '{shown(pattern, 300)}' "
                             "matches; left out (a learner may have made it; name the folder itself to include it)")
            elif os.path.isdir(match):
                folders.append(Path(match))
        if not folders and not missing_ok:
            raise CourseError("workspace", pattern, f"'{shown(pattern, 300)}' matches no folder; give learners' "
                              "course folders or homes, e.g. '/home/*' or 'uploads/*'")
        for folder in folders:
            name = folder.parent.name if folder.name == WORKSPACE_NAME and folder.parent.name else folder.name
            workspace = _workspace_in(name or str(folder), folder)
            if workspace is not None:
                found.setdefault(_key(workspace), workspace)
            elif missing_ok:
                notes.append(f"{shown(str(folder), 300)}: no workspace yet (never started a server?)")
    if not found and not missing_ok:
        named = " ".join(patterns)
        raise CourseError("workspace", named, f"no learner's workspace in {shown(named, 300)} (a folder holding "
                          f"exercises/, or a home holding {WORKSPACE_NAME}/exercises/)")
    return sorted(found.values(), key=lambda w: (w.name, str(w.path)))


def _hub_get(url: str, token: str, offset: int) -> Any:
    import urllib.error
    import urllib.request

    request = urllib.request.Request(f"{url.rstrip('/')}/hub/api/users?offset={offset}&limit={_PAGE}",
                                     headers={"Authorization": f"token {token}", "Accept": _PAGINATION})
    try:
        with urllib.request.urlopen(request, timeout=30) as response:  # noqa: S310 - the instructor's hub address
            data = response.read(_HUB_MAX_BYTES + 1)
        if len(data) > _HUB_MAX_BYTES:
            raise ValueError("its answer is larger than 64 MiB")
        return json.loads(data)
    except (urllib.error.URLError, ValueError, OSError, RecursionError) as exc:
        raise CourseError("--hub", url, f"did not list its users ({exc}); give the hub's address and an API token "
                          "allowed to list users in $JUPYTERHUB_API_TOKEN") from None


def hub_users(url: str, token: str) -> list[str]:
    """The name of every user of the JupyterHub at ``url``, from its REST API (``GET /hub/api/users``, every page).

    Args:
        url: The hub's address, e.g. ``http://127.0.0.1:8000``.
        token: An API token allowed to list users (an admin's, or a service's with ``list:users``).

    Returns:
        The names as the hub gives them (at most :data:`MAX_HUB_USERS`), in the hub's order; entries without a name
        are skipped.

    Raises:
        CourseError: If ``url`` is not an http(s) address, or the hub does not answer with its users.
    """
    if not url.startswith(("http://", "https://")):
        raise CourseError("--hub", url, f"--hub {shown(url, 300)}: give the hub's http:// or https:// address, e.g. "
                          "http://127.0.0.1:8000")
    names: list[str] = []
    offset = 0
    while len(names) < MAX_HUB_USERS:
        answer = _hub_get(url, token, offset)
        if isinstance(answer, list):  # a hub before 2.0: one list of every user
            items, following = answer, None
        elif isinstance(answer, dict) and isinstance(answer.get("items"), list):
            items = answer["items"]
            pages = answer.get("_pagination")
            following = pages.get("next") if isinstance(pages, dict) else None
        else:
            raise CourseError("--hub", url, "answered something other than JupyterHub's list of users")
        names += [u["name"] for u in items if isinstance(u, dict) and isinstance(u.get("name"), str)]
        next_offset = following.get("offset") if isinstance(following, dict) else None
        if not isinstance(next_offset, int) or isinstance(next_offset, bool) or next_offset <= offset:
            break
        offset = next_offset
    return names[:MAX_HUB_USERS]


def tljh_home(username: str) -> Path:
    """The home of a hub user on The Littlest JupyterHub: ``/home/jupyter-<name>``, where a system user name of 26
    characters or more is cut to 26 and followed by ``-`` and the first 5 hex digits of its sha256 (as TLJH's
    ``generate_system_username`` makes them)."""
    system = f"jupyter-{username}"
    if len(system) >= 26:
        system = f"{system[:26]}-{hashlib.sha256(system.encode('utf-8')).hexdigest()[:5]}"
    return Path("/home") / system


def _name_problem(username: str) -> str:
    if len(username) > MAX_HUB_NAME_CHARS:
        return f"is longer than {MAX_HUB_NAME_CHARS} characters"
    if username in ("", ".", "..") or "/" in username or "\0" in username:
        return "cannot be a folder's name"
    return ""


def hub_workspaces(usernames: list[str], template: str, notes: list[str]) -> list[Workspace]:
    """The workspace of each hub user, their home taken literally from ``template`` (never as a pattern).

    Args:
        usernames: The hub's user names (:func:`hub_users`).
        template: :data:`TLJH_HOMES` for TLJH's homes (:func:`tljh_home`), or a path with ``{username}``, e.g.
            ``/home/{username}``; the name is put in as it is.
        notes: Where a line goes for each user left out (a name that cannot be a folder's, no workspace yet).

    Raises:
        CourseError: If ``template`` is neither :data:`TLJH_HOMES` nor a path with ``{username}``.
    """
    if template != TLJH_HOMES and "{username}" not in template:
        raise CourseError("--home-template", template, "must contain {username}, e.g. '/home/{username}', or be "
                          f"'{TLJH_HOMES}' for The Littlest JupyterHub's homes")
    found: dict[str, Workspace] = {}
    for username in dict.fromkeys(usernames):
        problem = _name_problem(username)
        if problem:
            notes.append(f"hub user '{shown(username)}': the name {problem}; left out")
            continue
        home = tljh_home(username) if template == TLJH_HOMES else Path(template.replace("{username}", username))
        workspace = _workspace_in(username, home) if os.path.isdir(home) else None
        if workspace is None:
            notes.append(f"{shown(username)}: no workspace yet in {shown(str(home), 300)} (never started a server?)")
        else:
            found[username] = workspace
    return sorted(found.values(), key=lambda w: w.name)


def untouched_versions(course: Path | None) -> dict[int, set[str]]:
    """The version of each task's exercise as handed out (:func:`~rrbot_workshop.course.grading.attempts.
    files_version` of the course's ``exercises/taskNN_*``): self-checks of these files are not a start."""
    from rrbot_workshop.course.grading.attempts import files_version

    out: dict[int, set[str]] = {}
    folder = (course / "exercises") if course is not None else None
    if folder is None or not folder.is_dir():
        return out
    for child in sorted(folder.iterdir()):
        match = _TASK_DIR.match(child.name)
        if match and child.is_dir():
            out.setdefault(int(match.group(1)), set()).add(files_version(child))
    return out


@dataclass
class LearnerReport:
    """One learner: where they stand on each task they checked.

    Attributes:
        name: The learner (the hub's user name, the home folder's name, or the course folder's).
        workspace: The workspace folder.
        tasks: Task number -> state (tasks without a log are not started).
        last_activity: Their latest self-check [s since the epoch], or None.
        notes: Their files left out, and why.
    """

    name: str
    workspace: Path
    tasks: dict[int, TaskState] = field(default_factory=dict)
    last_activity: float | None = None
    notes: list[str] = field(default_factory=list)

    def state(self, task: int) -> TaskState:
        """The learner's state on ``task`` (not started without a log)."""
        return self.tasks.get(task) or TaskState(NOT_STARTED)


@dataclass
class RoomReport:
    """The room at one moment.

    Attributes:
        learners: Every learner, sorted by name.
        notes: The room's notes: hub users left out, links left out, every learner's notes.
        made_at: When the report was made [s since the epoch].
        stuck_after: How long a check must keep failing for a learner to be stuck on it [s].
    """

    learners: list[LearnerReport]
    notes: list[str]
    made_at: float
    stuck_after: float = DEFAULT_STUCK_AFTER_S

    def tasks(self) -> list[int]:
        """Every task someone checked, ascending."""
        return sorted({t for learner in self.learners for t in learner.tasks})

    def counts(self) -> dict[int, dict[str, int]]:
        """Per task: how many learners are at each status (every status present, 0 included)."""
        return {t: {s: sum(lr.state(t).status == s for lr in self.learners) for s in STATUSES} for t in self.tasks()}

    def stuck(self) -> list[dict[str, Any]]:
        """Per check failing now for learners who started the task: how many fail it, how many are stuck on it, and
        the most common reason among them. Most stuck first, then most failing."""
        reasons: dict[tuple[int, str], list[str]] = {}
        stuck: Counter[tuple[int, str]] = Counter()
        for learner in self.learners:
            for task, state in learner.tasks.items():
                if state.status not in (WORKING, STUCK):
                    continue
                for check, reason in state.failing.items():
                    reasons.setdefault((task, check), []).append(reason)
                    stuck[(task, check)] += check in state.stuck_on
        rows = []
        for (task, check), given in reasons.items():
            common, times = Counter(r for r in given if r).most_common(1)[0] if any(given) else ("", 0)
            rows.append({"task": task, "check": check, "learners_failing": len(given),
                         "learners_stuck": stuck[(task, check)], "most_common_reason": common,
                         "learners_with_that_reason": times})
        return sorted(rows, key=lambda r: (-r["learners_stuck"], -r["learners_failing"], r["task"], r["check"]))

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: when it was made, the option, learners (each task's state), counts, the stuck table, notes."""
        return {
            "made_at": self.made_at, "made_at_local": local_time(self.made_at), "stuck_after_s": self.stuck_after,
            "learners": [{"name": lr.name, "last_activity": lr.last_activity,
                          "tasks": {str(t): s.to_dict() for t, s in sorted(lr.tasks.items())}}
                         for lr in self.learners],
            "counts": {str(t): c for t, c in self.counts().items()},
            "stuck": self.stuck(),
            "notes": self.notes,
        }


def build_report(patterns: list[str] | tuple[str, ...] = (), missing_ok: bool = False, *,
                 workspaces: list[Workspace] | tuple[Workspace, ...] = (), notes: list[str] | None = None,
                 now: float | None = None, stuck_after: float = DEFAULT_STUCK_AFTER_S,
                 course: Path | None = None) -> RoomReport:
    """Read every workspace and classify each learner × task.

    Args:
        patterns: Workspaces, homes, or globs of them (see :func:`find_workspaces`).
        missing_ok: A pattern naming no workspace is a note, not an error.
        workspaces: More workspaces, found already (a hub's, see :func:`hub_workspaces`).
        notes: Notes found already (the hub users left out).
        now: The time the report is for [s since the epoch]; default now.
        stuck_after: How long the same check must keep failing for a learner to be stuck [s].
        course: The installed course, whose exercises as handed out are not a start (:func:`untouched_versions`);
            default the one this library belongs to.

    Raises:
        CourseError: If a pattern names no workspace (without ``missing_ok``), or ``stuck_after`` is not a number of
            seconds, 0 or more.
    """
    from rrbot_workshop.classroom.workspace import installed_course

    made_at = time.time() if now is None else now
    classify([], made_at, stuck_after)  # checks the option before any file is read
    room_notes = list(notes or [])
    found = find_workspaces(list(patterns), room_notes, missing_ok) if patterns else []
    seen = {_key(w) for w in found}
    found += [w for w in workspaces if _key(w) not in seen]
    source = course if course is not None else installed_course()
    untouched = untouched_versions(source)
    if not untouched:
        where = f"in {shown(str(source), 300)}/exercises" if source is not None else "no installed course"
        room_notes.insert(0, f"the course's exercises as handed out were not found ({where}); a self-check of an "
                          "untouched exercise counts as a start (give the course with --course)")
    read = [(w, read_logs(w.name, w.root, w.inside)) for w in sorted(found, key=lambda w: (w.name, str(w.path)))]
    _leave_out_shared_files(read)
    learners = []
    for workspace, logs in read:
        learner = LearnerReport(workspace.name, workspace.path, notes=logs.notes,
                                last_activity=last_activity(a for task in logs.attempts.values() for a in task))
        for task, attempts in sorted(logs.attempts.items()):
            learner.tasks[task] = classify(attempts, made_at, stuck_after, untouched.get(task, ()))
        learners.append(learner)
    return RoomReport(learners, room_notes + [n for lr in learners for n in lr.notes], made_at, stuck_after)


def _leave_out_shared_files(read: list[tuple[Workspace, LearnerLogs]]) -> None:
    """A log that is one file in several workspaces (a hard link between learners who share a Unix user) is no one's
    own: it is left out for each of them, with a note naming the others."""
    holders: dict[tuple[int, int], list[tuple[Workspace, LearnerLogs, int]]] = {}
    for workspace, logs in read:
        for task, inode in logs.files.items():
            holders.setdefault(inode, []).append((workspace, logs, task))
    for shared in (h for h in holders.values() if len(h) > 1):
        for workspace, logs, task in shared:
            others = ", ".join(shown(w.name, 40) for w, _, _ in shared if w is not workspace)
            logs.attempts.pop(task, None)
            logs.notes.append(f"{shown(workspace.name, 60)}: task {task}'s log task{task:02d}.json is the same file as "
                              f"a log of {others} (a hard link); left out for each of them")
