"""The instructor's live view of a room: ``rrbot-workshop class-service``, a JupyterHub service.

Every learner's self-check (``check(N)`` in a notebook, ``rrbot-workshop grade N`` in a terminal) posts its attempt
here with the learner's own hub token (:mod:`rrbot_workshop.course.grading.live_view`). The service asks the hub whose
token it is and files the attempt under that name: the name in a request's body, if any, is ignored, so nobody can
post for someone else. The page at the service's prefix is for instructors only (the hub's OAuth; a hub admin or a
member of ``--group``), refreshes itself, and shows for each learner and task whether they have not started, are
working, are stuck or have passed (the class report's status model, :mod:`rrbot_workshop.classroom.task_status`:
a self-check of the exercise as handed out is no start); each learner's last activity and server state (from the hub's REST API); the most
common reasons among those who tried; and when it was made. ``api/status`` gives the same as JSON.

It runs the same on The Littlest JupyterHub (a hub-managed service on 127.0.0.1, deploy/tljh) and on
zero-to-jupyterhub (a container beside the hub, deploy/z2jh). The results are kept in memory and appended to a
JSON-lines file (``--state``), read back at start. Without ``--ip``, it listens where the hub says
(``$JUPYTERHUB_SERVICE_URL``), else on 127.0.0.1.
"""

from __future__ import annotations

import html
import json
import logging
import os
import time
import urllib.parse
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rrbot_workshop.classroom.hub import server_state
from rrbot_workshop.classroom.task_status import (
    DEFAULT_STUCK_AFTER_S,
    NOT_STARTED,
    PASSED,
    STUCK,
    WORKING,
    Attempt,
    TaskState,
    classify,
)

__all__ = ["Results", "RoomView", "validate_attempt", "make_app", "serve", "MAX_BODY", "REFRESH_S"]

logger = logging.getLogger(__name__)

#: Largest result a learner may post [bytes].
MAX_BODY = 64 * 1024
#: How often the page reloads itself [s].
REFRESH_S = 20


def validate_attempt(body: Any) -> dict[str, Any]:
    """The attempt in a posted body, checked and trimmed as the status model reads attempt logs
    (:meth:`~rrbot_workshop.classroom.task_status.Attempt.from_record`); its time is the service's, set on arrival.

    Raises:
        ValueError: If a field is missing or of the wrong kind; the message names it.
    """
    if not isinstance(body, dict):
        raise ValueError("the body must be a JSON object")
    task = body.get("task")
    if not isinstance(task, int) or isinstance(task, bool) or not 0 <= task <= 99:
        raise ValueError("'task' must be an integer from 0 to 99")
    reasons = body.get("reasons", {})
    if not isinstance(reasons, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in reasons.items()):
        raise ValueError("'reasons' must be an object of check names -> reason")
    attempt = Attempt.from_record({**body, "time": 0.0})
    return {"task": task, "score": attempt.score, "max_score": attempt.max_score, "failed": list(attempt.failed),
            "reasons": dict(attempt.reasons), "version": attempt.version}


class Results:
    """The attempts learners posted, by learner and task, kept in a JSON-lines file.

    Args:
        path: The file (made if missing; read back at start), or None to keep them in memory only.
        clock: Seconds since the epoch (injectable for tests).
    """

    def __init__(self, path: Path | None = None, clock: Any = time.time) -> None:
        self.path = path
        self.clock = clock
        self._attempts: dict[str, dict[int, list[dict[str, Any]]]] = {}
        if path is not None and path.is_file():
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
                try:
                    entry = json.loads(line)
                    self._file(str(entry["user"]), validate_attempt(entry), float(entry["time"]))
                except (ValueError, KeyError, TypeError) as exc:
                    logger.warning("%s:%d: skipped (%s)", path, number, exc)

    def _file(self, user: str, attempt: dict[str, Any], when: float) -> dict[str, Any]:
        entry = {**attempt, "time": when}
        self._attempts.setdefault(user, {}).setdefault(int(attempt["task"]), []).append(entry)
        return entry

    def add(self, user: str, attempt: dict[str, Any]) -> dict[str, Any]:
        """File a checked attempt (see :func:`validate_attempt`) under ``user``, at the service's time of arrival."""
        entry = self._file(user, attempt, float(self.clock()))
        if self.path is not None:
            try:
                with self.path.open("a") as f:
                    f.write(json.dumps({"user": user, **entry}) + "\n")
            except OSError as exc:
                logger.warning("results not saved to %s: %s", self.path, exc)
        return entry

    def attempts(self) -> dict[str, dict[int, list[dict[str, Any]]]]:
        """Learner -> task -> attempts, oldest first."""
        return self._attempts


def _cell(state: TaskState) -> dict[str, Any]:
    started = state.status != NOT_STARTED or state.attempts > 0
    return {"status": state.status, "attempts": state.attempts,
            "points": state.points if started else None, "max_points": state.max_points if started else None,
            "stuck_on": list(state.stuck_on), "time_to_pass_s": state.time_to_pass_s}


@dataclass
class RoomView:
    """What the page shows, made from the results and the hub's user list at one moment.

    Attributes:
        made_at: When [s since the epoch].
        tasks: The task numbers shown.
        learners: One row per learner: name, server state, last activity, task -> (status, points, max points).
        reasons: Per task, the most common (check, reason, learners) among those whose latest attempt failed.
    """

    made_at: float
    tasks: list[int]
    learners: list[dict[str, Any]]
    reasons: dict[int, list[tuple[str, str, int]]]

    @classmethod
    def build(cls, results: Results, users: list[dict[str, Any]], tasks: list[int], now: float, hidden: set[str],
              untouched: dict[int, set[str]] | None = None, stuck_after: float = DEFAULT_STUCK_AFTER_S) -> RoomView:
        """The view of ``results`` for the hub's ``users`` at time ``now``, each learner × task classified by the
        class report's status model (:func:`~rrbot_workshop.classroom.task_status.classify`).

        Args:
            results: The posted attempts.
            users: The hub's user models (``/hub/api/users``); admins and ``hidden`` names are left out.
            tasks: Tasks to show even before anyone tried them.
            now: The time the view is for [s since the epoch].
            hidden: Names that are no learners (the instructors' group).
            untouched: Per task, the versions of its exercise as handed out: self-checks of those are no start.
            stuck_after: How long the same check must keep failing for "stuck" [s].
        """
        posted = results.attempts()
        untouched = untouched or {}
        names = {u["name"] for u in users if not u.get("admin") and u["name"] not in hidden}
        names |= set(posted) - hidden
        by_name = {u["name"]: u for u in users}
        shown = sorted(set(tasks) | {t for p in posted.values() for t in p})
        rows, reasons = [], {}
        counts: dict[int, Counter[tuple[str, str]]] = {}
        for name in sorted(names):
            state = server_state(by_name.get(name, {}))
            row: dict[str, Any] = {"name": name, "server": state.state, "last_activity": state.last_activity,
                                   "tasks": {}}
            for task in shown:
                records = [Attempt.from_record(a) for a in posted.get(name, {}).get(task, [])]
                task_state = classify(records, now, stuck_after, untouched.get(task, ()))
                row["tasks"][task] = _cell(task_state)
                if task_state.status in (WORKING, STUCK):  # among those who tried: why their latest attempt failed
                    for check, why in task_state.failing.items():
                        counts.setdefault(task, Counter())[(check, why)] += 1
            rows.append(row)
        for task, counter in counts.items():
            reasons[task] = [(check, why, n) for (check, why), n in counter.most_common(5)]
        return cls(now, shown, rows, reasons)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: what ``api/status`` answers."""
        return {"made_at": self.made_at, "tasks": self.tasks, "learners": self.learners,
                "reasons": {str(t): [{"check": c, "reason": r, "learners": n} for c, r, n in rows]
                            for t, rows in self.reasons.items()}}

    def html(self, refresh_s: int = REFRESH_S, titles: dict[int, str] | None = None,
             stuck_after: float = DEFAULT_STUCK_AFTER_S) -> str:
        """The page: the table, the reasons, when it was made; it reloads itself every ``refresh_s`` seconds.

        Args:
            refresh_s: Seconds between two reloads.
            titles: Task number -> name, shown when the pointer rests on a task's column.
            stuck_after: The stuck time the statuses were made with [s] (said in the legend).
        """
        titles = titles or {}
        stuck_minutes = stuck_after / 60
        made = time.strftime("%H:%M:%S %Z, %Y-%m-%d", time.localtime(self.made_at))
        head = "".join(f'<th title="{html.escape(titles.get(t, ""))}">{t}</th>' for t in self.tasks)
        marks = {PASSED: "✓", WORKING: "…", STUCK: "!", NOT_STARTED: "·"}
        body = []
        for row in self.learners:
            cells = []
            for task in self.tasks:
                cell = row["tasks"][task]
                tip = cell["status"] if cell["points"] is None else \
                    f"{cell['status']}: {cell['points']:g}/{cell['max_points']:g} points, {cell['attempts']} check(s)"
                if cell["stuck_on"]:
                    tip += "; failing for a while: " + ", ".join(cell["stuck_on"])
                tip = html.escape(tip)
                points = "" if cell["points"] is None else f" <small>{cell['points']:g}</small>"
                cells.append(f'<td class="{cell["status"].replace(" ", "-")}" title="{tip}">'
                             f'{marks[cell["status"]]}{points}</td>')
            body.append(f"<tr><th>{html.escape(row['name'])}</th><td class=\"server-{row['server']}\">"
                        f"{html.escape(row['server'])}</td><td>{_ago(row['last_activity'], self.made_at)}</td>"
                        f"{''.join(cells)}</tr>")
        reasons = []
        for task in sorted(self.reasons):
            items = "".join(f"<li><b>{n}</b> × <code>{html.escape(c)}</code>: {html.escape(r) or '(no reason given)'}"
                            f"</li>" for c, r, n in self.reasons[task])
            name = html.escape(titles.get(task, f"task {task}"))
            reasons.append(f"<h3>{name}</h3><ul>{items}</ul>")
        counts = Counter(c["status"] for r in self.learners for c in r["tasks"].values())
        legend = " ".join(f'<span class="{s.replace(" ", "-")}">{marks[s]} {s} ({counts[s]})</span>'
                          for s in (PASSED, WORKING, STUCK, NOT_STARTED))
        return f"""<!doctype html><html><head><meta charset="utf-8">
<meta http-equiv="refresh" content="{refresh_s}"><title>The room: rrbot_workshop</title><style>
body{{font-family:system-ui,sans-serif;margin:1.2em;color:#222}} table{{border-collapse:collapse;margin:.6em 0}}
th,td{{border:1px solid #ddd;padding:.25em .5em;text-align:center}} tr th:first-child{{text-align:left}}
.passed{{background:#c9efc9}} .working{{background:#fff1bf}} .stuck{{background:#f7b9b9;font-weight:bold}}
.not-started{{color:#aaa}} .legend span{{padding:.15em .5em;margin-right:.3em;border-radius:.3em}}
.server-ready{{color:#176317}} .server-stopped{{color:#999}} small{{color:#555}} li{{margin:.2em 0}}
code{{background:#f3f3f3;padding:0 .2em}}</style></head><body>
<h1>The room</h1>
<p>{len(self.learners)} learner(s) · made at {made} · reloads every {refresh_s} s</p>
<p class="legend">{legend}; stuck: the same check failing for {stuck_minutes:g} min or more; a self-check of
the exercise as handed out is no start</p>
<table><tr><th>learner</th><th>server</th><th>last active</th>{head}</tr>{''.join(body)}</table>
<h2>Most common reasons among those who tried</h2>{''.join(reasons) or '<p>none yet</p>'}
</body></html>"""


def _ago(stamp: str, now: float) -> str:
    """A hub time stamp (ISO 8601, UTC) as "N min ago"; "never" if none."""
    if not stamp:
        return "never"
    from datetime import datetime

    try:
        when = datetime.fromisoformat(stamp.replace("Z", "+00:00")).timestamp()
    except ValueError:
        return html.escape(stamp)
    minutes = max(0, int((now - when) // 60))
    return "just now" if minutes == 0 else f"{minutes} min ago"


def make_app(results: Results, prefix: str, api_url: str, token: str, tasks: dict[int, str], group: str = "",
             hub_auth: Any = None, untouched: dict[int, set[str]] | None = None,
             stuck_after: float = DEFAULT_STUCK_AFTER_S) -> Any:
    """The tornado application: ``POST <prefix>api/results``, ``GET <prefix>`` and ``<prefix>api/status``.

    Args:
        results: Where posted attempts go.
        prefix: The service's URL prefix (``/services/<name>/``).
        api_url: The hub's API (``.../hub/api``), reached with ``token``.
        token: The service's own API token (listing users, reading their servers).
        tasks: The tasks to show even before anyone tried them: number -> name.
        group: A hub group whose members may see the page (hub admins always may).
        hub_auth: JupyterHub's ``HubOAuth`` for the page (made from the environment if None).
        untouched: Per task, the versions of its exercise as handed out (self-checks of these are no start).
        stuck_after: How long the same check must keep failing for "stuck" [s].
    """
    from jupyterhub.services.auth import HubOAuth, HubOAuthCallbackHandler, HubOAuthenticated
    from tornado import web
    from tornado.httpclient import AsyncHTTPClient, HTTPClientError, HTTPRequest

    auth = hub_auth or HubOAuth(api_url=api_url, api_token=token, cache_max_age=60)
    client = AsyncHTTPClient()

    async def hub_get(path: str, with_token: str) -> Any:
        request = HTTPRequest(f"{api_url}/{path}", headers={"Authorization": f"token {with_token}",
                                                            "Accept": "application/json"}, request_timeout=10)
        try:
            return json.loads((await client.fetch(request)).body)
        except HTTPClientError as exc:
            if exc.code in (401, 403, 404):
                return None
            raise

    class ResultsHandler(web.RequestHandler):
        def check_xsrf_cookie(self) -> None:  # token-authenticated API, no cookies
            pass

        async def post(self) -> None:
            header = self.request.headers.get("Authorization", "")
            if not header.lower().startswith("token ") or not header[6:].strip():
                raise web.HTTPError(401, "a learner's hub token is needed: Authorization: token <token>")
            if len(self.request.body) > MAX_BODY:
                raise web.HTTPError(413, f"a result is at most {MAX_BODY} bytes")
            owner = await hub_get("user", header[6:].strip())
            if not owner or owner.get("kind", "user") != "user":
                raise web.HTTPError(403, "the hub knows no learner with this token")
            try:
                attempt = validate_attempt(json.loads(self.request.body))
            except ValueError as exc:
                raise web.HTTPError(400, str(exc)) from exc
            entry = results.add(str(owner["name"]), attempt)
            self.set_status(201)
            self.finish({"user": owner["name"], "task": entry["task"], "time": entry["time"]})

    class ViewHandler(HubOAuthenticated, web.RequestHandler):
        allow_all = True  # any hub user gets through OAuth; who may see the room is decided below

        async def view(self) -> RoomView:
            user = self.current_user
            model = await hub_get(f"users/{urllib.parse.quote(user['name'])}", token) if user else None
            if not model or not (model.get("admin") or (group and group in model.get("groups", []))):
                raise web.HTTPError(403, "the live view is for the room's instructors")
            users = await hub_get("users", token) or []
            staff = {u["name"] for u in users if group and group in u.get("groups", [])}
            return RoomView.build(results, users, list(tasks), time.time(), hidden=staff, untouched=untouched,
                                  stuck_after=stuck_after)

    class PageHandler(ViewHandler):
        @web.authenticated
        async def get(self) -> None:
            self.finish((await self.view()).html(titles=tasks, stuck_after=stuck_after))

    class StatusHandler(ViewHandler):
        @web.authenticated
        async def get(self) -> None:
            self.finish((await self.view()).to_dict())

    return web.Application([
        (prefix, PageHandler),
        (prefix + "api/status", StatusHandler),
        (prefix + "api/results", ResultsHandler),
        (prefix + "oauth_callback", HubOAuthCallbackHandler),
    ], hub_auth=auth, cookie_secret=os.urandom(32))


def serve(state: Path | None, ip: str | None, port: int | None, group: str, name: str,
          stuck_after: float = DEFAULT_STUCK_AFTER_S) -> None:
    """Run the service until it is stopped, configured from the hub's environment (``JUPYTERHUB_*``).

    Raises:
        CourseError: If the hub's API URL or the service's token is missing from the environment.
    """
    from tornado import ioloop

    from rrbot_workshop.classroom.class_report import untouched_versions
    from rrbot_workshop.course import tracks
    from rrbot_workshop.course.grading.runner import graded_tasks
    from rrbot_workshop.exceptions import CourseError

    name = os.environ.get("JUPYTERHUB_SERVICE_NAME", name)
    api_url, token = os.environ.get("JUPYTERHUB_API_URL", ""), os.environ.get("JUPYTERHUB_API_TOKEN", "")
    if not api_url or not token:
        raise CourseError("environment", "JUPYTERHUB_API_URL", "class-service runs as a JupyterHub service: the hub "
                          "sets JUPYTERHUB_API_URL and JUPYTERHUB_API_TOKEN (see deploy/)")
    prefix = os.environ.get("JUPYTERHUB_SERVICE_PREFIX", f"/services/{name}/")
    # what the hub sets for a service it starts, and what a service beside the hub (z2jh) derives from its name
    os.environ.setdefault("JUPYTERHUB_SERVICE_PREFIX", prefix)
    os.environ.setdefault("JUPYTERHUB_CLIENT_ID", f"service-{name}")
    os.environ.setdefault("JUPYTERHUB_OAUTH_CALLBACK_URL", prefix + "oauth_callback")
    os.environ.setdefault("JUPYTERHUB_BASE_URL", "/")
    where = urllib.parse.urlparse(os.environ.get("JUPYTERHUB_SERVICE_URL", "http://127.0.0.1:10101"))
    names = tracks.task_names()
    tasks = {task: names.get(task, f"task {task}") for task in graded_tasks()}
    app = make_app(Results(state), prefix, api_url.rstrip("/"), token, tasks, group,
                   untouched=untouched_versions(tracks.course_root()), stuck_after=stuck_after)
    app.listen(port or where.port or 10101, address=ip or where.hostname or "127.0.0.1", max_body_size=MAX_BODY)
    logger.info("rrbot-class: the live view at %s on %s:%s", prefix, ip or where.hostname, port or where.port)
    ioloop.IOLoop.current().start()
