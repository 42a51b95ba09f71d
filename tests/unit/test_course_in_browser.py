"""The course as a learner starts it: the README's start command on a fresh clone, JupyterLab in headless Chromium.

The server must listen on 127.0.0.1 only, open at the learner's copy of 00_intro, show the notebooks and the exercise
folders in the file browser, open an exercise file in the editor, and run the intro's first cells in the page; the
panels must render, answer real clicks and follow a system spinning in the background of the kernel. Screenshots are
written to ``RRBOT_WORKSHOP_SCREENSHOTS`` (a directory) when it is set, to be looked at. The server (and with it the
kernels) is stopped with the test.
"""

from __future__ import annotations

import hashlib
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
from browser_driver import CHROMIUM, HANG_GUARD, LAB_HELPERS, Browser, unavailable

from rrbot_workshop.classroom import kernels

ROOT = Path(__file__).resolve().parents[2]
#: The environment given to the course's test command, if any (see rrbot_workshop.classroom.launcher.PYTHON_ENV).
GIVEN = "RRBOT_WORKSHOP_PYTHON"
pytestmark = [pytest.mark.browser, pytest.mark.slow]


@pytest.fixture(autouse=True, scope="module")
def _browser_available() -> None:
    if CHROMIUM is None:
        unavailable("headless Chromium not installed (apt-get install -y chromium)")
    if not (ROOT / ".git").exists() or not ((ROOT / ".venv").exists() or os.environ.get(GIVEN)):
        unavailable("needs the course as a git checkout with its .venv")


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
    # The clone borrows the course's environment. Its start command re-installs the course into that environment
    # when pyproject.toml differs from the one it was set up for, which would point the checkout's .venv at this
    # temporary clone: only go on when they match (./workshop test brings .venv up to date before the tests).
    # An environment given to the test command (a student copy tested on CI's) is the clone's too: its launcher puts
    # the clone's own package first on PYTHONPATH.
    given = os.environ.get(GIVEN)
    stamp = Path(given).parent.parent / ".installed" if given else ROOT / ".venv" / ".installed"
    committed = hashlib.sha256((clone / "pyproject.toml").read_bytes()).hexdigest()
    if not stamp.exists() or stamp.read_text().strip() != committed:
        unavailable(".venv was set up for another pyproject.toml than the committed one; run ./workshop test "
                     "(it brings .venv up to date first) with pyproject.toml committed")
    if not given:
        (clone / ".venv").symlink_to(ROOT / ".venv")  # the course's environment, already set up
    port = _free_port()
    env = {k: v for k, v in os.environ.items() if not k.startswith("RRBOT_WORKSHOP_") or k == GIVEN}
    env.pop("PYTHONPATH", None)
    server = subprocess.Popen(
        [sys.executable, "workshop.py", "start", "--no-browser", f"--port={port}", "--ServerApp.token=",
         "--ServerApp.password=", "--LabApp.expose_app_in_browser=True"],
        cwd=clone, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + HANG_GUARD
        while True:
            try:
                urllib.request.urlopen(f"{url}/api/status", timeout=10)
                break
            except OSError:
                if server.poll() is not None or time.monotonic() > deadline:
                    pytest.fail(f"JupyterLab ended or hung before it answered (exit status {server.poll()})")
                time.sleep(0.5)
        yield url, clone
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)


def _page_once(url: str, profile: Path, ready: str, png: Path | None = None, listed: tuple[str, ...] = ()) -> str:
    """The DOM of ``url`` once the page shows ``ready`` (text in the page) and the file browser lists ``listed`` (it
    fills in on its own, after the document), and a screenshot of it into ``png``."""
    assert CHROMIUM is not None
    browser = Browser(CHROMIUM, profile)
    try:
        browser.viewport(1400, 900)
        browser.open(url)
        browser.wait_for(f"document.body && document.body.innerText.includes({ready!r})", what=f"{ready!r} on {url}")
        for name in listed:
            browser.wait_for(f"document.documentElement.outerHTML.includes({name!r})",
                             what=f"{name!r} in the file browser of {url}")
        if png is not None:
            browser.frames(5)
            browser.screenshot(png)
        return str(browser.js("document.documentElement.outerHTML"))
    finally:
        browser.close()


def test_the_server_listens_on_localhost_only(lab: tuple[str, Path]) -> None:
    url, _ = lab
    port = int(url.rsplit(":", 1)[1])
    addresses = _listening_addresses(port)
    assert addresses, f"nothing listens on port {port}"
    assert addresses <= {"0100007F", "00000000000000000000000001000000"}, f"listening on {addresses}, not 127.0.0.1"


def test_jupyterlab_opens_the_intro_and_shows_the_course_folders(lab: tuple[str, Path], tmp_path: Path) -> None:
    url, clone = lab
    assert (clone / "my_notebooks" / "00_intro.ipynb").is_file(), "the start command made no learner copies"
    png = tmp_path / "lab.png"
    dom = _page_once(f"{url}/lab/tree/my_notebooks/00_intro.ipynb", tmp_path / "profile",
                     "ros2_control in one picture", png, listed=("05_simulation.ipynb", "14_fault_lab.ipynb"))
    assert "05_simulation.ipynb" in dom and "14_fault_lab.ipynb" in dom, "the file browser does not list the notebooks"
    assert png.is_file() and png.stat().st_size > 20_000, "the screenshot of JupyterLab is blank"
    _keep(png)


def test_an_exercise_file_opens_in_the_editor(lab: tuple[str, Path], tmp_path: Path) -> None:
    url, _ = lab
    dom = _page_once(f"{url}/lab/tree/exercises/task08_write_a_controller/displacement_controller.py",
                     tmp_path / "profile", "DisplacementController")
    assert "TODO" in dom, "the exercise file is not shown in the editor"


def _keep(png: Path) -> None:
    """Copy a screenshot to RRBOT_WORKSHOP_SCREENSHOTS, if set."""
    target = os.environ.get("RRBOT_WORKSHOP_SCREENSHOTS")
    if target:
        Path(target).mkdir(parents=True, exist_ok=True)
        shutil.copy(png, Path(target) / png.name)


@pytest.fixture
def browser(tmp_path: Path) -> Iterator[Browser]:
    assert CHROMIUM is not None
    b = Browser(CHROMIUM, tmp_path / "profile")
    try:
        yield b
    finally:
        b.close()


def _open_notebook(browser: Browser, url: str, path: str) -> int:
    browser.open(f"{url}/lab")
    browser.wait_for("!!(window.jupyterapp && document.querySelector('.jp-DirListing'))", what="JupyterLab to start")
    browser.js(LAB_HELPERS)
    return int(browser.js(f"rrbotTest.open({path!r})"))


def _forked_kernels(clone: Path) -> list[int]:
    """The kernels working in ``clone`` whose parent is a kernel template (rrbot_workshop/classroom/kernels.py)."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            if not entry.name.isdigit() or not (entry / "cwd").resolve().is_relative_to(clone.resolve()):
                continue
            parent = (entry / "stat").read_text().rsplit(")", 1)[1].split()[1]
            if kernels.TEMPLATE_MODULE.encode() in Path(f"/proc/{parent}/cmdline").read_bytes():
                found.append(int(entry.name))
        except OSError:
            continue
    return found


def test_the_intro_runs_its_first_cells_in_the_browser(lab: tuple[str, Path], browser: Browser, tmp_path: Path) -> None:
    url, clone = lab
    assert _open_notebook(browser, url, "my_notebooks/00_intro.ipynb") > 10
    cells = [1, 4, 6]  # imports and %load_ext, the bring-up, %control list_controllers
    browser.js(f"rrbotTest.run({cells}); true")  # started, not awaited: done() is polled
    browser.wait_for(f"rrbotTest.done({cells})", what="the intro's first cells to run")
    assert browser.js("rrbotTest.errors()") == []
    listing = browser.js("rrbotTest.outputText(6)")
    assert "forward_position_controller" in listing and "active" in listing, listing
    if Path("/proc/self/cwd").exists():
        assert _forked_kernels(clone), "the notebook's kernel was not forked from the server's template"
    png = browser.screenshot(tmp_path / "intro_cells.png")
    assert png.stat().st_size > 20_000
    _keep(png)


PANELS_NOTEBOOK = [
    "import rrbot_workshop as rw\n"
    "from rrbot_workshop.msgs import Float64MultiArray\n"
    "system = rw.bringup('rrbot', 'rrbot_controllers.yaml', name='browser',\n"
    "                    spawn=['joint_state_broadcaster', 'forward_position_controller'],\n"
    "                    inactive=['joint_trajectory_controller'])",
    "rw.viz.ControllerManagerPanel(system)",
    "rw.viz.PlotPanel(system, ['joint1/position', 'joint2/position', '/joint_states:position[joint1]'], window=4.0)",
    "rw.viz.TrajectoryPanel(system)",
    "system.publish('/forward_position_controller/commands', Float64MultiArray(data=[0.8, -0.4]))\n"
    "system.spin_in_background()",
]

_CLICK = "[...document.querySelectorAll('button')].find(b => b.innerText.trim() === {!r}).click(); true"
_STATE = ("(() => {{ const row = [...document.querySelectorAll('.widget-html table tr')]"
          ".find(r => r.cells.length && r.cells[0].innerText.trim() === {!r});"
          " return row ? row.cells[row.cells.length - 1].innerText.trim() : ''; }})()")
_PLOT = "(document.querySelector('.widget-image') || {src: ''}).src"


def test_the_panels_answer_clicks_while_the_system_spins_in_the_background(
        lab: tuple[str, Path], browser: Browser, tmp_path: Path) -> None:
    import nbformat

    url, clone = lab
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in PANELS_NOTEBOOK])
    # without a kernelspec JupyterLab asks which kernel to start, and the notebook's session never becomes ready
    notebook.metadata["kernelspec"] = {"display_name": "Python 3", "language": "python", "name": "python3"}
    nbformat.write(notebook, clone / "my_notebooks" / "panels_in_the_browser.ipynb")
    assert _open_notebook(browser, url, "my_notebooks/panels_in_the_browser.ipynb") == len(PANELS_NOTEBOOK)
    cells = list(range(len(PANELS_NOTEBOOK)))
    browser.js(f"rrbotTest.run({cells}); true")  # started, not awaited: done() is polled
    browser.wait_for(f"rrbotTest.done({cells})", what="the panel cells to run")
    assert browser.js("rrbotTest.errors()") == []
    assert browser.wait_for(_STATE.format("forward_position_controller"), what="the controller manager panel's table") \
        == "active"

    # the plot is redrawn while no cell runs: the background loop moves the robot and the panel follows
    first = browser.wait_for(_PLOT, what="the live plot")
    browser.wait_for(f"{_PLOT} !== {first!r}", what="the live plot to change while the system spins")

    # choose the trajectory controller in the panel's dropdown, as a learner would
    browser.js("(() => { const s = document.querySelector('.widget-dropdown select');"
               " s.value = [...s.options].find(o => o.text === 'joint_trajectory_controller').value;"
               " s.dispatchEvent(new Event('change', {bubbles: true})); return true; })()")
    # activating it beside the forward controller would fail: nothing changes, the panel says why
    browser.js(_CLICK.format("activate"))
    browser.wait_for("document.body.innerText.includes('activate joint_trajectory_controller would fail; nothing was "
                     "changed')", what="the panel's why")
    assert browser.js(_STATE.format("joint_trajectory_controller")) == "inactive"
    # switching to it replaces the forward controller in one switch
    browser.js(_CLICK.format("switch to"))
    browser.wait_for(f"{_STATE.format('joint_trajectory_controller')} === 'active' && "
                     f"{_STATE.format('forward_position_controller')} === 'inactive'",
                     what="the switch to the trajectory controller to show in the table")
    browser.js(_CLICK.format("send and run"))
    browser.wait_for("[...document.querySelectorAll('.widget-label')].some(l => l.innerText.startsWith('goal'))",
                     what="the trajectory panel's status")
    browser.js("document.querySelector('.widget-image').scrollIntoView(); true")
    time.sleep(1.0)
    png = browser.screenshot(tmp_path / "panels.png")
    assert png.stat().st_size > 20_000
    _keep(png)
    browser.js("document.querySelector('.widget-html table').scrollIntoView(); true")
    _keep(browser.screenshot(tmp_path / "controller_manager_panel.png"))
