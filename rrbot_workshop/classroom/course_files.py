"""The course's own files in a learner's workspace: replaced by the installed course's at every start, with whatever
the learner changed or added among them kept.

A workspace holds copies of the course's files that a course folder needs (:data:`COURSE_FILES`: the README,
``notebooks/``, ``descriptions/``, the graders, ``exercises/README.md``). They are the course's: every start replaces
them. A learner may still have changed one, or saved a file of their own among them; :class:`CourseFiles` tells the
two apart by the record the workspace's marker keeps, the sha256 of every file the course copied there. A file
whose content is not in the record is the learner's: it stays where it was, or, where the course has a file of that
name, beside it as ``<name>.yours`` with one line saying so. A workspace with no record (made by an earlier version)
has its course files replaced whole, as it always had.

Each file is written atomically and each folder is copied beside its place and swapped in; the record written before
a swap holds the digests of both the old and the new copies, so a start killed half-way leaves nothing that the next
start would mistake for the learner's, and nothing of the learner's that it would mistake for the course's.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import stat
from pathlib import Path

from rrbot_workshop.classroom.launcher import (
    aside_name,
    clear_for_file,
    make_folder,
    move_aside,
    regular_file_bytes,
    write_atomically,
)

__all__ = ["COURSE_FILES", "SKIP", "CourseFiles", "course_digests"]

#: What a workspace copies from the course, course-relative; replaced on every update (the course's, not the learner's).
COURSE_FILES = ("README.md", "notebooks", "descriptions", "tests/conftest.py", "tests/tasks", "exercises/README.md")
#: Folders never copied nor kept (caches).
SKIP = frozenset({"__pycache__", ".ipynb_checkpoints", ".progress", "_generated"})
#: A file larger than this [bytes] is never a course file: it is the learner's without being read.
_COURSE_FILE_MAX_BYTES = 64 * 1024 * 1024


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def course_digests(src: Path) -> dict[str, str]:
    """The sha256 of every file of :data:`COURSE_FILES` in the course ``src``, by course-relative POSIX path."""
    out: dict[str, str] = {}
    for rel in COURSE_FILES:
        source = src / rel
        if source.is_dir():
            for path in sorted(source.rglob("*")):
                sub = path.relative_to(source)
                if path.is_file() and not set(sub.parts) & SKIP:
                    out[f"{rel}/{sub.as_posix()}"] = _sha(path.read_bytes())
        elif source.is_file():
            out[rel] = _sha(source.read_bytes())
    return out


class CourseFiles:
    """Replaces the course's own files in a workspace by the installed course's, keeping the learner's changes.

    Attributes:
        src: The installed course.
        workspace: The learner's workspace.
        new: The sha256 of each course file as installed now, by workspace-relative path.
        known: Every sha256 a copy of the course's may have at each path in the workspace (the marker's record), or
            None when the workspace has no record (its course files are replaced whole).
        notes: Where a line goes for each learner's file kept beside the course's.
    """

    def __init__(self, src: Path, workspace: Path, known: dict[str, list[str]] | None, notes: list[str]) -> None:
        self.src, self.workspace, self.known, self.notes = src, workspace, known, notes
        self.new = course_digests(src)

    def record_during(self) -> dict[str, list[str]]:
        """The record to keep while the copy runs: the old digests and the new ones."""
        paths = sorted(set(self.new) | set(self.known or {}))
        return {p: sorted(set((self.known or {}).get(p, [])) | ({self.new[p]} if p in self.new else set()))
                for p in paths}

    def record_after(self) -> dict[str, list[str]]:
        """The record once the copy is done: the new digests."""
        return {p: [d] for p, d in sorted(self.new.items())}

    def _is_courses(self, rel: str, path: Path) -> bool:
        """True if ``path`` (at workspace-relative ``rel``) is a regular file with content a copy of the course's had
        there (always, without a record)."""
        if self.known is None:
            return True
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            return True
        if not stat.S_ISREG(info.st_mode) or info.st_size > _COURSE_FILE_MAX_BYTES:
            return False
        data = regular_file_bytes(path, _COURSE_FILE_MAX_BYTES)
        if data is None:
            return False
        digest = _sha(data)
        return digest == self.new.get(rel) or digest in self.known.get(rel, ())

    def copy(self) -> None:
        """Copy every course file and folder into the workspace (see the module's documentation)."""
        for rel in COURSE_FILES:
            source = self.src / rel
            if source.is_dir():
                self._copy_folder(rel, source)
            elif source.is_file():
                data = source.read_bytes()
                dst = clear_for_file(self.workspace, rel, self.notes)
                if regular_file_bytes(dst, len(data)) == data:
                    continue
                if not self._is_courses(rel, dst):
                    self._kept_beside(rel, dst, dst)
                write_atomically(dst, data, source.stat().st_mode & 0o777)

    def _copy_folder(self, rel: str, source: Path) -> None:
        parent = make_folder(self.workspace, str(Path(rel).parent), self.notes)
        dst = parent / Path(rel).name
        staging, old = dst.with_name(f".{dst.name}.new"), dst.with_name(f".{dst.name}.old")
        if _is_folder(old):  # a swap that was killed: finish it
            if not os.path.lexists(dst):
                os.rename(old, dst)
            else:
                self._keep_learners(old, rel, dst)
        _remove(old)
        _remove(staging)
        shutil.copytree(source, staging, ignore=shutil.ignore_patterns(*SKIP))
        if os.path.lexists(dst):
            if _is_folder(dst):
                os.rename(dst, old)
            else:
                move_aside(dst, self.workspace, self.notes, "a folder")
        os.rename(staging, dst)
        if _is_folder(old):
            self._keep_learners(old, rel, dst)
            _remove(old)

    def _keep_learners(self, old: Path, rel: str, dst: Path) -> None:
        """Move every file of the learner's in the old copy ``old`` of the course folder ``rel`` into the new copy
        ``dst``: to the same place, or beside the course's file of the same name. A folder of the learner's where the
        new copy has a file goes beside that file whole."""
        for folder, dirs, files in os.walk(old, followlinks=False):
            entries = list(files)
            for name in list(dirs):
                path = Path(folder) / name
                if name in SKIP:
                    dirs.remove(name)
                elif path.is_symlink():  # a link to a folder: the learner's, not followed
                    dirs.remove(name)
                    entries.append(name)
                elif os.path.lexists(dst / path.relative_to(old)) and not _is_folder(dst / path.relative_to(old)):
                    dirs.remove(name)
                    if self._holds_learners(path, f"{rel}/{path.relative_to(old).as_posix()}"):
                        self._kept_beside(f"{rel}/{path.relative_to(old).as_posix()}", path,
                                          dst / path.relative_to(old))
            for name in entries:
                path = Path(folder) / name
                sub = path.relative_to(old)
                here = f"{rel}/{sub.as_posix()}"
                if self._is_courses(here, path):
                    continue
                target = make_folder(self.workspace, str(Path(rel) / sub.parent), self.notes) / name
                if os.path.lexists(target):
                    self._kept_beside(here, path, target)
                else:
                    os.rename(path, target)

    def _holds_learners(self, folder: Path, rel: str) -> bool:
        """True if anything under ``folder`` (at workspace-relative ``rel``) is the learner's."""
        for sub, dirs, files in os.walk(folder, followlinks=False):
            for name in files + dirs:
                path = Path(sub) / name
                if (path.is_symlink() or not path.is_dir()) and not self._is_courses(
                        f"{rel}/{path.relative_to(folder).as_posix()}", path):
                    return True
        return False

    def _kept_beside(self, rel: str, path: Path, place: Path) -> None:
        """Rename the learner's ``path`` beside ``place`` (where the course's file or folder goes) and say so."""
        aside = aside_name(place)
        os.rename(path, aside)
        if rel in self.new or (self.known and rel in self.known):
            self.notes.append(f"{rel}: you changed this file of the course's; the course's is in its place and yours "
                              f"is kept beside it as {aside.name}")
        else:
            what = "folder" if _is_folder(place) else "file"
            self.notes.append(f"{rel}: yours stands where the course now has a {what}; yours is kept beside it as "
                              f"{aside.name}")


def _is_folder(path: Path) -> bool:
    try:
        return stat.S_ISDIR(os.lstat(path).st_mode)
    except FileNotFoundError:
        return False


def _remove(path: Path) -> None:
    """Remove one of the names a copy stages under (a folder, or a file or link at that name)."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    if stat.S_ISDIR(mode):
        shutil.rmtree(path)
    else:
        os.unlink(path)
