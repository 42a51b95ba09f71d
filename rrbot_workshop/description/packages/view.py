"""The install view on disk: a folder per process that looks like a source tree's installed ``share/<pkg>``.

Xacro pastes ``$(find pkg)`` into text and opens files later, so a source tree with install rules needs a real
folder shaped as its installed form. This module writes it from an :class:`InstallTree`, and it writes nowhere else,
by construction:

* every view lives in one folder of this process, ``<tmp>/rrbot_workshop_views-<uid>/<pid>-<random>/``, made by it
  (mode ``0o700``; the parent must be a real folder of this user that nobody else can write, or a private
  :func:`tempfile.mkdtemp` folder is used instead);
* every folder of a view is a real folder made by :func:`os.mkdir`, checked with :func:`os.lstat` to be a folder
  and not a link before anything is made in it; a path with ``..`` is refused;
* the only links are to source *files*, made by :func:`os.symlink`, which never writes through an existing path
  (where links cannot be made, the file is copied into a file opened with ``O_CREAT | O_EXCL``);
* nothing is ever changed: a view that no longer matches its package is replaced by a new one.

The process's folder is removed when it exits; a folder whose process is gone (killed with ``kill -9``) is removed
by the next process that uses packages (:func:`remove_stale_views`).
"""

from __future__ import annotations

import atexit
import itertools
import os
import re
import secrets
import shutil
import stat
import tempfile
import threading
from pathlib import Path, PurePosixPath

from rrbot_workshop.description.packages.installed import InstallTree
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["views_parent", "process_folder", "build_view", "remove_stale_views"]

_LOCK = threading.RLock()
_FOLDER: Path | None = None
_OWNER_PID = 0
_SWEPT = False
_COUNTER = itertools.count()
_NAME = re.compile(r"([0-9]+)-[A-Za-z0-9_-]+")


def _user() -> str:
    if hasattr(os, "getuid"):
        return str(os.getuid())
    name = os.environ.get("USERNAME") or os.environ.get("USER") or "user"
    return re.sub(r"[^A-Za-z0-9_-]", "_", name)[:64]


def views_parent() -> Path:
    """The folder that holds every process's views: ``<tmp>/rrbot_workshop_views-<uid>``."""
    return Path(tempfile.gettempdir()) / f"rrbot_workshop_views-{_user()}"


def _private_folder(path: Path) -> bool:
    """True if ``path`` is a real folder (not a link) of this user that nobody else may write."""
    try:
        info = os.lstat(path)
    except OSError:
        return False
    if not stat.S_ISDIR(info.st_mode):
        return False
    if hasattr(os, "getuid") and (info.st_uid != os.getuid() or info.st_mode & 0o022):
        return False
    return True


def _trusted_parent() -> Path | None:
    parent = views_parent()
    try:
        os.mkdir(parent, 0o700)
    except FileExistsError:
        pass
    except OSError:
        return None
    return parent if _private_folder(parent) else None


def _alive(pid: int) -> bool:
    """True if process ``pid`` may still run (always True where this cannot be asked without harm: Windows)."""
    if os.name == "nt" or pid <= 0:
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def remove_stale_views() -> list[Path]:
    """Remove the view folders of processes that are gone (killed before they could remove their own).

    Only sub-folders named ``<pid>-<random>`` of :func:`views_parent` are considered, and only when the parent is
    a private folder of this user; :func:`shutil.rmtree` never follows the links inside them.

    Returns:
        The folders removed.
    """
    global _SWEPT
    _SWEPT = True
    parent = _trusted_parent()
    if parent is None:
        return []
    removed: list[Path] = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return []
    for entry in entries:
        match = _NAME.fullmatch(entry.name)
        if match is None or Path(entry.path) == _FOLDER:
            continue
        try:
            if not entry.is_dir(follow_symlinks=False) or _alive(int(match.group(1))):
                continue
        except (OSError, ValueError):
            continue
        shutil.rmtree(entry.path, ignore_errors=True)
        if not os.path.lexists(entry.path):
            removed.append(Path(entry.path))
    return removed


def _remove_own_folder(folder: Path, pid: int) -> None:
    if os.getpid() == pid:  # a forked child leaves its parent's folder alone
        shutil.rmtree(folder, ignore_errors=True)


def process_folder() -> Path:
    """This process's folder for views (made on first use, removed at exit), after sweeping stale ones."""
    global _FOLDER, _OWNER_PID
    with _LOCK:
        if _FOLDER is not None and _OWNER_PID == os.getpid() and _private_folder(_FOLDER):
            return _FOLDER
        if not _SWEPT:
            remove_stale_views()
        parent = _trusted_parent()
        if parent is not None:
            folder = parent / f"{os.getpid()}-{secrets.token_hex(6)}"
            os.mkdir(folder, 0o700)
        else:
            folder = Path(tempfile.mkdtemp(prefix=f"rrbot_workshop_view-{os.getpid()}-"))
        _FOLDER, _OWNER_PID = Path(os.path.realpath(folder)), os.getpid()
        atexit.register(_remove_own_folder, _FOLDER, _OWNER_PID)
        return _FOLDER


class _Writer:
    """Makes folders and links below one root, each checked to be inside it and never through a link."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.made: set[Path] = {root}

    def _path(self, relative: PurePosixPath) -> Path:
        if relative.is_absolute() or ".." in relative.parts or any(not p or "\x00" in p for p in relative.parts):
            raise DescriptionError(f"refusing to write '{relative}' in the install view: not a plain relative path")
        path = self.root.joinpath(*relative.parts) if relative.parts else self.root
        if path != self.root and path.parent not in self.made:
            raise DescriptionError(f"refusing to write {path}: its folder is not one the install view made")
        return path

    def folder(self, relative: PurePosixPath) -> None:
        path = self._path(relative)
        if path in self.made:
            return
        os.mkdir(path, 0o700)
        info = os.lstat(path)
        if not stat.S_ISDIR(info.st_mode):
            raise DescriptionError(f"refusing to write in {path}: it is not a folder the install view made")
        self.made.add(path)

    def link(self, relative: PurePosixPath, source: Path) -> None:
        path = self._path(relative)
        try:
            os.symlink(source, path)
        except FileExistsError:
            raise
        except (OSError, NotImplementedError):  # no symbolic links here (some Windows set-ups): copy the file
            flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_BINARY", 0)
            with open(source, "rb") as src, os.fdopen(os.open(path, flags, 0o600), "wb") as dst:
                shutil.copyfileobj(src, dst)


def build_view(tree: InstallTree) -> Path:
    """Write ``tree`` as a new view: ``<process folder>/<n>/share/<package>``; returns that folder.

    Raises:
        DescriptionError: If the package name or an installed path is not a plain name (never expected from
            :func:`~rrbot_workshop.description.packages.installed.install_tree`), or the view could not be
            written (the message names the folder).
    """
    name = tree.package
    if not name or name in (".", "..") or any(c in name for c in "/\\\x00"):
        raise DescriptionError(f"'{name}' is not a package name that can be a folder", element="package",
                               attribute=name)
    with _LOCK:
        share = PurePosixPath(str(next(_COUNTER)), "share", name)
        writer = _Writer(views_parent())
        try:
            writer = _Writer(process_folder())
            for relative in (share.parents[1], share.parent, share):
                writer.folder(relative)
            for folder in sorted(tree.folders):
                writer.folder(share / folder)
            for installed, source in sorted(tree.files.items()):
                writer.link(share / installed, source)
        except OSError as exc:
            raise DescriptionError(f"cannot write the install view of package '{name}' in {writer.root}: "
                                   f"{exc.strerror or exc}", element="package", attribute=name) from None
        return writer.root.joinpath(*share.parts)
