"""Packages found as ROS finds them: a package path, ``package.xml`` names, source and installed trees.

ROS finds a package by the ``<name>`` in its ``package.xml``, below the folders of a package path
(``ROS_PACKAGE_PATH`` in ROS 1; a colcon workspace's ``src/`` or an install prefix in ROS 2). This module does the
same without ROS. The package path is, in order:

1. the folders given by the caller (``rw.bringup(..., package_path=[...])``, ``--package-path DIR``);
2. the folders of ``RRBOT_WORKSHOP_PACKAGE_PATH`` (``os.pathsep``-separated, as ``ROS_PACKAGE_PATH``);
3. the course's ``descriptions/`` folder (:func:`~rrbot_workshop.description.xacro.descriptions_root`), whose
   sub-folders are packages named after the folder when they have no ``package.xml``.

Each folder is crawled as colcon crawls a workspace: a folder with a ``package.xml`` is a package and is not
descended into; folders holding ``COLCON_IGNORE``, ``AMENT_IGNORE`` or ``CATKIN_IGNORE`` and hidden folders are
skipped. An install prefix (``<prefix>/share/<pkg>/package.xml``) may be given directly; its ``share/*`` packages
are taken without crawling the rest of the prefix. When two packages have the same name, the first on the path
wins, as in ROS, and a warning names both.

**Source trees resolve as their installed form would.** ``$(find pkg)`` in ROS 2 is the package's *installed*
``share/<pkg>`` folder, and CMake's ``install(DIRECTORY ... DESTINATION share/${PROJECT_NAME})`` rules decide
what is there: ``install(DIRECTORY description/ros2_control DESTINATION share/${PROJECT_NAME})`` puts
``description/ros2_control/x.xacro`` at ``share/<pkg>/ros2_control/x.xacro``. For a package found as a source
tree, :meth:`Package.candidates` reads those rules from its ``CMakeLists.txt`` (``DIRECTORY`` with CMake's
trailing-slash meaning, ``FILES`` with ``RENAME``, ``${PROJECT_NAME}`` and simple ``set()`` variables) and maps a
share-relative path back to the source file. A package without such rules (``ament_python``, or rules this
reader cannot follow) resolves relative to its source folder.

**How ``$(find pkg)`` works in xacro.** Xacro pastes the result of ``$(find pkg)`` into text
(``$(find pkg)/ros2_control/x.xacro``) and opens the file later, so it needs a real folder that looks like the
installed one. For a source tree with install rules, :func:`share_directory` builds that folder once per
process: a small tree of symbolic links under a temporary folder (``<tmp>/rrbot_workshop_share_*/<n>/share/
<pkg>``), one link per install rule, removed when the process exits. Relative includes then behave as in the
installed package, and a file missing from it is reported by :func:`explain_missing` with every place it was
looked for. Installed trees, packages without rules and the course's ``descriptions/`` need no view: their own
folder is the share folder.
"""

from __future__ import annotations

import atexit
import contextvars
import logging
import os
import re
import shutil
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from rrbot_workshop.exceptions import DescriptionError

__all__ = [
    "PACKAGE_PATH_ENV",
    "IGNORE_MARKERS",
    "InstallRule",
    "Package",
    "PackageIndex",
    "package_path",
    "package_index",
    "find_package",
    "resolve",
    "resolve_uri",
    "share_directory",
    "explain_missing",
    "package_of",
    "use_package_path",
    "clear_cache",
]

_log = logging.getLogger(__name__)

#: Environment variable with extra package path folders, ``os.pathsep``-separated (as ``ROS_PACKAGE_PATH``).
PACKAGE_PATH_ENV = "RRBOT_WORKSHOP_PACKAGE_PATH"
#: Marker files that make colcon/ament/catkin skip a folder and everything below it.
IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")
#: Deepest folder level crawled below a path entry (a workspace's packages sit a few levels deep).
MAX_DEPTH = 12


# ============================================================================ install rules
@dataclass(frozen=True)
class InstallRule:
    """One ``install(DIRECTORY|FILES ...)`` source that lands in the package's ``share/<pkg>`` folder.

    Attributes:
        source: The file or folder in the source tree (absolute).
        destination: Folder below ``share/<pkg>`` it is installed into (``""``: ``share/<pkg>`` itself).
        kind: ``"directory"`` (the folder itself, ``install(DIRECTORY a/b ...)``), ``"contents"`` (what is in
            it, ``install(DIRECTORY a/b/ ...)``) or ``"file"`` (``install(FILES ...)``).
        name: Installed name of a file (``RENAME``), else the source's name.
        line: Line of the ``install(`` command in ``CMakeLists.txt``.
    """

    source: Path
    destination: PurePosixPath
    kind: str
    name: str = ""
    line: int = 0

    @property
    def installed_as(self) -> PurePosixPath:
        """Where the source lands, relative to ``share/<pkg>``."""
        if self.kind == "contents":
            return self.destination
        return self.destination / (self.name or self.source.name)

    def source_for(self, relative: PurePosixPath) -> Path | None:
        """The source-tree path installed as ``share/<pkg>/<relative>`` by this rule, or None."""
        base = self.installed_as
        if self.kind == "file":
            return self.source if relative == base else None
        if base == PurePosixPath("."):
            return self.source / relative if relative != PurePosixPath(".") else self.source
        if relative == base:
            return self.source
        try:
            rest = relative.relative_to(base)
        except ValueError:
            return None
        return self.source / rest

    def describe(self, root: Path, package: str) -> str:
        """The rule as a learner reads it: ``description/urdf -> share/<pkg>/urdf (CMakeLists.txt:57)``."""
        try:
            source = self.source.relative_to(root).as_posix() + ("/" if self.kind == "contents" else "")
        except ValueError:
            source = str(self.source)
        target = PurePosixPath("share", package, self.installed_as).as_posix()
        return f"{source} -> {target} (CMakeLists.txt:{self.line})"


_KEYWORDS = {
    "DESTINATION", "FILE_PERMISSIONS", "DIRECTORY_PERMISSIONS", "USE_SOURCE_PERMISSIONS", "OPTIONAL",
    "MESSAGE_NEVER", "CONFIGURATIONS", "COMPONENT", "EXCLUDE_FROM_ALL", "FILES_MATCHING", "PATTERN", "REGEX",
    "RENAME", "TYPE", "PERMISSIONS", "NAMELINK_COMPONENT",
}
_TOKEN = re.compile(r'"((?:[^"\\]|\\.)*)"|(\S+)')
_VARIABLE = re.compile(r"\$\{([A-Za-z0-9_.+-]+)\}")


def _strip_cmake_comments(text: str) -> str:
    """``text`` with CMake comments (``# ...`` and ``#[[ ... ]]``) blanked, keeping line numbers."""
    out: list[str] = []
    i, n = 0, len(text)
    in_quote = False
    while i < n:
        c = text[i]
        if in_quote:
            out.append(c)
            if c == "\\" and i + 1 < n:
                out.append(text[i + 1])
                i += 2
                continue
            if c == '"':
                in_quote = False
            i += 1
            continue
        if c == '"':
            in_quote = True
            out.append(c)
            i += 1
            continue
        if c == "#":
            bracket = re.match(r"#\[(=*)\[", text[i:])
            if bracket:
                end = text.find("]" + bracket.group(1) + "]", i)
                end = n if end < 0 else end + len(bracket.group(1)) + 2
            else:
                end = text.find("\n", i)
                end = n if end < 0 else end
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
            continue
        out.append(c)
        i += 1
    return "".join(out)


def _commands(text: str) -> Iterator[tuple[str, str, int]]:
    """(command name in lower case, argument text, line) for each command call in CMake ``text``."""
    for match in re.finditer(r"\b([A-Za-z_][A-Za-z0-9_]*)\s*\(", text):
        depth, i = 1, match.end()
        while i < len(text) and depth:
            if text[i] == "(":
                depth += 1
            elif text[i] == ")":
                depth -= 1
            elif text[i] == '"':
                close = text.find('"', i + 1)
                i = close if close > 0 else len(text)
            i += 1
        yield match.group(1).lower(), text[match.end():i - 1], text.count("\n", 0, match.start()) + 1


def _tokens(args: str) -> list[str]:
    return [m.group(1) if m.group(1) is not None else m.group(2) for m in _TOKEN.finditer(args)]


def parse_install_rules(cmake_file: Path, package: str) -> tuple[list[InstallRule], bool]:
    """The rules of ``cmake_file`` that install into ``share/<package>``.

    Args:
        cmake_file: A package's ``CMakeLists.txt``.
        package: The package name (the ``<name>`` of its ``package.xml``).

    Returns:
        ``(rules, complete)``: ``complete`` is False when an ``install()`` could not be followed (a variable this
        reader does not know, a destination it cannot read); the package then also resolves from its source
        folder.
    """
    try:
        text = _strip_cmake_comments(cmake_file.read_text(encoding="utf-8", errors="replace"))
    except OSError:
        return [], False
    root = cmake_file.parent
    variables = {
        "PROJECT_NAME": package, "CMAKE_CURRENT_SOURCE_DIR": str(root), "PROJECT_SOURCE_DIR": str(root),
        "CMAKE_SOURCE_DIR": str(root), "CMAKE_CURRENT_LIST_DIR": str(root),
    }
    rules: list[InstallRule] = []
    complete = True

    def expand(token: str) -> str | None:
        unknown = False

        def sub(m: re.Match[str]) -> str:
            nonlocal unknown
            if m.group(1) in variables:
                return variables[m.group(1)]
            unknown = True
            return m.group(0)

        value = _VARIABLE.sub(sub, token)
        return None if unknown else value

    for name, args, line in _commands(text):
        tokens = _tokens(args)
        if name == "project" and tokens:
            variables["PROJECT_NAME"] = variables["CMAKE_PROJECT_NAME"] = expand(tokens[0]) or package
        elif name == "set" and tokens and not any(t in ("CACHE", "PARENT_SCOPE") for t in tokens[1:]):
            values = [expand(t) for t in tokens[1:]]
            if all(v is not None for v in values):
                variables[tokens[0]] = ";".join(v for v in values if v is not None)
        elif name == "install" and tokens and tokens[0] in ("DIRECTORY", "FILES", "PROGRAMS"):
            kind = tokens[0]
            sources: list[str] = []
            i = 1
            while i < len(tokens) and tokens[i] not in _KEYWORDS:
                sources.append(tokens[i])
                i += 1
            options: dict[str, str] = {}
            while i < len(tokens):
                key = tokens[i]
                if key in ("DESTINATION", "RENAME", "TYPE", "COMPONENT") and i + 1 < len(tokens):
                    options[key] = tokens[i + 1]
                    i += 2
                else:  # flags, permissions, PATTERN/REGEX filters (the folder still maps: an over-approximation)
                    i += 1
            dest_text = options.get("DESTINATION")
            if dest_text is None:
                continue
            dest = expand(dest_text)
            if dest is None:
                complete = False
                continue
            dest_path = PurePosixPath(dest.replace("\\", "/"))
            share = PurePosixPath("share") / package
            if dest_path.is_absolute() or dest_path.parts[:1] != ("share",):
                continue  # include/, lib/ ...: not part of the share folder
            try:
                below = dest_path.relative_to(share)
            except ValueError:
                continue  # another package's share folder
            for raw in sources:
                expanded = expand(raw)
                if expanded is None:
                    complete = False
                    continue
                for item in expanded.split(";"):
                    if not item:
                        continue
                    if "$<" in item:
                        complete = False
                        continue
                    src = Path(item) if Path(item).is_absolute() else root / item
                    if kind == "DIRECTORY":
                        contents = item.endswith(("/", "\\")) or PurePosixPath(item).name in ("", ".")
                        rules.append(InstallRule(Path(os.path.normpath(src)), below,
                                                 "contents" if contents else "directory", line=line))
                    else:
                        rename = options.get("RENAME") if len(sources) == 1 else None
                        rules.append(InstallRule(Path(os.path.normpath(src)), below, "file",
                                                 name=expand(rename) or "" if rename else "", line=line))
    return rules, complete


# ============================================================================ packages
@dataclass(frozen=True)
class Package:
    """A package found on the package path.

    Attributes:
        name: The ``<name>`` of its ``package.xml`` (the folder name under ``descriptions/``).
        path: Its folder: the source folder with ``package.xml``, or the installed ``share/<name>`` folder.
        layout: ``"source"``, ``"installed"`` or ``"descriptions"`` (a folder of the course's ``descriptions/``).
        entry: The package path folder it was found below.
        manifest: Its ``package.xml`` (None for a ``descriptions/`` folder without one).
        rules: Install rules of a source tree (see :class:`InstallRule`), in the order CMake runs them.
        rules_complete: False when some ``install()`` could not be followed; the source folder is then also searched.
    """

    name: str
    path: Path
    layout: str
    entry: Path
    manifest: Path | None = None
    rules: tuple[InstallRule, ...] = ()
    rules_complete: bool = True

    @property
    def maps_through_rules(self) -> bool:
        """True when share-relative paths map through install rules (a source tree with share rules)."""
        return self.layout == "source" and bool(self.rules)

    def candidates(self, relative: str | PurePosixPath) -> list[Path]:
        """Every file that ``share/<name>/<relative>`` may be, in the order they are tried.

        For a source tree with install rules, the later rule first (CMake installs in order, so a later rule
        overwrites an earlier one), then ``package.xml`` (ament always installs it), then, only when some rule
        could not be read, the same path in the source folder. Otherwise the path in the package's folder.
        """
        rel = PurePosixPath(str(relative).replace("\\", "/").lstrip("/"))
        if not self.maps_through_rules:
            return [self.path / rel]
        found: list[Path] = []
        for rule in reversed(self.rules):
            source = rule.source_for(rel)
            if source is not None and source not in found:
                found.append(source)
        if rel == PurePosixPath("package.xml") and self.manifest is not None:
            found.append(self.manifest)
        if not self.rules_complete and self.path / rel not in found:
            found.append(self.path / rel)
        return found

    def find(self, relative: str | PurePosixPath) -> Path | None:
        """The first of :meth:`candidates` that exists, or None."""
        for candidate in self.candidates(relative):
            if candidate.exists():
                return candidate
        return None

    def describe(self) -> str:
        """``name (source tree /path)`` as messages show it."""
        kind = {"source": "source tree", "installed": "installed", "descriptions": "course description"}[self.layout]
        return f"{self.name} ({kind} {self.path})"


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


def _read_manifest(manifest: Path) -> str:
    """The ``<name>`` of a ``package.xml``.

    Raises:
        DescriptionError: If the file is not well-formed XML, its root is not ``<package>``, or it has no name.
    """
    try:
        root = ET.parse(manifest).getroot()
    except ET.ParseError as exc:
        line, column = exc.position
        reason = str(exc).split(":")[0]
        raise DescriptionError(f"malformed package.xml at line {line}, column {column + 1}: {reason}",
                               source=str(manifest)) from None
    except OSError as exc:
        raise DescriptionError(f"cannot read package.xml: {exc.strerror}", source=str(manifest)) from None
    if root.tag != "package":
        raise DescriptionError(f"package.xml's root element is <{root.tag}>, not <package>", source=str(manifest))
    name = (root.findtext("name") or "").strip()
    if not name:
        raise DescriptionError("package.xml has no <name> (it names the package: <name>my_robot</name>)",
                               source=str(manifest))
    return name


def _check_entry(entry: Path) -> None:
    home = Path.home().resolve() if "HOME" in os.environ or os.name != "nt" else None
    if entry == Path(entry.anchor) or (home is not None and entry == home):
        raise DescriptionError(
            f"package path folder '{entry}' is the file system root or the home folder; give the folder that holds "
            "the packages (a workspace's src/, a clone, or an install prefix) instead", element="package_path")


def _crawl(entry: Path, index: PackageIndex, descriptions: bool) -> None:
    """Add the packages below one path entry to ``index`` (first found wins)."""
    found: list[Package] = []
    share = entry / "share"
    prefix_packages = sorted(share.glob("*/package.xml")) if share.is_dir() else []
    if (entry / "package.xml").is_file():
        manifests = [entry / "package.xml"]
    elif prefix_packages:  # an install prefix: its share/* only
        manifests = prefix_packages
    else:
        manifests = []
        seen: set[str] = set()
        for walked, dirs, files in os.walk(entry, followlinks=True):
            here = Path(walked)
            real = os.path.realpath(walked)
            depth = len(here.relative_to(entry).parts)
            if real in seen or depth > MAX_DEPTH:
                dirs[:] = []
                continue
            seen.add(real)
            if here != entry and any(m in files for m in IGNORE_MARKERS):
                dirs[:] = []
                continue
            if "package.xml" in files and here != entry:
                manifests.append(here / "package.xml")
                dirs[:] = []
                continue
            dirs[:] = sorted(d for d in dirs if not d.startswith((".", "__")))
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
        if not installed and (folder / "CMakeLists.txt").is_file():
            rules, complete = parse_install_rules(folder / "CMakeLists.txt", name)
        found.append(Package(name, folder, "installed" if installed else "source", entry, manifest, tuple(rules),
                             complete))
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


# ============================================================================ the package path
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
    return Path(__file__).resolve().parents[2] / "descriptions"



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
        DescriptionError: If a path folder is invalid (see :func:`package_path`).
    """
    entries = package_path(extra)
    if not refresh and entries in _CACHE:
        return _CACHE[entries]
    index = PackageIndex(entries)
    descriptions = entries[-1]
    for entry in entries:
        _crawl(entry, index, descriptions=entry == descriptions)
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
        DescriptionError: If there is none: the message lists the known packages and the folders searched.
    """
    if not name or "/" in name or "\\" in name:
        raise DescriptionError(f"'{name}' is not a package name", element="package", attribute=name)
    index = package_index(extra)
    if name not in index.packages:
        index = package_index(extra, refresh=True)  # a package added since the last crawl
    package = index.get(name)
    _SEEN[name] = package
    return package


def _not_found(package: Package, relative: str, candidates: Sequence[Path]) -> DescriptionError:
    looked = "; ".join(str(c) for c in candidates) or "nowhere"
    extra = ""
    if package.maps_through_rules:
        plain = package.path / relative
        if plain.exists() and plain not in candidates:
            extra = (f"; {plain} exists in the source tree, but no install(... DESTINATION share/{package.name}...) "
                     "rule of its CMakeLists.txt installs it there, so ROS would not find it either")
        else:
            rules = "; ".join(r.describe(package.path, package.name) for r in package.rules)
            extra = f" (install rules: {rules})"
    return DescriptionError(
        f"file '{relative}' of package '{package.name}' ({package.layout} tree at {package.path}) not found; "
        f"looked for: {looked}{extra}", element="package", attribute=f"{package.name}/{relative}")


def resolve(package: str, relative: str = "",
            extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None) -> Path:
    """The file that ``share/<package>/<relative>`` is, found through the package path.

    Args:
        package: Package name (the ``<name>`` of its ``package.xml``).
        relative: Path below the package's installed ``share/<package>`` folder (``"urdf/robot.urdf.xacro"``).
        extra: Folders to search first.

    Returns:
        The existing file or folder (for a source tree: where the install rules take it from).

    Raises:
        DescriptionError: If the package is unknown (the message lists the known packages and the path searched),
            or the file is not there (the message lists every place it was looked for).
    """
    pkg = find_package(package, extra)
    if not relative.strip("/"):
        return pkg.path
    found = pkg.find(relative)
    if found is None:
        raise _not_found(pkg, relative, pkg.candidates(relative))
    return found


def resolve_uri(uri: str, extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None,
                must_exist: bool = True) -> Path:
    """The file of a ``package://<pkg>/<path>`` URI or a ``$(find <pkg>)/<path>`` text.

    Args:
        uri: The URI or text.
        extra: Folders to search first.
        must_exist: If False, a missing file gives its first candidate instead of an error (viewers report
            missing meshes themselves). An unknown package raises either way.

    Raises:
        DescriptionError: If the text is neither form, the package is unknown, or (``must_exist``) the file is missing.
    """
    package, relative = split_package_reference(uri)
    if package is None:
        raise DescriptionError(f"'{uri}' is neither package://<pkg>/<path> nor $(find <pkg>)/<path>")
    try:
        pkg = find_package(package, extra)
    except DescriptionError:
        # after a bringup with its own package path returned (a viewer showing its meshes): the packages met so far
        earlier = [_SEEN.get(package)] + [i.packages.get(package) for i in reversed(list(_CACHE.values()))]
        known = next((p for p in earlier if p is not None), None)
        if known is None or must_exist:
            raise
        pkg = known
    if not relative:
        return pkg.path
    found = pkg.find(relative)
    if found is not None:
        return found
    if must_exist:
        raise _not_found(pkg, relative, pkg.candidates(relative))
    candidates = pkg.candidates(relative)
    return candidates[0] if candidates else pkg.path / relative


_FIND = re.compile(r"^\$\(\s*find\s+([^)\s]+)\s*\)(?:[/\\](.*))?$", re.S)


def split_package_reference(text: str) -> tuple[str | None, str]:
    """``(package, relative path)`` of ``package://pkg/rel`` or ``$(find pkg)/rel``; ``(None, text)`` otherwise.

    Raises:
        DescriptionError: If a ``package://`` URI has no package name.
    """
    text = text.strip()
    if text.startswith("package://"):
        package, _, relative = text[len("package://"):].partition("/")
        if not package:
            raise DescriptionError(f"URI '{text}' has no package name (expected package://<pkg>/<path>)")
        return package, relative
    match = _FIND.match(text)
    if match:
        return match.group(1), (match.group(2) or "")
    return None, text


def package_of(path: str | os.PathLike[str],
               extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None) -> Package | None:
    """The package on the package path whose folder holds ``path``, or None."""
    target = Path(path).expanduser().resolve()
    best: Package | None = None
    for pkg in package_index(extra).packages.values():
        root = pkg.path.resolve()
        if target == root or root in target.parents:
            if best is None or len(root.parts) > len(best.path.resolve().parts):
                best = pkg
    return best


# ============================================================================ the install view for xacro
_VIEW_ROOT: Path | None = None
_VIEWS: dict[Path, Path] = {}


def _view_root() -> Path:
    global _VIEW_ROOT
    if _VIEW_ROOT is None or not _VIEW_ROOT.is_dir():
        _VIEW_ROOT = Path(tempfile.mkdtemp(prefix="rrbot_workshop_share_"))
        atexit.register(shutil.rmtree, _VIEW_ROOT, True)
    return _VIEW_ROOT


def _link(source: Path, target: Path) -> None:
    """Make ``target`` show ``source``, merging folders that two rules install into the same place."""
    if not source.exists():
        return
    if target.is_symlink() or target.exists():
        if source.is_dir() and target.is_dir():
            if target.is_symlink():  # two rules fill one folder: turn the link into a real folder of links
                previous = Path(os.readlink(target))
                target.unlink()
                target.mkdir()
                for child in previous.iterdir():
                    _link(child, target / child.name)
            for child in source.iterdir():
                _link(child, target / child.name)
            return
        if target.is_dir() and not target.is_symlink():
            shutil.rmtree(target)
        else:
            target.unlink()
    target.parent.mkdir(parents=True, exist_ok=True)
    try:
        target.symlink_to(source, target_is_directory=source.is_dir())
    except OSError:  # no symbolic links (some Windows set-ups): copy instead
        if source.is_dir():
            shutil.copytree(source, target)
        else:
            shutil.copy2(source, target)


def _build_view(package: Package) -> Path:
    share = _view_root() / str(len(_VIEWS)) / "share" / package.name
    share.mkdir(parents=True)
    for rule in package.rules:  # in CMake's order: a later rule overwrites an earlier one
        target = share / rule.installed_as
        if rule.kind == "contents":
            if rule.source.is_dir():
                target.mkdir(parents=True, exist_ok=True)
                for child in sorted(rule.source.iterdir()):
                    _link(child, target / child.name)
        else:
            _link(rule.source, target)
    if package.manifest is not None and not (share / "package.xml").exists():
        _link(package.manifest, share / "package.xml")
    return share


def share_directory(package: str | Package,
                    extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None,
                    rebuild: bool = False) -> Path:
    """A folder that looks like the package's installed ``share/<package>``: what ``$(find package)`` gives.

    Installed trees, packages without install rules and the course's descriptions give their own folder. A source
    tree with install rules gives a view built of symbolic links (see the module docstring), built once per
    process (``rebuild``: again, e.g. after files were added at the top of a folder installed by its contents).

    Raises:
        DescriptionError: If the package is unknown.
    """
    pkg = package if isinstance(package, Package) else find_package(package, extra)
    if not pkg.maps_through_rules:
        return pkg.path
    view = _VIEWS.get(pkg.path)
    if view is None or rebuild or not view.is_dir():
        view = _VIEWS[pkg.path] = _build_view(pkg)
        _VIEW_PACKAGES[view] = pkg
    return view


_VIEW_PACKAGES: dict[Path, Package] = {}


def explain_missing(path: str | os.PathLike[str]) -> DescriptionError | None:
    """For a missing file below a view made by :func:`share_directory`: the error that lists every place it was
    looked for in the source tree; None for any other path."""
    target = Path(os.path.abspath(path))
    for view, pkg in _VIEW_PACKAGES.items():
        try:
            relative = target.relative_to(view)
        except ValueError:
            continue
        rel = relative.as_posix()
        return _not_found(pkg, rel, pkg.candidates(rel))
    return None


def view_to_source(text: str) -> str:
    """``text`` with every view folder replaced by ``$(find <pkg>)`` (for messages that quote view paths)."""
    for view, pkg in _VIEW_PACKAGES.items():
        text = text.replace(str(view), f"$(find {pkg.name})")
    return text
