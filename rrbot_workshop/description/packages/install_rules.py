"""CMake's ``install(DIRECTORY|FILES ... DESTINATION share/${PROJECT_NAME}...)`` rules, read from a package's
``CMakeLists.txt``: what its installed ``share/<pkg>`` folder holds, and which source file each path comes from.

The file is read by :func:`~rrbot_workshop.description.packages.cmake.parse_cmake` in one pass, and variables are
expanded within a budget proportional to the file's size, so a file of any shape (a hundred thousand commands, deep
nesting, ``set(A ${A}${A})`` doubling, a command never closed) costs time linear in its size. What the reader cannot
follow (a variable it does not know, a value past the budget, a file CMake could not read) makes the rules
*incomplete*: the package then also resolves from its source folder.
"""

from __future__ import annotations

import logging
import os
import posixpath
import re
import stat
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from rrbot_workshop.description.packages.cmake import Argument, Command, parse_cmake
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["InstallRule", "parse_install_rules", "MAX_CMAKE_BYTES"]

_log = logging.getLogger("rrbot_workshop.description.packages")

#: Largest ``CMakeLists.txt`` read [bytes]; a larger one is not read (its package resolves from its source folder).
MAX_CMAKE_BYTES = 16 * 1024 * 1024
#: Longest value a variable may take [characters]; a longer one counts as unknown.
MAX_VALUE = 64 * 1024


@dataclass(frozen=True)
class InstallRule:
    """One ``install(DIRECTORY|FILES ...)`` source that lands in the package's ``share/<pkg>`` folder.

    Attributes:
        source: The file or folder in the source tree (absolute).
        destination: Folder below ``share/<pkg>`` it is installed into (``"."``: ``share/<pkg>`` itself); never
            leaves it.
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
_INNERMOST = re.compile(r"\$\{([A-Za-z0-9_./+-]*)\}")


class _Variables:
    """CMake variables as far as this reader follows them, expanded within a budget of characters."""

    def __init__(self, root: Path, package: str, budget: int) -> None:
        self.values = {
            "PROJECT_NAME": package, "CMAKE_CURRENT_SOURCE_DIR": str(root), "PROJECT_SOURCE_DIR": str(root),
            "CMAKE_SOURCE_DIR": str(root), "CMAKE_CURRENT_LIST_DIR": str(root),
        }
        self.budget = budget

    def expand(self, text: str) -> str | None:
        """``text`` with every ``${VAR}`` replaced (innermost first); None if one is unknown or the budget is spent."""
        for _ in range(8):  # ${a_${b}} nests; deeper nesting is not followed
            if "${" not in text:
                break
            unknown = False

            def sub(match: re.Match[str]) -> str:
                nonlocal unknown
                value = self.values.get(match.group(1))
                if value is None:
                    unknown = True
                    return ""
                return value

            text = _INNERMOST.sub(sub, text)
            self.budget -= len(text)
            if unknown or self.budget < 0 or len(text) > MAX_VALUE:
                return None
        if "${" in text or "$ENV{" in text or "$CACHE{" in text:
            return None
        return text

    def items(self, args: list[Argument]) -> list[str] | None:
        """The list elements of ``args`` after expansion (unquoted ones split at ``;``); None if one is unknown."""
        out: list[str] = []
        for arg in args:
            value = self.expand(arg.text)
            if value is None:
                return None
            out.extend([value] if arg.quoted else [v for v in value.split(";") if v])
        return out


def _read(cmake_file: Path) -> str | None:
    """The text of ``cmake_file`` if it is a regular file of at most :data:`MAX_CMAKE_BYTES`, else None."""
    try:
        info = os.stat(cmake_file)
        if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_CMAKE_BYTES:
            _log.warning("%s is not read (%s); its package resolves from its source folder", cmake_file,
                         "not a regular file" if not stat.S_ISREG(info.st_mode)
                         else f"larger than {MAX_CMAKE_BYTES} bytes")
            return None
        with open(cmake_file, "rb") as handle:
            data = handle.read(MAX_CMAKE_BYTES + 1)
    except OSError:
        return None
    if len(data) > MAX_CMAKE_BYTES:
        return None
    return data.decode("utf-8", errors="replace")


def _refuse(cmake_file: Path, text: str, command: Command, why: str) -> DescriptionError:
    rule = " ".join(text[command.start:command.end].split())
    if len(rule) > 160:
        rule = rule[:157] + "..."
    return DescriptionError(
        f"line {command.line}: {rule} {why}; colcon would write outside install/. Give a DESTINATION below "
        "share/${PROJECT_NAME}", source=str(cmake_file), element="install", attribute=f"line {command.line}")


def _share_relative(norm: str, package: str) -> PurePosixPath | None:
    """A normalized install path relative to ``share/<package>``, or None if it lies elsewhere in the prefix."""
    parts = PurePosixPath(norm).parts
    if parts[:2] != ("share", package):
        return None
    return PurePosixPath(*parts[2:]) if len(parts) > 2 else PurePosixPath(".")


def _leaves_prefix(norm: str) -> bool:
    return norm == ".." or norm.startswith("../")


def _install(command: Command, variables: _Variables, root: Path, package: str, cmake_file: Path,
             text: str) -> tuple[list[InstallRule], bool]:
    """The share rules of one ``install(DIRECTORY|FILES|PROGRAMS ...)`` and whether it was followed in full.

    Raises:
        DescriptionError: If its DESTINATION, or a file's DESTINATION/RENAME, leaves the install prefix.
    """
    args = list(command.arguments)
    kind = args[0].text
    i = 1
    while i < len(args) and args[i].text not in _KEYWORDS:
        i += 1
    sources = args[1:i]
    options: dict[str, Argument] = {}
    while i < len(args):
        key = args[i].text
        if key in ("DESTINATION", "RENAME", "TYPE", "COMPONENT") and i + 1 < len(args):
            options[key] = args[i + 1]
            i += 2
        else:  # flags, permissions, PATTERN/REGEX filters (the folder still maps: an over-approximation)
            i += 1
    if "DESTINATION" not in options:
        return [], True  # TYPE ...: another folder than share/<pkg>
    dest = variables.expand(options["DESTINATION"].text)
    if dest is None:
        return [], False
    norm = posixpath.normpath(dest.replace("\\", "/")) if dest else "."
    if norm.startswith("/"):
        return [], True  # an absolute DESTINATION: outside share/<pkg>, nothing of $(find pkg)
    if _leaves_prefix(norm):
        raise _refuse(cmake_file, text, command, f"installs into {dest!r}, which leaves the install prefix")
    below = _share_relative(norm, package)
    if below is None:
        return [], True  # include/, lib/, another package's share folder
    items = variables.items(sources)
    if items is None:
        return [], False
    rename: str | None = None
    if "RENAME" in options and kind != "DIRECTORY":
        rename = variables.expand(options["RENAME"].text)
        if rename is None:
            return [], False
        renamed = posixpath.normpath(f"{norm}/{rename}")
        if rename.startswith("/") or _leaves_prefix(renamed):
            raise _refuse(cmake_file, text, command, f"renames a file to {rename!r}, which leaves the install prefix")
        if _share_relative(renamed, package) in (None, PurePosixPath(".")):
            return [], True
    rules: list[InstallRule] = []
    complete = True
    for item in items:
        if "$<" in item:  # a generator expression: known only when CMake generates
            complete = False
            continue
        src = Path(os.path.normpath(Path(item) if Path(item).is_absolute() else root / item))
        if kind == "DIRECTORY":
            contents = item.endswith(("/", "\\")) or PurePosixPath(item).name in ("", ".")
            rules.append(InstallRule(src, below, "contents" if contents else "directory", line=command.line))
        elif rename is not None and len(items) == 1:
            where = _share_relative(posixpath.normpath(f"{norm}/{rename}"), package)
            assert where is not None
            rules.append(InstallRule(src, where.parent, "file", name=where.name, line=command.line))
        else:
            rules.append(InstallRule(src, below, "file", line=command.line))
    return rules, complete


def parse_install_rules(cmake_file: Path, package: str) -> tuple[list[InstallRule], bool]:
    """The rules of ``cmake_file`` that install into ``share/<package>``, in the order CMake runs them.

    Args:
        cmake_file: A package's ``CMakeLists.txt``.
        package: The package name (the ``<name>`` of its ``package.xml``).

    Returns:
        ``(rules, complete)``: ``complete`` is False when an ``install()`` could not be followed (a variable this
        reader does not know, a destination it cannot read) or the file could not be read in full (not a regular
        file, larger than :data:`MAX_CMAKE_BYTES`, a command never closed); the package then also resolves from its
        source folder.

    Raises:
        DescriptionError: If a rule's DESTINATION (or a file's RENAME) leaves the install prefix
            (``DESTINATION ../x``, ``share/${PROJECT_NAME}/../../..``): the message names the file, the line and the
            rule.
    """
    text = _read(cmake_file)
    if text is None:
        return [], False
    root = cmake_file.parent
    parsed = parse_cmake(text, keep=("project", "set", "unset", "install"))
    variables = _Variables(root, package, budget=4 * len(text) + (1 << 20))
    rules: list[InstallRule] = []
    complete = not parsed.problem
    if parsed.problem:
        _log.warning("%s:%d: %s (CMake would stop here); install rules after it are not read", cmake_file,
                     parsed.problem_line, parsed.problem)
    for command in parsed.commands:
        args = command.arguments
        if command.name == "project" and args:
            name = variables.expand(args[0].text)
            variables.values["PROJECT_NAME"] = variables.values["CMAKE_PROJECT_NAME"] = name or package
        elif command.name == "set" and args:
            if any(a.text in ("CACHE", "PARENT_SCOPE") for a in args[1:]):
                continue
            values = variables.items(list(args[1:]))
            if values is None or len(args) == 1:
                variables.values.pop(args[0].text, None)  # unknown from now on (set(X) unsets X)
            else:
                joined = ";".join(values)
                if len(joined) > MAX_VALUE:
                    variables.values.pop(args[0].text, None)
                else:
                    variables.values[args[0].text] = joined
        elif command.name == "unset" and args:
            variables.values.pop(args[0].text, None)
        elif command.name == "install" and args and args[0].text in ("DIRECTORY", "FILES", "PROGRAMS"):
            found, followed = _install(command, variables, root, package, cmake_file, text)
            rules.extend(found)
            complete = complete and followed
    return rules, complete
