"""The course as a learner starts it: the README's start command on a fresh clone, JupyterLab in headless Chromium.

The server must listen on 127.0.0.1 only, open at the learner's copy of 00_intro, show the notebooks and the exercise
folders in the file browser, and open an exercise file in the editor; the page must not be blank. The server is
stopped with the test.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

pytestmark = [
    pytest.mark.browser,
    pytest.mark.slow,
    pytest.mark.skipif(CHROMIUM is None, reason="headless Chromium not installed (apt-get install -y chromium)"),
    pytest.mark.skipif(not (ROOT / ".git").exists() or not (ROOT / ".venv").exists(),
                       reason="needs the course as a git checkout with its .venv"),
]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _listening_addresses(port: int) -> set[str]:
    """Local addresses (hex, as /proc/net/tcp writes them) listening on ``port``."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not Path(table).exists():
            continue
        for line in Path(table).read_text().splitlines()[1:]:
            local, state = line.split()[1], line.split()[3]
            address, _, hex_port = local.rpartition(":")
            if state == "0A" and int(hex_port, 16) == port:
                found.add(address)
    return found


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[str, Path]]:
    clone = tmp_path_factory.mktemp("lab") / "course"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    (clone / ".venv").symlink_to(ROOT / ".venv")  # the course's environment, already set up
    port = _free_port()
    env = {k: v for k, v in os.environ.items() if not k.startswith("RRBOT_WORKSHOP_")}
    server = subprocess.Popen(
        [sys.executable, "workshop.py", "start", "--no-browser", f"--port={port}", "--ServerApp.token=",
         "--ServerApp.password="],
        cwd=clone, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    url = f"http://127.0.0.1:{port}"
    try:
        for _ in range(120):
            try:
                urllib.request.urlopen(f"{url}/api/status", timeout=1)
                break
            except OSError:
                time.sleep(0.5)
        else:
            pytest.fail("JupyterLab did not answer within 60 s")
        yield url, clone
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)


def _chromium(url: str, profile: Path, *args: str) -> str:
    command = [CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-sync",
               "--disable-background-networking", f"--user-data-dir={profile}", "--virtual-time-budget=20000", *args,
               url]
    return subprocess.run(command, check=False, capture_output=True, text=True, timeout=180).stdout


def test_the_server_listens_on_localhost_only(lab: tuple[str, Path]) -> None:
    url, _ = lab
    port = int(url.rsplit(":", 1)[1])
    addresses = _listening_addresses(port)
    assert addresses, f"nothing listens on port {port}"
    assert addresses <= {"0100007F", "00000000000000000000000001000000"}, f"listening on {addresses}, not 127.0.0.1"


def test_jupyterlab_opens_the_intro_and_shows_the_course_folders(lab: tuple[str, Path], tmp_path: Path) -> None:
    url, clone = lab
    assert (clone / "my_notebooks" / "00_intro.ipynb").is_file(), "the start command made no learner copies"
    dom = _chromium(f"{url}/lab/tree/my_notebooks/00_intro.ipynb", tmp_path / "profile", "--dump-dom")
    assert "ros2_control in one picture" in dom, "the intro notebook is not rendered"
    assert "05_simulation.ipynb" in dom and "14_fault_lab.ipynb" in dom, "the file browser does not list the notebooks"
    png = tmp_path / "lab.png"
    _chromium(f"{url}/lab/tree/my_notebooks/00_intro.ipynb", tmp_path / "profile2", f"--screenshot={png}",
              "--window-size=1400,900")
    assert png.is_file() and png.stat().st_size > 20_000, "the screenshot of JupyterLab is blank"


def test_an_exercise_file_opens_in_the_editor(lab: tuple[str, Path], tmp_path: Path) -> None:
    url, _ = lab
    dom = _chromium(f"{url}/lab/tree/exercises/task08_write_a_controller/displacement_controller.py",
                    tmp_path / "profile", "--dump-dom")
    assert "DisplacementController" in dom and "TODO" in dom, "the exercise file is not shown in the editor"
