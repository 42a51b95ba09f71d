"""The instructor's tools: restore an exercise (after backing up the learner's work) and hand out a course copy.

The pristine version of ``exercises/taskNN_<name>/`` comes from git (``HEAD``) when the course is a git
checkout that tracks it. A student copy made by :func:`export_student_copy` is built from git ``HEAD`` and is a
git repository of its own; it also carries the exercises in ``.pristine/exercises.tar.gz``, so
``rrbot-workshop reset`` works in a copy whose ``.git`` was removed.
"""

from __future__ import annotations

import io
import logging
import os
import re
import shutil
import subprocess
import tarfile
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path, PurePosixPath

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading.references import readme_section, write_withheld_copy
from rrbot_workshop.exceptions import CourseError

__all__ = ["PRISTINE_ARCHIVE", "EXPORT_EXCLUDE", "ResetResult", "pristine_files", "reset_exercise",
           "export_student_copy", "uncommitted_changes"]

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
        try:
            shutil.copytree(folder, backup)
        except OSError as exc:
            shutil.rmtree(backup, ignore_errors=True)
            raise CourseError("backup folder", str(backup.parent),
                              f"cannot back up your files there ({exc.strerror or exc}); nothing was changed. Make "
                              "'backups/' writable (or free some space) and reset again") from None
    # the pristine files go to a folder beside the exercise first; the learner's folder is swapped out only once
    # they are all written, so a failure half-way leaves the learner's files where they were
    fresh = folder.with_name(f".{folder.name}.reset")
    old = folder.with_name(f".{folder.name}.old")
    for leftover in (fresh, old):
        shutil.rmtree(leftover, ignore_errors=True)
    try:
        for rel, content in sorted(files.items()):
            target = fresh / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(content)
        if folder.exists():
            folder.rename(old)
        try:
            fresh.rename(folder)
        except OSError:
            if old.exists():
                old.rename(folder)
            raise
    except OSError as exc:
        shutil.rmtree(fresh, ignore_errors=True)
        raise CourseError("exercise folder", str(folder),
                          f"could not be restored ({exc.strerror or exc}); your files are unchanged"
                          + (f" and also saved in {backup}" if backup else "")) from None
    shutil.rmtree(old, ignore_errors=True)
    logger.info("restored %s from %s (backup: %s)", folder, source, backup)
    return ResetResult(folder=folder, backup=backup, source=source, files=len(files))


def _ignore(root: Path) -> Callable[[str, list[str]], set[str]]:
    def ignore(directory: str, names: list[str]) -> set[str]:
        skipped = {n for n in names if n in EXPORT_EXCLUDE or n.endswith(".egg-info")}
        if Path(directory).resolve() == root:
            skipped |= {n for n in names if n in EXPORT_EXCLUDE_TOP}
        return skipped

    return ignore


def _git_snapshot(root: Path) -> dict[str, bytes] | None:
    """Every file committed at ``HEAD`` (course-relative POSIX path -> bytes), or None without git or a commit."""
    if shutil.which("git") is None or not (root / ".git").exists():
        return None
    result = _git(root, "archive", "--format=zip", "HEAD")
    if result.returncode != 0:
        return None
    with zipfile.ZipFile(io.BytesIO(result.stdout)) as archive:
        return {info.filename: archive.read(info) for info in archive.infolist() if not info.is_dir()}


def uncommitted_changes(root: Path) -> list[str]:
    """Tracked files of the course that differ from ``HEAD`` (they are not part of a student copy)."""
    if shutil.which("git") is None or not (root / ".git").exists():
        return []
    result = _git(root, "status", "--porcelain", "--untracked-files=no")
    return [line[3:] for line in result.stdout.decode(errors="replace").splitlines() if line.strip()]


def _student_readme(text: str) -> str:
    """The README without its instructor-only parts (between ``<!-- instructor -->`` and ``<!-- /instructor -->``)."""
    return re.sub(r"<!-- instructor -->.*?<!-- /instructor -->\n?", "", text, flags=re.DOTALL)


def _with_section(text: str, section: str) -> str:
    """``text`` with ``section`` before its "## License" heading (at the end if it has none)."""
    at = text.find("\n## License")
    return text.rstrip("\n") + "\n" + section if at < 0 else text[:at].rstrip("\n") + "\n" + section + text[at:]


def _exported(rel: str) -> bool:
    parts = PurePosixPath(rel).parts
    return not (parts[0] in EXPORT_EXCLUDE_TOP or any(p in EXPORT_EXCLUDE or p.endswith(".egg-info") for p in parts))


def export_student_copy(dest: str | os.PathLike[str], *, withhold_references: bool = False) -> Path:
    """Write a copy of the course for learners, as released: the files committed at git ``HEAD``, no ``solutions/``.

    The copy is built from git, never from the working tree, so an instructor's solved exercises or edits that are
    not committed never reach learners (:func:`uncommitted_changes` lists what was left out). The README loses its
    instructor-only parts. The copy is itself a git repository with one commit, so its own test command and
    ``rrbot-workshop reset`` find the pristine exercises the same way; ``.pristine/exercises.tar.gz`` is kept for a
    copy whose ``.git`` is removed. A course folder that is not a git checkout is copied as it is (with a warning).

    The copy's README lists what the library itself contains that answers tasks
    (:data:`~rrbot_workshop.course.grading.references.REFERENCES`).

    Args:
        dest: New folder (must not exist, or be empty, and must be outside the course folder).
        withhold_references: Replace the library's Python references (the task-7 driver, the task-8 controller, the
            task-13 planner) by stand-ins (see :mod:`rrbot_workshop.course.grading.references`).

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
    snapshot = _git_snapshot(root)
    if snapshot is None:
        logger.warning("%s is not a git checkout: the student copy is made from the working tree", root)
        shutil.copytree(root, target, ignore=_ignore(root), dirs_exist_ok=True)
    else:
        target.mkdir(parents=True, exist_ok=True)
        for rel, data in snapshot.items():
            if not _exported(rel):
                continue
            path = target / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
            if rel in ("workshop", "workshop.py", ".ci/run"):
                path.chmod(0o755)
    if withhold_references:
        write_withheld_copy(target)
    readme = target / "README.md"
    if readme.is_file():
        readme.write_text(_with_section(_student_readme(readme.read_text()), readme_section(withhold_references)))
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
    if snapshot is not None:
        _init_repository(target)
    logger.info("wrote a student copy of %s to %s", root, target)
    return target


def _init_repository(target: Path) -> None:
    """Make the copy a git repository with one commit of everything in it (best effort: git may be missing)."""
    identity = {"GIT_AUTHOR_NAME": "rrbot_workshop", "GIT_AUTHOR_EMAIL": "course@rrbot-workshop.invalid",
                "GIT_COMMITTER_NAME": "rrbot_workshop", "GIT_COMMITTER_EMAIL": "course@rrbot-workshop.invalid"}
    env = {k: v for k, v in os.environ.items() if k not in ("GIT_DIR", "GIT_WORK_TREE", "GIT_INDEX_FILE")}
    env.update(identity)
    for args in (["init", "-q"], ["add", "-A"], ["commit", "-q", "-m", "rrbot_workshop course, student copy"]):
        result = subprocess.run(["git", *args], cwd=target, env=env, capture_output=True, check=False)
        if result.returncode != 0:
            logger.warning("the student copy is not a git repository (git %s: %s)", args[0],
                           result.stderr.decode(errors="replace").strip())
            return
