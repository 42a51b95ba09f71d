"""A meshcat server that listens on 127.0.0.1 only and dies with the process that started it.

meshcat 0.3.2 ships a ZeroMQ-to-WebSocket bridge (``meshcat.servers.zmqserver``). Its ZeroMQ socket
binds to 127.0.0.1, but its web server calls tornado's ``listen(port)`` without an address, which
listens on every interface (0.0.0.0 and [::]). A course runs on learners' laptops, often on shared
networks, so we never start that server as shipped. Instead we start *this* module as a child process:
it patches tornado's ``Application.listen`` to bind 127.0.0.1, lets the operating system pick free
ports for both sockets, and exits as soon as its parent goes away.

The parent side is :class:`MeshcatServer`: it starts the child, reads the two URLs it prints, and
kills it on :meth:`MeshcatServer.close`, when it is garbage collected, and at interpreter exit.
"""

from __future__ import annotations

import atexit
import logging
import os
import subprocess
import sys
import threading
import weakref
from typing import Any

__all__ = ["MeshcatServer", "LOOPBACK", "live_servers"]

_log = logging.getLogger(__name__)

#: The only address the server binds.
LOOPBACK = "127.0.0.1"

#: Seconds the parent waits for the child to print its URLs.
_START_TIMEOUT = 30.0

# Every server started by this process that is still running (for tests and atexit).
_LIVE: weakref.WeakSet[MeshcatServer] = weakref.WeakSet()


def _kill(proc: subprocess.Popen[bytes]) -> None:
    """Terminate ``proc`` (then kill it if it lingers) and reap it."""
    if proc.poll() is not None:
        return
    try:
        proc.terminate()
        proc.wait(timeout=3.0)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(timeout=3.0)
    except OSError:  # already gone
        pass


class MeshcatServer:
    """A running meshcat server bound to 127.0.0.1, owned by this process.

    Attributes:
        zmq_url: ZeroMQ endpoint the visualizer connects to (``tcp://127.0.0.1:<port>``).
        web_url: URL of the viewer page (``http://127.0.0.1:<port>/static/``).

    Raises:
        RuntimeError: If the server process exits before it reports its URLs, or does not report them
            within 30 s.
    """

    def __init__(self) -> None:
        args = [sys.executable, "-u", "-m", __name__, "--parent-pid", str(os.getpid())]
        env = dict(os.environ)
        # The child must import the same rrbot_workshop and meshcat as we do, even when the package
        # was put on sys.path by hand (a notebook next to the repository).
        package_root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        env["PYTHONPATH"] = os.pathsep.join(p for p in (package_root, env.get("PYTHONPATH", "")) if p)
        self._proc: subprocess.Popen[bytes] = subprocess.Popen(
            args,
            stdin=subprocess.PIPE,  # EOF on this pipe tells the child its parent is gone
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env=env,
            # A new session: an interrupt (Ctrl-C, "interrupt kernel") sent to our process group
            # does not take the viewer down with the cell that was running.
            start_new_session=True,
        )
        self._finalizer = weakref.finalize(self, _kill, self._proc)
        _LIVE.add(self)
        try:
            self.zmq_url, self.web_url = self._read_urls()
        except BaseException:
            self.close()
            raise
        _log.info("meshcat server (pid %d) at %s", self._proc.pid, self.web_url)

    def _read_urls(self) -> tuple[str, str]:
        assert self._proc.stdout is not None
        found: dict[str, str] = {}
        result: list[BaseException] = []

        def reader() -> None:
            assert self._proc.stdout is not None
            try:
                while len(found) < 2:
                    line = self._proc.stdout.readline().decode("utf-8", "replace").strip()
                    if not line:
                        return  # EOF: the child died
                    key, _, value = line.partition("=")
                    if key in ("zmq_url", "web_url"):
                        found[key] = value
            except BaseException as exc:  # noqa: BLE001 - handed to the waiting thread
                result.append(exc)

        thread = threading.Thread(target=reader, daemon=True)
        thread.start()
        thread.join(_START_TIMEOUT)
        if len(found) < 2:
            code = self._proc.poll()
            why = f"exited with code {code}" if code is not None else f"did not start within {_START_TIMEOUT:.0f} s"
            raise RuntimeError(f"the meshcat server (python -m {__name__}) {why}")
        return found["zmq_url"], found["web_url"]

    @property
    def pid(self) -> int:
        """Process id of the server."""
        return self._proc.pid

    @property
    def running(self) -> bool:
        """True while the server process is alive."""
        return self._proc.poll() is None

    def close(self) -> None:
        """Stop the server process and wait for it to exit. Calling it twice is harmless."""
        self._finalizer()
        _LIVE.discard(self)

    def __enter__(self) -> MeshcatServer:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "running" if self.running else "stopped"
        return f"<MeshcatServer pid={self.pid} {state} {getattr(self, 'web_url', '')}>"


def live_servers() -> list[MeshcatServer]:
    """Servers started by this process that are still running."""
    return [s for s in list(_LIVE) if s.running]


@atexit.register
def _close_all() -> None:
    for server in list(_LIVE):
        server.close()


# ---------------------------------------------------------------------------------------------- child side
def _watch_parent(parent_pid: int) -> None:
    """Exit the server as soon as the parent process is gone (stdin EOF or re-parenting)."""

    def stdin_eof() -> None:
        try:
            while sys.stdin.buffer.read(1024):
                pass
        except (OSError, ValueError):
            pass
        os._exit(0)

    def poll_ppid() -> None:
        import time

        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(0)

    threading.Thread(target=stdin_eof, daemon=True).start()
    threading.Thread(target=poll_ppid, daemon=True).start()


def _set_parent_death_signal() -> None:
    """On Linux, also ask the kernel to send SIGTERM when the parent dies (belt and braces)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        import signal

        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGTERM, 0, 0, 0)
    except (OSError, AttributeError):
        pass


def _serve(parent_pid: int) -> None:
    """Run a meshcat bridge on loopback, with free ports chosen by the operating system."""
    _set_parent_death_signal()
    if os.getppid() != parent_pid:  # the parent died before we got here
        return
    _watch_parent(parent_pid)

    import tornado.web
    import zmq
    from meshcat.servers import zmqserver

    bound: dict[str, int] = {}
    original_listen = tornado.web.Application.listen

    def listen_on_loopback(self: tornado.web.Application, port: int, address: str = "", **kwargs: Any) -> Any:
        # meshcat passes no address, which tornado takes as "every interface"; force loopback.
        server = original_listen(self, port, address=LOOPBACK, **kwargs)
        sockets = list(getattr(server, "_sockets", {}).values())
        bound["web"] = sockets[0].getsockname()[1] if sockets else port
        return server

    tornado.web.Application.listen = listen_on_loopback  # type: ignore[method-assign,assignment]

    bridge = zmqserver.ZMQWebSocketBridge(zmq_url=f"tcp://{LOOPBACK}:*", host=LOOPBACK, port=0)
    endpoint = bridge.zmq_socket.getsockopt(zmq.LAST_ENDPOINT).decode("utf-8")
    bridge.zmq_url = endpoint
    bridge.fileserver_port = bound["web"]
    bridge.web_url = f"http://{LOOPBACK}:{bound['web']}/static/"
    sys.stdout.write(f"zmq_url={bridge.zmq_url}\nweb_url={bridge.web_url}\n")
    sys.stdout.flush()
    # Nothing else is read from our stdout: send later chatter nowhere so a full pipe cannot block us.
    devnull = open(os.devnull, "w")  # noqa: SIM115 - lives as long as the process
    sys.stdout = devnull
    sys.stderr = devnull
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass


def main(argv: list[str] | None = None) -> None:
    """Entry point of the child process (``python -m rrbot_workshop.viz.meshcat_server``)."""
    import argparse

    parser = argparse.ArgumentParser(description="meshcat server bound to 127.0.0.1")
    parser.add_argument("--parent-pid", type=int, required=True)
    args = parser.parse_args(argv)
    _serve(args.parent_pid)


if __name__ == "__main__":
    main()
