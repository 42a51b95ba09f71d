"""The README's start command opens JupyterLab on the notebooks, listening on 127.0.0.1 only."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _listening_addresses(port: int) -> set[str]:
    """Local addresses listening on ``port``, from /proc/net/tcp and tcp6 (state 0A = LISTEN)."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            local, state = line.split()[1], line.split()[3]
            address, port_hex = local.split(":")
            if state == "0A" and int(port_hex, 16) == port:
                found.add(address)
    return found


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="needs Linux /proc/net/tcp")
def test_start_command_serves_jupyterlab_on_loopback_only() -> None:
    """`./workshop start` listens on 127.0.0.1 (0100007F) and nowhere else, and stops when told."""
    port = _free_port()
    proc = subprocess.Popen(
        [str(ROOT / "workshop"), "start", "--no-browser", f"--port={port}", "--ServerApp.port_retries=0"],
        cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 90
        addresses: set[str] = set()
        while time.monotonic() < deadline and not addresses:
            assert proc.poll() is None, "the start command exited early"
            time.sleep(0.5)
            addresses = _listening_addresses(port)
        assert addresses == {"0100007F"}, f"JupyterLab listens on {addresses or 'nothing'}"
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert not _listening_addresses(port)


def test_solutions_are_hidden_from_the_learners_file_browser_unless_an_instructor_shows_them() -> None:
    from rrbot_workshop.classroom.launcher import jupyterlab_command

    learner = next(a for a in jupyterlab_command(Path("python"), ROOT) if a.startswith("--ContentsManager.hide_globs="))
    instructor = next(a for a in jupyterlab_command(Path("python"), ROOT, show_solutions=True)
                      if a.startswith("--ContentsManager.hide_globs="))
    assert "'solutions'" in learner and "'notebooks'" in learner
    assert "'solutions'" not in instructor and "'notebooks'" in instructor


def test_help_exits_0_and_an_unknown_command_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    from rrbot_workshop.classroom.launcher import main

    assert main(["--help"], root=ROOT) == 0 and "usage:" in capsys.readouterr().out
    assert main(["frobnicate"], root=ROOT) == 2 and "usage:" in capsys.readouterr().err
    result = subprocess.run([str(ROOT / ".venv" / "bin" / "python"), "-m", "rrbot_workshop", "--help"],
                            capture_output=True, text=True, check=False, cwd=ROOT)
    assert result.returncode == 0 and result.stdout.startswith("usage:")


def test_the_tool_runs_from_any_terminal_through_the_workshop_script() -> None:
    """`./workshop tasks` is `rrbot-workshop tasks` without the environment on the PATH."""
    env = {k: v for k, v in os.environ.items() if k != "VIRTUAL_ENV"}
    # only the Python the course was installed with, and the system's folders: not the course's environment
    env["PATH"] = os.pathsep.join((os.path.dirname(os.path.realpath(sys.executable)), "/usr/bin", "/bin"))
    result = subprocess.run([str(ROOT / "workshop"), "tasks"], capture_output=True, text=True, check=False, cwd=ROOT,
                            env=env)
    assert result.returncode == 0, result.stderr
    assert "task01_description" in result.stdout
