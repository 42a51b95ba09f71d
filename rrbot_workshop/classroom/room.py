"""A workshop room on this machine: JupyterHub on 127.0.0.1 with learners who work through a notebook and grade.

Used by the room test (3 learners) and ``benchmarks/bench_room.py`` (10 and 30). :class:`Room` starts JupyterHub
(its proxy, a local-process spawner, JupyterHub's ``SharedPasswordAuthenticator`` with a room password and a separate
instructor's password, and the instructor's live view as a hub-managed service, all on loopback) in a folder of its
own; each learner's server is ``rrbot-workshop singleuser``, so their workspace is made on first start, as in a real
room. With ``unix_users`` (the hub must run as root), each learner is a Unix account of their own, made for the room
and removed with it, whose server runs as that account in a private home: learners are kept apart by the operating
system, as on The Littlest JupyterHub. Without it, every server runs as this process's user, homes inside the folder.

:meth:`Room.learner_session` does what a learner does: logs in through the hub's REST API (a token of their own),
starts their server, opens notebook 02 in a kernel and runs its cells through the kernel protocol, the last of which
grades task 2 (and posts the result to the live view). :meth:`Room.login_form` logs in as a browser does, with a
password. :meth:`Room.stop` stops the hub, the proxy, every server and the service, removes the accounts, and reports
any process of the room left.

Nothing here listens on anything but 127.0.0.1, and every wait is bounded in time.
"""

from __future__ import annotations

import http.cookiejar
import json
import os
import pwd
import re
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.parse
import urllib.request
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rrbot_workshop.classroom.hub import HubAPI, json_request

__all__ = ["Room", "LearnerRun", "free_port", "run_cells", "portable_python", "SERVICE"]

#: The live view's name on the hub (its pages are at ``/services/rrbot-class/``), as in ``deploy/``.
SERVICE = "rrbot-class"
#: What the hub's log says when the hub and a server differ in version enough to matter (JupyterHub's own words).
VERSION_WARNING = "could cause failure to authenticate"
#: Seconds :meth:`Room.stop` waits for the hub to stop its servers (SIGTERM to the hub) before killing it.
STOP_WAIT = 90.0
#: Seconds it then waits for servers and kernels that were told to stop to end by themselves.
ENDING_WAIT = 20.0


def free_port() -> int:
    """A TCP port free on 127.0.0.1 now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _open_to_all(path: Path) -> bool:
    """Whether any account can reach ``path`` (every folder above it searchable by others) and read it."""
    path = path.resolve()
    if not path.exists() or not path.stat().st_mode & 0o004:
        return False
    return all(parent.stat().st_mode & 0o001 for parent in path.parents)


def portable_python(folder: Path, python: str = sys.executable, force: bool = False, open_to_all: bool = True) -> str:
    """A Python any account can run, with the packages of ``python``.

    ``python`` itself when every account can run it (and ``force`` is not set); else a venv in ``folder`` over a
    system interpreter of the same version that others can run (``/usr/bin/python3.X``, ...), whose ``.pth`` file adds
    ``python``'s site-packages after its own (so what is installed in the venv wins), with ``python``'s
    ``configurable-http-proxy`` beside it. A course installed under a private home (a pyenv Python under ``/root``)
    thus runs as the learners' accounts, as the course installed in ``/opt`` does on a real hub. With
    ``open_to_all`` False, the venv is made over this Python when no other will do (a venv of its own, for packages
    installed over ``python``'s, but for this user only).

    Raises:
        FileNotFoundError: If no interpreter of that version can be run by every account.
    """
    import sysconfig

    if not force and _open_to_all(Path(python)) and _open_to_all(Path(sysconfig.get_paths()["stdlib"])):
        return python
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    base = next((c for c in (f"/usr/bin/python{version}", f"/usr/local/bin/python{version}", sys.executable)
                 if _open_to_all(Path(c))), None if open_to_all else sys.executable)
    if base is None:
        raise FileNotFoundError(f"no Python {version} that every account can run (/usr/bin/python{version}?)")
    subprocess.run([base, "-m", "venv", "--without-pip", str(folder)], check=True, capture_output=True, timeout=120)
    ours = subprocess.run([python, "-c", "import sysconfig; p = sysconfig.get_paths(); print(p['purelib']); "
                                         "print(p['platlib']); print(sysconfig.get_path('scripts'))"],
                          capture_output=True, text=True, check=True, timeout=60).stdout.split()
    site = subprocess.run([str(folder / "bin" / "python"), "-c", "import sysconfig; print(sysconfig.get_paths()"
                                                                  "['purelib'])"],
                          capture_output=True, text=True, check=True, timeout=60).stdout.strip()
    lines = "".join(f"import site; site.addsitedir({d!r})\n" for d in dict.fromkeys(ours[:2]))
    (Path(site) / "zz_rrbot_workshop_environment.pth").write_text(lines)
    proxy = Path(ours[2]) / "configurable-http-proxy"
    if proxy.exists():
        (folder / "bin" / "configurable-http-proxy").symlink_to(proxy)
    # the environment's kernel spec names its own (private) Python: this venv's comes first on JUPYTER_PATH
    kernel = folder / "share" / "jupyter" / "kernels" / "python3"
    kernel.mkdir(parents=True)
    (kernel / "kernel.json").write_text(json.dumps({
        "argv": [str(folder / "bin" / "python"), "-Xfrozen_modules=off", "-m", "ipykernel_launcher", "-f",
                 "{connection_file}"], "display_name": "Python 3 (rrbot_workshop)", "language": "python"}))
    (folder / "environment.json").write_text(json.dumps({"prefix": str(Path(ours[2]).parent)}))
    folder.chmod(0o755)
    return str(folder / "bin" / "python")


def _jupyter_environment(python: str) -> dict[str, str]:
    """For a :func:`portable_python` venv: where Jupyter finds the data and config of the environment it adds
    (JupyterLab's files, the server extensions enabled there); nothing for any other Python."""
    marker = Path(python).parent.parent / "environment.json"
    if not marker.is_file():
        return {}
    prefix = json.loads(marker.read_text())["prefix"]
    return {"JUPYTER_PATH": f"{marker.parent}/share/jupyter{os.pathsep}{prefix}/share/jupyter",
            "JUPYTER_CONFIG_PATH": f"{prefix}/etc/jupyter",
            "JUPYTERLAB_DIR": f"{prefix}/share/jupyter/lab"}


@dataclass
class LearnerRun:
    """What one learner did and how long it took.

    Attributes:
        name: The learner.
        login_s: Seconds to get their token from the hub.
        server_s: Seconds from asking for their server to its answering.
        cell_s: Seconds of each executed cell.
        first_result_s: Seconds from login to the graded result of task 2.
        score: Points of task 2 (from their attempt log), and the maximum.
        errors: Cells that raised, with their error.
        token: The learner's API token (valid while the room runs).
        server_status: The hub's answer to their asking for the server (201 started, 202 starting, 400 running
            already: a warmed room).
    """

    name: str
    login_s: float = 0.0
    server_s: float = 0.0
    cell_s: list[float] = field(default_factory=list)
    first_result_s: float = 0.0
    score: tuple[float, float] = (0.0, 0.0)
    errors: list[str] = field(default_factory=list)
    token: str = ""
    server_status: int = 0


class Room:
    """JupyterHub for a room of learners, on 127.0.0.1, in ``folder``.

    Args:
        folder: Where the hub keeps its database, its log, the live view's results and (without ``unix_users``) the
            learners' homes (``home/<name>``). With ``unix_users`` every folder above it must be open to others
            (``o+x``), as ``/tmp`` is, for the learners' accounts to reach their homes.
        python: The Python whose JupyterHub runs the hub and the learners' servers (default: this one; with
            ``unix_users``, one every account can run: see :func:`portable_python`).
        timeout: Longest wait for any one step [s].
        unix_users: Give every learner a Unix account of their own (needs root).

    Raises:
        PermissionError: If ``unix_users`` is asked for without root.
    """

    def __init__(self, folder: Path, python: str | None = None, timeout: float = 120.0,
                 unix_users: bool = False) -> None:
        if unix_users and os.geteuid() != 0:
            raise PermissionError("a room with a Unix account per learner must be started as root")
        self.folder = folder
        self.python = python or sys.executable
        self.timeout = timeout
        self.unix_users = unix_users
        self.port, self.hub_port, self.api_port, self.service_port = (free_port() for _ in range(4))
        self.url = f"http://127.0.0.1:{self.port}"
        self.token = secrets.token_hex(24)  # the room's own service (the test's and the benchmark's hands)
        self.room_password = secrets.token_urlsafe(12)
        self.instructor_password = secrets.token_urlsafe(36)
        # accounts of concurrent rooms on one machine must not collide: a prefix of this room's own
        self.prefix = f"rw{secrets.token_hex(2)}-" if unix_users else ""
        self.instructor = f"{self.prefix}instructor"
        self.homes = folder / "home"
        self.accounts: list[str] = []
        self.process: subprocess.Popen[bytes] | None = None
        self.hub = HubAPI(self.url, self.token, timeout=30.0)

    def name(self, learner: str) -> str:
        """The hub's (and, with ``unix_users``, the system's) name for ``learner``."""
        return f"{self.prefix}{learner}"

    # ------------------------------------------------------------------ the hub
    def config(self) -> str:
        """The hub's ``jupyterhub_config.py`` (the passwords come from the hub's environment, not from the file)."""
        bin_dir = Path(self.python).parent
        if self.unix_users:
            spawner = 'c.JupyterHub.spawner_class = "localprocess"'
            args: list[str] = []
        else:
            spawner = (f'c.JupyterHub.spawner_class = "simple"\n'
                       f'c.SimpleLocalProcessSpawner.home_dir_template = {str(self.homes) + "/{username}"!r}')
            args = ["--allow-root"] if os.geteuid() == 0 else []
        service_url = f"http://127.0.0.1:{self.service_port}"
        proxy = [str(bin_dir / "configurable-http-proxy"), "--proxy-timeout", str(int(self.timeout * 1000))]
        environment = {"PATH": f"{bin_dir}{os.pathsep}/usr/bin:/bin", "RRBOT_WORKSHOP_ROOT": "", "MPLBACKEND": "Agg",
                       "RRBOT_WORKSHOP_CLASS_SERVICE": f"{service_url}/services/{SERVICE}/",
                       **_jupyter_environment(self.python)}
        return f"""import os
c = get_config()  # noqa
c.JupyterHub.ip = "127.0.0.1"
c.JupyterHub.port = {self.port}
c.JupyterHub.hub_ip = "127.0.0.1"
c.JupyterHub.hub_port = {self.hub_port}
c.ConfigurableHTTPProxy.api_url = "http://127.0.0.1:{self.api_port}"
# the Python proxy gives up on a server after 20 s unless told (Node's, on a real hub, waits): a room's step limit
c.ConfigurableHTTPProxy.command = {proxy!r}
c.JupyterHub.db_url = "sqlite:///{self.folder / 'hub.sqlite'}"
c.JupyterHub.cookie_secret_file = {str(self.folder / 'cookie_secret')!r}
c.JupyterHub.pid_file = {str(self.folder / 'hub.pid')!r}
c.JupyterHub.authenticator_class = "shared-password"
c.SharedPasswordAuthenticator.user_password = os.environ["RRBOT_ROOM_PASSWORD"]
c.SharedPasswordAuthenticator.admin_password = os.environ["RRBOT_INSTRUCTOR_PASSWORD"]
c.Authenticator.admin_users = {{{self.instructor!r}}}
c.Authenticator.allow_all = True
{spawner}
c.Spawner.ip = "127.0.0.1"
c.Spawner.cmd = [{self.python!r}, "-m", "rrbot_workshop.cli", "singleuser"]
c.Spawner.environment = {environment!r}
c.Spawner.args = {args!r}
c.Spawner.start_timeout = {int(self.timeout)}
c.Spawner.http_timeout = {int(self.timeout)}
c.JupyterHub.services = [
    {{"name": "room", "api_token": os.environ["RRBOT_ROOM_TOKEN"]}},
    {{"name": {SERVICE!r}, "url": "{service_url}", "oauth_no_confirm": True,
      "command": [{self.python!r}, "-m", "rrbot_workshop.cli", "class-service",
                  "--state", {str(self.folder / 'class_results.jsonl')!r}]}},
]
c.JupyterHub.load_roles = [
    {{"name": "room", "services": ["room"],
      "scopes": ["admin:users", "admin:servers", "tokens", "access:servers", "list:users", "admin:groups"]}},
    {{"name": {SERVICE!r}, "services": [{SERVICE!r}],
      "scopes": ["list:users", "read:users", "read:users:activity", "read:servers", "read:groups"]}},
    {{"name": "{SERVICE}-viewers", "groups": ["instructors"], "scopes": ["access:services!service={SERVICE}"]}},
]
c.JupyterHub.cleanup_servers = True
"""

    def start(self) -> None:
        """Start the hub (and its proxy and the live view); return when its API answers."""
        self.folder.mkdir(parents=True, exist_ok=True)
        self.homes.mkdir(exist_ok=True)
        if self.unix_users:
            self.folder.chmod(0o755)
            self.homes.chmod(0o755)
        (self.folder / "jupyterhub_config.py").write_text(self.config())
        log = (self.folder / "hub.log").open("wb")
        env = {k: v for k, v in os.environ.items() if not k.startswith(("JUPYTERHUB_", "RRBOT_WORKSHOP_"))}
        env.update(RRBOT_ROOM_PASSWORD=self.room_password, RRBOT_INSTRUCTOR_PASSWORD=self.instructor_password,
                   RRBOT_ROOM_TOKEN=self.token)
        self.process = subprocess.Popen(
            [self.python, "-m", "jupyterhub", "-f", str(self.folder / "jupyterhub_config.py")],
            cwd=self.folder, stdout=log, stderr=subprocess.STDOUT, env=env, start_new_session=True)
        self._wait(lambda: self.hub.request("GET", "")[0] == 200, "the hub's API")

    def version(self) -> str:
        """The hub's JupyterHub version."""
        return str((self.hub.request("GET", "")[1] or {}).get("version", ""))

    def log(self) -> str:
        """The hub's log so far (the learners' servers and the live view write to it too)."""
        return (self.folder / "hub.log").read_text(errors="replace")

    def api(self, method: str, path: str, body: Any = None, token: str | None = None) -> tuple[int, Any]:
        """A request through the hub's proxy (``/hub/...``, ``/user/...``, ``/services/...``); ``(status, JSON or
        None)``."""
        return json_request(self.url + path, method, body, token or self.token, 30.0)

    def _wait(self, ready: Any, what: str) -> None:
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.process is not None and self.process.poll() is not None:
                raise RuntimeError(f"the hub exited while waiting for {what}; see {self.folder / 'hub.log'}")
            if ready():
                return
            time.sleep(0.2)
        raise TimeoutError(f"{what} did not answer within {self.timeout:g} s; see {self.folder / 'hub.log'}")

    # ------------------------------------------------------------------ accounts
    def add_account(self, name: str) -> None:
        """With ``unix_users``: the learner's Unix account, its home private (0700) in the room's ``home/``."""
        if not self.unix_users or name in self.accounts:
            return
        home = self.homes / name
        subprocess.run(["useradd", "--home-dir", str(home), "--create-home", "--shell", "/bin/bash", "--user-group",
                        name], check=True, capture_output=True, timeout=60)
        self.accounts.append(name)
        home.chmod(0o700)

    def give(self, name: str, path: Path) -> None:
        """Make the learner ``name`` the owner of ``path`` and everything in it (files put there for them)."""
        if not self.unix_users:
            return
        account = pwd.getpwnam(name)
        for item in [path, *path.rglob("*")]:
            os.lchown(item, account.pw_uid, account.pw_gid)

    def _remove_accounts(self) -> None:
        for name in self.accounts:
            uid = pwd.getpwnam(name).pw_uid
            for pid in _pids_of(uid):  # what the room started as that learner, by process id
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError:
                    pass
            subprocess.run(["userdel", "--remove", name], capture_output=True, timeout=60, check=False)
            subprocess.run(["groupdel", name], capture_output=True, timeout=60, check=False)
        self.accounts.clear()

    # ------------------------------------------------------------------ a learner
    def login(self, name: str) -> str:
        """Create the learner (and their account) and a token of theirs through the REST API; the token."""
        self.add_account(name)
        status, _ = self.hub.request("POST", f"users/{name}")
        if status not in (201, 409):
            raise RuntimeError(f"creating user {name}: HTTP {status}")
        status, token = self.hub.request("POST", f"users/{name}/tokens", {"note": "room test"})
        if status != 201 or not token:
            raise RuntimeError(f"a token for {name}: HTTP {status}")
        return str(token["token"])

    def login_form(self, name: str, password: str) -> urllib.request.OpenerDirector | None:
        """Log in as a browser does (the hub's form, its XSRF token, cookies); an opener that carries the session,
        or None if the hub refused the password."""
        jar = http.cookiejar.CookieJar()
        opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(jar))
        with opener.open(f"{self.url}/hub/login", timeout=30) as page:
            match = re.search(r'name="_xsrf"\s+value="([^"]+)"', page.read().decode())
        form = {"username": name, "password": password, **({"_xsrf": match.group(1)} if match else {})}
        try:
            with opener.open(f"{self.url}/hub/login?next=%2Fhub%2Fhome",
                             urllib.parse.urlencode(form).encode(), timeout=30) as answer:
                answer.read()
        except urllib.error.HTTPError as exc:
            if exc.code == 403:
                return None
            raise
        return opener if any(c.name.startswith("jupyterhub-session") for c in jar) else None

    def start_server(self, name: str, token: str) -> int:
        """Start the learner's server and wait until it answers; the hub's first answer (400: running already)."""
        deadline = time.monotonic() + self.timeout
        while True:
            status, _ = self.hub.request("POST", f"users/{name}/server", token=token)
            # 429/503: the hub is busy with other spawns and says to try again, as a learner's browser would
            if status not in (0, 429, 503) or time.monotonic() > deadline:
                break
            time.sleep(1.0)
        if status not in (201, 202, 400):
            raise RuntimeError(f"starting {name}'s server: HTTP {status}")
        self._wait(lambda: self.api("GET", f"/user/{name}/api/status", token=token)[0] == 200, f"{name}'s server")
        return status

    def learner_session(self, name: str, notebook: str = "my_notebooks/02_mock_hardware.ipynb",
                        prepare: Any = None, observe: Any = None) -> LearnerRun:
        """What a learner does: log in, start the server, run ``notebook``'s code cells in a kernel (the last one
        grades the task), read the score from their attempt log.

        Args:
            name: The learner (the hub's name: see :meth:`name`).
            notebook: The notebook to run, relative to the workspace.
            prepare: Called with the learner's workspace once it exists (e.g. to put a solved exercise there); what
                it writes is given to the learner.
            observe: Called with ``"login"`` as the learner logs in and ``"result"`` when their grade is in (the
                benchmark measures the learner's processes then).
        """
        run = LearnerRun(name)
        if observe is not None:
            observe("login")
        start = time.monotonic()
        run.token = token = self.login(name)
        run.login_s = time.monotonic() - start
        begin = time.monotonic()
        run.server_status = self.start_server(name, token)
        run.server_s = time.monotonic() - begin
        workspace = self.homes / name / "rrbot_workshop"
        if prepare is not None:
            prepare(workspace)
            self.give(name, workspace)
        cells = [c for c in json.loads((workspace / notebook).read_text())["cells"] if c["cell_type"] == "code"]
        kernel = self.kernel(name, token, notebook)
        url = f"ws://127.0.0.1:{self.port}/user/{name}/api/kernels/{kernel}/channels"
        run.cell_s, run.errors = run_cells(url, token, ["".join(c["source"]) for c in cells], self.timeout)
        run.first_result_s = time.monotonic() - start
        if observe is not None:
            observe("result")
        log = workspace / "exercises" / ".progress" / "task02.json"
        if log.is_file():
            last = json.loads(log.read_text())["attempts"][-1]
            run.score = (float(last["score"]), float(last["max_score"]))
        return run

    def kernel(self, name: str, token: str, notebook: str) -> str:
        """A kernel for ``notebook`` in the learner's server (a session, as JupyterLab opens one); its id."""
        status, session = self.api("POST", f"/user/{name}/api/sessions", {
            "path": notebook, "type": "notebook", "name": Path(notebook).name, "kernel": {"name": "python3"}},
            token=token)
        if status != 201 or not session:
            raise RuntimeError(f"{name}: a kernel for {notebook}: HTTP {status}")
        return str(session["kernel"]["id"])

    def run_code(self, name: str, token: str, kernel: str, code: str) -> list[str]:
        """Run ``code`` in one of the learner's kernels; the errors it raised."""
        url = f"ws://127.0.0.1:{self.port}/user/{name}/api/kernels/{kernel}/channels"
        return run_cells(url, token, [code], self.timeout)[1]

    # ------------------------------------------------------------------ the end
    def stop(self) -> list[str]:
        """Stop every server, the hub, the proxy and the live view, remove the accounts; the commands of any
        process of the room that was left running (and is killed now)."""
        if self.process is not None and self.process.poll() is None:
            # the hub stops every server (cleanup_servers), its services and its proxy when it ends
            os.killpg(self.process.pid, signal.SIGTERM)
            try:  # each server gets the spawner's interrupt, then terminate, timeouts (10 s + 5 s) and more on a busy machine
                self.process.wait(timeout=STOP_WAIT)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
        # servers and kernels told to stop may still be ending (closing kernels, writing files): wait a while
        deadline = time.monotonic() + ENDING_WAIT
        while self.processes() and time.monotonic() < deadline:
            time.sleep(0.2)
        left = self._leftovers()
        self._remove_accounts()
        return left

    def processes(self) -> dict[int, str]:
        """This room's processes (the hub, its proxy, servers, kernels, the live view): pid -> command line."""
        marks = (str(self.folder), f":{self.api_port}", f"--port={self.port}")
        uids = {pwd.getpwnam(n).pw_uid for n in self.accounts}
        found = {}
        for proc in Path("/proc").glob("[0-9]*"):
            try:
                cmdline = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
                mine = proc.stat().st_uid in uids
            except OSError:
                continue
            # (an empty command line: a process that has ended and waits for its parent; nothing left to stop)
            if cmdline and int(proc.name) != os.getpid() and (mine or any(m in cmdline for m in marks)):
                found[int(proc.name)] = cmdline
        return found

    def _leftovers(self) -> list[str]:
        """This room's processes still running, killed; their command lines."""
        found = self.processes()
        for pid in found:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        return list(found.values())

    def remove(self) -> None:
        """Delete the room's folder."""
        shutil.rmtree(self.folder, ignore_errors=True)


def _pids_of(uid: int) -> list[int]:
    """The processes running as ``uid`` (Linux /proc)."""
    pids = []
    for proc in Path("/proc").glob("[0-9]*"):
        try:
            if proc.stat().st_uid == uid:
                pids.append(int(proc.name))
        except OSError:
            continue
    return pids


def run_cells(url: str, token: str, sources: list[str], timeout: float) -> tuple[list[float], list[str]]:
    """Execute each source in the kernel behind the websocket ``url`` (Jupyter's kernel protocol, JSON over a
    websocket); the seconds each took, and the errors of cells that raised."""
    import websocket  # websocket-client

    ws = websocket.create_connection(url, header=[f"Authorization: token {token}"], timeout=timeout)
    session = uuid.uuid4().hex
    times, errors = [], []
    try:
        for source in sources:
            msg_id = uuid.uuid4().hex
            ws.send(json.dumps({
                "header": {"msg_id": msg_id, "msg_type": "execute_request", "session": session, "username": "",
                           "version": "5.3", "date": ""},
                "parent_header": {}, "metadata": {}, "channel": "shell", "buffers": [],
                "content": {"code": source, "silent": False, "store_history": True, "user_expressions": {},
                            "allow_stdin": False, "stop_on_error": True},
            }))
            begin = time.monotonic()
            while True:
                message = json.loads(ws.recv())
                if message.get("parent_header", {}).get("msg_id") != msg_id:
                    continue
                if message["header"]["msg_type"] == "execute_reply" and message.get("channel") == "shell":
                    # the reply says whether the cell raised (its iopub "error" may come before or after it)
                    content = message["content"]
                    if content.get("status") == "error":
                        errors.append(f"{content.get('ename')}: {content.get('evalue')}")
                    break
            times.append(time.monotonic() - begin)
    finally:
        ws.close()
    return times, errors
