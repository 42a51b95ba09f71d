"""What a source tree's installed ``share/<pkg>`` folder would hold: every installed path and the source file it is.

CMake runs a package's install rules in order, so a later rule overwrites a file an earlier one installed;
``install(DIRECTORY a)`` installs the folder ``a`` and ``install(DIRECTORY a/)`` what is in it; ``RENAME`` names a
file; ament installs ``package.xml``. :func:`install_tree` replays the rules the same way, in memory, reading the
source tree only. Folders are walked as CMake copies them, with three limits of this library's own:

* a link to a folder is followed only when the folder it leads to is inside the package or the rule's source (a
  link to ``/`` inside an installed folder is not a way into the whole file system), and never into a folder it is
  already inside (a loop);
* files that are not regular files (FIFOs, devices, sockets) are left out: reading them could block;
* at most :data:`MAX_ENTRIES` files and folders in all, and :data:`MAX_DEPTH` levels: past that, a
  :class:`~rrbot_workshop.exceptions.DescriptionError` names the rule.

A rule that installs a file where another installed a folder (or the reverse) is an error, as it is for CMake.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from rrbot_workshop.description.packages.install_rules import InstallRule
from rrbot_workshop.description.packages.package import Package
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["InstallTree", "install_tree", "MAX_ENTRIES", "MAX_DEPTH"]

_log = logging.getLogger("rrbot_workshop.description.packages")

#: Most files and folders one package's installed share folder may hold.
MAX_ENTRIES = 20_000
#: Deepest folder level below ``share/<pkg>``.
MAX_DEPTH = 32
_ROOT = PurePosixPath(".")


@dataclass
class InstallTree:
    """The installed ``share/<pkg>`` folder of a source tree, as paths relative to it.

    Attributes:
        package: The package's name.
        files: Installed path -> the source file it is (a link to a file is kept as the link's path).
        folders: Every installed folder (``"."`` is ``share/<pkg>`` itself).
        not_followed: Links to folders that were left out, with why (for messages).
    """

    package: str
    files: dict[PurePosixPath, Path] = field(default_factory=dict)
    folders: set[PurePosixPath] = field(default_factory=lambda: {_ROOT})
    not_followed: list[str] = field(default_factory=list)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, InstallTree) and self.package == other.package and self.files == other.files
                and self.folders == other.folders)

    __hash__ = None  # type: ignore[assignment]


def _inside(real: str, roots: tuple[str, ...]) -> bool:
    return any(real == root or real.startswith(root.rstrip(os.sep) + os.sep) for root in roots)


class _Builder:
    """Replays install rules into an :class:`InstallTree`, counting every entry against :data:`MAX_ENTRIES`."""

    def __init__(self, package: Package) -> None:
        self.package = package
        self.tree = InstallTree(package.name)
        self.makers: dict[PurePosixPath, str] = {}  # installed path -> the rule that made it (for conflicts)
        self.count = 0

    def _what(self, rule: InstallRule | None) -> str:
        return rule.describe(self.package.path, self.package.name) if rule is not None else "package.xml (ament)"

    def _conflict(self, path: PurePosixPath, rule: InstallRule | None, wanted: str, found: str) -> DescriptionError:
        return DescriptionError(
            f"install rule {self._what(rule)} installs a {wanted} at share/{self.package.name}/{path.as_posix()}, "
            f"where {self.makers.get(path, 'an earlier rule')} installed a {found}; CMake cannot install both. "
            "Give one of them another DESTINATION or RENAME", source=str(self.package.path / "CMakeLists.txt"),
            element="install", attribute=path.as_posix())

    def _count(self, rule: InstallRule | None) -> None:
        self.count += 1
        if self.count > MAX_ENTRIES:
            raise DescriptionError(
                f"the install rules of package '{self.package.name}' install more than {MAX_ENTRIES} files and "
                f"folders (reached at {self._what(rule)}); this library reads at most that many",
                source=str(self.package.path / "CMakeLists.txt"), element="install")

    def folder(self, path: PurePosixPath, rule: InstallRule | None, weak: bool = False) -> bool:
        """Install folder ``path`` (and its parents); False where a weak one yields to a file."""
        if path in self.tree.folders:
            return True
        if path != _ROOT and not self.folder(path.parent, rule, weak):
            return False
        if path in self.tree.files:
            if weak:
                return False
            raise self._conflict(path, rule, "folder", "file")
        self._count(rule)
        self.tree.folders.add(path)
        self.makers[path] = self._what(rule)
        return True

    def file(self, path: PurePosixPath, source: Path, rule: InstallRule | None, weak: bool = False) -> None:
        """Install ``source`` as ``path``; a later rule's file replaces an earlier one's."""
        if not self.folder(path.parent, rule, weak):
            return
        if path in self.tree.folders:
            if weak:
                return
            raise self._conflict(path, rule, "file", "folder")
        if weak and path in self.tree.files:
            return
        self._count(rule)
        self.tree.files[path] = source
        self.makers[path] = self._what(rule)

    def walk(self, source: Path, at: PurePosixPath, rule: InstallRule | None, weak: bool = False) -> None:
        """Install what folder ``source`` holds at ``at``, walking it as CMake copies it (see the module doc)."""
        roots = tuple(os.path.realpath(p) for p in (self.package.path, source))
        stack: list[tuple[Path, PurePosixPath, tuple[str, ...]]] = [(source, at, (os.path.realpath(source),))]
        while stack:
            folder, here, chain = stack.pop()
            if not self.folder(here, rule, weak):
                continue
            try:
                with os.scandir(folder) as scan:
                    entries = sorted(scan, key=lambda e: e.name)
            except OSError:
                continue  # unreadable: nothing of it is installed
            for entry in reversed(entries):
                target = here / entry.name
                if weak and here == at and entry.name.startswith("."):
                    continue
                try:
                    if entry.is_symlink():
                        real = os.path.realpath(entry.path)
                        if os.path.isdir(real):
                            self._follow(entry, real, target, chain, roots, stack, rule)
                        elif os.path.isfile(real):
                            self.file(target, Path(entry.path), rule, weak)
                    elif entry.is_dir(follow_symlinks=False):  # below a followed link it may be an ancestor
                        self._follow(entry, os.path.join(chain[-1], entry.name), target, chain, roots, stack, rule)
                    elif entry.is_file(follow_symlinks=False):
                        self.file(target, Path(entry.path), rule, weak)
                except OSError:
                    continue

    def _follow(self, entry: os.DirEntry[str], real: str, target: PurePosixPath, chain: tuple[str, ...],
                roots: tuple[str, ...], stack: list[tuple[Path, PurePosixPath, tuple[str, ...]]],
                rule: InstallRule | None) -> None:
        if real in chain or not _inside(real, roots) or len(chain) >= MAX_DEPTH:
            why = "a loop" if real in chain else "outside the package" if not _inside(real, roots) else "too deep"
            self.tree.not_followed.append(f"{entry.path} -> {real} ({why})")
            _log.info("share/%s/%s: the link %s -> %s is not followed (%s)", self.package.name, target.as_posix(),
                      entry.path, real, why)
            return
        stack.append((Path(entry.path), target, (*chain, real)))

    def rule(self, rule: InstallRule) -> None:
        """Replay one install rule (a missing source installs nothing here; CMake would stop with an error)."""
        source = rule.source
        if rule.kind == "file":
            if os.path.isfile(source):
                self.file(rule.installed_as, source, rule)
        elif os.path.isdir(source):
            self.walk(source, rule.installed_as, rule)


def install_tree(package: Package) -> InstallTree:
    """The installed ``share/<pkg>`` folder of a source tree with install rules, computed from the rules.

    A package whose rules could not all be followed (``rules_complete`` False) also shows its source folder's own
    files wherever no rule installs anything (hidden entries at its top left out), as :meth:`Package.candidates`
    looks there last.

    Raises:
        DescriptionError: If two rules install a file and a folder at one path, or the rules install more than
            :data:`MAX_ENTRIES` files and folders.
    """
    builder = _Builder(package)
    for rule in package.rules:
        builder.rule(rule)
    if package.manifest is not None:
        builder.file(PurePosixPath("package.xml"), package.manifest, None)  # ament_package(), the last command
    if not package.rules_complete:
        builder.walk(package.path, _ROOT, None, weak=True)
    return builder.tree
