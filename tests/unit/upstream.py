"""The real upstream files the tests read: ros2_control_demos, The Littlest JupyterHub, the zero-to-jupyterhub chart.

They are kept beside the project, never copied into it (``../shared/upstream/`` next to the repository; its README
lists them). Tests find that folder in this order:

1. ``$RRBOT_WORKSHOP_UPSTREAM``;
2. ``shared/upstream`` beside this repository;
3. ``shared/upstream`` beside the repository this one was cloned from, when its ``origin`` is a local folder (a fresh
   clone made with ``git clone /path/to/course``).

Where none holds the file a test needs, the test is skipped on a learner's machine and fails where
``$RRBOT_WORKSHOP_REQUIRE_UPSTREAM`` is set (``.ci/run`` sets it: in CI these tests must run).
"""

from __future__ import annotations

import os
import subprocess
import tarfile
from functools import cache
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
UPSTREAM_ENV = "RRBOT_WORKSHOP_UPSTREAM"
REQUIRE_ENV = "RRBOT_WORKSHOP_REQUIRE_UPSTREAM"

#: The files ``shared/upstream`` holds, by what the tests call them.
DEMOS = "ros2_control_demos-jazzy-c8f35457.tar.gz"
TLJH = "the-littlest-jupyterhub-84ed38f.tar.gz"
Z2JH = "zero-to-jupyterhub-4.4.0"


def _origin_folder() -> Path | None:
    try:
        url = subprocess.run(["git", "config", "--get", "remote.origin.url"], cwd=REPO, capture_output=True,
                             text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    if not url or "://" in url and not url.startswith("file://"):
        return None
    path = Path(url.removeprefix("file://")).expanduser()
    if not path.is_absolute():
        path = (REPO / path).resolve()
    return path if path.is_dir() else None


@cache
def upstream_folder() -> Path | None:
    """The folder that holds the upstream files, or None."""
    candidates = []
    if os.environ.get(UPSTREAM_ENV):
        candidates.append(Path(os.environ[UPSTREAM_ENV]).expanduser())
    candidates.append(REPO.parent / "shared" / "upstream")
    origin = _origin_folder()
    if origin is not None:
        candidates.append(origin.parent / "shared" / "upstream")
    return next((c.resolve() for c in candidates if c.is_dir()), None)


def shared_folder() -> Path | None:
    """The ``shared`` folder that holds ``upstream/`` (and ``conformance/``), found as :func:`upstream_folder` is."""
    folder = upstream_folder()
    return folder.parent if folder is not None else None


def upstream(name: str) -> Path:
    """The upstream file or folder ``name`` (one of :data:`DEMOS`, :data:`TLJH`, :data:`Z2JH`).

    Skips the calling test when it is missing, or fails it where ``$RRBOT_WORKSHOP_REQUIRE_UPSTREAM`` is set.
    """
    folder = upstream_folder()
    path = folder / name if folder is not None else None
    if path is not None and path.exists():
        return path
    why = (f"the upstream file {name} is not here (looked in ${UPSTREAM_ENV}, ../shared/upstream beside the "
           "repository and beside its origin); set RRBOT_WORKSHOP_UPSTREAM to the folder that holds it")
    if os.environ.get(REQUIRE_ENV):
        pytest.fail(why, pytrace=False)
    pytest.skip(why)


def extract(name: str, into: Path) -> Path:
    """The upstream tarball ``name`` extracted below ``into`` (once); returns its top folder.

    The tree is made read-only-safe for tests that hash it: nothing outside ``into`` is written.
    """
    archive = upstream(name)
    with tarfile.open(archive) as tar:
        tops = {m.name.split("/", 1)[0] for m in tar.getmembers()}
        if len(tops) != 1:
            raise ValueError(f"{archive} holds {len(tops)} top folders; expected one")
        top = into / tops.pop()
        if not top.is_dir():
            tar.extractall(into, filter="data")
    return top
