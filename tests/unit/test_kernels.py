"""Notebook kernels forked from the server's template process (Linux only).

Kernels are started the way a Jupyter server starts them: jupyter_client's ``KernelManager`` with the provisioner the
server is given (:func:`rrbot_workshop.classroom.kernels.server_args`), spoken to over Jupyter's protocol. The last
test starts a real Jupyter server with those arguments.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from rrbot_workshop.classroom import kernels

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="kernels are forked on Linux only")

FLAGS = ["-Xfrozen_modules=off"]  # ipykernel's own kernel's Python options


class Kernel:
    """A kernel started as a server starts one, and a client to it."""

    def __init__(self, cwd: Path, env: dict[str, str] | None = None,
                 provisioner: str = kernels.PROVISIONER_NAME, **start: Any) -> None:
        from jupyter_client import KernelManager
        from jupyter_client.provisioning import KernelProvisionerFactory

        factory = KernelProvisionerFactory.instance()  # the provisioner is chosen when the kernel starts
        default, factory.default_provisioner_name = factory.default_provisioner_name, provisioner
        try:
            self.manager = KernelManager(kernel_name="python3")
            self.manager.start_kernel(cwd=str(cwd), env={**os.environ, **(env or {})}, **start)
        finally:
            factory.default_provisioner_name = default
        self.client = self.manager.client()
        self.client.start_channels()
        self.client.wait_for_ready(timeout=60)

    @property
    def forked(self) -> bool:
        return type(self.manager.provisioner.process).__name__ == "_ForkedKernel"

    @property
    def pid(self) -> int:
        return int(self.manager.provisioner.process.pid)

    def value(self, expression: str, setup: str = "", timeout: float = 60.0) -> Any:
        reply = self.client.execute_interactive(setup, user_expressions={"v": f"__import__('json').dumps({expression})"},
                                                timeout=timeout, output_hook=lambda message: None)
        assert reply["content"]["status"] == "ok", reply["content"]
        return json.loads(__import__("ast").literal_eval(reply["content"]["user_expressions"]["v"]["data"]["text/plain"]))

    def outputs(self, code: str) -> list[tuple[str, str, list[str]]]:
        """What running ``code`` sends: each message's type, its stream or its ``data``'s media types."""
        seen: list[dict[str, Any]] = []
        self.client.execute_interactive(code, timeout=60, output_hook=seen.append)
        return [(m["msg_type"], m["content"].get("name", ""), sorted(m["content"].get("data", {})))
                for m in seen if m["msg_type"] not in ("status", "execute_input")]

    def stop(self) -> None:
        self.client.stop_channels()
        self.manager.shutdown_kernel(now=True)


@contextlib.contextmanager
def _own_template(flags: list[str] = FLAGS) -> Iterator[Any]:
    """A template of the test's own, the one the provisioner asks while the block runs (another test, or nbval in the
    same worker, may have started this process's template, for another kernel's options)."""
    handle, kept = kernels._Template(), kernels._TEMPLATE
    kernels._TEMPLATE = handle
    try:
        assert handle.start(flags)
        deadline = time.monotonic() + 120
        while not handle.ready():
            assert time.monotonic() < deadline and handle.started(), "the template did not start"
            time.sleep(0.05)
        yield handle
    finally:
        handle.stop()
        kernels._TEMPLATE = kept


@pytest.fixture(scope="module")
def template() -> Iterator[Any]:
    with _own_template() as handle:
        yield handle


def _wait_gone(pid: int, limit: float = 30.0) -> bool:
    deadline = time.monotonic() + limit
    while kernels._alive(pid):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


def test_a_kernel_is_forked_and_looks_like_one_started_with_python_m(template: Any, tmp_path: Path) -> None:
    kernel = Kernel(tmp_path, {"RRBOT_TEST_VARIABLE": "from the server"})
    try:
        assert kernel.forked
        seen = kernel.value("[os.getcwd(), sys.path[0], os.environ.get('RRBOT_TEST_VARIABLE'), __name__, "
                            "os.getpgid(0) == os.getpid(), int(os.environ['JPY_PARENT_PID']) == os.getppid(), "
                            "sys.argv[1], 'yourdfpy' in sys.modules, os.getpid()]", "import os, sys")
        cwd, _, variable, name, own_group, parent, argv1, preloaded, pid = seen
        assert (cwd, variable, name) == (str(tmp_path), "from the server", "__main__")
        assert own_group and parent and argv1 == "-f" and preloaded and pid == kernel.pid
        assert kernel.value("matplotlib.get_backend()", "import matplotlib.pyplot") == kernels.INLINE_BACKEND
        parent_poller = kernel.value("__import__('ipykernel.kernelapp').kernelapp.IPKernelApp.instance().parent_handle")
        assert parent_poller == kernel.value("os.getppid()")
    finally:
        kernel.stop()


def test_kernels_get_fresh_random_states_and_a_new_process_has_the_same_sys_path(template: Any,
                                                                                   tmp_path: Path) -> None:
    first, second = Kernel(tmp_path), Kernel(tmp_path)
    try:
        draws = [k.value("[float(numpy.random.rand()), random.random()]", "import numpy, random")
                 for k in (first, second)]
        assert draws[0][0] != draws[1][0] and draws[0][1] != draws[1][1]
        path = first.value("sys.path", "import sys")
    finally:
        first.stop()
        second.stop()
    plain = Kernel(tmp_path, provisioner="local-provisioner")  # as Jupyter starts a kernel by itself
    try:
        assert not plain.forked
        assert plain.value("sys.path", "import sys") == path
    finally:
        plain.stop()


CELLS = [  # what notebooks do that a kernel's start decides: figures inline, warnings shown, printed output
    "import matplotlib.pyplot as plt\nplt.plot([1, 2, 3]);",
    "import matplotlib.pyplot as plt\nfig, ax = plt.subplots()\nax.plot([3, 1])\nplt.show()",
    "import warnings\nwarnings.warn('a learner should see this')",
    "print('printed')\n6 * 7",
    "%load_ext rrbot_workshop",
]


def test_a_forked_kernel_sends_what_a_new_process_sends(template: Any, tmp_path: Path) -> None:
    kernels_both = [Kernel(tmp_path), Kernel(tmp_path, provisioner="local-provisioner")]
    try:
        assert [k.forked for k in kernels_both] == [True, False]
        forked, plain = ([k.outputs(cell) for cell in CELLS] for k in kernels_both)
        assert ("display_data", "", ["image/png", "text/plain"]) in forked[0], forked[0]
        assert forked == plain
    finally:
        for kernel in kernels_both:
            kernel.stop()


def test_interrupt_restart_and_shutdown_reach_the_forked_kernel(template: Any, tmp_path: Path) -> None:
    kernel = Kernel(tmp_path)
    try:
        kernel.client.execute("import time\ntime.sleep(60)")
        time.sleep(1.0)
        kernel.manager.interrupt_kernel()
        deadline = time.monotonic() + 30
        while True:
            message = kernel.client.get_shell_msg(timeout=30)
            if message["msg_type"] == "execute_reply":
                break
            assert time.monotonic() < deadline
        assert message["content"]["ename"] == "KeyboardInterrupt"
        first = kernel.pid
        kernel.manager.restart_kernel(now=False)
        kernel.client.wait_for_ready(timeout=60)
        assert kernel.forked and kernel.pid != first and _wait_gone(first)
        assert kernel.value("6 * 7") == 42
    finally:
        last = kernel.pid
        kernel.stop()
    assert _wait_gone(last)


def test_the_kernels_output_streams_given_as_to_popen_are_its_own(template: Any, tmp_path: Path) -> None:
    """nbval, for one, starts its kernels with ``stderr=open(os.devnull, "w")``."""
    errors = tmp_path / "errors.txt"
    with errors.open("w") as stream:
        kernel = Kernel(tmp_path, stderr=stream)
    try:
        assert kernel.forked
        kernel.value("os.write(2, b'to the stream given\\n')", "import os")
    finally:
        kernel.stop()
    assert "to the stream given" in errors.read_text()


def test_a_kernel_that_exits_is_seen_to_have_exited_with_its_status(template: Any, tmp_path: Path) -> None:
    kernel = Kernel(tmp_path)
    process = kernel.manager.provisioner.process
    kernel.client.execute("import os\nos._exit(3)")
    assert process.wait(timeout=30) == 3
    assert kernel.manager.provisioner.process is process and process.poll() == 3
    kernel.stop()


def test_a_kernel_whose_startup_environment_differs_is_started_as_a_new_process(template: Any,
                                                                                 tmp_path: Path) -> None:
    kernel = Kernel(tmp_path, {"PYTHONPATH": str(tmp_path)})
    try:
        assert not kernel.forked
        assert str(tmp_path) in kernel.value("sys.path", "import sys")
    finally:
        kernel.stop()
    template_socket = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    template_socket.connect(template.address)
    template_socket.sendall(b'{"cmd": ["/bin/sh", "-c", "echo"], "env": {}, "cwd": "/"}\n')
    answer = json.loads(template_socket.makefile().readline())
    template_socket.close()
    assert "pid" not in answer and "is not" in answer["refused"]


def test_a_changed_preloaded_file_retires_the_template_after_its_kernels(tmp_path: Path) -> None:
    """A file the template imported changes (``git pull`` of the library): the next kernel is a new process, the old
    template ends once its kernels have, and a new one serves the kernels after."""
    site = tmp_path / "site"
    site.mkdir()
    module = site / "sitecustomize.py"  # imported at Python's start, so the template has read it
    module.write_text("VALUE = 1\n")
    env = {"PYTHONPATH": str(site)}
    saved = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        with _own_template() as handle:
            first_template = handle._process
            early = Kernel(tmp_path)
            assert early.forked and early.value("sitecustomize.VALUE", "import sitecustomize") == 1
            module.write_text("VALUE = 2\n")
            late = Kernel(tmp_path)
            assert not late.forked and late.value("sitecustomize.VALUE", "import sitecustomize") == 2
            assert early.value("6 * 7") == 42  # the retired template still keeps its kernel
            assert first_template is not None and first_template.poll() is None
            early.stop()
            late.stop()
            first_template.wait(timeout=30)  # ...and ends after it
            deadline = time.monotonic() + 120
            while not handle.ready():
                assert time.monotonic() < deadline
                time.sleep(0.05)
            newest = Kernel(tmp_path)
            assert newest.forked and newest.value("sitecustomize.VALUE", "import sitecustomize") == 2
            newest.stop()
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def test_kernels_end_when_the_template_ends(tmp_path: Path) -> None:
    with _own_template() as handle:
        kernel = Kernel(tmp_path)
        assert kernel.forked
        pid = kernel.pid
        handle.stop()  # as when the server ends
        assert _wait_gone(pid)
        assert kernel.manager.provisioner.process.poll() is not None
        kernel.client.stop_channels()


def _children(pid: int) -> list[int]:
    try:
        return [int(p) for p in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="reads the process tree from /proc")
def test_a_jupyter_server_started_with_the_courses_arguments_forks_its_kernels_and_restarts_them_on_new_ports(
        tmp_path: Path) -> None:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    token = "rrbot-kernels-test"
    server = subprocess.Popen(
        [sys.executable, "-m", "jupyter_server", "--ip=127.0.0.1", f"--port={port}", "--no-browser", "--allow-root",
         f"--IdentityProvider.token={token}", f"--ServerApp.root_dir={tmp_path}", *kernels.server_args()],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env={**os.environ, "JUPYTER_RUNTIME_DIR": str(tmp_path)})
    url = f"http://127.0.0.1:{port}/api/kernels"
    headers = {"Authorization": f"token {token}"}
    try:
        deadline = time.monotonic() + 120
        template_pid = None
        while template_pid is None:
            assert server.poll() is None and time.monotonic() < deadline, "the server or its template did not start"
            for child in _children(server.pid):
                command = Path(f"/proc/{child}/cmdline").read_bytes().decode().split("\0")
                if kernels.TEMPLATE_MODULE in command:  # ready once its socket is there
                    address = command[command.index(kernels.TEMPLATE_MODULE) + 1]
                    template_pid = child if Path(address).exists() else None
            time.sleep(0.2)
        request = urllib.request.Request(url, data=b"{}", headers=headers, method="POST")
        kernel_id = json.load(urllib.request.urlopen(request, timeout=60))["id"]
        kernel_pids = _children(template_pid)
        assert len(kernel_pids) == 1, "the kernel is not the template's child"
        # another server's kernel takes this kernel's port as it dies (a room's port race): it comes back on new ports
        connection = tmp_path / f"kernel-{kernel_id}.json"
        shell_port = json.loads(connection.read_text())["shell_port"]
        with socket.socket() as taken:
            os.kill(kernel_pids[0], signal.SIGKILL)
            assert _wait_gone(kernel_pids[0])
            taken.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            taken.bind(("127.0.0.1", shell_port))
            taken.listen()
            deadline = time.monotonic() + 120
            while not (_children(template_pid) and connection.is_file()
                       and json.loads(connection.read_text())["shell_port"] != shell_port):
                assert time.monotonic() < deadline, "the kernel did not come back on new ports"
                time.sleep(0.2)
            time.sleep(5.0)  # past the restarter's next check: the new kernel stays up
            state = json.load(urllib.request.urlopen(urllib.request.Request(f"{url}/{kernel_id}", headers=headers),
                                                     timeout=60))["execution_state"]
            assert state in ("idle", "busy", "starting"), state
            kernel_pids = _children(template_pid)
            assert len(kernel_pids) == 1
        urllib.request.urlopen(urllib.request.Request(f"{url}/{kernel_id}", headers=headers, method="DELETE"),
                               timeout=60)
        assert _wait_gone(kernel_pids[0])
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
    assert template_pid is not None and _wait_gone(template_pid)


def test_the_same_python_is_the_same_interpreter_in_the_same_folder_even_through_a_link(tmp_path: Path) -> None:
    executable = os.path.abspath(sys.executable)
    linked_folder = tmp_path / "linked_bin"
    linked_folder.symlink_to(Path(executable).parent)  # a clone's .venv linked to the course's
    other_env = tmp_path / "other_env" / "bin"
    other_env.mkdir(parents=True)
    (other_env / "python").symlink_to(os.path.realpath(executable))  # another environment on the same interpreter
    assert kernels._same_python(str(linked_folder / Path(executable).name), executable)
    assert not kernels._same_python(str(other_env / "python"), executable)
    assert not kernels._same_python(str(tmp_path / "missing" / "python"), executable)
