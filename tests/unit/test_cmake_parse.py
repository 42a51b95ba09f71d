"""CMake's language read in one pass (``description/packages/cmake.py``) and the install rules read through it.

The work is counted, never timed: the function calls made (Python and C), and the characters that the reader's own
``str.count``/``str.find`` calls span, must grow no faster than the file."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from rrbot_workshop.description.packages import parse_cmake, parse_install_rules


def _args(text: str, index: int = 0) -> list[str]:
    return [a.text for a in parse_cmake(text).commands[index].arguments]


def test_commands_have_lower_case_names_lines_and_offsets() -> None:
    text = "\n# a comment (with parens)\nProject(p)\n  SET( A\n  b c )\n#[[ bracket\ncomment ]]install(FILES x)\n"
    parsed = parse_cmake(text)
    assert [(c.name, c.line) for c in parsed.commands] == [("project", 3), ("set", 4), ("install", 7)]
    assert parsed.problem == "" and _args(text, 1) == ["A", "b", "c"]
    first = parsed.commands[0]
    assert text[first.start:first.end] == "Project(p)"


def test_quoted_bracket_and_escaped_arguments() -> None:
    """Quoted arguments keep spaces and decode escapes; bracket arguments are verbatim; comments inside a command are
    skipped; nested parentheses are not arguments."""
    text = 'message("a \\"b\\" c\\n" [=[x ]] y]=] # note ) (\n  (nested ARG) z\\ w)\n'
    parsed = parse_cmake(text)
    args = parsed.commands[0].arguments
    assert [a.text for a in args] == ['a "b" c\n', "x ]] y", "nested", "ARG", "z w"]
    assert [a.quoted for a in args] == [True, True, False, False, False]


def test_keep_returns_only_the_named_commands_but_reads_them_all() -> None:
    parsed = parse_cmake('set(A 1)\nmessage("unclosed\ninstall(FILES x)\n', keep=("set", "install"))
    assert [c.name for c in parsed.commands] == ["set"]
    assert "quoted argument of message() is never closed" in parsed.problem and parsed.problem_line == 2


@pytest.mark.parametrize(("text", "problem", "line"), [
    ("set(A 1)\n\ninstall(DIRECTORY x\n  DESTINATION share/p\n", "install( at line 3 is never closed", 3),
    ("set(A 1)\nset(B [==[ never\nclosed\n", "a bracket argument of set() opened with '[==[' is never closed", 2),
    ("set(A 1)\n#[[ comment\n", "a bracket comment opened with '#[[' is never closed", 2),
    ("set(A 1)\nnot cmake\nset(B 2)\n", "'not cmake\nset(B 2)\n' is not a command", 2),
])
def test_text_cmake_cannot_read_gives_the_commands_before_it_and_the_fault(text: str, problem: str,
                                                                         line: int) -> None:
    parsed = parse_cmake(text)
    assert parsed.problem.startswith(problem) and parsed.problem_line == line
    assert parsed.commands[0].name == "set"


def test_an_unclosed_command_keeps_the_rules_before_it_and_marks_them_incomplete(tmp_path: Path) -> None:
    cmake = tmp_path / "CMakeLists.txt"
    cmake.write_text("install(DIRECTORY urdf DESTINATION share/${PROJECT_NAME})\ninstall(DIRECTORY config\n")
    rules, complete = parse_install_rules(cmake, "p")
    assert [r.source.name for r in rules] == ["urdf"] and not complete


# ============================================================================ work grows with the size, no faster
def _many_commands(n: int) -> str:
    return "".join(f'set(V{i} "config/{i}") # c\ninstall(DIRECTORY d{i}/ DESTINATION share/${{PROJECT_NAME}})\n'
                   f"#[[ b\n]]\n" for i in range(n // 100))


SHAPES: dict[str, Callable[[int], str]] = {
    "many commands": _many_commands,
    "deep nesting": lambda n: "if(" + "(" * (n // 2) + ")" * (n // 2) + ")\n",
    "nesting runs": lambda n: "if(" + "((a) " * (n // 5) + ")" * (n // 5) + ")\n",
    "doubling set": lambda n: "set(A x)\n" + "set(A ${A}${A})\n" * (n // 16),
    "unclosed command": lambda n: "install(DIRECTORY x\n" + "foo(bar baz\n" * (n // 12),
    "unclosed quote": lambda n: 'message("' + "foo(bar) \\\" baz\n" * (n // 16),
    "comments": lambda n: "# foo(bar)\n#[[ x ]] set(A 1)\n" * (n // 30),
}


class _Metered(str):
    """A text whose ``count`` and ``find`` calls add up the characters they span."""

    spanned = 0

    def count(self, sub: str, start: int | None = None, end: int | None = None) -> int:  # type: ignore[override]
        _Metered.spanned += (len(self) if end is None else end) - (start or 0)
        return str.count(self, sub, start, end)

    def find(self, sub: str, start: int | None = None, end: int | None = None) -> int:  # type: ignore[override]
        found = str.find(self, sub, start, end)
        _Metered.spanned += (len(self) if found < 0 else found + len(sub)) - (start or 0)
        return found


def _work(text: str, path: Path) -> tuple[int, int]:
    """(function calls while the file's rules are read, characters the reader's count/find calls spanned)."""
    calls = 0

    def count(frame: object, event: str, arg: object) -> None:
        nonlocal calls
        if event in ("call", "c_call"):
            calls += 1

    path.write_text(text)
    sys.setprofile(count)
    try:
        parse_install_rules(path, "p")
    finally:
        sys.setprofile(None)
    _Metered.spanned = 0
    parse_cmake(_Metered(text))
    return calls, _Metered.spanned


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_reading_work_grows_linearly_with_the_file(shape: str, tmp_path: Path) -> None:
    """Four times the text costs at most 4.4 times the calls; the reader's scans of the text add up to at most three
    times its length (each character is looked at a bounded number of times)."""
    small, large = SHAPES[shape](16_000), SHAPES[shape](64_000)
    calls_small, spanned_small = _work(small, tmp_path / "CMakeLists.txt")
    calls_large, spanned_large = _work(large, tmp_path / "CMakeLists.txt")
    assert calls_large <= 4.4 * calls_small * len(large) / (4 * len(small)) + 200
    assert spanned_small <= 3 * len(small) and spanned_large <= 3 * len(large)


def test_doubling_set_gives_up_the_value_instead_of_growing_it(tmp_path: Path) -> None:
    """``set(A ${A}${A})`` 40 times would be 2**40 characters; past the limit ${A} is unknown (rules incomplete)."""
    cmake = tmp_path / "CMakeLists.txt"
    cmake.write_text("set(A x)\n" + "set(A ${A}${A})\n" * 40 + "install(DIRECTORY ${A} DESTINATION share/p)\n"
                     "install(DIRECTORY urdf DESTINATION share/p)\n")
    rules, complete = parse_install_rules(cmake, "p")
    assert [r.source.name for r in rules] == ["urdf"] and not complete


def test_variables_known_and_unknown(tmp_path: Path) -> None:
    """set() lists, nested ${a_${b}}, unset() and set(X) forget, $ENV is unknown."""
    cmake = tmp_path / "CMakeLists.txt"
    cmake.write_text("set(DIRS urdf config)\nset(K D)\nset(DIR_D meshes)\n"
                     "install(DIRECTORY ${DIRS} ${DIR_${K}} DESTINATION share/${PROJECT_NAME})\n"
                     "unset(DIRS)\ninstall(DIRECTORY ${DIRS} DESTINATION share/p)\n")
    rules, complete = parse_install_rules(cmake, "p")
    assert [r.source.name for r in rules] == ["urdf", "config", "meshes"] and not complete
    cmake.write_text("install(DIRECTORY $ENV{HOME}/x DESTINATION share/p)\n")
    assert parse_install_rules(cmake, "p") == ([], False)
