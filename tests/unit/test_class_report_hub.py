"""The class report's learners from a JupyterHub's user list: every page of ``GET /hub/api/users``, names taken
literally (never as patterns, never as paths), homes as The Littlest JupyterHub makes them.

The hub here answers on 127.0.0.1 as JupyterHub's REST API does (the user model, its pagination and its Accept
header, its 403 without a token); the room test (``test_room.py``) runs the report against a real hub.
"""

from __future__ import annotations

import json
import tarfile
import threading
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import parse_qs, urlparse

import pytest
from upstream import TLJH, upstream
from workspace_helpers import no_hang, tree

from rrbot_workshop.classroom.class_report import (
    MAX_HUB_NAME_CHARS,
    TLJH_HOMES,
    WORKSPACE_NAME,
    build_report,
    hub_users,
    hub_workspaces,
    tljh_home,
)
from rrbot_workshop.cli import main
from rrbot_workshop.exceptions import CourseError

TOKEN = "secret-token"
PAGINATION = "application/jupyterhub-pagination+json"
T0 = 1_800_000_000.0


def _user_model(name: str) -> dict:
    """A user as JupyterHub 5 and 6 list them."""
    return {"kind": "user", "name": name, "admin": False, "roles": ["user"], "groups": [], "server": None,
            "pending": None, "created": "2026-05-04T08:00:00.000000Z", "last_activity": None, "servers": {}}


class _Hub(BaseHTTPRequestHandler):
    users: list[str] = []
    requests: list[dict] = []
    default_limit, max_limit = 50, 200  # JupyterHub's api_page_default_limit and api_page_max_limit

    def do_GET(self) -> None:  # noqa: N802 - http.server's name
        url = urlparse(self.path)
        query = parse_qs(url.query)
        type(self).requests.append({"path": url.path, "query": query, "accept": self.headers.get("Accept", ""),
                                    "auth": self.headers.get("Authorization", "")})
        if url.path != "/hub/api/users":
            return self._send(404, {"status": 404, "message": "Not Found"})
        if self.headers.get("Authorization") != f"token {TOKEN}":
            return self._send(403, {"status": 403, "message": "Missing or invalid credentials."})
        paginated = PAGINATION in {s.strip() for s in self.headers.get("Accept", "").split(",")}
        offset = int(query.get("offset", ["0"])[0])
        limit = min(int(query.get("limit", [str(self.default_limit if paginated else self.max_limit)])[0]),
                    self.max_limit)
        items = [_user_model(n) for n in self.users[offset:offset + limit]]
        if not paginated:
            return self._send(200, items)
        following = offset + limit
        nxt = {"offset": following, "limit": limit, "url": f"http://127.0.0.1/hub/api/users?offset={following}"} \
            if following < len(self.users) else None
        self._send(200, {"items": items, "_pagination": {"offset": offset, "limit": limit, "total": len(self.users),
                                                          "next": nxt}})

    def _send(self, status: int, body: object) -> None:
        data = json.dumps(body).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)

    def log_message(self, *args: object) -> None:
        pass


@pytest.fixture
def hub() -> Iterator[tuple[str, type[_Hub]]]:
    handler = type("Hub", (_Hub,), {"users": [], "requests": []})
    server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}", handler
    finally:
        server.shutdown()
        server.server_close()


def _workspace(home: Path, passed: bool = True) -> None:
    progress = home / WORKSPACE_NAME / "exercises" / ".progress"
    progress.mkdir(parents=True)
    (progress / "task01.json").write_text(json.dumps({"attempts": [
        {"time": T0, "score": 4 if passed else 0, "max_score": 4, "failed": [] if passed else ["x"]}]}))


def test_every_page_of_the_hubs_users_is_read(hub) -> None:
    url, handler = hub
    handler.users = [f"learner{i:03d}" for i in range(450)]
    assert hub_users(url, TOKEN) == handler.users
    assert [r["query"].get("offset") for r in handler.requests] == [["0"], ["200"], ["400"]]
    assert all(r["accept"] == PAGINATION and r["auth"] == f"token {TOKEN}" for r in handler.requests)


def test_a_hub_that_answers_one_plain_list_is_read_too(hub) -> None:
    """A hub before JupyterHub 2.0 ignores the pagination media type and answers one list of every user."""
    url, handler = hub
    handler.users = ["ana", "ben"]
    send = handler._send
    handler._send = lambda self, status, body: send(self, status, body["items"] if isinstance(body, dict) else body)
    assert hub_users(url, TOKEN) == ["ana", "ben"] and len(handler.requests) == 1


def test_hub_users_raises_course_error_without_a_valid_token_a_hub_or_an_http_address(hub) -> None:
    url, _ = hub
    with pytest.raises(CourseError, match="did not list its users.*403"):
        hub_users(url, "wrong")
    with pytest.raises(CourseError, match="did not list its users"):
        hub_users("http://127.0.0.1:9", TOKEN)
    with pytest.raises(CourseError, match="give the hub's http:// or https:// address"):
        hub_users("file:///etc/passwd", TOKEN)


def test_hub_workspaces_raises_course_error_for_a_template_without_the_user() -> None:
    with pytest.raises(CourseError, match=r"must contain \{username\}"):
        hub_workspaces(["ana"], "/home/nobody", [])


def test_user_names_are_taken_literally_never_as_globs_or_paths(hub, tmp_path: Path) -> None:
    """A user named '*' is the folder '*', not every home; '[ab]na' is not 'ana'; '../ana' and a 10,000-character
    name are notes; braces in a name are not a template's; the rest of the room is reported."""
    url, handler = hub
    homes = tmp_path / "home"
    for name in ("ana", "*", "[ab]na", "x{username}"):
        _workspace(homes / name, passed=name == "ana")
    handler.users = ["ana", "*", "[ab]na", "x{username}", "../ana", "ana/..", "x" * 10_000, ".", "nobody"]
    notes: list[str] = []
    found = hub_workspaces(hub_users(url, TOKEN), f"{homes}/{{username}}", notes)
    assert sorted(w.name for w in found) == sorted(["ana", "*", "[ab]na", "x{username}"])
    assert {w.name: w.root for w in found}["*"] == homes / "*"
    assert notes == ["hub user '../ana': the name cannot be a folder's name; left out",
                     "hub user 'ana/..': the name cannot be a folder's name; left out",
                     f"hub user '{'x' * 80}… (10000 characters)': the name is longer than {MAX_HUB_NAME_CHARS} "
                     "characters; left out",
                     "hub user '.': the name cannot be a folder's name; left out",
                     f"nobody: no workspace yet in {homes}/nobody (never started a server?)"]
    before = tree(homes)
    report = no_hang(build_report, workspaces=found, notes=notes, now=T0 + 60, course=tmp_path / "no-course")
    assert tree(homes) == before
    assert {lr.name: lr.state(1).status for lr in report.learners} == {
        "*": "working", "[ab]na": "working", "ana": "passed", "x{username}": "working"}


def test_the_command_with_a_hub_reports_the_room(hub, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    url, handler = hub
    homes = tmp_path / "home"
    _workspace(homes / "ana")
    handler.users = ["ana", "*", "y" * 10_000]
    monkeypatch.setenv("JUPYTERHUB_API_TOKEN", TOKEN)
    code = main(["class-report", "--hub", url, "--home-template", f"{homes}/{{username}}",
                 "--out", str(tmp_path / "r")])
    assert code == 0
    out = capsys.readouterr().out
    assert out.startswith("1 learner(s); wrote ")
    assert "note: hub user 'yyyy" in out and "note: *: no workspace yet" in out
    assert json.loads((tmp_path / "r" / "report.json").read_text())["learners"][0]["name"] == "ana"


def _tljh_generate_system_username():
    """TLJH's own ``generate_system_username``, from the upstream source."""
    with tarfile.open(upstream(TLJH)) as tar:
        member = next(m for m in tar.getmembers() if m.name.endswith("tljh/normalize.py"))
        source = tar.extractfile(member).read().decode()
    namespace: dict = {}
    exec(compile(source, member.name, "exec"), namespace)  # noqa: S102 - TLJH's module, one pure function
    return namespace["generate_system_username"]


@pytest.mark.parametrize("name", ["ana", "a" * 17, "a" * 18, "a" * 40, "x" * 10_000, "Ünïcode-name-for-a-learner"])
def test_tljh_homes_are_the_ones_tljh_makes(name: str) -> None:
    generate = _tljh_generate_system_username()
    assert tljh_home(name) == Path("/home") / generate(f"jupyter-{name}")


def test_the_commands_default_homes_are_tljhs_and_name_the_home_looked_at() -> None:
    from rrbot_workshop.cli import build_parser

    args = build_parser().parse_args(["class-report", "--hub", "http://127.0.0.1:8000", "--out", "r"])
    assert args.home_template == TLJH_HOMES
    notes: list[str] = []
    name = "a-learner-with-a-long-name"
    assert hub_workspaces([name], TLJH_HOMES, notes) == []
    assert notes == [f"{name}: no workspace yet in {tljh_home(name)} (never started a server?)"]
    assert tljh_home(name).name.startswith("jupyter-a-learner-with-a-") and len(tljh_home(name).name) == 32
