"""``$(find pkg)`` and ``package://pkg/...`` resolved through the package path, and the install view xacro opens.

See :mod:`rrbot_workshop.description.packages` for how a source tree resolves as its installed form would.
"""

from __future__ import annotations

import atexit
import os
import re
import shutil
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path

from rrbot_workshop.description.packages.crawl import Package, find_package, known_package, package_index
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
