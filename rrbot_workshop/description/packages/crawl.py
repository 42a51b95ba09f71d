"""The package path, crawled as colcon crawls a workspace: packages found by the ``<name>`` of their ``package.xml``.

See :mod:`rrbot_workshop.description.packages` for the order of the path and how packages are found.
"""

from __future__ import annotations

import contextvars
import logging
import os
import re
import stat
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from rrbot_workshop.description.packages.install_rules import InstallRule, parse_install_rules
from rrbot_workshop.description.packages.package import Package
from rrbot_workshop.description.packages.view import remove_stale_views
from rrbot_workshop.exceptions import DescriptionError

__all__ = [
    "PACKAGE_PATH_ENV",
    "DESCRIPTIONS_ENV",
    "IGNORE_MARKERS",
    "Package",
    "PackageIndex",
    "descriptions_root",
    "package_path",
    "package_index",
    "find_package",
    "known_package",
    "use_package_path",
    "clear_cache",
]

_log = logging.getLogger("rrbot_workshop.description.packages")

#: Environment variable with extra package path folders, ``os.pathsep``-separated (as ``ROS_PACKAGE_PATH``).
PACKAGE_PATH_ENV = "RRBOT_WORKSHOP_PACKAGE_PATH"
#: Marker files that make colcon/ament/catkin skip a folder and everything below it.
IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")
#: Deepest folder level crawled below a path entry (a workspace's packages sit a few levels deep).
MAX_DEPTH = 12


@dataclass
class PackageIndex:
    """The packages below a package path, found once (see :func:`package_index`).

    Attributes:
        entries: The package path folders, in order.
        packages: Name -> the package that wins (first on the path).
        shadowed: Name -> packages of the same name that lost to the first.
        broken: ``package.xml`` files that could not be read -> why.
    """

    entries: tuple[Path, ...]
    packages: dict[str, Package] = field(default_factory=dict)
    shadowed: dict[str, list[Package]] = field(default_factory=dict)
    broken: dict[Path, str] = field(default_factory=dict)

    def names(self) -> list[str]:
        """The package names, sorted."""
        return sorted(self.packages)

    def get(self, name: str) -> Package:
        """The package called ``name``.

        Raises:
            DescriptionError: If there is none: the message lists the known packages, the folders searched and
                the ``package.xml`` files that could not be read.
        """
        try:
            return self.packages[name]
        except KeyError:
            pass
        searched = ", ".join(str(e) for e in self.entries) or "none"
        known = ", ".join(self.names()) or "none"
        broken = ""
        if self.broken:
            broken = "; these package.xml files could not be read: " + "; ".join(
                f"{p}: {why}" for p, why in sorted(self.broken.items()))
        raise DescriptionError(
            f"unknown package '{name}' (valid: {known}); package path searched: {searched}{broken}; add the folder "
            f"that holds it with package_path=[...], --package-path DIR or {PACKAGE_PATH_ENV}",
            element="package", attribute=name,
        )


#: Largest ``package.xml`` read [bytes].
MAX_MANIFEST_BYTES = 1024 * 1024
#: Most folders looked at below one package path folder; past that the crawl stops with an error.
MAX_FOLDERS = 20_000
_PACKAGE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,199}")


def _read_manifest(manifest: Path) -> str:
    """The ``<name>`` of a ``package.xml``.

    Raises:
        DescriptionError: If the file is not a regular file of at most :data:`MAX_MANIFEST_BYTES`, not well-formed
            XML, its root is not ``<package>``, or its name is missing or cannot be a folder name.
    """
    try:
        info = os.stat(manifest)
        if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_MANIFEST_BYTES:
            what = "not a regular file" if not stat.S_ISREG(info.st_mode) else f"larger than {MAX_MANIFEST_BYTES} bytes"
            raise DescriptionError(f"package.xml is {what}; it is not read", source=str(manifest))
        with open(manifest, "rb") as handle:
            data = handle.read(MAX_MANIFEST_BYTES + 1)
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        line, column = exc.position
        reason = str(exc).split(":")[0]
        raise DescriptionError(f"malformed package.xml at line {line}, column {column + 1}: {reason}",
                               source=str(manifest)) from None
    except OSError as exc:
        raise DescriptionError(f"cannot read package.xml: {exc.strerror or exc}", source=str(manifest)) from None
    if root.tag != "package":
        raise DescriptionError(f"package.xml's root element is <{root.tag}>, not <package>", source=str(manifest))
    name = (root.findtext("name") or "").strip()
    if not name:
        raise DescriptionError("package.xml has no <name> (it names the package: <name>my_robot</name>)",
                               source=str(manifest))
    if not _PACKAGE_NAME.fullmatch(name) or set(name) == {"."}:
        raise DescriptionError(f"package.xml names the package {name[:80]!r}, which is not a package name (letters, "
                               "digits and underscores, as my_robot_description)", source=str(manifest))
    return name


def _check_entry(entry: Path) -> None:
    home = Path.home().resolve() if "HOME" in os.environ or os.name != "nt" else None
    if entry == Path(entry.anchor) or (home is not None and entry == home):
        raise DescriptionError(
            f"package path folder '{entry}' is the file system root or the home folder; give the folder that holds "
            "the packages (a workspace's src/, a clone, or an install prefix) instead", element="package_path")


def _inside(real: str, root: str) -> bool:
    return real == root or real.startswith(root.rstrip(os.sep) + os.sep)


def _walk(entry: Path) -> list[Path]:
    """The ``package.xml`` files below ``entry``, crawled as colcon crawls (see :func:`_crawl`)."""
    root = os.path.realpath(entry)
    seen: set[str] = set()
    manifests: list[Path] = []
    stack: list[tuple[Path, int]] = [(entry, 0)]
    while stack:
        folder, depth = stack.pop()
        real = os.path.realpath(folder)
        if real in seen:
            continue
        seen.add(real)
        if len(seen) > MAX_FOLDERS:
            raise DescriptionError(
                f"package path folder '{entry}' holds more than {MAX_FOLDERS} folders outside packages; give the "
                "folder that holds the packages (a workspace's src/, a clone) instead", element="package_path")
        try:
            with os.scandir(folder) as scan:
                entries = sorted(scan, key=lambda e: e.name)
        except OSError:
            continue
        names = {e.name for e in entries}
        if folder != entry and names & set(IGNORE_MARKERS):
            continue
        if folder != entry and "package.xml" in names:
            manifests.append(folder / "package.xml")
            continue
        if depth >= MAX_DEPTH:
            continue
        for sub in reversed(entries):
            if sub.name.startswith((".", "__")):
                continue
            try:
                if not sub.is_dir():
                    continue
                if sub.is_symlink() and not _inside(os.path.realpath(sub.path), root):
                    # a link out of the folder: only a package itself is taken (src/my_pkg -> ~/repos/my_pkg)
                    target = os.path.realpath(sub.path)
                    if target not in seen and os.path.isfile(os.path.join(target, "package.xml")):
                        seen.add(target)
                        if not any(os.path.isfile(os.path.join(target, m)) for m in IGNORE_MARKERS):
                            manifests.append(Path(sub.path) / "package.xml")
                    continue
            except OSError:
                continue
            stack.append((Path(sub.path), depth + 1))
    return manifests


def _crawl(entry: Path, index: PackageIndex, descriptions: bool) -> None:
    """Add the packages below one path entry to ``index`` (first found wins).

    As colcon: a folder with ``package.xml`` is a package and is not descended into; folders with an ignore marker
    and hidden folders are skipped; links are followed, each real folder once (a loop ends there). Unlike colcon, the
    crawl never leaves ``entry``: a link that leads out of it is taken only when it points at a package, which is
    read and not descended into; and it looks at :data:`MAX_FOLDERS` folders at most.

    Raises:
        DescriptionError: If ``entry`` holds more than :data:`MAX_FOLDERS` folders outside packages.
    """
    found: list[Package] = []
    share = entry / "share"
    prefix_packages = sorted(share.glob("*/package.xml")) if share.is_dir() else []
    if (entry / "package.xml").is_file():
        manifests = [entry / "package.xml"]
    elif prefix_packages:  # an install prefix: its share/* only
        manifests = prefix_packages
    else:
        manifests = _walk(entry)
    for manifest in manifests:
        try:
            name = _read_manifest(manifest)
        except DescriptionError as exc:
            index.broken[manifest] = str(exc).split(": ", 1)[-1]
            _log.warning("%s", exc)
            continue
        folder = manifest.parent
        installed = folder.parent.name == "share" and folder.name == name
        rules: list[InstallRule] = []
        complete = True
        refused: DescriptionError | None = None
        if not installed and (folder / "CMakeLists.txt").is_file():
            try:
                rules, complete = parse_install_rules(folder / "CMakeLists.txt", name)
            except DescriptionError as exc:  # an install rule that leaves the prefix: the package is refused on use
                refused = exc
                _log.warning("%s", exc)
        found.append(Package(name, folder, "installed" if installed else "source", entry, manifest, tuple(rules),
                             complete, refused))
    if descriptions and entry.is_dir():
        taken = {p.path for p in found}
        for sub in sorted(entry.iterdir()):
            if sub.is_dir() and not sub.name.startswith((".", "_")) and sub not in taken:
                found.append(Package(sub.name, sub, "descriptions", entry))
    for package in found:
        first = index.packages.get(package.name)
        if first is None:
            index.packages[package.name] = package
            continue
        index.shadowed.setdefault(package.name, []).append(package)
        _log.warning("package '%s' is found twice: using %s, ignoring %s (the first on the package path wins, "
                     "as in ROS)", package.name, first.path, package.path)


_EXTRA: contextvars.ContextVar[tuple[Path, ...]] = contextvars.ContextVar("rrbot_workshop_package_path", default=())
_CACHE: dict[tuple[Path, ...], PackageIndex] = {}
#: Every package resolved in this process: the last resort for ``package://`` URIs met after bringup returned.
_SEEN: dict[str, Package] = {}


#: Environment variable that points the package lookup at another ``descriptions/`` folder.
DESCRIPTIONS_ENV = "RRBOT_WORKSHOP_DESCRIPTIONS"

def descriptions_root() -> Path:
    """Folder that holds one sub-folder per robot description package (``rrbot/``, ``diffbot/``, ...).

    Returns:
        ``$RRBOT_WORKSHOP_DESCRIPTIONS`` if set, else ``descriptions/`` at the repository root.
    """
    override = os.environ.get(DESCRIPTIONS_ENV)
    if override:
        return Path(override).expanduser().resolve()
    return Path(__file__).resolve().parents[3] / "descriptions"



def _as_entries(paths: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None) -> list[Path]:
    if paths is None:
        return []
    if isinstance(paths, str | os.PathLike):
        paths = [p for p in str(paths).split(os.pathsep) if p]
    return [Path(p).expanduser().resolve() for p in paths if str(p).strip()]


def package_path(extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None) -> tuple[Path, ...]:
    """The package path: ``extra``, the folders of :func:`use_package_path`, ``$RRBOT_WORKSHOP_PACKAGE_PATH``, then
    the course's ``descriptions/``.

    Args:
        extra: Folders to search first (a list, or one ``os.pathsep``-separated string).

    Returns:
        The folders, absolute, without repeats, in search order.

    Raises:
        DescriptionError: If a folder does not exist, or is the file system root or the home folder.
    """
    entries: list[Path] = []
    given = [*_as_entries(extra), *_EXTRA.get()]
    from_env = _as_entries(os.environ.get(PACKAGE_PATH_ENV, ""))
    for entry in given:
        if not entry.is_dir():
            raise DescriptionError(f"package path folder '{entry}' does not exist", element="package_path")
    for entry in from_env:
        if not entry.is_dir():
            _log.warning("%s names '%s', which does not exist; skipped", PACKAGE_PATH_ENV, entry)
    for entry in [*given, *(e for e in from_env if e.is_dir())]:
        _check_entry(entry)
        if entry not in entries:
            entries.append(entry)
    root = descriptions_root()
    if root not in entries:
        entries.append(root)
    return tuple(entries)


def package_index(extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None,
                  refresh: bool = False) -> PackageIndex:
    """The packages on :func:`package_path` ``(extra)``, crawled once per path (``refresh`` crawls again).

    Raises:
        DescriptionError: If a path folder is invalid (see :func:`package_path`), cannot be read, or holds more
            than :data:`MAX_FOLDERS` folders outside packages.
    """
    entries = package_path(extra)
    if not refresh and entries in _CACHE:
        return _CACHE[entries]
    remove_stale_views()  # install views of processes that were killed (see view.py)
    index = PackageIndex(entries)
    descriptions = entries[-1]
    for entry in entries:
        try:
            _crawl(entry, index, descriptions=entry == descriptions)
        except OSError as exc:  # a folder it may not read (permissions): one line naming it
            raise DescriptionError(f"package path folder '{entry}' cannot be read: {exc.strerror or exc}"
                                   f"{f' ({exc.filename})' if exc.filename else ''}", element="package_path") from None
    _CACHE[entries] = index
    return index


def clear_cache() -> None:
    """Forget every crawled package path (the next lookup crawls again)."""
    _CACHE.clear()


@contextmanager
def use_package_path(extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None) -> Iterator[tuple[Path, ...]]:
    """Within the block, every lookup (xacro's ``$(find)``, ``package://``) searches ``extra`` first.

    Yields:
        The package path in effect.

    Raises:
        DescriptionError: If a folder does not exist, or is the file system root or the home folder.
    """
    entries = tuple(_as_entries(extra))
    token = _EXTRA.set(entries + tuple(e for e in _EXTRA.get() if e not in entries))
    try:
        yield package_path()
    finally:
        _EXTRA.reset(token)


def find_package(name: str, extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None) -> Package:
    """The package called ``name`` on the package path (crawled again once if it is not known yet).

    Raises:
        DescriptionError: If there is none (the message lists the known packages and the folders searched), or its
            install rules were refused (a DESTINATION that leaves the install prefix).
    """
    if not name or "/" in name or "\\" in name:
        raise DescriptionError(f"'{name}' is not a package name", element="package", attribute=name)
    index = package_index(extra)
    if name not in index.packages:
        index = package_index(extra, refresh=True)  # a package added since the last crawl
    package = index.get(name)
    package.check()
    _SEEN[name] = package
    return package


def known_package(name: str) -> Package | None:
    """The package called ``name`` as this process last met it on any package path, or None.

    A viewer showing a robot's meshes after the bringup that found its packages returned uses it.
    """
    earlier = [_SEEN.get(name)] + [index.packages.get(name) for index in reversed(list(_CACHE.values()))]
    return next((p for p in earlier if p is not None), None)
