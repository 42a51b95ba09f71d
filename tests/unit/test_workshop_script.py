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
    result = subprocess.run([sys.executable, "-m", "rrbot_workshop", "--help"],  # the course's environment
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


def test_the_test_command_compares_the_notebooks_on_the_exercises_and_runs_them_on_the_solutions(tmp_path: Path) -> None:
    """One run for the library with the notebooks compared on the untouched exercises, one for the solutions track; a
    copy without the library's references runs its WITHHELD.json notebooks without comparing, and has no solutions."""
    from rrbot_workshop.classroom.launcher import planned_runs

    course = tmp_path / "course"
    (course / "notebooks").mkdir(parents=True)
    (course / "solutions").mkdir()
    for name in ("01_a.ipynb", "02_b.ipynb"):
        (course / "notebooks" / name).write_text("{}")
    runs = planned_runs(course, {"X": "1"})
    assert [r[1][0] for r in runs] == ["--nbval", "--nbval-lax"]
    assert "tests/unit" in runs[0][1] and "notebooks/02_b.ipynb" in runs[0][1]
    assert runs[0][2]["RRBOT_WORKSHOP_TRACK"] == "exercises" and runs[1][2]["RRBOT_WORKSHOP_TRACK"] == "solutions"
    assert all(r[2]["X"] == "1" for r in runs)

    copy = tmp_path / "copy"
    (copy / "notebooks").mkdir(parents=True)
    for name in ("01_a.ipynb", "02_b.ipynb"):
        (copy / "notebooks" / name).write_text("{}")
    (copy / "WITHHELD.json").write_text('{"notebooks": ["notebooks/02_b.ipynb"]}')
    runs = planned_runs(copy, {})
    assert [(r[1][0], r[1][-1]) for r in runs] == [("--nbval", "notebooks/01_a.ipynb"),
                                                   ("--nbval-lax", "notebooks/02_b.ipynb")]


def test_the_compared_notebooks_run_in_forked_kernels_and_the_solutions_track_in_new_processes(tmp_path: Path) -> None:
    """The launcher names the course's kernel provisioner itself: the name of its entry point; the exercises' run (the
    notebooks compared) gives it to Jupyter, the solutions track's run does not, so both ways of starting a kernel run
    every notebook."""
    from importlib.metadata import entry_points

    from rrbot_workshop.classroom import kernels
    from rrbot_workshop.classroom.launcher import FORKED_KERNELS, PROVISIONER_ENV, planned_runs

    assert FORKED_KERNELS == kernels.PROVISIONER_NAME
    assert FORKED_KERNELS in {e.name for e in entry_points(group="jupyter_client.kernel_provisioners")}
    from jupyter_client.provisioning.factory import KernelProvisionerFactory

    assert PROVISIONER_ENV == KernelProvisionerFactory.default_provisioner_name_env
    course = tmp_path / "course"
    (course / "notebooks").mkdir(parents=True)
    (course / "solutions").mkdir()
    (course / "notebooks" / "01_a.ipynb").write_text("{}")
    runs = planned_runs(course, {})
    assert runs[0][2][PROVISIONER_ENV] == FORKED_KERNELS
    assert all(PROVISIONER_ENV not in env for what, _, env in runs if "solutions" in what)


def test_the_test_command_counts_what_every_run_tested(tmp_path: Path) -> None:
    """The counts printed at the end come from each run's JUnit report; a run that wrote none counts nothing."""
    from rrbot_workshop.classroom.launcher import _tally

    report = tmp_path / "r.xml"
    report.write_text('<testsuites><testsuite tests="10" failures="1" errors="1" skipped="3"/></testsuites>')
    assert _tally(report) == (10, 2, 3, 5)
    assert _tally(tmp_path / "missing.xml") == (0, 0, 0, 0)


def test_a_given_environment_is_used_only_when_set_up_from_the_same_pyproject(tmp_path: Path,
                                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """RRBOT_WORKSHOP_PYTHON: the environment's stamp must be this course's pyproject.toml's, and the course's own
    package must be the one it imports (the course's folder first on PYTHONPATH)."""
    import hashlib

    from rrbot_workshop.classroom.launcher import PYTHON_ENV, course_env, setup

    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    python = venv / "bin" / "python"
    python.symlink_to(sys.executable)
    monkeypatch.setenv(PYTHON_ENV, str(python))
    with pytest.raises(SystemExit, match="not an environment set up from this course's pyproject.toml"):
        setup(ROOT)
    (venv / ".installed").write_text(hashlib.sha256((ROOT / "pyproject.toml").read_bytes()).hexdigest())
    assert setup(ROOT) == python
    env = course_env(ROOT, {PYTHON_ENV: str(python), "PYTHONPATH": "/elsewhere"})
    assert env["PYTHONPATH"].split(os.pathsep) == [str(ROOT), "/elsewhere"]
    assert "PYTHONPATH" not in course_env(ROOT, {})
    other = tmp_path / "other"  # a course folder whose package the environment cannot import
    other.mkdir()
    (other / "pyproject.toml").write_bytes((ROOT / "pyproject.toml").read_bytes())
    with pytest.raises(SystemExit, match="imports rrbot_workshop from"):
        setup(other)
    # run from another checkout's folder (CI tests a student copy from the repository's root): the course's own
    # package is still the one found, not the package in the folder the command was started from
    monkeypatch.chdir(other)
    (other / "rrbot_workshop").mkdir()
    (other / "rrbot_workshop" / "__init__.py").write_text("")
    assert setup(ROOT) == python
