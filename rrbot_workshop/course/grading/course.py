"""The instructor's tools: restore an exercise (after backing up the learner's work) and hand out a course copy.

The pristine version of ``exercises/taskNN_<name>/`` comes from git (``HEAD``) when the course is a git
checkout that tracks it. A student copy made by :func:`export_student_copy` has no ``.git``; it carries the
exercises as exported in ``.pristine/exercises.tar.gz`` instead, so ``rrbot-workshop reset`` works there too.
"""

from __future__ import annotations

import io
import logging
import os
import shutil
import subprocess
import tarfile
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path, PurePosixPath

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError

__all__ = ["PRISTINE_ARCHIVE", "EXPORT_EXCLUDE", "ResetResult", "pristine_files", "reset_exercise",
           "export_student_copy"]

logger = logging.getLogger(__name__)

#: Archive of the exercises as handed out, relative to the course folder (written by :func:`export_student_copy`).
PRISTINE_ARCHIVE = PurePosixPath(".pristine/exercises.tar.gz")
#: Names never copied into a student copy (at any depth).
EXPORT_EXCLUDE = frozenset({
    ".git", ".venv", "venv", "__pycache__", ".pytest_cache", ".mypy_cache", ".ruff_cache", ".ipynb_checkpoints",
})
#: Top-level folders never copied into a student copy.
EXPORT_EXCLUDE_TOP = frozenset({"solutions", "backups", ".pristine", "build", "dist"})


def _git(root: Path, *args: str) -> subprocess.CompletedProcess[bytes]:
    # The course folder decides which repository is asked, not a GIT_DIR inherited from the caller.
    env = {k: v for k, v in os.environ.items() if k not in ("GIT_DIR", "GIT_WORK_TREE", "GIT_INDEX_FILE")}
    return subprocess.run(["git", *args], cwd=root, env=env, capture_output=True, check=False)


def _git_pristine(root: Path, folder: str) -> dict[str, bytes] | None:
    """Files under ``folder`` (course-relative, POSIX) at git ``HEAD``, or None if git does not know them."""
    if shutil.which("git") is None:
        return None
    listing = _git(root, "ls-tree", "-r", "-z", "--name-only", "HEAD", "--", folder + "/")
    if listing.returncode != 0:
        return None
    names = [n for n in listing.stdout.decode().split("\0") if n]
    if not names:
        return None
    files: dict[str, bytes] = {}
    for name in names:
        blob = _git(root, "show", f"HEAD:./{name}")
        if blob.returncode != 0:
            return None
        files[str(PurePosixPath(name).relative_to(folder))] = blob.stdout
    return files


def _archive_pristine(root: Path, folder: str) -> dict[str, bytes] | None:
    archive = root / PRISTINE_ARCHIVE
    if not archive.is_file():
        return None
    files: dict[str, bytes] = {}
    with tarfile.open(archive, "r:gz") as tar:
        for member in tar.getmembers():
            path = PurePosixPath(member.name)
            if not member.isfile() or ".." in path.parts or path.is_absolute():
                continue
            if path.parts[: len(PurePosixPath(folder).parts)] == PurePosixPath(folder).parts:
                extracted = tar.extractfile(member)
                if extracted is not None:
                    files[str(path.relative_to(folder))] = extracted.read()
    return files or None


def pristine_files(task: int) -> tuple[dict[str, bytes], str]:
    """The files of ``exercises/taskNN_<name>/`` as handed out.

    Args:
        task: Task number.

    Returns:
        ``(files, source)``: path relative to the task folder -> content, and ``"git"`` or ``"archive"``.

    Raises:
        CourseError: If the task does not exist or no pristine copy is found.
    """
    root = tracks.course_root()
    folder = f"exercises/{tracks.task_name(task)}"
    files = _git_pristine(root, folder)
    if files is not None:
        return files, "git"
    files = _archive_pristine(root, folder)
    if files is not None:
        return files, "archive"
    raise CourseError(
        "task", task,
        f"no pristine copy of {folder}/: git HEAD does not track it and there is no {PRISTINE_ARCHIVE}",
    )


@dataclass(frozen=True)
class ResetResult:
    """What :func:`reset_exercise` did.

    Attributes:
        folder: The restored exercise folder.
        backup: Where the learner's files were copied, or None if the folder did not exist.
        source: ``"git"`` or ``"archive"``.
        files: Number of files restored.
    """

    folder: Path
    backup: Path | None
    source: str
    files: int


def _backup_dir(root: Path, task: int, now: datetime) -> Path:
    base = root / "backups" / f"task{task:02d}_{now:%Y%m%d-%H%M%S}"
    candidate, n = base, 1
    while candidate.exists():
        n += 1
        candidate = base.with_name(f"{base.name}_{n}")
    return candidate


def reset_exercise(task: int, *, now: datetime | None = None) -> ResetResult:
    """Restore ``exercises/taskNN_<name>/`` to its pristine state, after copying it to ``backups/``.

    The learner's folder is copied whole to ``backups/taskNN_<YYYYmmdd-HHMMSS>/`` first; only then is it
    replaced by the pristine files (files the learner added are removed from the exercise, kept in the backup).

    Args:
        task: Task number.
        now: Time used in the backup folder's name; default the wall clock.

    Raises:
        CourseError: If the task does not exist or no pristine copy is found (nothing is changed then).
    """
    root = tracks.course_root()
    files, source = pristine_files(task)
    folder = root / "exercises" / tracks.task_name(task)
    backup: Path | None = None
    if folder.exists():
        backup = _backup_dir(root, task, now or datetime.now())
        shutil.copytree(folder, backup)
        shutil.rmtree(folder)
    for rel, content in sorted(files.items()):
        target = folder / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(content)
    logger.info("restored %s from %s (backup: %s)", folder, source, backup)
    return ResetResult(folder=folder, backup=backup, source=source, files=len(files))


def _ignore(root: Path) -> Callable[[str, list[str]], set[str]]:
    def ignore(directory: str, names: list[str]) -> set[str]:
        skipped = {n for n in names if n in EXPORT_EXCLUDE or n.endswith(".egg-info")}
        if Path(directory).resolve() == root:
            skipped |= {n for n in names if n in EXPORT_EXCLUDE_TOP}
        return skipped

    return ignore


def export_student_copy(dest: str | os.PathLike[str]) -> Path:
    """Write a copy of the course for learners: no ``solutions/``, no ``.git``, no ``.venv``, no backups.

    The copy still grades (graders use the exercises track) and carries ``.pristine/exercises.tar.gz`` so
    ``rrbot-workshop reset`` works in it.

    Args:
        dest: New folder (must not exist, or be empty, and must be outside the course folder).

    Returns:
        The copy's folder.

    Raises:
        CourseError: If ``dest`` is not empty or lies inside the course folder.
    """
    root = tracks.course_root()
    target = Path(dest).expanduser().resolve()
    if target == root or target.is_relative_to(root):
        raise CourseError("folder", str(target), f"the student copy must be outside the course folder '{root}'")
    if target.exists() and (not target.is_dir() or any(target.iterdir())):
        raise CourseError("folder", str(target), f"'{target}' exists and is not an empty folder")
    shutil.copytree(root, target, ignore=_ignore(root), dirs_exist_ok=True)
    archive = target / PRISTINE_ARCHIVE
    archive.parent.mkdir(parents=True, exist_ok=True)
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz") as tar:
        exercises = target / "exercises"
        if exercises.is_dir():
            for path in sorted(p for p in exercises.rglob("*") if p.is_file()):
                rel = path.relative_to(target).as_posix()
                info = tarfile.TarInfo(rel)
                data = path.read_bytes()
                info.size = len(data)
                info.mode = 0o644
                tar.addfile(info, io.BytesIO(data))
    archive.write_bytes(buffer.getvalue())
    logger.info("wrote a student copy of %s to %s", root, target)
    return target
