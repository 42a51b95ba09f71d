"""Short tracebacks in notebooks: a library error shows its clear line first, then where *you* called it.

An :class:`~rrbot_workshop.RRBotWorkshopError` raised deep inside the library (a xacro expansion, a
controller switch) would otherwise print dozens of frames of library code before the one line that says
what is wrong. ``%load_ext rrbot_workshop`` registers :func:`short_traceback` as IPython's handler for
these errors: it prints

* the error's type and message, the clear line, first;
* the frames of the learner's code only: notebook cells and files outside the library and Python itself;
* how many library frames were left out, and that ``%tb`` prints the full traceback.

When the error comes from something the learner's code raised earlier in the same cell, and the library caught and
logged (an ``on_configure`` that raised, so the switch that needed it was refused), that exception is shown first:
the learner's file, line, function and exception, before what the library did because of it.

Any other exception keeps IPython's usual traceback.

A cell that runs the learner's code and goes on whatever happens (a ``write`` that raises is caught, as ros2_control
does, and the component taken out) raises nothing for IPython to show: :class:`LearnerErrors` keeps, within a block,
what the learner's code raised and the library caught, and says it in one line each (file, line, function, exception).
"""

from __future__ import annotations

import logging
import os
import sysconfig
import traceback
from pathlib import Path
from types import TracebackType
from typing import Any

from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.middleware.compiled import FILENAME_PREFIX

__all__ = ["is_learner_frame", "CellErrors", "CELL_ERRORS", "LearnerErrors", "short_traceback_lines", "short_traceback",
           "register"]

_PACKAGE_DIR = Path(__file__).resolve().parent.parent


def _python_dirs() -> list[Path]:
    dirs = set()
    for key in ("stdlib", "platstdlib", "purelib", "platlib"):
        path = sysconfig.get_paths().get(key)
        if path:
            dirs.add(Path(path).resolve())
    return sorted(dirs)


_PYTHON_DIRS = _python_dirs()


def is_learner_frame(filename: str) -> bool:
    """True for a frame of the learner's code: a notebook cell or a file outside the library and Python."""
    if not filename or filename.startswith(("<frozen", FILENAME_PREFIX)):  # Python's, or the compiled control cycle
        return False
    if filename.startswith("<"):  # "<string>", "<ipython-input-...>": code typed by someone
        return True
    path = Path(filename).resolve()
    return not any(path.is_relative_to(d) for d in (_PACKAGE_DIR, *_PYTHON_DIRS))


def _where(frame: traceback.FrameSummary, shell: Any = None) -> str:
    compiler = getattr(shell, "compile", None)
    label = None
    if compiler is not None and hasattr(compiler, "format_code_name"):
        label = compiler.format_code_name(frame.filename)
    place = f"{label[0]} {label[1]}" if label else os.path.basename(frame.filename)
    code = f": {frame.line.strip()}" if frame.line else ""
    return f"  {place}, line {frame.lineno}{code}"


def _learner_files_frames(tb: TracebackType | None) -> list[traceback.FrameSummary]:
    """Frames in the learner's files (not notebook cells: the cell is where the library was called from)."""
    return [f for f in traceback.extract_tb(tb) if is_learner_frame(f.filename) and not f.filename.startswith("<")]


class CellErrors(logging.Handler):
    """Keeps, for the running cell, the exceptions raised in the learner's files that the library caught and logged."""

    def __init__(self) -> None:
        super().__init__(level=logging.WARNING)
        self.found: list[tuple[BaseException, traceback.FrameSummary]] = []

    def emit(self, record: logging.LogRecord) -> None:
        exc = record.exc_info[1] if record.exc_info else None
        if exc is None or any(e is exc for e, _ in self.found):
            return
        mine = _learner_files_frames(exc.__traceback__)
        if mine:
            self.found.append((exc, mine[-1]))

    def clear(self, *args: Any) -> None:
        """Forget the previous cell's exceptions (IPython's ``pre_run_cell`` event)."""
        self.found = []

    def lines(self, shell: Any = None) -> list[str]:
        """The learner's exceptions of this cell, first one first, or ``[]``."""
        if not self.found:
            return []
        exc, frame = self.found[0]
        code = f": {frame.line.strip()}" if frame.line else ""
        out = ["Your code raised first (the library caught it and stopped what depended on it):",
               f"  {os.path.basename(frame.filename)}, line {frame.lineno}, in {frame.name}{code}",
               f"    {type(exc).__name__}: {exc}"]
        if len(self.found) > 1:
            out.append(f"  (and {len(self.found) - 1} more exception(s) from your code in this cell; see the log above)")
        out.append("Then:")
        return out


#: The handler :func:`register` installs on the root logger.
CELL_ERRORS = CellErrors()


class LearnerErrors:
    """Within a ``with`` block, the exceptions of the learner's code that the library caught and logged, or that left
    the block, each as ``"your <file>, line N, in <function>: <Type>: <message>"``.

    The library's own log lines (and their tracebacks) are kept out of the cell while the block runs; the learner reads
    :meth:`report` instead. An exception that leaves the block is noted and goes on.

    Example:
        >>> with LearnerErrors() as errors:  # doctest: +SKIP
        ...     system.spin(5.0)
        >>> errors.report()  # doctest: +SKIP
        Your code raised: your my_robot_hardware.py, line 80, in write: ValueError: no limiter for joint3

    Attributes:
        found: The learner's exceptions, first first.
        reason: The last error the library logged (its own words: what it did about the exception), or ``""``.
    """

    #: The library's logger, whose records the block keeps.
    LOGGER = "rrbot_workshop"

    def __init__(self) -> None:
        from rrbot_workshop.course.grading.learner_errors import LearnerErrorLog, learner_root

        self._log = LearnerErrorLog(learner_root())
        self.found: list[str] = self._log.found
        self.reason = ""
        self._saved: tuple[int, bool] | None = None

    def _keep_reason(self, record: logging.LogRecord) -> bool:
        if record.levelno >= logging.ERROR:
            self.reason = record.getMessage().strip().splitlines()[-1] if record.getMessage().strip() else ""
        return True

    def __enter__(self) -> LearnerErrors:
        logger = logging.getLogger(self.LOGGER)
        self._saved = (logger.level, logger.propagate)
        logger.setLevel(min(logger.getEffectiveLevel(), logging.ERROR))
        logger.propagate = False
        self._log.addFilter(self._keep_reason)
        logger.addHandler(self._log)
        return self

    def note(self, exc: BaseException) -> None:
        """Keep ``exc`` if it passed through the learner's code (for an exception caught inside the block)."""
        from rrbot_workshop.course.grading.learner_errors import learner_location

        where = learner_location(exc, self._log.root)
        if where is not None and where not in self.found:
            self.found.append(where)

    def __exit__(self, exc_type: Any, exc: BaseException | None, tb: Any) -> None:
        logger = logging.getLogger(self.LOGGER)
        logger.removeHandler(self._log)
        if self._saved is not None:
            logger.setLevel(self._saved[0])
            logger.propagate = self._saved[1]
        if exc is not None:
            self.note(exc)

    def lines(self) -> list[str]:
        """One line per exception of the learner's code (the first, and how many followed), or ``[]``."""
        if not self.found:
            return []
        more = len(self.found) - 1
        return [f"Your code raised: {self.found[0]}"] + (
            [f"  (and {more} more exception{'s' if more > 1 else ''} from your code after it)"] if more else [])

    def report(self) -> bool:
        """Print :meth:`lines`; True if the learner's code raised."""
        for line in self.lines():
            print(line)
        return bool(self.found)


def short_traceback_lines(value: BaseException, tb: TracebackType | None, shell: Any = None) -> list[str]:
    """The lines of the short traceback of ``value``: the learner's own exception first when the library caught one
    in this cell, then the error's clear line, the learner's frames, how to see all.

    Args:
        value: The exception.
        tb: Its traceback.
        shell: The IPython shell, to name notebook cells ``Cell In[5]`` (optional).
    """
    frames = traceback.extract_tb(tb)
    mine = [f for f in frames if is_learner_frame(f.filename)]
    lines = CELL_ERRORS.lines(shell) + [f"{type(value).__name__}: {value}"]
    lines += [_where(f, shell) for f in mine[-3:]]
    hidden = len(frames) - len(mine[-3:])
    if hidden:
        what = "frame" if hidden == 1 else "frames"
        lines.append(f"({hidden} {what} inside rrbot_workshop and Python left out; run %tb for the full traceback)")
    return lines


def short_traceback(
    shell: Any, etype: type[BaseException], value: BaseException, tb: TracebackType | None, tb_offset: Any = None
) -> list[str]:
    """IPython custom exception handler: show the short traceback, keep the full one for ``%tb``."""
    shell._get_exc_info((etype, value, tb))  # sets sys.last_* so that %tb shows the whole traceback
    stb = short_traceback_lines(value, tb, shell)
    shell._showtraceback(etype, value, stb)
    return stb


def register(ipython: Any) -> None:
    """Make ``ipython`` show :class:`RRBotWorkshopError` (and its subclasses) with :func:`short_traceback`."""
    if hasattr(ipython, "set_custom_exc"):
        ipython.set_custom_exc((RRBotWorkshopError,), short_traceback)
    events = getattr(ipython, "events", None)
    if events is not None and CELL_ERRORS not in logging.getLogger().handlers:
        logging.getLogger().addHandler(CELL_ERRORS)
        events.register("pre_run_cell", CELL_ERRORS.clear)

