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
laptop: the course's own files are replaced (what the learner changed or added among them is kept, see
:mod:`~rrbot_workshop.classroom.course_files`); an exercise file is updated only where the learner never changed it
(it still equals the version handed out), and a changed one is kept, with the new version beside it as
``<name>.course-update``; new tasks' folders are added; a notebook copy the course updated is moved to
``my_notebooks/backups/`` first.

A workspace always starts:

* Every file ``init`` writes is written beside its place and renamed over it; a folder of the course's is copied
  beside its place and swapped in. Killed at any moment, ``init`` leaves each file old or new, never cut short, and
  the next ``init`` finishes the update. The record of what was handed out (``.pristine/exercises.tar.gz``) is
  written last, once the exercise files it describes are in place.
* A damaged record (the archive, the marker file, the notebook index) is rebuilt from the installed course, with one
  line saying so; with no trustworthy record, every exercise file that differs from the course's is taken as the
  learner's and kept.
* Where the learner has a file and the course now needs a folder, or the other way round (or a link, which ``init``
  never writes through), the learner's version is renamed beside it (``<name>.yours``), one line names it, and the
  update goes on.
* The workspace follows the course as installed now (``$RRBOT_WORKSHOP_ROOT``, else the course this library belongs
  to); when that is not the course it was made from, one line says so.
* The workspace folder may be a link of the learner's to a folder elsewhere (that folder is the workspace); below it,
  no link is followed.
"""

from __future__ import annotations

import json
import os
import stat
import time
from dataclasses import dataclass, field
from pathlib import Path

from rrbot_workshop.classroom.course_files import COURSE_FILES, SKIP, CourseFiles
from rrbot_workshop.classroom.launcher import (
    PARTIAL_SUFFIX,
    clear_for_file,
    make_folder,
    move_aside,
    refresh_notebook_copies,
    regular_file_bytes,
    write_atomically,
)
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading.course import (
    ARCHIVE_MAX_BYTES,
    PRISTINE_ARCHIVE,
    pristine_archive_bytes,
    read_pristine_archive,
)
from rrbot_workshop.exceptions import CourseError

__all__ = ["MARKER", "COURSE_FILES", "InitResult", "init_workspace", "default_workspace", "singleuser_command",
           "installed_course", "is_workspace"]

#: The file that marks a folder as a workspace made by :func:`init_workspace` (what it was made from, and when).
MARKER = ".rrbot_workshop_workspace.json"
_ARCHIVE = PRISTINE_ARCHIVE.as_posix()
#: The largest marker file read [bytes] (it holds a digest per course file).
_MARKER_MAX_BYTES = 4 * 1024 * 1024


@dataclass
class InitResult:
    """What :func:`init_workspace` did.

    Attributes:
        workspace: The learner's workspace.
        created: True when it was made now, False when it was updated.
        source: The installed course it was made or updated from.
        added: Exercise files copied (new tasks, or files the learner does not have).
        updated: Exercise files the course changed and the learner had not: replaced.
        kept: Exercise files the course changed and the learner had: kept, the course's beside them.
        notebooks: One line per notebook copied to or refreshed in ``my_notebooks/``.
        notes: One line per problem met and dealt with (a damaged record rebuilt, a learner's file kept beside the
            place the course needed, the course moved).
    """

    workspace: Path
    created: bool
    source: Path | None = None
    added: list[str] = field(default_factory=list)
    updated: list[str] = field(default_factory=list)
    kept: list[str] = field(default_factory=list)
    notebooks: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def default_workspace() -> Path:
    """``~/rrbot_workshop``."""
    return Path.home() / "rrbot_workshop"


def is_workspace(folder: Path) -> bool:
    """True if ``folder`` (or the folder a link of the learner's there leads to) is marked as a workspace by
    :func:`init_workspace`."""
    try:
        return stat.S_ISDIR(os.stat(folder).st_mode) and os.path.lexists(folder / MARKER)
    except OSError:
        return False


def _is_course(folder: Path) -> bool:
    return (folder / "tests" / "tasks").is_dir() and (folder / "exercises").is_dir()


def _files(folder: Path) -> dict[str, bytes]:
    out = {}
    for path in sorted(folder.rglob("*")):
        rel = path.relative_to(folder)
        if path.is_file() and not (set(rel.parts) & SKIP) and not path.name.endswith(PARTIAL_SUFFIX):
            out[rel.as_posix()] = path.read_bytes()
    return out


def _read_marker(workspace: Path, notes: list[str]) -> dict[str, object]:
    """The workspace's marker, or ``{}`` (with a line in ``notes`` when it exists but is damaged)."""
    path = workspace / MARKER
    if not os.path.lexists(path):
        return {}
    data = regular_file_bytes(path, _MARKER_MAX_BYTES)
    try:
        marker = json.loads(data.decode()) if data is not None else None
    except (ValueError, UnicodeDecodeError):
        marker = None
    record = marker.get("course_files", {}) if isinstance(marker, dict) else None
    if (isinstance(marker, dict) and isinstance(marker.get("source", ""), str) and isinstance(record, dict)
            and all(isinstance(v, list) and all(isinstance(d, str) for d in v) for v in record.values())):
        return marker
    notes.append(f"{MARKER} was damaged: it is rebuilt (the workspace follows the course installed now)")
    return {}


def installed_course() -> Path | None:
    """The course as installed now: ``$RRBOT_WORKSHOP_ROOT``, else the course folder this library belongs to (an
    editable install, as on a hub), else None. Never the folder the command runs in: that may be the workspace."""
    override = os.environ.get(tracks.ROOT_ENV)
    if override:
        return Path(override).expanduser().resolve()
    here = Path(__file__).resolve().parents[2]  # classroom/ -> rrbot_workshop/ -> the installed clone
    return here if _is_course(here) else None


def _choose_source(source: str | os.PathLike[str] | None, marker: dict[str, object], created: bool,
                   notes: list[str]) -> Path:
    """The course to copy from: ``source``, else the course installed now, else the one the workspace was made from
    (when it is still there). Says when that is not the course the workspace was made from."""
    made_from = Path(str(marker["source"])) if marker.get("source") else None
    if source is not None:
        src = Path(source).expanduser().resolve()
    else:
        now = installed_course()
        src = now if now is not None else made_from if made_from is not None else Path(__file__).resolve().parents[2]
    if not created and made_from is not None and made_from != src and _is_course(src):
        where = "is no longer there" if not _is_course(made_from) else "is not the course installed now"
        notes.append(f"this workspace was made from the course at {made_from}, which {where}: it now follows the "
                     f"course at {src}")
    return src


def init_workspace(target: str | os.PathLike[str] | None = None, source: str | os.PathLike[str] | None = None,
                   now: float | None = None) -> InitResult:
    """Make a learner's workspace from the installed course, or update one (see the module's docstring).

    Args:
        target: The workspace; default ``~/rrbot_workshop``.
        source: The installed course folder; default the course installed now (``$RRBOT_WORKSHOP_ROOT``, else the
            folder above the installed package when it is a course), else the one the workspace was made from.
        now: Time used in backup folders' names; default now.

    Returns:
        What was copied, updated and kept, and a line per problem met on the way.

    Raises:
        CourseError: If the source is not a course folder, the target is inside it, the target exists and is
            neither empty nor a workspace (or is a file), or a file cannot be written (the message names it; what
            was written so far is whole, and the next ``init`` goes on from there).
    """
    # resolved: a workspace the learner keeps elsewhere through a link of their own is that folder (below it, no link
    # is ever followed)
    given = Path(target if target is not None else default_workspace()).expanduser()
    if given.is_symlink() and not given.exists():
        raise CourseError("workspace", str(given), f"{given} is a link to {os.readlink(given)}, which is not there; "
                          "remove the link, or make the folder it leads to")
    workspace = given.resolve()
    notes: list[str] = []
    created = not os.path.lexists(workspace / MARKER)
    marker = {} if created else _read_marker(workspace, notes)
    src = _choose_source(source, marker, created, notes)
    if not _is_course(src):
        raise CourseError("course folder", str(src), "is not an installed course (it needs exercises/ and "
                          "tests/tasks/); give the shared clone, e.g. --from /opt/rrbot_workshop")
    if workspace == src or workspace.is_relative_to(src):
        raise CourseError("workspace", str(workspace), f"must be outside the installed course '{src}'")
    if os.path.lexists(workspace) and not workspace.is_dir():
        raise CourseError("workspace", str(workspace), "is a file; give a folder (default ~/rrbot_workshop)")
    try:
        occupied = created and workspace.exists() and any(workspace.iterdir())
    except OSError as exc:
        raise CourseError("workspace", str(workspace), f"{workspace} cannot be read ({exc.strerror or exc}); give a "
                          "folder you can read and write") from None
    if occupied:
        raise CourseError("workspace", str(workspace), "exists, is not empty and is not a workspace made by "
                          "`rrbot-workshop init`; give a new folder")
    result = InitResult(workspace, created, source=src, notes=notes)
    try:
        workspace.mkdir(parents=True, exist_ok=True)
        made = marker.get("made")
        made = float(made) if isinstance(made, int | float) else time.time()
        # the record of the course's files: none in a new workspace or a damaged marker (every file that differs
        # from the course's is then the learner's); a workspace made before records were kept has its replaced whole
        known = {} if not marker else marker["course_files"] if "course_files" in marker else None
        course_files = CourseFiles(src, workspace, known, notes)  # type: ignore[arg-type]
        # marked first (a first init killed half-way is still a workspace, finished next time), with the digests of
        # the course's files old and new (a copy killed half-way leaves none the next start takes for the learner's)
        _write_marker(workspace, src, made, None, course_files.record_during(), notes)
        course_files.copy()
        _fill(src, workspace, result, now)
        _write_marker(workspace, src, made, time.time(), course_files.record_after(), notes)
    except OSError as exc:
        where = exc.filename or workspace
        raise CourseError("workspace", str(where), f"{where} cannot be written ({exc.strerror or exc}); every file "
                          "written so far is whole, and the next `rrbot-workshop init` goes on from there. Free some "
                          "space or fix the folder's permissions") from None
    return result


def _write_marker(workspace: Path, src: Path, made: float, updated: float | None, record: dict[str, list[str]],
                  notes: list[str]) -> None:
    marker = {"source": str(src), "made": made, "updated": updated, "course_files": record}
    write_atomically(clear_for_file(workspace, MARKER, notes), (json.dumps(marker, indent=1) + "\n").encode())


def _handed_out(workspace: Path, notes: list[str]) -> dict[str, bytes]:
    """The exercises as the workspace last received them (its pristine archive), workspace-relative; ``{}`` with a
    line in ``notes`` when the archive is damaged (then every file that differs from the course's is kept)."""
    archive = workspace / _ARCHIVE
    if not os.path.lexists(archive):
        return {}
    try:
        return {rel: data for rel, data in read_pristine_archive(archive).items() if rel.startswith("exercises/")}
    except CourseError as exc:
        why = str(exc).removeprefix(f"{archive} ")
        if not stat.S_ISREG(os.lstat(archive).st_mode):  # not ours to remove: kept beside, in this one line
            why += f"; what stood there is kept beside it as {move_aside(archive, workspace, [], 'a file').name}"
        notes.append(f"{_ARCHIVE} could not be read ({why}): it is rebuilt from the installed course; each exercise "
                     "file of yours that differs from the course's is kept, the course's beside it")
        return {}


def _state(workspace: Path, rel: str) -> tuple[str, int]:
    """What stands at ``workspace/rel``, looked at without following any link: ``("missing", 0)``, ``("file",
    size)`` (a regular file), ``("other", 0)`` (a folder, link or special file) or ``("blocked", 0)`` (one of its
    folders is not a real folder: a file, a link)."""
    path = workspace
    for part in Path(rel).parts[:-1]:
        path = path / part
        try:
            if not stat.S_ISDIR(os.lstat(path).st_mode):
                return "blocked", 0
        except FileNotFoundError:
            return "missing", 0
    try:
        info = os.lstat(workspace / rel)
    except FileNotFoundError:
        return "missing", 0
    return ("file", info.st_size) if stat.S_ISREG(info.st_mode) else ("other", 0)


def _update_exercises(src: Path, workspace: Path, result: InitResult) -> dict[str, bytes]:
    """Add, update or keep each exercise file of the course (see the module's docstring); return them all."""
    new = {f"exercises/{k}": v for k, v in _files(src / "exercises").items() if k != "README.md"}
    old = _handed_out(workspace, result.notes)
    for rel, data in new.items():  # first the folders the course writes into where the learner has a file or link
        if old.get(rel) != data and _state(workspace, rel)[0] == "blocked":
            make_folder(workspace, str(Path(rel).parent), result.notes)
    for rel, data in new.items():
        handed = old.get(rel)
        state, size = _state(workspace, rel)
        if state == "file":
            mine = regular_file_bytes(workspace / rel, max(len(data), len(handed or b""))) if size in (
                len(data), len(handed or b"")) else None
            if mine == data or handed == data:
                continue  # the same, or the course did not change it: the learner's file stays
            if handed is not None and mine == handed:
                write_atomically(workspace / rel, data)  # the learner never changed it: the course's update replaces it
                result.updated.append(rel)
            else:
                beside = clear_for_file(workspace, f"{rel}.course-update", result.notes)
                write_atomically(beside, data)
                result.kept.append(rel)
            continue
        if state in ("other", "blocked") and handed == data:
            continue  # the learner made something else of it, and the course did not change it: theirs stays
        write_atomically(clear_for_file(workspace, rel, result.notes), data)
        result.added.append(rel)
    return new


def _fill(src: Path, workspace: Path, result: InitResult, now: float | None) -> None:
    """Update the exercises, their record and the notebook copies (see :func:`init_workspace`)."""
    new = _update_exercises(src, workspace, result)
    archive = clear_for_file(workspace, _ARCHIVE, result.notes)
    data = pristine_archive_bytes(new)
    if len(data) > ARCHIVE_MAX_BYTES:
        raise CourseError("course folder", str(src), f"its exercises make an archive of {len(data)} bytes, more than "
                          f"the {ARCHIVE_MAX_BYTES} a workspace keeps")
    if regular_file_bytes(archive, len(data)) != data:
        write_atomically(archive, data)  # last: the record of what was handed out follows the files it describes
    result.notebooks = refresh_notebook_copies(workspace, now, result.notes)


def singleuser_command(workspace: Path, args: list[str]) -> list[str]:
    """The JupyterHub single-user server for a learner: JupyterLab at their workspace, opening their intro, with the
    same hidden folders as on a laptop (``args`` are the spawner's). It is the hub's ``jupyterhub-singleuser`` of
    this Python, started lighter (:mod:`rrbot_workshop.classroom.server`)."""
    import sys

    from rrbot_workshop.classroom import kernels
    from rrbot_workshop.classroom.launcher import HIDDEN
    from rrbot_workshop.classroom.server import extension_args

    return [sys.executable, "-m", "rrbot_workshop.classroom.server", f"--ServerApp.root_dir={workspace}",
            "--ServerApp.default_url=/lab/tree/my_notebooks/00_intro.ipynb",
            f"--ContentsManager.hide_globs={list(HIDDEN)!r}", *extension_args(), *kernels.server_args(), *args]
