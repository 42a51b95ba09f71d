"""A workshop room on this machine: JupyterHub on 127.0.0.1 with learners who work through a notebook and grade.

Used by the room test (3 learners) and ``benchmarks/bench_room.py`` (10 and 30). :class:`Room` starts JupyterHub
(its proxy, the local-process spawner, the test authenticator, all on loopback) in a folder of its own, with every
learner's home inside it; each learner's server is ``rrbot-workshop singleuser``, so their workspace is made on first
start, as in a real room. :meth:`Room.learner_session` then does what a learner does: logs in through the hub's REST
API (a token of their own), starts their server, opens notebook 02 in a kernel and runs its cells through the kernel
protocol, the last of which grades task 2. :meth:`Room.stop` stops the hub, the proxy and every server, and checks
that no process of the room is left.

Nothing here listens on anything but 127.0.0.1, and every wait is bounded in time.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["Room", "LearnerRun", "free_port", "run_cells"]


def free_port() -> int:
    """A TCP port free on 127.0.0.1 now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


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
    """

    name: str
    login_s: float = 0.0
    server_s: float = 0.0
    cell_s: list[float] = field(default_factory=list)
    first_result_s: float = 0.0
    score: tuple[float, float] = (0.0, 0.0)
    errors: list[str] = field(default_factory=list)


class Room:
    """JupyterHub for a room of learners, on 127.0.0.1, in ``folder``.

    Args:
        folder: Where the hub keeps its database, its log and the learners' homes (``home/<name>``).
        python: The environment whose JupyterHub and course are used (default: this one).
        timeout: Longest wait for any one step [s].
    """

    def __init__(self, folder: Path, python: str | None = None, timeout: float = 120.0) -> None:
        self.folder = folder
        self.python = python or sys.executable
        self.timeout = timeout
        self.port, self.hub_port, self.api_port = free_port(), free_port(), free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.token = secrets.token_hex(24)
        self.homes = folder / "home"
        self.process: subprocess.Popen[bytes] | None = None

    # ------------------------------------------------------------------ the hub
    def config(self) -> str:
        """The hub's ``jupyterhub_config.py``."""
        bin_dir = Path(self.python).parent
        return f"""
c = get_config()  # noqa
c.JupyterHub.ip = "127.0.0.1"
c.JupyterHub.port = {self.port}
c.JupyterHub.hub_ip = "127.0.0.1"
c.JupyterHub.hub_port = {self.hub_port}
c.ConfigurableHTTPProxy.api_url = "http://127.0.0.1:{self.api_port}"
c.ConfigurableHTTPProxy.command = [{str(bin_dir / 'configurable-http-proxy')!r}]
c.JupyterHub.db_url = "sqlite:///{self.folder / 'hub.sqlite'}"
c.JupyterHub.cookie_secret_file = {str(self.folder / 'cookie_secret')!r}
c.JupyterHub.pid_file = {str(self.folder / 'hub.pid')!r}
c.JupyterHub.authenticator_class = "dummy"
c.Authenticator.allow_all = True
c.JupyterHub.spawner_class = "simple"
c.SimpleLocalProcessSpawner.home_dir_template = {str(self.homes) + '/{username}'!r}
c.Spawner.ip = "127.0.0.1"
c.Spawner.cmd = [{self.python!r}, "-m", "rrbot_workshop.cli", "singleuser"]
c.Spawner.environment = {{"PATH": {str(bin_dir) + os.pathsep + '/usr/bin:/bin'!r},
                          "RRBOT_WORKSHOP_ROOT": "", "MPLBACKEND": "Agg"}}
c.Spawner.args = {["--allow-root"] if hasattr(os, "geteuid") and os.geteuid() == 0 else []!r}
c.Spawner.start_timeout = {int(self.timeout)}
c.Spawner.http_timeout = {int(self.timeout)}
c.JupyterHub.services = [{{"name": "instructor", "api_token": {self.token!r}}}]
c.JupyterHub.load_roles = [{{"name": "instructor", "services": ["instructor"],
                            "scopes": ["admin:users", "admin:servers", "tokens", "access:servers"]}}]
c.JupyterHub.cleanup_servers = True
"""

    def start(self) -> None:
        """Start the hub (and its proxy); return when its API answers."""
        self.folder.mkdir(parents=True, exist_ok=True)
        self.homes.mkdir(exist_ok=True)
        (self.folder / "jupyterhub_config.py").write_text(self.config())
        log = (self.folder / "hub.log").open("wb")
        env = {k: v for k, v in os.environ.items() if not k.startswith(("JUPYTERHUB_", "RRBOT_WORKSHOP_"))}
        self.process = subprocess.Popen(
            [self.python, "-m", "jupyterhub", "-f", str(self.folder / "jupyterhub_config.py")],
            cwd=self.folder, stdout=log, stderr=subprocess.STDOUT, env=env, start_new_session=True)
        self._wait(lambda: self.api("GET", "/hub/api/")[0] == 200, "the hub's API")

    def api(self, method: str, path: str, body: Any = None, token: str | None = None) -> tuple[int, Any]:
        """A request to the hub (or through its proxy); ``(status, JSON or None)``."""
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(self.url + path, data=data, method=method,
                                         headers={"Authorization": f"token {token or self.token}",
                                                  "Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=30) as response:
                text = response.read()
                return response.status, json.loads(text) if text else None
        except urllib.error.HTTPError as exc:
            return exc.code, None
        except (urllib.error.URLError, ConnectionError, TimeoutError):
            return 0, None

    def _wait(self, ready: Any, what: str) -> None:
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.process is not None and self.process.poll() is not None:
                raise RuntimeError(f"the hub exited while waiting for {what}; see {self.folder / 'hub.log'}")
            if ready():
                return
            time.sleep(0.2)
        raise TimeoutError(f"{what} did not answer within {self.timeout:g} s; see {self.folder / 'hub.log'}")

    # ------------------------------------------------------------------ a learner
    def login(self, name: str) -> str:
        """Create the learner and a token of theirs through the REST API; the token."""
        status, _ = self.api("POST", f"/hub/api/users/{name}")
        if status not in (201, 409):
            raise RuntimeError(f"creating user {name}: HTTP {status}")
        status, token = self.api("POST", f"/hub/api/users/{name}/tokens", {"note": "room test"})
        if status != 201 or not token:
            raise RuntimeError(f"a token for {name}: HTTP {status}")
        return str(token["token"])

    def start_server(self, name: str, token: str) -> None:
        """Start the learner's server and wait until it answers."""
        deadline = time.monotonic() + self.timeout
        while True:
            status, _ = self.api("POST", f"/hub/api/users/{name}/server", token=token)
            # 429/503: the hub is busy with other spawns and says to try again, as a learner's browser would
            if status not in (0, 429, 503) or time.monotonic() > deadline:
                break
            time.sleep(1.0)
        if status not in (201, 202, 400):
            raise RuntimeError(f"starting {name}'s server: HTTP {status}")
        self._wait(lambda: self.api("GET", f"/user/{name}/api/status", token=token)[0] == 200, f"{name}'s server")

    def learner_session(self, name: str, notebook: str = "my_notebooks/02_mock_hardware.ipynb",
                        prepare: Any = None) -> LearnerRun:
        """What a learner does: log in, start the server, run ``notebook``'s code cells in a kernel (the last one
        grades the task), read the score from their attempt log.

        Args:
            name: The learner.
            notebook: The notebook to run, relative to the workspace.
            prepare: Called with the learner's workspace once it exists (e.g. to put a solved exercise there).
        """
        run = LearnerRun(name)
        start = time.monotonic()
        token = self.login(name)
        run.login_s = time.monotonic() - start
        begin = time.monotonic()
        self.start_server(name, token)
        run.server_s = time.monotonic() - begin
        workspace = self.homes / name / "rrbot_workshop"
        if prepare is not None:
            prepare(workspace)
        cells = [c for c in json.loads((workspace / notebook).read_text())["cells"] if c["cell_type"] == "code"]
        status, session = self.api("POST", f"/user/{name}/api/sessions", {
            "path": notebook, "type": "notebook", "name": Path(notebook).name, "kernel": {"name": "python3"}},
            token=token)
        if status != 201 or not session:
            raise RuntimeError(f"{name}: a kernel for {notebook}: HTTP {status}")
        kernel = session["kernel"]["id"]
        url = f"ws://127.0.0.1:{self.port}/user/{name}/api/kernels/{kernel}/channels"
        run.cell_s, run.errors = run_cells(url, token, ["".join(c["source"]) for c in cells], self.timeout)
        run.first_result_s = time.monotonic() - start
        log = workspace / "exercises" / ".progress" / "task02.json"
        if log.is_file():
            last = json.loads(log.read_text())["attempts"][-1]
            run.score = (float(last["score"]), float(last["max_score"]))
        return run

    # ------------------------------------------------------------------ the end
    def stop(self) -> list[str]:
        """Stop every server, the hub and the proxy; the commands of any process of the room left running."""
        if self.process is not None and self.process.poll() is None:
            status, users = self.api("GET", "/hub/api/users")
            for user in users or []:
                if user.get("server"):
                    self.api("DELETE", f"/hub/api/users/{user['name']}/server")
            os.killpg(self.process.pid, signal.SIGTERM)
            try:
                self.process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
        return self._leftovers()

    def processes(self) -> dict[int, str]:
        """This room's processes (the hub, its proxy, servers, kernels): pid -> command line (Linux /proc)."""
        marks = (str(self.folder), f":{self.api_port}", f"--port={self.port}")
        found = {}
        for proc in Path("/proc").glob("[0-9]*"):
            try:
                cmdline = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
            except OSError:
                continue
            if int(proc.name) != os.getpid() and any(m in cmdline for m in marks):
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
                kind = message["header"]["msg_type"]
                if kind == "error":
                    errors.append(f"{message['content']['ename']}: {message['content']['evalue']}")
                if kind == "execute_reply" and message.get("channel") == "shell":
                    break
            times.append(time.monotonic() - begin)
    finally:
        ws.close()
    return times, errors
