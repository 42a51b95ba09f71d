"""JupyterHub's REST API, as the classroom uses it: who is in the room, their servers, starting them.

:class:`HubAPI` holds a hub's URL and a token, and makes plain HTTP requests (the standard library only: it also runs
where only the course is installed, as ``rrbot-workshop room warm`` does on an instructor's laptop). Every request is
bounded in time; an unreachable hub is status 0, never an exception.
"""

from __future__ import annotations

import json
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from rrbot_workshop.exceptions import CourseError

__all__ = ["HubAPI", "ServerState", "server_state", "warm_room"]


@dataclass(frozen=True)
class ServerState:
    """A learner's default server as the hub reports it.

    Attributes:
        state: ``"ready"``, ``"starting"``, ``"stopping"`` or ``"stopped"``.
        last_activity: The hub's last record of the learner's activity (ISO 8601, UTC), or "" if none.
        started: When the server started (ISO 8601), or "".
    """

    state: str
    last_activity: str = ""
    started: str = ""


def server_state(user: dict[str, Any]) -> ServerState:
    """The default server's state in a user model of the hub's ``/users`` answer."""
    server = (user.get("servers") or {}).get("")
    last = str(user.get("last_activity") or "")
    if not server:
        pending = user.get("pending")
        return ServerState("starting" if pending == "spawn" else "stopped", last)
    if server.get("ready"):
        state = "ready"
    else:
        state = {"spawn": "starting", "stop": "stopping"}.get(str(server.get("pending")), "starting")
    return ServerState(state, str(server.get("last_activity") or last), str(server.get("started") or ""))


class HubAPI:
    """A JupyterHub's REST API.

    Args:
        url: The hub's public URL (``https://hub.example.org``) or its API URL (``.../hub/api``).
        token: An API token; what it may do is what its owner may (listing users needs ``list:users``; starting
            servers, ``admin:servers``; making users, ``admin:users``).
        timeout: Longest wait for one request [s].
    """

    def __init__(self, url: str, token: str, timeout: float = 30.0) -> None:
        url = url.rstrip("/")
        self.api = url if url.endswith("/hub/api") else f"{url}/hub/api"
        self.token = token
        self.timeout = timeout

    def request(self, method: str, path: str, body: Any = None, token: str | None = None) -> tuple[int, Any]:
        """One request to ``<api>/<path>``; ``(HTTP status, JSON answer or None)``, status 0 if the hub is not
        reached."""
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(f"{self.api}/{path.lstrip('/')}", data=data, method=method, headers={
            "Authorization": f"token {token or self.token}", "Content-Type": "application/json",
            "Accept": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=self.timeout) as response:
                text = response.read()
                return response.status, json.loads(text) if text else None
        except urllib.error.HTTPError as exc:
            return exc.code, None
        except (OSError, ValueError):
            return 0, None

    def users(self) -> list[dict[str, Any]]:
        """Every user, with their servers (all pages of the hub's list).

        Raises:
            CourseError: If the hub refuses the token or cannot be reached.
        """
        found: list[dict[str, Any]] = []
        while True:
            status, page = self.request("GET", f"users?include_stopped_servers=0&offset={len(found)}&limit=200")
            if status != 200 or not isinstance(page, list):
                raise CourseError("hub", self.api, _why(status, "list the users", "list:users"))
            found.extend(page)
            if len(page) < 200:
                return found

    def whoami(self, token: str) -> dict[str, Any] | None:
        """The user (or service) a token belongs to, as the hub says; None if it belongs to nobody."""
        status, model = self.request("GET", "user", token=token)
        return model if status == 200 and isinstance(model, dict) else None

    def create_users(self, names: list[str]) -> list[str]:
        """Make the users among ``names`` that do not exist yet; the names made.

        Raises:
            CourseError: If the hub refuses.
        """
        existing = {u["name"] for u in self.users()}
        new = [n for n in names if n not in existing]
        if new:
            status, _ = self.request("POST", "users", {"usernames": new})
            if status != 201:
                raise CourseError("hub", self.api, _why(status, f"make the users {new}", "admin:users"))
        return new

    def start_server(self, name: str) -> int:
        """Ask for ``name``'s default server; the hub's status (201 started, 202 starting, 400 running already)."""
        status, _ = self.request("POST", f"users/{urllib.parse.quote(name)}/server")
        return status

    def wait(self, ready: Callable[[], bool], timeout: float, poll: float = 1.0) -> bool:
        """Call ``ready`` every ``poll`` seconds until it is true or ``timeout`` seconds passed; whether it was."""
        deadline = time.monotonic() + timeout
        while True:
            if ready():
                return True
            if time.monotonic() >= deadline:
                return False
            time.sleep(poll)


def _why(status: int, what: str, scope: str) -> str:
    if status == 0:
        return f"cannot reach the hub to {what}"
    if status in (401, 403):
        return f"the hub refused to {what} (HTTP {status}): the token needs the scope {scope}"
    return f"the hub could not {what} (HTTP {status})"


def warm_room(api: HubAPI, names: list[str], stagger: float = 2.0, at_once: int = 4, timeout: float = 900.0,
              report: Callable[[str], None] = print) -> dict[str, ServerState]:
    """Start every learner's server before the workshop, a few at a time: the learners made if missing, then one
    server asked for every ``stagger`` seconds while fewer than ``at_once`` are starting, until all are ready or
    ``timeout`` seconds passed.

    Args:
        api: The hub, with a token that may make users and start their servers (an admin's).
        names: The learners.
        stagger: Seconds between two starts [s].
        at_once: Most servers starting at the same time.
        timeout: Longest wait for the whole room [s].
        report: Where progress lines go.

    Returns:
        Each learner's server state at the end.

    Raises:
        CourseError: If the hub refuses the token or a name.
    """
    made = api.create_users(names)
    if made:
        report(f"made {len(made)} learner(s): {', '.join(made)}")
    deadline = time.monotonic() + timeout
    waiting = list(names)

    def states() -> dict[str, ServerState]:
        return {u["name"]: server_state(u) for u in api.users() if u["name"] in names}

    current = states()
    while time.monotonic() < deadline:
        starting = [n for n, s in current.items() if s.state == "starting"]
        while waiting and len(starting) < at_once:
            name = waiting.pop(0)
            if current.get(name, ServerState("stopped")).state == "stopped":
                status = api.start_server(name)
                report(f"{name}: asked for the server (HTTP {status})")
                starting.append(name)
                if waiting:
                    time.sleep(stagger)
        current = states()
        if not waiting and all(s.state == "ready" for s in current.values()):
            break
        time.sleep(min(stagger, 2.0) or 0.5)
    ready = sum(s.state == "ready" for s in current.values())
    report(f"{ready} of {len(names)} server(s) ready")
    return current
