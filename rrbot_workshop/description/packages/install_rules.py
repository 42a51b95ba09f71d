"""CMake's ``install(DIRECTORY|FILES ... DESTINATION share/${PROJECT_NAME}...)`` rules, read from a package's
``CMakeLists.txt``: what its installed ``share/<pkg>`` folder holds, and which source file each path comes from.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

__all__ = ["InstallRule", "parse_install_rules"]


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
