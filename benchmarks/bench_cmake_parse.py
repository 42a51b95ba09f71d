"""Seconds per MB to read the install rules of a CMakeLists.txt, by file shape and size (up to 5 MB).

Each shape is written to a temporary file of each size and read with ``parse_install_rules`` (the whole path a
package's CMakeLists.txt takes: reading, the one-pass parser, variable expansion, the rules). Times are CPU seconds
of this process (``time.process_time``), steadier than wall time on a shared machine. A figure per MB that stays flat
as the size grows means time linear in the size; one that grows with it means worse.

    .venv/bin/python benchmarks/bench_cmake_parse.py [--sizes 0.5 1 2 5] [--repeat 3]
"""

from __future__ import annotations

import argparse
import logging
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from rrbot_workshop.description.packages import parse_install_rules

MB = 1024 * 1024


def many_commands(size: int) -> str:
    """Ordinary commands one after another: set(), install(DIRECTORY), install(FILES ... RENAME), comments."""
    block = ('set(CONFIG_{i} "config/{i}.yaml")  # a comment\n'
             "install(DIRECTORY description/urdf_{i} launch/ DESTINATION share/${{PROJECT_NAME}}/d{i})\n"
             "install(FILES ${{CONFIG_{i}}} DESTINATION share/${{PROJECT_NAME}}/config RENAME c{i}.yaml)\n"
             "#[[ a bracket\ncomment ]]\n")
    parts, total, i = ["project(bench)\n"], 0, 0
    while total < size:
        parts.append(block.format(i=i))
        total += len(parts[-1])
        i += 1
    return "".join(parts)


def deep_nesting(size: int) -> str:
    """One if() whose arguments nest parentheses as deep as the file allows, then an install()."""
    depth = (size - 100) // 2
    return "if(" + "(" * depth + ")" * depth + ")\ninstall(DIRECTORY urdf DESTINATION share/${PROJECT_NAME})\n"


def doubling_set(size: int) -> str:
    """set(A ${A}${A}) over and over: the value would double each time (2**n characters)."""
    line = "set(A ${A}${A})\n"
    return "set(A x)\n" + line * ((size - 9) // len(line)) + "install(DIRECTORY ${A} DESTINATION share/p)\n"


def unclosed_command(size: int) -> str:
    """An install( never closed, followed by commands that each look like the start of another one."""
    line = "foo(bar baz\n"
    return "install(DIRECTORY urdf DESTINATION share/${PROJECT_NAME}\n" + line * (size // len(line))


def quoted_and_brackets(size: int) -> str:
    """Quoted arguments with escapes and bracket arguments in every command (the token-by-token path)."""
    line = 'message(STATUS "a \\"quoted\\" ${PROJECT_NAME};b" [=[bracket ]] text]=] (nested (x)))\n'
    return line * (size // len(line))


SHAPES: dict[str, Callable[[int], str]] = {
    "many commands": many_commands,
    "deep nesting": deep_nesting,
    "doubling set()": doubling_set,
    "unclosed command": unclosed_command,
    "quoted and brackets": quoted_and_brackets,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=float, nargs="+", default=[0.5, 1, 2, 5], help="file sizes in [MB]")
    parser.add_argument("--repeat", type=int, default=3, help="runs per figure (the fastest is shown)")
    args = parser.parse_args()
    logging.disable(logging.WARNING)  # the unclosed command's warning, once per run
    print(f"{'shape':<22}" + "".join(f"{f'{s:g} MB':>14}" for s in args.sizes) + "   (CPU seconds per MB)")
    with tempfile.TemporaryDirectory() as folder:
        cmake = Path(folder) / "CMakeLists.txt"
        for name, make in SHAPES.items():
            row = []
            for size in args.sizes:
                cmake.write_text(make(int(size * MB)))
                best = float("inf")
                for _ in range(args.repeat):
                    start = time.process_time()
                    parse_install_rules(cmake, "bench")
                    best = min(best, time.process_time() - start)
                row.append(best / (cmake.stat().st_size / MB))
            print(f"{name:<22}" + "".join(f"{v:>14.3f}" for v in row))


if __name__ == "__main__":
    main()
