"""Notebook kernels forked from a warm process: the template process and the server's handle on it.

A learner's first minute on a hub goes largely to new Python processes importing things: the kernel's own start (ipykernel,
IPython, zmq), then notebook 02's imports (numpy, the library, xacro, lxml, matplotlib) and the 3D viewer's
kinematics (yourdfpy imports trimesh, and trimesh much of scipy and networkx). Measured with
``benchmarks/bench_room.py``, that was about 2 of the 5.35 CPU-seconds from a learner's login to their first graded
result (the difference this module makes), and 30 learners paid it in the same minute.

So a learner's Jupyter server (on a hub, and ``./workshop start`` on Linux) starts a *template* beside itself when it
starts, before anybody opens a notebook: a Python that imports :data:`KERNEL_PRELOAD` once and waits on a socket in a
folder only its user can enter. The server's kernels are started by
:class:`~rrbot_workshop.classroom.kernel_provisioner.ForkingProvisioner` (the server's
``KernelProvisionerFactory.default_provisioner_name``, see :func:`server_args`): the template forks a child that
becomes ``python -m ipykernel_launcher -f CONNECTION_FILE`` as the server would have started it, with the kernel's
command, working folder and environment, in a session of its own (an interrupt reaches the kernel's process group as
before). The child runs the launcher module as ``__main__`` with ``runpy``, as ``-m`` does, and at the end waits for
its threads and runs the ``atexit`` handlers, as an interpreter's exit does.

What a kernel can tell: its parent is the template, not the server (``JPY_PARENT_PID`` names the template, so the
kernel ends when the template does, and the template ends with the server); ``ps`` shows the template's command line
for it; the preloaded modules are in ``sys.modules`` already; and all kernels share the template's ``str`` hash seed.
numpy's global random state, matplotlib's backend and Python's ``random`` are set afresh in each kernel, as a new
process has them, and ipykernel's application module runs again in each (:data:`FRESH`). Before each kernel the
template compares the file of every module it holds with what it read; when one changed (``git pull``, a ``pip
install``) the kernel starts as a new process, the template takes no more and ends after its last kernel, and a new
template starts for the next ones.

Linux only. A kernel is started the usual way (jupyter_client's ``LocalProvisioner``) on other systems, while the
template is still importing after :data:`READY_WAIT`, when the command is not ``python [OPTIONS] -m MODULE ...`` of
the template's own Python and options, when an environment variable that Python or numpy read at start differs from
the template's (:data:`STARTUP_VARIABLES`, ``PYTHON*``), or with ``RRBOT_WORKSHOP_KERNEL_FORK=0``.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import warnings
from pathlib import Path
from typing import Any

__all__ = ["KERNEL_PRELOAD", "FORK_ENV", "PROVISIONER_NAME", "EXTENSION", "server_args", "template", "kernel_flags",
           "enabled"]

logger = logging.getLogger(__name__)

#: What the template imports once: the kernel's own machinery, then what the notebooks' first cells and the 3D
#: viewer import (each that imports; matplotlib with the backend a kernel sets, see :func:`_as_new_process`). Not the
#: inline backend's module: imported outside an IPython session, it would leave a kernel's figures undisplayed.
KERNEL_PRELOAD = (
    "ipykernel.kernelapp", "ipykernel.ipkernel", "ipykernel.zmqshell", "ipykernel.debugger", "IPython",
    "numpy", "yaml", "lxml.etree", "xacro", "rrbot_workshop", "rrbot_workshop.course.magics", "rrbot_workshop.bringup",
    "rrbot_workshop.controllers", "rrbot_workshop.hardware", "rrbot_workshop.description", "rrbot_workshop.viz",
    "yourdfpy", "trimesh", "meshcat", "matplotlib", "matplotlib.pyplot",
    "ipywidgets",
)
#: Preloaded for what they import, then forgotten: their classes read the environment when the module runs (ipykernel's
#: ``JPY_PARENT_PID``), so each kernel runs them again, in its own environment.
FRESH = ("ipykernel.kernelapp", "ipykernel.embed")
#: Set to ``0`` to start every kernel as a new process.
FORK_ENV = "RRBOT_WORKSHOP_KERNEL_FORK"
#: The provisioner's entry point (group ``jupyter_client.kernel_provisioners`` in pyproject.toml).
PROVISIONER_NAME = "rrbot-workshop-forked"
#: The server extension that starts the template with the server (beside the provisioner).
EXTENSION = "rrbot_workshop.classroom.kernel_provisioner"
#: The template's own module (this one), run as ``python -m``.
TEMPLATE_MODULE = "rrbot_workshop.classroom.kernels"
#: The backend ipykernel gives matplotlib when the environment names none.
INLINE_BACKEND = "module://matplotlib_inline.backend_inline"
#: How long a kernel asked for while the template still imports waits for it [s]; it would spend the same time importing
#: the same modules as a new process, so it waits, up to this limit, and then starts as one.
READY_WAIT = 60.0
#: Environment variables read when Python or a preloaded module starts: a kernel whose values differ is not forked.
STARTUP_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "LD_PRELOAD", "LD_LIBRARY_PATH",
                     "VIRTUAL_ENV", "MPLCONFIGDIR")


def server_args() -> list[str]:
    """The Jupyter server's arguments that start the template with the server and fork kernels from it.

    And one for a room, where 30 servers on one host pick their kernels' ports at the same minute: a server picks a
    free port and its kernel binds it a moment later, so another server may pick the same one in between (measured:
    one kernel in two 30-learner rooms). With jupyter_client's default, a kernel restarts on the ports it was given
    first and fails again, five times, for good; ``cache_ports=False`` lets its restarter take new ports, as it says.
    """
    return [f"--ServerApp.jpserver_extensions={EXTENSION}=True",
            f"--KernelProvisionerFactory.default_provisioner_name={PROVISIONER_NAME}",
            "--KernelManager.cache_ports=False"]


def kernel_flags(argv: list[str]) -> list[str] | None:
    """Python's options in a kernel's command ``PYTHON [OPTIONS] -m MODULE ...`` (ipykernel's own kernel passes
    ``-Xfrozen_modules=off``); ``None`` when the command has no ``-m``."""
    if "-m" not in argv[1:]:
        return None
    return list(argv[1:argv.index("-m", 1)])


def enabled() -> bool:
    """Whether kernels are forked here: on Linux (macOS's system libraries are not safe to use in a forked child, which
    is why Python no longer forks there by default), and not turned off with ``RRBOT_WORKSHOP_KERNEL_FORK=0``."""
    return os.environ.get(FORK_ENV, "1") != "0" and sys.platform == "linux"


# --------------------------------------------------------------------------------------------- the server's side


class _ForkedKernel:
    """What the provisioner holds of a forked kernel, shaped like :class:`subprocess.Popen`: its process id, and the
    template's connection that says how it ended."""

    stdin = stdout = stderr = None

    def __init__(self, pid: int, channel: socket.socket, buffer: bytes = b"") -> None:
        self.pid = pid
        self.returncode: int | None = None
        self._channel: socket.socket | None = channel
        self._buffer = buffer

    def _read(self, timeout: float | None) -> None:
        if self.returncode is not None:
            return
        if self._channel is None:  # the template ended without saying: the kernel ends with it (its parent poller)
            self.returncode = None if _alive(self.pid) else -1
            return
        while b"\n" not in self._buffer:
            self._channel.settimeout(timeout)
            try:
                data = self._channel.recv(4096)
            except (BlockingIOError, TimeoutError):
                return
            except OSError:
                data = b""
            if not data:
                self._channel.close()
                self._channel = None
                self._read(timeout)
                return
            self._buffer += data
        self.returncode = int(json.loads(self._buffer.split(b"\n", 1)[0])["exit"])
        self._channel.close()
        self._channel = None

    def poll(self) -> int | None:
        self._read(0.0)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        self._read(timeout)
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.returncode is None and self._channel is None and (deadline is None or time.monotonic() < deadline):
            time.sleep(0.1)
            self._read(0.0)
        if self.returncode is None:
            raise subprocess.TimeoutExpired(f"kernel {self.pid}", timeout or 0.0)
        return self.returncode

    def send_signal(self, signum: int) -> None:
        if self.poll() is None:
            os.kill(self.pid, signum)

    def terminate(self) -> None:
        self.send_signal(signal.SIGTERM)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (one that ended and was not collected yet, a zombie, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    with contextlib.suppress(OSError, IndexError):
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    return True


class _Template:
    """The server's handle on its template process: started once, in the background; asked for a kernel."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._process: subprocess.Popen[bytes] | None = None
        self._folder: str | None = None
        self._flags: list[str] = []
        self._retired: list[subprocess.Popen[bytes]] = []  # templates that still keep kernels, and end after them

    @property
    def address(self) -> str | None:
        return None if self._folder is None else os.path.join(self._folder, "template.sock")

    def start(self, flags: list[str] | None = None) -> bool:
        """Start the template (once; again when the last one ended), with Python's ``flags`` (those of the kernel's
        command before ``-m``; default the last ones given). Returns whether one is starting or running."""
        if not enabled():
            return False
        with self._lock:
            if self._process is not None and self._process.poll() is None:
                return True
            if flags is not None:
                self._flags = list(flags)
            self._folder = tempfile.mkdtemp(prefix="rrbot_kernels_")  # 0700: only this user reaches the socket
            self._process = subprocess.Popen(  # noqa: S603 - this Python, this module
                [sys.executable, *self._flags, "-m", TEMPLATE_MODULE, self.address or "", json.dumps(self._flags)],
                stdin=subprocess.PIPE, cwd=self._folder)
            return True

    def ready(self) -> bool:
        """Whether the template has imported everything and takes requests."""
        address = self.address
        return (address is not None and self._process is not None and self._process.poll() is None
                and os.path.exists(address))

    def retire(self) -> None:
        """Start no more kernels from this template (it ends by itself after its kernels); a new one starts."""
        with self._lock:
            if self._process is not None:
                self._retired.append(self._process)
            self._process = None
            self._retired = [p for p in self._retired if p.poll() is None]
        self.start()

    def started(self) -> bool:
        """Whether a template was started here and runs (importing or ready)."""
        process = self._process
        return process is not None and process.poll() is None

    def starting(self) -> bool:
        """Whether the template runs but still imports (its socket is not there yet)."""
        return self.started() and not self.ready()

    def stop(self) -> None:
        """End the template, and retired ones (closing its input ends it; its kernels end with it)."""
        with self._lock:
            stopping = [p for p in (self._process, *self._retired) if p is not None]
            self._process, self._retired = None, []
        for process in stopping:
            with contextlib.suppress(OSError):
                if process.stdin:
                    process.stdin.close()
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()

    def launch(self, cmd: list[str], env: dict[str, str], cwd: str,
               streams: dict[str, int] | None = None) -> _ForkedKernel | None:
        """Ask the template for a kernel; ``None`` when it cannot give one (start it the usual way then).

        ``streams`` gives the kernel's ``stdout`` and ``stderr`` as open file descriptors, as they would be handed to
        ``Popen`` (jupyter_client passes them through; nbval sends the kernel's errors to ``os.devnull``); the others
        are the template's, which are the server's.
        """
        if not self.ready():
            return None
        names = sorted(streams or {})
        channel = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            channel.settimeout(10.0)
            channel.connect(self.address or "")
            request = (json.dumps({"cmd": cmd, "env": env, "cwd": cwd, "streams": names}) + "\n").encode("utf-8")
            sent = socket.send_fds(channel, [request[:1]], [(streams or {})[n] for n in names]) if names else 0
            channel.sendall(request[sent:])
            received = b""
            while b"\n" not in received:
                data = channel.recv(4096)
                if not data:
                    break
                received += data
            line, newline, rest = received.partition(b"\n")
            answer = json.loads(line) if newline else {"refused": "the template closed the connection"}
        except (OSError, ValueError) as exc:
            channel.close()
            logger.info("kernel template did not answer (%s): starting the kernel as a new process", exc)
            return None
        if "pid" not in answer:
            channel.close()
            logger.info("kernel template: %s; starting the kernel as a new process", answer.get("refused"))
            if answer.get("stale"):
                self.retire()  # a new one for the next kernel
            return None
        return _ForkedKernel(int(answer["pid"]), channel, rest)


_TEMPLATE = _Template()


def template() -> _Template:
    """This server's template (one per process)."""
    return _TEMPLATE


# --------------------------------------------------------------------------------------------- the template's side


def _fingerprint() -> dict[str, tuple[int, int]]:
    """The files of the modules loaded now: path -> (size, modification time)."""
    seen: dict[str, tuple[int, int]] = {}
    for module in list(sys.modules.values()):
        path = getattr(module, "__file__", None)
        if isinstance(path, str) and path not in seen:
            with contextlib.suppress(OSError):
                stat = os.stat(path)
                seen[path] = (stat.st_size, stat.st_mtime_ns)
    return seen


def _changed(files: dict[str, tuple[int, int]]) -> str | None:
    for path, was in files.items():
        try:
            stat = os.stat(path)
        except OSError:
            return path
        if (stat.st_size, stat.st_mtime_ns) != was:
            return path
    return None


def _startup(env: dict[str, str] | os._Environ[str]) -> dict[str, str]:
    return {k: v for k, v in env.items() if k.startswith("PYTHON") or k in STARTUP_VARIABLES}


def _same_python(command: str, executable: str) -> bool:
    """Whether ``command`` starts the template's Python in the template's environment: the same interpreter, found
    in the same folder (a virtual environment's ``bin/python`` is a link to the base interpreter, and that folder is
    what makes it the environment's; the folder may be reached through a link, as a clone's ``.venv`` is)."""
    try:
        return (os.path.samefile(command, executable)
                and os.path.realpath(os.path.dirname(command)) == os.path.realpath(os.path.dirname(executable)))
    except OSError:
        return False


def _refusal(request: dict[str, Any], executable: str, flags: list[str], startup: dict[str, str]) -> str | None:
    """Why the template cannot give this kernel; ``None`` when it can."""
    cmd = request.get("cmd")
    if not (isinstance(cmd, list) and len(cmd) >= 3 and all(isinstance(a, str) for a in cmd)):
        return "the kernel's command is not a list of strings"
    if not _same_python(cmd[0], executable) or kernel_flags(cmd) != flags or len(cmd) < len(flags) + 3:
        expected = " ".join([executable, *flags, "-m", "MODULE ..."])
        return f"the kernel's command {' '.join(cmd[:len(flags) + 3])} is not `{expected}`"
    if not isinstance(request.get("env"), dict) or not isinstance(request.get("cwd"), str):
        return "the request has no environment or working folder"
    if _startup(request["env"]) != startup:
        return "the kernel's environment differs in what Python reads at start"
    if not os.path.isdir(request["cwd"]):
        return f"the kernel's working folder {request['cwd']} does not exist"
    return None


def _kernel_main(request: dict[str, Any]) -> None:
    """In the forked child: become ``python -m MODULE ARGS`` in the request's folder and environment; never returns."""
    code = 0
    try:
        os.setsid()
        signal.set_wakeup_fd(-1)
        for number in (signal.SIGCHLD, signal.SIGTERM, signal.SIGHUP):
            signal.signal(number, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        quiet = os.open(os.devnull, os.O_RDONLY)  # as jupyter_client gives a kernel: no input
        os.dup2(quiet, 0)
        os.close(quiet)
        cwd = request["cwd"]
        os.chdir(cwd)
        env = dict(request["env"])
        env["JPY_PARENT_PID"] = str(os.getppid())  # the kernel ends when the template does
        os.environ.clear()
        os.environ.update(env)
        _as_new_process(env)
        sys.path[0] = cwd  # as `python -m` puts it
        at = request["cmd"].index("-m", 1)
        module, args = request["cmd"][at + 1], request["cmd"][at + 2:]
        sys.argv = [module, *args]
        import runpy

        runpy.run_module(module, run_name="__main__", alter_sys=True)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except BaseException:  # noqa: BLE001 - as an interpreter prints an uncaught exception
        import traceback

        traceback.print_exc()
        code = 1
    finally:
        with contextlib.suppress(BaseException):
            threading._shutdown()  # type: ignore[attr-defined]  # an interpreter waits for its threads, then:
        with contextlib.suppress(BaseException):
            import atexit

            atexit._run_exitfuncs()
        with contextlib.suppress(BaseException):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


def _as_new_process(env: dict[str, str]) -> None:
    """What a new process would have differently from the template: numpy's global random state, matplotlib's
    backend (ipykernel names the inline one when the environment names none)."""
    numpy = sys.modules.get("numpy")
    if numpy is not None:
        numpy.random.seed()
    matplotlib = sys.modules.get("matplotlib")
    if matplotlib is not None:
        matplotlib.rcParams["backend"] = env.get("MPLBACKEND") or INLINE_BACKEND


def _preload() -> None:
    import importlib

    given = os.environ.get("MPLBACKEND")
    os.environ.setdefault("MPLBACKEND", INLINE_BACKEND)  # matplotlib takes its backend when imported
    for name in KERNEL_PRELOAD:
        with contextlib.suppress(Exception):
            importlib.import_module(name)
    if given is None:  # the template's environment as it was given (a kernel gets its own, see _kernel_main)
        del os.environ["MPLBACKEND"]
    for name in FRESH:
        sys.modules.pop(name, None)
        package, _, attribute = name.rpartition(".")
        with contextlib.suppress(AttributeError, KeyError):
            delattr(sys.modules[package], attribute)


def _answer(channel: socket.socket, message: dict[str, Any]) -> None:
    """Send ``message`` to the server as one JSON line (the server may have given up on it: then nobody reads it)."""
    with contextlib.suppress(OSError):
        channel.sendall((json.dumps(message) + "\n").encode("utf-8"))


def _reap(children: dict[int, socket.socket]) -> None:
    while children:
        try:
            pid, status = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        channel = children.pop(pid, None)
        if channel is not None:
            _answer(channel, {"exit": os.waitstatus_to_exitcode(status)})
            channel.close()


def _read_request(channel: socket.socket) -> tuple[dict[str, Any], list[int]]:
    """A kernel request and the file descriptors that came with it (the kernel's output streams)."""
    channel.settimeout(10.0)
    data, fds, _, _ = socket.recv_fds(channel, 65536, 2)
    try:
        while not data.endswith(b"\n"):
            chunk = channel.recv(65536)
            if not chunk:
                raise ValueError("the request ended early")
            data += chunk
            if len(data) > 4_000_000:
                raise ValueError("the request is too long")
        request = json.loads(data)
        if not isinstance(request, dict):
            raise ValueError("the request is not an object")
        streams = request.get("streams", [])
        if not (isinstance(streams, list) and len(streams) == len(fds) and set(streams) <= {"stdout", "stderr"}):
            raise ValueError("the request's output streams do not match what came with it")
    except BaseException:
        for fd in fds:
            os.close(fd)
        raise
    return request, list(fds)


def serve(address: str, flags: list[str]) -> None:
    """The template: import :data:`KERNEL_PRELOAD`, listen at ``address``, fork a kernel for each request; end when
    standard input closes (the server ended) or, once a preloaded file changed, when its last kernel has ended."""
    executable = os.path.abspath(sys.executable)
    startup = _startup(os.environ)
    _preload()
    files = _fingerprint()
    import gc

    gc.collect()
    gc.freeze()  # what the template holds stays shared with its kernels: their collections skip it
    wake_r, wake_w = os.pipe()
    os.set_blocking(wake_w, False)
    signal.set_wakeup_fd(wake_w)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # an interrupt of the server's terminal is the server's
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    partial = address + ".binding"
    listener.bind(partial)
    listener.listen(16)
    os.replace(partial, address)  # the socket appears when it takes requests
    children: dict[int, socket.socket] = {}
    accepting = True
    stdin = sys.stdin.fileno()
    while accepting or children:
        watched = [wake_r, stdin] + ([listener] if accepting else [])
        with contextlib.suppress(InterruptedError):
            readable, _, _ = select.select(watched, [], [], 5.0)
        _reap(children)
        if stdin in readable and not os.read(stdin, 1024):
            break  # the server ended
        if wake_r in readable:
            with contextlib.suppress(OSError):
                os.read(wake_r, 1024)
        if accepting and listener in readable:
            channel, _ = listener.accept()
            try:
                request, fds = _read_request(channel)
            except (OSError, ValueError) as exc:
                _answer(channel, {"refused": str(exc)})
                channel.close()
                continue
            changed = _changed(files)
            refusal = _refusal(request, executable, flags, startup)
            if changed or refusal:
                for fd in fds:
                    os.close(fd)
                _answer(channel, {"refused": refusal or f"{changed} changed since the template read it",
                                  "stale": bool(changed)})
                channel.close()
                if changed:
                    accepting = False
                    listener.close()
                    with contextlib.suppress(OSError):
                        os.unlink(address)
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DeprecationWarning)  # Python 3.12+: numpy's BLAS threads
                pid = os.fork()
            if pid == 0:
                listener.close()
                channel.close()
                os.close(wake_r)
                os.close(wake_w)
                for name, fd in zip(request.get("streams", []), fds, strict=True):
                    os.dup2(fd, 1 if name == "stdout" else 2)
                    os.close(fd)
                _kernel_main(request)
            for fd in fds:
                os.close(fd)
            children[pid] = channel
            _answer(channel, {"pid": pid})
    with contextlib.suppress(OSError):
        os.unlink(address)
    with contextlib.suppress(OSError):
        os.rmdir(os.path.dirname(address))  # the server made it for this template


if __name__ == "__main__":
    serve(sys.argv[1], json.loads(sys.argv[2]))
