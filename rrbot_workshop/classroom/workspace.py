"""A learner's own workspace, made from a course installed once for a whole room (JupyterHub).

On a laptop the course is a git clone: the learner works in it, and ``git pull`` brings updates. In a workshop room
the course is installed once, in a shared environment (a clone, say ``/opt/rrbot_workshop``, installed into the
environment every learner's server uses), and each learner gets a *workspace* in their home:
``rrbot-workshop init [DIR]`` (default ``~/rrbot_workshop``) copies what a learner works with:

* ``exercises/`` as handed out (their files; ``.progress/`` holds their attempt log),
* ``my_notebooks/``: their copies of the notebooks,
* what the course reads from a course folder: ``notebooks/`` (hidden in JupyterLab), ``descriptions/``, the graders in
  ``tests/tasks/``, the READMEs, and ``.pristine/exercises.tar.gz`` for ``rrbot-workshop reset``.

The library itself is not copied: it comes from the shared environment; nor are ``solutions/``. Every course command
run inside the workspace (a notebook in ``my_notebooks/``, a terminal there) uses it as the course folder.

Running ``init`` again updates the workspace without touching the learner's work, as ``git pull`` does on a
laptop: the course's own files are replaced; an exercise file is updated only where the learner never changed it
(it still equals the version handed out), and a changed one is kept, with the new version beside it as
``<name>.course-update``; new tasks' folders are added; a notebook copy the course updated is moved to
``my_notebooks/backups/`` first.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import tarfile
import time
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError

__all__ = ["MARKER", "COURSE_FILES", "InitResult", "init_workspace", "default_workspace", "singleuser_command"]

#: The file that marks a folder as a workspace made by :func:`init_workspace` (what it was made from, and when).
MARKER = ".rrbot_workshop_workspace.json"
#: What a workspace copies from the course, course-relative; replaced on every update (the course's, not the learner's).
COURSE_FILES = ("README.md", "notebooks", "descriptions", "tests/conftest.py", "tests/tasks", "exercises/README.md")
_ARCHIVE = PurePosixPath(".pristine/exercises.tar.gz")
_SKIP = {"__pycache__", ".ipynb_checkpoints", ".progress", "_generated"}


@dataclass
class InitResult:
    """What :func:`init_workspace` did.

    Attributes:
        workspace: The learner's workspace.
        created: True when it was made now, False when it was updated.
        added: Exercise files copied (new tasks, or files the learner does not have).
        updated: Exercise files the course changed and the learner had not: replaced.
        kept: Exercise files the course changed and the learner had: kept, the course's beside them.
        notebooks: One line per notebook copied to or refreshed in ``my_notebooks/``.
    """

    workspace: Path
    created: bool
    added: list[str] = field(default_factory=list)
    updated: list[str] = field(default_factory=list)
    kept: list[str] = field(default_factory=list)
    notebooks: list[str] = field(default_factory=list)


def default_workspace() -> Path:
    """``~/rrbot_workshop``."""
    return Path.home() / "rrbot_workshop"


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _files(folder: Path) -> dict[str, bytes]:
    out = {}
    for path in sorted(folder.rglob("*")):
        rel = path.relative_to(folder)
        if path.is_file() and not (set(rel.parts) & _SKIP):
            out[rel.as_posix()] = path.read_bytes()
    return out


def _handed_out(workspace: Path) -> dict[str, bytes]:
    """The exercises as the workspace last received them (its pristine archive), course-relative."""
    archive = workspace / _ARCHIVE
    if not archive.is_file():
        return {}
    out = {}
    with tarfile.open(archive, "r:gz") as tar:
        for member in tar.getmembers():
            path = PurePosixPath(member.name)
            if member.isfile() and ".." not in path.parts and not path.is_absolute():
                extracted = tar.extractfile(member)
                if extracted is not None:
                    out[str(path)] = extracted.read()
    return out


def _write_archive(workspace: Path, exercises: dict[str, bytes]) -> None:
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz") as tar:
        for rel, data in sorted(exercises.items()):
            info = tarfile.TarInfo(rel)
            info.size, info.mode, info.mtime = len(data), 0o644, 0
            tar.addfile(info, io.BytesIO(data))
    (workspace / _ARCHIVE).parent.mkdir(parents=True, exist_ok=True)
    (workspace / _ARCHIVE).write_bytes(buffer.getvalue())


def _copy_course_files(source: Path, workspace: Path) -> None:
    for rel in COURSE_FILES:
        src, dst = source / rel, workspace / rel
        if src.is_dir():
            staging = dst.with_name(f".{dst.name}.new")
            shutil.rmtree(staging, ignore_errors=True)
            shutil.copytree(src, staging, ignore=shutil.ignore_patterns(*_SKIP))
            if dst.exists():
                shutil.rmtree(dst)
            staging.rename(dst)
        elif src.is_file():
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dst)


def _installed_course(workspace: Path) -> Path:
    """Where a workspace is made from: what it was made from before, else ``$RRBOT_WORKSHOP_ROOT``, else the course
    the library belongs to (never the folder the command runs in: that may be the workspace itself)."""
    try:
        return Path(json.loads((workspace / MARKER).read_text())["source"])
    except (OSError, ValueError, KeyError, TypeError):
        pass
    override = os.environ.get(tracks.ROOT_ENV)
    if override:
        return Path(override).expanduser().resolve()
    return Path(__file__).resolve().parents[2]  # classroom/ -> rrbot_workshop/ -> the installed clone


def init_workspace(target: str | os.PathLike[str] | None = None, source: str | os.PathLike[str] | None = None,
                   now: float | None = None) -> InitResult:
    """Make a learner's workspace from the installed course, or update one (see the module's docstring).

    Args:
        target: The workspace; default ``~/rrbot_workshop``.
        source: The installed course folder; default the one the workspace was made from, else
            ``$RRBOT_WORKSHOP_ROOT``, else the folder above the installed package.
        now: Time used in backup folders' names; default now.

    Returns:
        What was copied, updated and kept.

    Raises:
        CourseError: If the source is not a course folder, the target is inside it, or the target exists and is
            neither empty nor a workspace.
    """

    workspace = Path(target).expanduser().resolve() if target is not None else default_workspace()
    src = Path(source).expanduser().resolve() if source is not None else _installed_course(workspace)
    if not (src / "tests" / "tasks").is_dir() or not (src / "exercises").is_dir():
        raise CourseError("course folder", str(src), "is not an installed course (it needs exercises/ and "
                          "tests/tasks/); give the shared clone, e.g. --from /opt/rrbot_workshop")
    if workspace == src or workspace.is_relative_to(src):
        raise CourseError("workspace", str(workspace), f"must be outside the installed course '{src}'")
    if workspace.exists() and not workspace.is_dir():
        raise CourseError("workspace", str(workspace), "is a file; give a folder (default ~/rrbot_workshop)")
    created = not (workspace / MARKER).is_file()
    if created and workspace.exists() and any(workspace.iterdir()):
        raise CourseError("workspace", str(workspace), "exists, is not empty and is not a workspace made by "
                          "`rrbot-workshop init`; give a new folder")
    result = InitResult(workspace, created)
    try:
        _fill(src, workspace, result, now)
    except OSError as exc:
        raise CourseError("workspace", str(workspace), f"{workspace} cannot be written ({exc.strerror or exc}); give a folder "
                          "you can write, e.g. ~/rrbot_workshop (what was copied so far is kept)") from None
    return result


def _fill(src: Path, workspace: Path, result: InitResult, now: float | None) -> None:
    """Copy and update the workspace's files (see :func:`init_workspace`)."""
    from rrbot_workshop.classroom.launcher import refresh_notebook_copies

    workspace.mkdir(parents=True, exist_ok=True)
    _copy_course_files(src, workspace)

    new = {f"exercises/{k}": v for k, v in _files(src / "exercises").items() if k != "README.md"}
    old = _handed_out(workspace)
    for rel, data in new.items():
        path = workspace / rel
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
            result.added.append(rel)
            continue
        mine = path.read_bytes()
        if mine == data or old.get(rel) == data:
            continue  # the same, or the course did not change it: the learner's file stays
        if rel in old and _digest(mine) == _digest(old[rel]):
            path.write_bytes(data)  # the learner never changed it: the course's update replaces it
            result.updated.append(rel)
        else:
            path.with_name(path.name + ".course-update").write_bytes(data)
            result.kept.append(rel)
    _write_archive(workspace, new)
    result.notebooks = refresh_notebook_copies(workspace, now)
    try:
        made = float(json.loads((workspace / MARKER).read_text())["made"])
    except (OSError, ValueError, KeyError, TypeError):
        made = time.time()
    marker = {"source": str(src), "made": made, "updated": time.time()}
    (workspace / MARKER).write_text(json.dumps(marker, indent=1) + "\n")


def singleuser_command(workspace: Path, args: list[str]) -> list[str]:
    """The JupyterHub single-user server for a learner: JupyterLab at their workspace, opening their intro, with the
    same hidden folders as on a laptop (``args`` are the spawner's). It is the hub's ``jupyterhub-singleuser`` of
    this Python, started lighter (:mod:`rrbot_workshop.classroom.server`)."""
    import sys

    from rrbot_workshop.classroom.launcher import HIDDEN
    from rrbot_workshop.classroom.server import extension_args

    return [sys.executable, "-m", "rrbot_workshop.classroom.server", f"--ServerApp.root_dir={workspace}",
            "--ServerApp.default_url=/lab/tree/my_notebooks/00_intro.ipynb",
            f"--ContentsManager.hide_globs={list(HIDDEN)!r}", *extension_args(), *args]
