"""``rrbot-workshop``: one command-line tool for the course, the tools and the classroom.

The course's commands (grade, progress, tasks, reset, export) live in :mod:`rrbot_workshop.course.commands`, the
tools' (lint, bringup) in :mod:`rrbot_workshop.tools.commands`, the classroom's (init, singleuser, class-report) in
:mod:`rrbot_workshop.classroom.commands`; this module builds one parser from the three and runs a command.

Exit status: 0 when the command ran (a low score is still a successful grading), 1 when a grader could not
run or ``lint`` found an error, 2 for a usage error (unknown task, unknown track, bad folder). Output carries no
wall-clock times, so notebook cells that call it give the same output every run.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence
from typing import NoReturn

from rrbot_workshop.classroom import commands as classroom_commands
from rrbot_workshop.course import commands as course_commands
from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError, GradingError, RRBotWorkshopError
from rrbot_workshop.tools import commands as tool_commands
from rrbot_workshop.tools.commands import LINT_ERRORS, USAGE_ERROR

__all__ = ["main", "build_parser", "USAGE_ERROR", "GRADER_ERROR", "LINT_ERRORS"]

#: Exit status when a grader could not run.
GRADER_ERROR = 1

_Handler = Callable[[argparse.Namespace], int]


class _Parser(argparse.ArgumentParser):
    """argparse, with a usage error said in one line (and where to find the usage) instead of the whole usage."""

    def error(self, message: str) -> NoReturn:
        self.exit(USAGE_ERROR, f"{self.prog}: error: {message.splitlines()[0] if message else 'bad arguments'} "
                               f"(see: {self.prog} --help)\n")


def _build(handlers: dict[str, _Handler]) -> argparse.ArgumentParser:
    parser = _Parser(
        prog="rrbot-workshop", description="Self-checks and instructor tools for the rrbot_workshop course."
    )
    parser.add_argument("--course", metavar="DIR", help="course folder (default: found from the current folder)")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for package in (course_commands, classroom_commands, tool_commands):
        handlers.update(package.add_commands(sub))
    return parser


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``rrbot-workshop``, with every command's sub-parser."""
    return _build({})


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``rrbot-workshop`` with ``argv`` (default ``sys.argv[1:]``) and return the exit status."""
    handlers: dict[str, _Handler] = {}
    parser = _build(handlers)
    given = list(sys.argv[1:] if argv is None else argv)
    if given[:1] == ["singleuser"] and not {"-h", "--help"} & set(given[1:2]):
        # everything after the command is the spawner's, options included (argparse would take them as ours)
        return handlers["singleuser"](argparse.Namespace(args=given[1:]))
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help (0) or a usage error (2)
        return int(exc.code) if isinstance(exc.code, int) else USAGE_ERROR
    previous_root = os.environ.get(tracks.ROOT_ENV)
    if args.course:
        os.environ[tracks.ROOT_ENV] = os.path.abspath(args.course)
    try:
        return handlers[args.command](args)
    except CourseError as exc:
        print(f"rrbot-workshop: error: {exc}", file=sys.stderr)
        return USAGE_ERROR
    except GradingError as exc:
        print(f"rrbot-workshop: the grader could not run: {exc}", file=sys.stderr)
        return GRADER_ERROR
    except (RRBotWorkshopError, OSError) as exc:  # a file or value the command could not use: one line, usage error
        text = str(exc).strip().splitlines()
        print(f"rrbot-workshop: error: {text[0] if text else type(exc).__name__}", file=sys.stderr)
        return USAGE_ERROR
    finally:
        if previous_root is None:
            os.environ.pop(tracks.ROOT_ENV, None)
        else:
            os.environ[tracks.ROOT_ENV] = previous_root


if __name__ == "__main__":
    sys.exit(main())
