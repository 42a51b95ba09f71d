"""The instructor's tools: restore an exercise (after backing up the learner's work) and hand out a course copy.

The pristine version of ``exercises/taskNN_<name>/`` comes from git (``HEAD``) when the course is a git
checkout that tracks it. A student copy made by :func:`export_student_copy` is built from git ``HEAD`` and is a
git repository of its own; it also carries the exercises in ``.pristine/exercises.tar.gz``, so
``rrbot-workshop reset`` works in a copy whose ``.git`` was removed.
"""

from __future__ import annotations

import gzip
import io
import logging
import os
import re
import shutil
import stat
import subprocess
import tarfile
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path, PurePosixPath

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading.references import (
    README_END,
    README_MARK,
    instructor_only,
    readme_section,
    write_withheld_copy,
)
from rrbot_workshop.exceptions import CourseError

__all__ = ["PRISTINE_ARCHIVE", "EXPORT_EXCLUDE", "ResetResult", "pristine_files", "reset_exercise",
           "export_student_copy", "uncommitted_changes", "read_pristine_archive", "pristine_archive_bytes",
           "ARCHIVE_MAX_MEMBERS", "ARCHIVE_MAX_BYTES"]

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


#: What a pristine archive may hold: members, bytes in all (unpacked) and bytes read from disk. A course's exercises are
#: a few hundred kB; the archive sits in a learner's folder, where it may be damaged or replaced by anything.
ARCHIVE_MAX_MEMBERS = 10_000
ARCHIVE_MAX_BYTES = 256 * 1024 * 1024


def read_pristine_archive(archive: Path) -> dict[str, bytes]:
    """The files of a pristine archive (course-relative POSIX path -> bytes), read within bounds.

    Only regular files with a relative path that stays inside the course are taken (links, folders and ``..`` are
    skipped). The archive itself must be a regular file: a link, a FIFO or a device is never opened.

    Args:
        archive: The ``.tar.gz`` file (:data:`PRISTINE_ARCHIVE` in a course folder).

    Raises:
        CourseError: If the archive is missing, not a regular file, damaged (truncated, not gzip, not tar) or larger
            than :data:`ARCHIVE_MAX_BYTES` unpacked or :data:`ARCHIVE_MAX_MEMBERS` members.
    """
    def damaged(why: str) -> CourseError:
        return CourseError("pristine archive", str(archive), f"{archive} {why}")

    try:
        info = os.lstat(archive)
    except OSError as exc:
        raise damaged(f"cannot be read ({exc.strerror or exc})") from None
    if not stat.S_ISREG(info.st_mode):
        raise damaged("is not a regular file")
    if info.st_size > ARCHIVE_MAX_BYTES:
        raise damaged(f"is {info.st_size} bytes, more than the {ARCHIVE_MAX_BYTES} an archive of exercises may have")
    files: dict[str, bytes] = {}
    total = 0
    try:
        fd = os.open(archive, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as raw, tarfile.open(fileobj=raw, mode="r:gz") as tar:
            for count, member in enumerate(tar, start=1):
                if count > ARCHIVE_MAX_MEMBERS:
                    raise damaged(f"holds more than {ARCHIVE_MAX_MEMBERS} members")
                path = PurePosixPath(member.name)
                if not member.isfile() or ".." in path.parts or path.is_absolute():
                    continue
                total += member.size
                if total > ARCHIVE_MAX_BYTES:
                    raise damaged(f"unpacks to more than {ARCHIVE_MAX_BYTES} bytes")
                extracted = tar.extractfile(member)
                if extracted is not None:
                    files[str(path)] = extracted.read(member.size)
    except CourseError:
        raise
    except (tarfile.TarError, EOFError, OSError, zlib.error, ValueError) as exc:
        raise damaged(f"is damaged ({type(exc).__name__}: {exc})") from None
    return files


def pristine_archive_bytes(files: dict[str, bytes]) -> bytes:
    """A pristine archive of ``files`` (course-relative POSIX path -> bytes), the same bytes for the same files."""
    buffer = io.BytesIO()
    with gzip.GzipFile(fileobj=buffer, mode="wb", mtime=0) as packed, tarfile.open(fileobj=packed, mode="w") as tar:
        for rel, data in sorted(files.items()):
            info = tarfile.TarInfo(rel)
            info.size, info.mode, info.mtime = len(data), 0o644, 0
            tar.addfile(info, io.BytesIO(data))
    return buffer.getvalue()


def _archive_pristine(root: Path, folder: str) -> dict[str, bytes] | None:
    archive = root / PRISTINE_ARCHIVE
    if not os.path.lexists(archive):
        return None
    try:
        everything = read_pristine_archive(archive)
    except CourseError as exc:
        raise CourseError("pristine archive", str(archive), f"{exc}; in a workspace, `rrbot-workshop init` rebuilds it "
                          "from the installed course") from None
    prefix = PurePosixPath(folder).parts
    files = {str(PurePosixPath(rel).relative_to(folder)): data for rel, data in everything.items()
             if PurePosixPath(rel).parts[: len(prefix)] == prefix}
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
    """A new, empty backup folder ``backups/taskNN_<YYYYmmdd-HHMMSS>/`` (``..._2/``, ... when the name is taken): it is
    made here, with an exclusive mkdir, so two resets in the same second never share one."""
    base = root / "backups" / f"task{task:02d}_{now:%Y%m%d-%H%M%S}"
    base.parent.mkdir(parents=True, exist_ok=True)
    for n in range(1, 10_000):
        candidate = base if n == 1 else base.with_name(f"{base.name}_{n}")
        try:
            candidate.mkdir()
            return candidate
        except FileExistsError:
            continue
    raise FileExistsError(f"no free backup folder name for {base}")


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
        try:
            backup = _backup_dir(root, task, now or datetime.now())
            shutil.copytree(folder, backup, symlinks=True, dirs_exist_ok=True)
        except OSError as exc:
            if backup is not None:
                shutil.rmtree(backup, ignore_errors=True)
            raise CourseError("backup folder", str(root / "backups"),
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
        here = Path(directory).resolve()
        if here == root:
            skipped |= {n for n in names if n in EXPORT_EXCLUDE_TOP}
        rel = here.relative_to(root) if here.is_relative_to(root) else None
        if rel is not None:
            skipped |= {n for n in names if instructor_only((rel / n).as_posix())
                        or instructor_only((rel / n).as_posix() + "/x")}
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
    """``text`` with ``section`` before its "## License" heading (at the end if it has none), in place of the one an
    earlier export wrote (a copy of a student copy)."""
    text = re.sub(re.escape(README_MARK) + ".*?" + re.escape(README_END), "\n", text, flags=re.DOTALL)
    at = text.find("\n## License")
    return text.rstrip("\n") + "\n" + section if at < 0 else text[:at].rstrip("\n") + "\n" + section + text[at:]


def _exported(rel: str) -> bool:
    parts = PurePosixPath(rel).parts
    return not (parts[0] in EXPORT_EXCLUDE_TOP or any(p in EXPORT_EXCLUDE or p.endswith(".egg-info") for p in parts)
                or instructor_only(rel))


def export_student_copy(dest: str | os.PathLike[str], *, withhold_references: bool = False) -> Path:
    """Write a copy of the course for learners, as released: the files committed at git ``HEAD``, no ``solutions/`` and
    none of the graders' own wrong and right solutions (:data:`~rrbot_workshop.course.grading.references.INSTRUCTOR_ONLY`).

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
            source = root / rel  # executable as in the checkout (git keeps the mode): scripts, binder/start
            if rel in ("workshop", "workshop.py", ".ci/run") or (source.is_file() and source.stat().st_mode & 0o111):
                path.chmod(0o755)
    if withhold_references:
        write_withheld_copy(target)
    readme = target / "README.md"
    if readme.is_file():
        readme.write_text(_with_section(_student_readme(readme.read_text()), readme_section(withhold_references)))
    archive = target / PRISTINE_ARCHIVE
    archive.parent.mkdir(parents=True, exist_ok=True)
    exercises = target / "exercises"
    handed_out = ({path.relative_to(target).as_posix(): path.read_bytes()
                   for path in sorted(exercises.rglob("*")) if path.is_file()} if exercises.is_dir() else {})
    archive.write_bytes(pristine_archive_bytes(handed_out))
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
