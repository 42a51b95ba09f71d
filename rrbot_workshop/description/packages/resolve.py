"""``$(find pkg)`` and ``package://pkg/...`` resolved through the package path, and the install view xacro opens.

See :mod:`rrbot_workshop.description.packages` for how a source tree resolves as its installed form would.
"""

from __future__ import annotations

import os
import re
import threading
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from rrbot_workshop.description.packages.crawl import find_package, known_package, package_index
from rrbot_workshop.description.packages.installed import InstallTree, install_tree
from rrbot_workshop.description.packages.package import Package
from rrbot_workshop.description.packages.view import build_view
from rrbot_workshop.exceptions import DescriptionError

__all__ = [
    "resolve",
    "resolve_uri",
    "split_package_reference",
    "package_of",
    "share_directory",
    "explain_missing",
    "view_to_source",
]


def _not_found(package: Package, relative: str, candidates: Sequence[Path]) -> DescriptionError:
    looked = "; ".join(str(c) for c in candidates) or "nowhere"
    special = [c for c in candidates if os.path.lexists(c) and not (os.path.isfile(c) or os.path.isdir(c))]
    if special:  # a FIFO, a device, a socket or a broken link: reading it could block, or there is nothing
        return DescriptionError(
            f"file '{relative}' of package '{package.name}' is {special[0]}, which is not a regular file (a FIFO, "
            "device, socket or broken link); give a regular file", element="package",
            attribute=f"{package.name}/{relative}")
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
        known = known_package(package)
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
@dataclass(frozen=True)
class _View:
    path: Path
    tree: InstallTree


_LOCK = threading.RLock()
_VIEWS: dict[Path, _View] = {}
_VIEW_PACKAGES: dict[Path, Package] = {}


def share_directory(package: str | Package,
                    extra: Iterable[str | os.PathLike[str]] | str | os.PathLike[str] | None = None,
                    rebuild: bool = False) -> Path:
    """A folder that looks like the package's installed ``share/<package>``: what ``$(find package)`` gives.

    Installed trees, packages without install rules and the course's descriptions give their own folder. A source
    tree with install rules gives its install view (see :mod:`~rrbot_workshop.description.packages.view`): real
    folders of its own and links to the source files. The installed tree is worked out again on every call, and a
    new view is written when it differs from the last one (a file added, a rule changed) or ``rebuild`` is set;
    nothing outside the view's own folder is ever written.

    Raises:
        DescriptionError: If the package is unknown, its install rules were refused (a DESTINATION that leaves the
            install prefix), two rules install a file and a folder at one path, or the rules install more files
            than :data:`~rrbot_workshop.description.packages.installed.MAX_ENTRIES`.
    """
    pkg = package if isinstance(package, Package) else find_package(package, extra)
    pkg.check()
    if not pkg.maps_through_rules:
        return pkg.path
    tree = install_tree(pkg)
    with _LOCK:
        known = _VIEWS.get(pkg.path)
        if known is not None and not rebuild and known.tree == tree and os.path.isdir(known.path):
            return known.path
        view = build_view(tree)
        _VIEWS[pkg.path] = _View(view, tree)
        _VIEW_PACKAGES[view] = pkg
    return view


def explain_missing(path: str | os.PathLike[str]) -> DescriptionError | None:
    """For a missing file below a view made by :func:`share_directory`: the error that lists every place it was
    looked for in the source tree; None for any other path."""
    target = Path(os.path.abspath(path))
    for view, pkg in list(_VIEW_PACKAGES.items()):
        try:
            relative = target.relative_to(view)
        except ValueError:
            continue
        rel = relative.as_posix()
        return _not_found(pkg, rel, pkg.candidates(rel))
    return None


def view_to_source(text: str) -> str:
    """``text`` with every view folder replaced by ``$(find <pkg>)`` (for messages that quote view paths)."""
    for view, pkg in list(_VIEW_PACKAGES.items()):
        text = text.replace(str(view), f"$(find {pkg.name})")
    return text
