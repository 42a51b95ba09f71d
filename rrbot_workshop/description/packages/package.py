"""One package found on the package path: its name, its folder, how it was found, and where its installed files are.

:class:`Package` is what the crawl (:mod:`~rrbot_workshop.description.packages.crawl`) finds and what the install
replay (:mod:`~rrbot_workshop.description.packages.installed`) reads; it depends on neither.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from rrbot_workshop.description.packages.install_rules import InstallRule
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["Package"]


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
    refused: DescriptionError | None = field(default=None, compare=False)

    def check(self) -> None:
        """Raise the error that makes this package unusable, if any.

        Raises:
            DescriptionError: If its ``CMakeLists.txt`` has a rule that installs outside the install prefix.
        """
        if self.refused is not None:
            raise DescriptionError(str(self.refused), element="package", attribute=self.name)

    @property
    def maps_through_rules(self) -> bool:
        """True when share-relative paths map through install rules (a source tree with share rules)."""
        return self.layout == "source" and bool(self.rules)

    def candidates(self, relative: str | PurePosixPath) -> list[Path]:
        """Every file that ``share/<name>/<relative>`` may be, in the order they are tried.

        For a source tree with install rules: for ``package.xml`` the manifest first (ament installs it last), then
        the later rule first (CMake installs in order, so a later rule overwrites an earlier one), then, only when
        some rule could not be read, the same path in the source folder. Otherwise the path in the package's folder.

        Raises:
            DescriptionError: If the package's install rules were refused (see :meth:`check`).
        """
        self.check()
        rel = PurePosixPath(str(relative).replace("\\", "/").lstrip("/"))
        if not self.maps_through_rules:
            return [self.path / rel]
        found: list[Path] = []
        if rel == PurePosixPath("package.xml") and self.manifest is not None:
            found.append(self.manifest)  # ament_package() installs it last
        for rule in reversed(self.rules):
            source = rule.source_for(rel)
            if source is not None and source not in found:
                found.append(source)
        if not self.rules_complete and self.path / rel not in found:
            found.append(self.path / rel)
        return found

    def find(self, relative: str | PurePosixPath) -> Path | None:
        """The first of :meth:`candidates` that is a regular file or a folder, or None (a FIFO or device is never
        taken: reading it could block)."""
        for candidate in self.candidates(relative):
            if os.path.isfile(candidate) or os.path.isdir(candidate):  # False, never an error, where it cannot look
                return candidate
        return None

    def describe(self) -> str:
        """``name (source tree /path)`` as messages show it."""
        kind = {"source": "source tree", "installed": "installed", "descriptions": "course description"}[self.layout]
        return f"{self.name} ({kind} {self.path})"
