"""The deployment files follow their tools' conventions and install what the laptop installs.

* ``binder/`` (repo2docker): the same pinned dependencies as ``pyproject.toml``, a supported Python, scripts that run;
* ``.devcontainer/devcontainer.json``: sets the course up with its own command, forwards JupyterLab's port;
* the image's JupyterHub is the zero-to-jupyterhub chart's hub's, so hub and learners' servers agree.

``deploy/z2jh/config.yaml`` is checked against the chart's own schema in test_z2jh.py, and ``deploy/tljh/`` through
The Littlest JupyterHub's own code in test_tljh.py.
"""

from __future__ import annotations

import json
import re
import subprocess
import tomllib
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[2]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())

#: The jupyterhub the zero-to-jupyterhub chart 4.4.0's hub image runs (the chart's appVersion; ../shared/upstream).
CHART_HUB = "jupyterhub==5.5.0"


def _requirements(path: Path) -> list[str]:
    return [line.strip() for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")]


def test_repo2docker_installs_the_laptops_pins_and_the_charts_hub_on_a_supported_python() -> None:
    pins = PYPROJECT["project"]["dependencies"] + [CHART_HUB]
    assert _requirements(ROOT / "binder" / "requirements.txt") == pins
    assert all(re.fullmatch(r"[A-Za-z0-9_.\-\[\]]+==[0-9][A-Za-z0-9.]*", p) for p in pins)
    # the single-user server at the hub's version: within the course's hub extra, so no mismatch warning in the logs
    (hub_extra,) = [Requirement(r) for r in PYPROJECT["project"]["optional-dependencies"]["hub"]]
    assert hub_extra.name == "jupyterhub" and Version(CHART_HUB.split("==")[1]) in hub_extra.specifier
    runtime = (ROOT / "binder" / "runtime.txt").read_text().strip()
    major, minor = (int(x) for x in runtime.removeprefix("python-").split("."))
    assert (3, 11) <= (major, minor) <= (3, 13)
    hub_pin = next(p for p in PYPROJECT["project"]["optional-dependencies"]["dev"] if p.startswith("jupyterhub=="))
    assert Version(hub_pin.split("==")[1]) in hub_extra.specifier  # the room test's hub (it also runs the chart's)


@pytest.mark.parametrize("script", ["postBuild", "start"])
def test_repo2docker_scripts_are_executable_bash(script: str) -> None:
    path = ROOT / "binder" / script
    assert path.stat().st_mode & 0o111 and path.read_text().startswith("#!/bin/bash")
    assert subprocess.run(["bash", "-n", str(path)], capture_output=True, check=False).returncode == 0


def test_devcontainer_sets_the_course_up_with_its_own_command() -> None:
    config = json.loads((ROOT / ".devcontainer" / "devcontainer.json").read_text())
    assert "workshop.py" in config["postCreateCommand"] and 8888 in config["forwardPorts"]
    assert re.search(r"python:3\.1[1-3]$", config["image"])
