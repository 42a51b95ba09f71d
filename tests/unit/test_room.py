"""A workshop room on this machine: JupyterHub on 127.0.0.1, three learners, notebook 02, task 2's grade, the
instructor's live view.

The room runs twice: with the hub the course pins (the dev extra's jupyterhub) and with the hub of the
zero-to-jupyterhub chart 4.4.0 (jupyterhub 5.5.0, installed from PyPI into the session's temporary folder over this
environment, learners' servers included, as the image built from binder/ pairs them). In each, every learner logs
in through the hub's REST API, gets a server of their own (their workspace is made on first start, by
``rrbot-workshop singleuser``), runs notebook 02's cells through the kernel protocol and grades task 2, which posts
the result to the live view; two of them have solved it. As root (CI), every learner is a Unix account of their
own, made for the room and removed after it, and one learner's kernel tries the others' workspace. The room's
password and the instructor's are tried on the admin page; the live view is read as the instructor, refused to a
learner, and opened in headless Chromium. Then the class report reads the homes. Nothing is left running.
"""

from __future__ import annotations

import json
import os
import pwd
import re
import shutil
import subprocess
import sys
import tempfile
import urllib.error
import urllib.request
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from browser_driver import CHROMIUM, Browser, unavailable

from rrbot_workshop.classroom import kernels
from rrbot_workshop.classroom.class_report import build_report
from rrbot_workshop.classroom.class_report_page import write_report
from rrbot_workshop.classroom.hub import server_state
from rrbot_workshop.classroom.room import SERVICE, VERSION_WARNING, LearnerRun, Room, portable_python
from rrbot_workshop.classroom.task_status import PASSED, WORKING
from rrbot_workshop.cli import main

ROOT = Path(__file__).resolve().parents[2]
SOLUTION = ROOT / "solutions" / "task02_mock_hardware"
#: The hub of the zero-to-jupyterhub chart 4.4.0 (see ../shared/upstream/README.md and binder/requirements.txt).
CHART_HUB = "5.5.0"
ROOT_USER = hasattr(os, "geteuid") and os.geteuid() == 0
#: Why learners cannot have Unix accounts here although this runs as root (no Python every account can run).
NO_ACCOUNTS: list[str] = []

# JupyterHub and its proxy come with the course's dev extras, which the test command installs: no skip without them
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not SOLUTION.is_dir(), reason="this copy of the course has no solutions/")]

LEARNERS = {"ana": True, "ben": False, "cleo": True}  # name -> has solved task 2 (ben has started, no more)


def _solve(workspace: Path) -> None:
    target = workspace / "exercises" / "task02_mock_hardware"
    shutil.rmtree(target)
    shutil.copytree(SOLUTION, target, ignore=shutil.ignore_patterns("__pycache__"))


def _start(workspace: Path) -> None:
    """A first change of the learner's own: a self-check of the exercise as handed out would not be a start."""
    yaml = next((workspace / "exercises" / "task02_mock_hardware").rglob("*.yaml"))
    yaml.write_text(yaml.read_text() + "\n# my first try\n")


@pytest.fixture(scope="session")
def room_base() -> Iterator[Path]:
    """A folder under /tmp that learners' accounts can reach (pytest's own is private to root)."""
    base = Path(tempfile.mkdtemp(prefix="rrbot_room_", dir="/tmp"))
    base.chmod(0o755)
    yield base
    shutil.rmtree(base, ignore_errors=True)


@pytest.fixture(scope="session")
def pinned_python(room_base: Path) -> str:
    """This environment's Python, or one every learner's account can run with this environment's packages."""
    if not ROOT_USER:
        return sys.executable
    try:
        return portable_python(room_base / "python-pinned")
    except FileNotFoundError as exc:  # the rooms then run every server as this user; the account tests say why
        NO_ACCOUNTS.append(str(exc))
        return sys.executable


@pytest.fixture(scope="session")
def chart_hub_python(room_base: Path) -> str:
    """A Python with jupyterhub 5.5.0 (from PyPI) over this environment's packages, for the hub and the servers."""
    try:
        python = portable_python(room_base / f"python-jupyterhub-{CHART_HUB}", force=True)
    except FileNotFoundError as exc:
        NO_ACCOUNTS.append(str(exc))
        python = portable_python(room_base / f"python-jupyterhub-{CHART_HUB}", force=True, open_to_all=False)
    proc = subprocess.run([sys.executable, "-m", "pip", "--python", python, "install", "--quiet", "--no-deps",
                           f"jupyterhub=={CHART_HUB}"], capture_output=True, text=True, timeout=600, check=False)
    if proc.returncode != 0:
        why = f"could not install jupyterhub {CHART_HUB} from PyPI: {proc.stderr[-500:]}"
        if os.environ.get("RRBOT_WORKSHOP_REQUIRE_UPSTREAM"):
            pytest.fail(why, pytrace=False)
        pytest.skip(why)
    return python


@dataclass
class RoomRecord:
    """What happened in one room, gathered while it ran; the tests read it after the room stopped."""

    room: Room
    hub: str
    version: str = ""
    runs: dict[str, LearnerRun] = field(default_factory=dict)
    admin_page: dict[str, Any] = field(default_factory=dict)
    isolation: list[str] = field(default_factory=list)
    kernel_parent: str = ""
    status: dict[str, Any] = field(default_factory=dict)
    learner_view: int = 0
    assistant_view: int = 0
    posts: dict[str, Any] = field(default_factory=dict)
    page_text: str = ""
    screenshot: Path | None = None
    log: str = ""
    left: list[str] = field(default_factory=list)
    accounts: list[str] = field(default_factory=list)
    workspaces: dict[str, dict[str, Any]] = field(default_factory=dict)
    warm: int = -1
    warmed: dict[str, str] = field(default_factory=dict)
    report: Any = None
    report_html: str = ""


def _open(opener: urllib.request.OpenerDirector, url: str) -> tuple[int, bytes]:
    try:
        with opener.open(url, timeout=60) as answer:
            return answer.status, answer.read()
    except urllib.error.HTTPError as exc:
        return exc.code, b""


def _post(url: str, token: str | None, body: Any) -> int:
    headers = {"Content-Type": "application/json", **({"Authorization": f"token {token}"} if token else {})}
    request = urllib.request.Request(url, data=json.dumps(body).encode(), headers=headers, method="POST")
    try:
        with urllib.request.urlopen(request, timeout=30) as answer:
            return answer.status
    except urllib.error.HTTPError as exc:
        return exc.code


def _admin_page(room: Room, record: RoomRecord) -> None:
    ana = room.name("ana")
    as_instructor = room.login_form(room.instructor, room.instructor_password)
    as_learner = room.login_form(ana, room.room_password)
    record.admin_page = {
        "instructor with the room's password": room.login_form(room.instructor, room.room_password) is not None,
        "learner with the instructor's password": room.login_form(ana, room.instructor_password) is not None,
        "instructor": _open(as_instructor, f"{room.url}/hub/admin")[0] if as_instructor else None,
        "learner": _open(as_learner, f"{room.url}/hub/admin")[0] if as_learner else None,
    }
    if as_instructor:
        status, body = _open(as_instructor, f"{room.url}/services/{SERVICE}/api/status")
        record.status = json.loads(body) if status == 200 else {"http": status}
        record.page_text = _open(as_instructor, f"{room.url}/services/{SERVICE}/")[1].decode()
    if as_learner:
        record.learner_view = _open(as_learner, f"{room.url}/services/{SERVICE}/api/status")[0]
    # a teaching assistant: a learner's password, a member of the hub group "instructors"
    assistant = room.name("tess")
    room.hub.request("POST", "users", {"usernames": [assistant]})
    room.hub.request("POST", "groups/instructors/users", {"users": [assistant]})
    as_assistant = room.login_form(assistant, room.room_password)
    record.assistant_view = _open(as_assistant, f"{room.url}/services/{SERVICE}/api/status")[0] if as_assistant else 0


def _forgeries(room: Room, record: RoomRecord) -> None:
    """Posts the live view must file under the token's owner, or refuse."""
    url = f"http://127.0.0.1:{room.service_port}/services/{SERVICE}/api/results"
    full = {"task": 5, "score": 10.0, "max_score": 10.0, "failed": [], "reasons": {}}
    record.posts = {
        "ben claims to be ana": _post(url, record.runs[room.name("ben")].token, {**full, "user": room.name("ana")}),
        "no token": _post(url, None, full),
        "a made-up token": _post(url, "0" * 32, full),
        "the room's service token": _post(url, room.token, full),
        "a bad body": _post(url, record.runs[room.name("ben")].token, {"task": "two"}),
    }


def _isolation(room: Room, record: RoomRecord) -> None:
    """Ana's kernel reads and writes in Ben's workspace."""
    ana, ben = room.name("ana"), room.name("ben")
    theirs = room.homes / ben / "rrbot_workshop" / "exercises" / "task02_mock_hardware"
    kernel = room.kernel(ana, record.runs[ana].token, "my_notebooks/isolation.ipynb")
    code = [f"open({str(next(p for p in theirs.rglob('*') if p.is_file()))!r}).read()",
            f"open({str(theirs / 'planted.py')!r}, 'w').write('x = 1')",
            f"import os; os.listdir({str(room.homes / ben)!r})"]
    for snippet in code:
        errors = room.run_code(ana, record.runs[ana].token, kernel, snippet)
        record.isolation.append(errors[0] if errors else "")
    # what started the kernel: raised as an error, the one thing run_code gives back
    parent = "import os; raise RuntimeError(open(f'/proc/{os.getppid()}/cmdline', 'rb').read().replace(b'\\0', b' '))"
    errors = room.run_code(ana, record.runs[ana].token, kernel, parent)
    record.kernel_parent = errors[0] if errors else ""


def _browser(room: Room, record: RoomRecord, folder: Path) -> None:
    if CHROMIUM is None:
        unavailable("headless Chromium not installed (apt-get install -y chromium)")
    browser = Browser(CHROMIUM, folder / "chromium-profile", size=(1300, 700))
    try:
        browser.open(f"{room.url}/hub/login?next=%2Fhub%2Fhome")
        browser.js(f"""document.querySelector('#username_input').value = {json.dumps(room.instructor)};
                       document.querySelector('#password_input').value = {json.dumps(room.instructor_password)};
                       document.querySelector('form').submit(); true""")
        browser.wait_for("location.pathname.startsWith('/hub/') && !location.pathname.startsWith('/hub/login')",
                         what="the hub to log the instructor in")
        browser.open(f"{room.url}/services/{SERVICE}/")
        browser.wait_for("document.querySelector('table') !== null", what="the live view's table")
        record.page_text = browser.js("document.body.innerText")
        record.screenshot = browser.screenshot(folder / f"live_view_{record.hub}.png")
    finally:
        browser.close()


@pytest.fixture(scope="module", params=["pinned", "chart"], ids=["hub as pinned", f"hub {CHART_HUB} (z2jh chart)"])
def room(request: pytest.FixtureRequest, room_base: Path, tmp_path_factory: pytest.TempPathFactory) -> RoomRecord:
    python = request.getfixturevalue("pinned_python" if request.param == "pinned" else "chart_hub_python")
    room = Room(room_base / request.param, python=python, timeout=180.0, unix_users=ROOT_USER and not NO_ACCOUNTS)
    record = RoomRecord(room, request.param)
    shots = tmp_path_factory.mktemp("live_view")
    try:
        room.start()
        record.version = room.version()
        names = {room.name(n): solved for n, solved in LEARNERS.items()}
        # the instructor warms the room before the learners arrive: every server started through the hub's API
        for name in names:
            room.add_account(name)
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("JUPYTERHUB_API_TOKEN", room.token)
            record.warm = main(["room", "warm", "--hub", room.url, "--learners", *names, "--stagger", "0.5",
                                "--at-once", "2", "--timeout", "300"])
        record.warmed = {u["name"]: server_state(u).state for u in room.hub.users() if u["name"] in names}
        with ThreadPoolExecutor(max_workers=len(names)) as pool:
            futures = {name: pool.submit(room.learner_session, name, prepare=_solve if solved else _start)
                       for name, solved in names.items()}
            record.runs = {name: future.result() for name, future in futures.items()}
        room.login(room.name("dan"))  # a learner who never started a server: no workspace yet
        record.accounts = list(room.accounts)
        if room.unix_users:
            _isolation(room, record)
        _forgeries(room, record)
        _admin_page(room, record)
        _browser(room, record, shots)
        # the instructor asks the hub who is in the room, and reads their homes
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("JUPYTERHUB_API_TOKEN", room.token)
            code = main(["class-report", "--hub", room.url, "--home-template", f"{room.homes}/{{username}}",
                         "--out", str(room.folder / "hub_report")])
        assert code == 0
        record.report = build_report([str(room.homes / "*")])
        record.report_html = write_report(record.report, shots / "report")[2].read_text()
        for name in names:
            workspace = room.homes / name / "rrbot_workshop"
            log = workspace / "exercises" / ".progress" / "task02.json"
            record.workspaces[name] = {
                "notebook": (workspace / "my_notebooks" / "02_mock_hardware.ipynb").is_file(),
                "solutions or library": (workspace / "solutions").exists() or (workspace / "rrbot_workshop").exists(),
                "attempts": len(json.loads(log.read_text())["attempts"]) if log.is_file() else 0,
                "owner": pwd.getpwuid(workspace.stat().st_uid).pw_name,
                "home mode": oct((room.homes / name).stat().st_mode & 0o777)}
        record.log = room.log()
    finally:
        record.left = room.stop()
    return record


def test_the_room_runs_the_hub_it_was_asked_for(room: RoomRecord) -> None:
    import jupyterhub

    assert room.version == (jupyterhub.__version__ if room.hub == "pinned" else CHART_HUB)


def test_hub_and_servers_agree_on_their_version(room: RoomRecord) -> None:
    """JupyterHub warns, in the hub's log, when a server's version differs enough to break logins ("could cause
    failure to authenticate and result in redirect loops"); the room pairs them as the deployments do."""
    servers = re.findall(r"Starting jupyterhub single-user server(?: extension)? version (\S+)", room.log)
    assert servers and set(servers) == {room.version}, servers
    assert VERSION_WARNING not in room.log


def test_room_warm_starts_every_learners_server_before_they_arrive(room: RoomRecord) -> None:
    assert room.warm == 0
    assert room.warmed == {room.room.name(n): "ready" for n in LEARNERS}
    for name in LEARNERS:  # the learner arrives to a running server: the hub says it is running already
        assert room.runs[room.room.name(name)].server_status == 400


def test_every_learner_runs_notebook_02_and_gets_the_right_grade(room: RoomRecord) -> None:
    max_score = None
    for name, solved in LEARNERS.items():
        run = room.runs[room.room.name(name)]
        assert run.errors == [], f"{name}: cells raised {run.errors}"
        assert len(run.cell_s) > 10
        score, maximum = run.score
        max_score = max_score or maximum
        assert maximum > 0 and maximum == max_score
        assert score == (maximum if solved else 0.0), f"{name} (solved: {solved}) got {score}/{maximum}"


def test_each_learner_has_their_own_workspace_from_the_shared_course(room: RoomRecord) -> None:
    for name, facts in room.workspaces.items():
        assert facts["notebook"] and not facts["solutions or library"] and facts["attempts"] == 1, (name, facts)
        if room.room.unix_users:  # made by their own server, as their own account, in a home only they can open
            assert facts["owner"] == name and facts["home mode"] == "0o700", (name, facts)


def _needs_accounts(room: RoomRecord) -> None:
    if not ROOT_USER:
        pytest.skip("a Unix account per learner needs root (CI runs as root)")
    if not room.room.unix_users:
        pytest.fail(f"running as root, yet the learners had no Unix accounts: {NO_ACCOUNTS}", pytrace=False)


def test_one_learner_cannot_read_or_write_anothers_workspace(room: RoomRecord) -> None:
    _needs_accounts(room)
    assert len(room.isolation) == 3
    assert all(error.startswith("PermissionError") for error in room.isolation), room.isolation


@pytest.mark.skipif(not Path("/proc/self/cmdline").exists(), reason="reads the kernel's parent from /proc")
def test_a_learners_kernel_is_forked_from_their_servers_kernel_template(room: RoomRecord) -> None:
    assert kernels.TEMPLATE_MODULE in room.kernel_parent, room.kernel_parent


def test_the_learners_accounts_are_removed_with_the_room(room: RoomRecord) -> None:
    _needs_accounts(room)
    assert sorted(room.accounts) == sorted(room.room.name(n) for n in [*LEARNERS, "dan"])
    for name in room.accounts:
        with pytest.raises(KeyError):
            pwd.getpwnam(name)


def test_only_the_instructors_password_opens_the_admin_page(room: RoomRecord) -> None:
    assert room.admin_page == {"instructor with the room's password": False,
                               "learner with the instructor's password": False,
                               "instructor": 200, "learner": 403}


def test_the_live_view_shows_each_learner_and_task_from_their_own_self_checks(room: RoomRecord) -> None:
    rows = {row["name"]: row for row in room.status["learners"]}
    name = room.room.name
    assert sorted(rows) == sorted(name(n) for n in [*LEARNERS, "dan"])  # the instructor is not a learner
    assert "tess" not in "".join(rows)  # read before the assistant joined
    for learner, solved in LEARNERS.items():
        row = rows[name(learner)]
        assert row["tasks"]["2"]["status"] == ("passed" if solved else "working")
        assert row["tasks"]["2"]["attempts"] == 1
        assert row["server"] == "ready" and row["last_activity"]
    assert rows[name("dan")]["server"] == "stopped"
    assert all(cell["status"] == "not started" for cell in rows[name("dan")]["tasks"].values())
    (reasons,) = [room.status["reasons"]["2"]]
    assert reasons and all(r["learners"] == 1 for r in reasons)  # ben's failed checks, and why
    assert room.status["made_at"] > 0


def test_nobody_can_post_for_someone_else(room: RoomRecord) -> None:
    assert room.posts == {"ben claims to be ana": 201, "no token": 401, "a made-up token": 403,
                          "the room's service token": 403, "a bad body": 400}
    rows = {row["name"]: row for row in room.status["learners"]}
    assert rows[room.room.name("ben")]["tasks"]["5"]["status"] == "passed"
    assert rows[room.room.name("ana")]["tasks"]["5"]["status"] == "not started"


def test_the_live_view_is_for_instructors_only(room: RoomRecord) -> None:
    assert room.learner_view == 403
    assert room.assistant_view == 200  # a member of the hub group "instructors"


def test_the_live_view_opens_in_a_browser_and_reloads_itself(room: RoomRecord) -> None:
    assert room.screenshot is not None and room.screenshot.stat().st_size > 10_000
    for learner in LEARNERS:
        assert room.room.name(learner) in room.page_text
    assert "✓ passed (" in room.page_text and "… working (1)" in room.page_text and "· not started (" in room.page_text
    assert "reloads every" in room.page_text and "made at " in room.page_text


def test_the_class_report_shows_the_room(room: RoomRecord) -> None:
    report = room.report
    assert [lr.name for lr in report.learners] == sorted(room.room.name(n) for n in LEARNERS)
    for learner in report.learners:
        solved = LEARNERS[learner.name.removeprefix(room.room.prefix)]
        assert learner.state(2).status == (PASSED if solved else WORKING) and learner.state(2).attempts == 1
        assert learner.last_activity is not None and learner.notes == []
    failing = report.stuck()  # ben's failing checks, none for ten minutes yet
    assert failing and all(r["task"] == 2 and r["learners_failing"] == 1 and r["learners_stuck"] == 0
                           for r in failing)
    assert room.room.name("ben") in room.report_html


def test_the_class_report_can_take_the_learners_from_the_hubs_user_list(room: RoomRecord) -> None:
    data = json.loads((room.room.folder / "hub_report" / "report.json").read_text())
    assert sorted(lr["name"] for lr in data["learners"]) == sorted(room.room.name(n) for n in LEARNERS)
    assert any(room.room.name("dan") in note and "no workspace yet" in note for note in data["notes"])


def test_nothing_of_the_room_is_left_running(room: RoomRecord) -> None:
    assert room.left == [], f"still running after stop: {room.left}"
    assert room.room.process is not None and room.room.process.poll() is not None
