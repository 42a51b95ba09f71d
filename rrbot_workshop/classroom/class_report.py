"""The instructor's view of a room: every learner's progress, where the room is stuck, progress over time.

``rrbot-workshop class-report WORKSPACE... --out DIR`` reads the attempt logs that each learner's self-checks write
(``exercises/.progress/taskNN.json`` in the learner's workspace, see :mod:`rrbot_workshop.course.grading.attempts`)
and writes ``report.json``, ``report.csv`` and ``report.html`` (with a plot of the room's progress over the
workshop's time). It grades nothing and writes nothing in any learner's folder: it reads what their own checks
recorded, so a room of 30 is reported in a second. A log that cannot be read, or that a check was writing at that
moment, becomes a note in the report, never an error.

A workspace is a learner's course folder (the one holding ``exercises/``), or a home folder holding one at
``rrbot_workshop/`` (what ``rrbot-workshop init`` makes); each may be given as a glob (``/home/*``). On a hub, the
learners can come from the hub's user list instead (:func:`hub_homes`: ``--hub URL --home-template
'/home/jupyter-{username}'``, with an API token in ``$JUPYTERHUB_API_TOKEN``).
"""

from __future__ import annotations

import base64
import csv
import glob
import html
import io
import json
import os
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import CourseError

__all__ = ["LearnerTask", "Learner", "RoomReport", "find_workspaces", "hub_homes", "read_learner", "build_report",
           "write_report", "WORKSPACE_NAME"]

#: The folder ``rrbot-workshop init`` makes in a learner's home.
WORKSPACE_NAME = "rrbot_workshop"

_LOG_RE = re.compile(r"^task(\d{2})\.json$")


@dataclass
class LearnerTask:
    """One learner's record of one task, from their attempt log.

    Attributes:
        task: Task number.
        attempts: Self-checks run.
        passed: Whether an attempt got every point.
        points: Points of the latest attempt.
        max_points: Points available at the latest attempt.
        time_to_pass_s: Seconds from the first attempt to the first full score, or None.
        failing: The latest attempt's failed checks -> reason.
        times: Time of each attempt [s since the epoch], and whether it passed.
    """

    task: int
    attempts: int = 0
    passed: bool = False
    points: float = 0.0
    max_points: float = 0.0
    time_to_pass_s: float | None = None
    failing: dict[str, str] = field(default_factory=dict)
    times: list[tuple[float, bool]] = field(default_factory=list)


@dataclass
class Learner:
    """A learner's workspace and what its logs say.

    Attributes:
        name: The learner (the home folder's name, or the workspace's).
        workspace: The course folder.
        tasks: Task number -> record.
        notes: Logs that could not be read, and why.
    """

    name: str
    workspace: Path
    tasks: dict[int, LearnerTask] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


@dataclass
class RoomReport:
    """The room: learners, and per check how many fail it now."""

    learners: list[Learner]
    notes: list[str]

    def tasks(self) -> list[int]:
        """Every task someone checked, ascending."""
        return sorted({t for learner in self.learners for t in learner.tasks})

    def stuck(self) -> list[dict[str, Any]]:
        """Per check failing now (in learners' latest attempts): how many learners, and the most common reason."""
        counts: dict[tuple[int, str], list[str]] = {}
        for learner in self.learners:
            for record in learner.tasks.values():
                for check, reason in record.failing.items():
                    counts.setdefault((record.task, check), []).append(reason)
        rows = []
        for (task, check), reasons in counts.items():
            common, times = Counter(r for r in reasons if r).most_common(1)[0] if any(reasons) else ("", 0)
            rows.append({"task": task, "check": check, "learners_failing": len(reasons),
                         "most_common_reason": common, "learners_with_that_reason": times})
        return sorted(rows, key=lambda r: (-r["learners_failing"], r["task"], r["check"]))

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: learners (each with their tasks), the checks where the room is stuck, notes."""
        return {
            "learners": [{"name": lr.name, "tasks": {str(t): _task_dict(r) for t, r in sorted(lr.tasks.items())}}
                         for lr in self.learners],
            "stuck": self.stuck(),
            "notes": self.notes,
        }


def _task_dict(record: LearnerTask) -> dict[str, Any]:
    return {"attempts": record.attempts, "passed": record.passed, "points": record.points,
            "max_points": record.max_points, "time_to_pass_s": record.time_to_pass_s,
            "failing": sorted(record.failing)}


def find_workspaces(patterns: list[str]) -> list[tuple[str, Path]]:
    """``(learner name, course folder)`` for each workspace the patterns (paths or globs) name, sorted by name.

    Raises:
        CourseError: If a pattern matches nothing, or nothing matched is a workspace.
    """
    found: dict[Path, str] = {}
    for pattern in patterns:
        matches = sorted(glob.glob(os.path.expanduser(pattern))) if glob.has_magic(pattern) else [pattern]
        matches = [m for m in matches if Path(m).expanduser().is_dir()]
        if not matches:
            raise CourseError("workspace", pattern, "matches no folder; give learners' course folders or homes, e.g. "
                              "'/home/*' or 'uploads/*'")
        for match in matches:
            folder = Path(match).expanduser().resolve()
            if (folder / "exercises").is_dir():
                found.setdefault(folder, folder.name)
            elif (folder / WORKSPACE_NAME / "exercises").is_dir():
                found.setdefault(folder / WORKSPACE_NAME, folder.name)
    if not found:
        raise CourseError("workspace", " ".join(patterns), "no learner's workspace there (a folder holding exercises/, "
                          f"or a home holding {WORKSPACE_NAME}/exercises/)")
    return sorted(((name, path) for path, name in found.items()), key=lambda item: (item[0], str(item[1])))


def hub_homes(url: str, token: str, template: str) -> list[str]:
    """The home of every user of the JupyterHub at ``url`` (its REST API's user list), from ``template``.

    Args:
        url: The hub's address, e.g. ``http://127.0.0.1:8000``.
        token: An API token allowed to list users (an admin's, or a service's with ``list:users``).
        template: A home folder with ``{username}``, e.g. ``/home/jupyter-{username}`` (TLJH's).

    Raises:
        CourseError: If the template has no ``{username}``, or the hub does not answer with its users.
    """
    import urllib.error
    import urllib.request

    if "{username}" not in template:
        raise CourseError("--home-template", template, "must contain {username}, e.g. '/home/jupyter-{username}'")
    request = urllib.request.Request(url.rstrip("/") + "/hub/api/users", headers={"Authorization": f"token {token}"})
    try:
        with urllib.request.urlopen(request, timeout=30) as response:
            users = json.loads(response.read())
    except (urllib.error.URLError, ValueError, OSError) as exc:
        raise CourseError("--hub", url, f"did not list its users ({exc}); give the hub's address and an API token "
                          "allowed to list users in $JUPYTERHUB_API_TOKEN") from None
    if not isinstance(users, list):
        raise CourseError("--hub", url, "answered something other than a list of users")
    return [template.format(username=u["name"]) for u in users if isinstance(u, dict) and isinstance(u.get("name"), str)]


def read_learner(name: str, workspace: Path) -> Learner:
    """What a learner's attempt logs say; unreadable logs become notes."""
    learner = Learner(name, workspace)
    folder = workspace / "exercises" / ".progress"
    if not folder.is_dir():
        return learner
    for path in sorted(folder.iterdir()):
        match = _LOG_RE.match(path.name)
        if not match:
            continue
        task = int(match.group(1))
        why = ""
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except UnicodeDecodeError:
            why = "not UTF-8 text"
        except ValueError:
            why = "half-written or not JSON"
        except OSError as exc:
            why = f"unreadable: {exc.strerror or exc}"
        else:
            attempts = data.get("attempts") if isinstance(data, dict) else None
            try:
                if not isinstance(attempts, list):
                    raise ValueError("no list of attempts")
                learner.tasks[task] = _record(task, attempts)
            except (ValueError, TypeError) as exc:
                why = f"not an attempt log: {exc}"
        if why:
            learner.notes.append(f"{name}: task {task}'s log {path.name} could not be read ({why}); left out")
    return learner


def _record(task: int, attempts: list[Any]) -> LearnerTask:
    record = LearnerTask(task)
    good = [a for a in attempts if isinstance(a, dict) and isinstance(a.get("time"), int | float)]
    if len(good) != len(attempts):
        raise ValueError("an attempt without a time")
    record.attempts = len(good)
    for attempt in good:
        full = bool(attempt.get("max_score")) and attempt.get("score") == attempt.get("max_score")
        record.times.append((float(attempt["time"]), full))
        if full and not record.passed:
            record.passed = True
            record.time_to_pass_s = round(float(attempt["time"]) - float(good[0]["time"]), 1)
    if good:
        last = good[-1]
        record.points = float(last.get("score", 0.0))
        record.max_points = float(last.get("max_score", 0.0))
        given = last.get("reasons")
        reasons: dict[str, Any] = given if isinstance(given, dict) else {}
        record.failing = {str(c): str(reasons.get(c, "")) for c in last.get("failed", [])}
    return record


def build_report(patterns: list[str], missing_ok: bool = False) -> RoomReport:
    """Read every workspace the patterns name (see :func:`find_workspaces`).

    Args:
        patterns: Workspaces, homes, or globs of them.
        missing_ok: A home without a workspace (a hub user who never started a server) is a note, not an error.
    """
    notes: list[str] = []
    if missing_ok:
        kept = []
        for pattern in patterns:
            try:
                find_workspaces([pattern])
            except CourseError:
                notes.append(f"{pattern}: no workspace yet (never started a server?)")
            else:
                kept.append(pattern)
        patterns = kept
    learners = [read_learner(name, path) for name, path in find_workspaces(patterns)] if patterns else []
    return RoomReport(learners, notes + [note for learner in learners for note in learner.notes])


def _progress_png(report: RoomReport) -> bytes:
    """Tasks passed in the room over the workshop's time (minutes since the first self-check)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    firsts = sorted(next(t for t, ok in r.times if ok) for lr in report.learners for r in lr.tasks.values()
                    if r.passed)
    starts = [t for lr in report.learners for r in lr.tasks.values() for t, _ in r.times]
    figure = Figure(figsize=(7, 3))
    axes = figure.subplots()
    if starts:
        start = min(starts)
        minutes = [(t - start) / 60.0 for t in firsts]
        axes.step([0.0, *minutes], list(range(len(minutes) + 1)), where="post")
    axes.set_xlabel("minutes since the room's first self-check")
    axes.set_ylabel("tasks passed (all learners)")
    axes.grid(True, alpha=0.3)
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=90)
    return buffer.getvalue()


def _html(report: RoomReport) -> str:
    tasks = report.tasks()
    esc = html.escape
    head = "".join(f"<th>task {t}</th>" for t in tasks)
    rows = []
    for learner in report.learners:
        cells = []
        for task in tasks:
            record = learner.tasks.get(task)
            if record is None:
                cells.append('<td class="none">–</td>')
                continue
            mark = "passed" if record.passed else "open"
            when = f", {record.time_to_pass_s:g} s" if record.time_to_pass_s is not None else ""
            cells.append(f'<td class="{mark}">{record.points:g}/{record.max_points:g}<br>'
                         f'<small>{record.attempts} check{"s" if record.attempts != 1 else ""}{when}</small></td>')
        rows.append(f"<tr><th>{esc(learner.name)}</th>{''.join(cells)}</tr>")
    stuck = "".join(f"<tr><td>{r['task']}</td><td>{esc(r['check'])}</td><td>{r['learners_failing']}</td>"
                    f"<td>{esc(r['most_common_reason'])}</td></tr>" for r in report.stuck())
    notes = "".join(f"<li>{esc(n)}</li>" for n in report.notes) or "<li>none</li>"
    png = base64.b64encode(_progress_png(report)).decode()
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>rrbot_workshop: the room</title>
<style>body{{font-family:sans-serif;margin:1.5em}} table{{border-collapse:collapse;margin-bottom:1.5em}}
td,th{{border:1px solid #ccc;padding:.3em .6em;text-align:center}} td.passed{{background:#d9f2d9}}
td.open{{background:#fdf0d5}} td.none{{color:#999}}</style></head><body>
<h1>The room: {len(report.learners)} learner{"s" if len(report.learners) != 1 else ""}</h1>
<h2>Learners × tasks (points of the latest self-check; checks run, time to pass)</h2>
<table><tr><th>learner</th>{head}</tr>{''.join(rows)}</table>
<h2>Where the room is stuck (checks failing now)</h2>
<table><tr><th>task</th><th>check</th><th>learners</th><th>most common reason</th></tr>{stuck}</table>
<h2>Progress over the workshop</h2><img alt="tasks passed over time" src="data:image/png;base64,{png}">
<h2>Notes</h2><ul>{notes}</ul></body></html>
"""


def write_report(report: RoomReport, out: Path) -> list[Path]:
    """Write ``report.json``, ``report.csv`` (one row per learner and task) and ``report.html`` into ``out``.

    Raises:
        CourseError: If ``out`` is a file or cannot be written.
    """
    if out.exists() and not out.is_dir():
        raise CourseError("--out", str(out), "is a file; give a folder for report.json, report.csv and report.html")
    paths = [out / "report.json", out / "report.csv", out / "report.html"]
    try:
        out.mkdir(parents=True, exist_ok=True)
        paths[0].write_text(json.dumps(report.to_dict(), indent=1) + "\n", encoding="utf-8")
        with paths[1].open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(["learner", "task", "passed", "points", "max_points", "attempts", "time_to_pass_s",
                             "failing_checks"])
            for learner in report.learners:
                for task, record in sorted(learner.tasks.items()):
                    writer.writerow([learner.name, task, record.passed, record.points, record.max_points,
                                     record.attempts, "" if record.time_to_pass_s is None else record.time_to_pass_s,
                                     " ".join(sorted(record.failing))])
        paths[2].write_text(_html(report), encoding="utf-8")
    except OSError as exc:
        raise CourseError("--out", str(out), f"cannot be written ({exc.strerror or exc})") from None
    return paths
