"""CMake's language read in one pass: the commands of a ``CMakeLists.txt``, their arguments and their lines.

The reader follows the grammar of ``cmake-language(7)``: a file is command invocations (``name(arguments)``), line
comments (``# ...``), bracket comments (``#[[ ... ]]``) and white space; arguments are bracket arguments
(``[=[ ... ]=]``), quoted arguments (``"..."`` with ``\\`` escapes) and unquoted arguments, with parentheses nesting
inside a command. It never backs up: every character is looked at a bounded number of times, so the time it takes
grows with the size of the file and not faster (``benchmarks/bench_cmake_parse.py`` measures it). A file CMake could
not read (a command or quoted argument never closed) gives the commands before the fault and a :class:`CMakeFile`
whose :attr:`~CMakeFile.problem` says where it is.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass, field
from typing import NamedTuple

__all__ = ["Argument", "Command", "CMakeFile", "parse_cmake"]


class Argument(NamedTuple):
    """One argument of a command.

    Attributes:
        text: Its value, escapes decoded (``"a\\"b"`` is ``a"b``); variable references are left as written.
        quoted: True for a quoted or bracket argument (CMake never splits those at ``;``).
    """

    text: str
    quoted: bool = False


class Command(NamedTuple):
    """One command invocation.

    Attributes:
        name: The command's name in lower case (CMake's command names are case-insensitive).
        arguments: Its arguments in order (parentheses nested inside it group arguments for ``if()``; they are not
            kept).
        line: Line of the command's name, from 1.
        start: Offset of the name in the text.
        end: Offset just past the closing parenthesis.
    """

    name: str
    arguments: tuple[Argument, ...]
    line: int
    start: int
    end: int


@dataclass
class CMakeFile:
    """The commands of a file, and what stopped the reader if the file is not valid CMake.

    Attributes:
        commands: The command invocations, in order.
        problem: Why the reader stopped (``""`` when it read the whole file).
        problem_line: The line of :attr:`problem` (0 when there is none).
    """

    commands: list[Command] = field(default_factory=list)
    problem: str = ""
    problem_line: int = 0


# One command whose arguments are plain words (no quotes, brackets, comments, escapes or nested parentheses): most
# commands of a real CMakeLists.txt, read with one match. Anything else is read token by token.
_SIMPLE = re.compile(r"([A-Za-z_][A-Za-z0-9_]*+)[ \t]*+\(([^()\"#\\\[\]]*+)\)")
_NAME = re.compile(r"([A-Za-z_][A-Za-z0-9_]*+)[ \t]*+\(")
_SPACE = re.compile(r"[ \t\r\n]++")
_LINE_COMMENT = re.compile(r"#[^\n]*+")
_BRACKET_OPEN = re.compile(r"#?\[(=*+)\[")
_QUOTED = re.compile(r'"([^"\\]*+(?:\\.[^"\\]*+)*+)"', re.S)
_UNQUOTED = re.compile(r'(?:[^\s()#"\\]++|\\.)++', re.S)
_OTHER = re.compile(r"[^\s#]++|#")
_OPENING = re.compile(r"\(++")
_CLOSING = re.compile(r"\)++")
_ESCAPE = re.compile(r"\\(.)", re.S)
_ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "\n": "", ";": "\\;"}


def _decode(text: str) -> str:
    if "\\" not in text:
        return text
    return _ESCAPE.sub(lambda m: _ESCAPES.get(m.group(1), m.group(1)), text)


class _Reader:
    """The reading position over one text: offset and line, moved forward only."""

    def __init__(self, text: str, keep: Collection[str] | None) -> None:
        self.text = text
        self.keep = keep
        self.pos = 0
        self.line = 1
        self.result = CMakeFile()

    def advance(self, to: int) -> None:
        self.line += self.text.count("\n", self.pos, to)
        self.pos = to

    def fail(self, problem: str, line: int) -> None:
        self.result.problem, self.result.problem_line = problem, line
        self.advance(len(self.text))

    def bracket(self, open_match: re.Match[str], what: str) -> str | None:
        """Skip a bracket comment or argument that starts at ``open_match``; its content, or None if unclosed."""
        close = "]" + open_match.group(1) + "]"
        end = self.text.find(close, open_match.end())
        if end < 0:
            self.fail(f"{what} opened with '{open_match.group(0)}' is never closed with '{close}'", self.line)
            return None
        content = self.text[open_match.end():end]
        self.advance(end + len(close))
        return content[1:] if content.startswith("\n") else content

    def comment(self) -> bool:
        """Skip a comment at the position; False if the file ends inside it."""
        opened = _BRACKET_OPEN.match(self.text, self.pos)
        if opened is not None and opened.group(0).startswith("#"):
            return self.bracket(opened, "a bracket comment") is not None
        match = _LINE_COMMENT.match(self.text, self.pos)
        assert match is not None  # the position holds '#'
        self.pos = match.end()
        return True

    def arguments(self, name: str, line: int, start: int) -> bool:
        """Read the arguments of the command ``name`` up to its closing parenthesis; False if it is not closed."""
        text, depth = self.text, 1
        args: list[Argument] = []
        while self.pos < len(text):
            char = text[self.pos]
            if char in " \t\r\n":
                self.advance(_SPACE.match(text, self.pos).end())  # type: ignore[union-attr]
            elif char == "(":  # a run of them at once: nesting costs one step per run, not per parenthesis
                run = _OPENING.match(text, self.pos).end()  # type: ignore[union-attr]
                depth += run - self.pos
                self.pos = run
            elif char == ")":
                run = _CLOSING.match(text, self.pos).end()  # type: ignore[union-attr]
                if run - self.pos >= depth:
                    self.pos += depth
                    if self.keep is None or name in self.keep:
                        self.result.commands.append(Command(name, tuple(args), line, start, self.pos))
                    return True
                depth -= run - self.pos
                self.pos = run
            elif char == "#":
                if not self.comment():
                    return False
            elif char == '"':
                quoted = _QUOTED.match(text, self.pos)
                if quoted is None:
                    self.fail(f"a quoted argument of {name}() is never closed with '\"'", self.line)
                    return False
                args.append(Argument(_decode(quoted.group(1)).replace("\\;", ";"), quoted=True))
                self.advance(quoted.end())
            elif char == "[" and (opened := _BRACKET_OPEN.match(text, self.pos)) is not None:
                content = self.bracket(opened, f"a bracket argument of {name}()")
                if content is None:
                    return False
                args.append(Argument(content, quoted=True))
            else:
                word = _UNQUOTED.match(text, self.pos)
                if word is None:  # a lone backslash at the end of the file
                    self.pos += 1
                    continue
                args.append(Argument(_decode(word.group(0))))
                self.advance(word.end())
        self.fail(f"{name}( at line {line} is never closed with ')'", line)
        return False

    def read(self) -> CMakeFile:
        text, n, keep, commands = self.text, len(self.text), self.keep, self.result.commands
        while self.pos < n:
            char = text[self.pos]
            if char in " \t\r\n":
                self.advance(_SPACE.match(text, self.pos).end())  # type: ignore[union-attr]
                continue
            if char == "#":
                if not self.comment():
                    break
                continue
            simple = _SIMPLE.match(text, self.pos)
            if simple is not None:
                name = simple.group(1).lower()
                if keep is None or name in keep:
                    args = tuple([Argument(word, False) for word in simple.group(2).split()])
                    commands.append(Command(name, args, self.line, self.pos, simple.end()))
                self.advance(simple.end())
                continue
            named = _NAME.match(text, self.pos)
            if named is not None:
                start, line = self.pos, self.line
                self.advance(named.end())
                if not self.arguments(named.group(1).lower(), line, start):
                    break
                continue
            # not CMake (a stray word or parenthesis): CMake stops with a parse error; note it and read on
            if not self.result.problem:
                self.result.problem = f"'{text[self.pos:self.pos + 20]}' is not a command (name(arguments))"
                self.result.problem_line = self.line
            self.advance(_OTHER.match(text, self.pos).end())  # type: ignore[union-attr]
        return self.result


def parse_cmake(text: str, keep: Collection[str] | None = None) -> CMakeFile:
    """The command invocations of CMake ``text``, in one pass (time proportional to ``len(text)``).

    Args:
        text: The content of a ``CMakeLists.txt`` or ``.cmake`` file.
        keep: Names (lower case) of the commands to return; None returns every command. The others are read all
            the same (a fault in them is found), only not kept.

    Returns:
        The commands read; when the text is not valid CMake, the ones before the fault, and the fault in
        :attr:`CMakeFile.problem` with its line.
    """
    return _Reader(text, keep).read()
