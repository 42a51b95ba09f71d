"""The learner's own error first: where in the learner's files an exception was raised, for a grader's reason.

A check fails for a reason the grader states ("the switch was rejected"), but the cause is often an exception in
the learner's code that the library caught and logged, as ros2_control does (an ``on_configure`` that raises is an
ERROR, the switch that needed it is refused). :class:`LearnerErrorLog` keeps every such exception logged during a
check; :func:`learner_location` finds the learner's line in an exception that reached the check itself. The
plugin puts what they find before the grader's own words: ``your rrbot_hardware_interface.py, line 57, in
on_configure: TypeError: ...``.
"""

from __future__ import annotations

import logging
import traceback
from pathlib import Path

from rrbot_workshop.course import tracks

__all__ = ["learner_root", "learner_location", "LearnerErrorLog", "LEARNER_LOGGER"]

#: Logger on which :func:`rrbot_workshop.course.learner.load_module` reports, at DEBUG, a file that does not import.
LEARNER_LOGGER = "rrbot_workshop.course.learner"

_CHAIN_DEPTH = 8


def learner_root() -> Path | None:
    """The folder holding the graded task folders (a track's folder, or the copy named by ``--root``)."""
    try:
        first = min(tracks.task_names())
        return tracks.task_dir(first).parent.resolve()
    except Exception:  # noqa: BLE001 - no course around (a grader run outside one): nothing is the learner's
        return None


def _relative(filename: str, root: Path) -> str | None:
    if not filename or filename.startswith("<"):
        return None
    try:
        path = Path(filename).resolve()
    except (OSError, ValueError):
        return None
    if not path.is_relative_to(root):
        return None
    parts = path.relative_to(root).parts
    # the task folder itself is implied: "rrbot_bringup/bringup.py", not "task05_simulation/rrbot_bringup/..."
    return Path(*parts[1:]).as_posix() if len(parts) > 1 else parts[0]


def _message(exc: BaseException) -> str:
    text = " ".join(line.strip() for line in str(exc).splitlines() if line.strip())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _one(exc: BaseException, root: Path) -> str | None:
    if isinstance(exc, SyntaxError) and exc.filename:
        rel = _relative(exc.filename, root)
        if rel is not None:
            where = f", line {exc.lineno}" if exc.lineno else ""
            return f"your {rel}{where}: {type(exc).__name__}: {exc.msg}"
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if _relative(f.filename, root) is not None]
    if not frames:
        return None
    last = frames[-1]
    rel = _relative(last.filename, root)
    return f"your {rel}, line {last.lineno}, in {last.name}: {_message(exc)}"


def learner_location(exc: BaseException | None, root: Path | None) -> str | None:
    """``"your <file>, line N, in <function>: <Type>: <message>"`` for the first exception of ``exc``'s chain that
    passed through the learner's files (its innermost learner frame), or ``None``."""
    if root is None:
        return None
    seen: set[int] = set()
    todo = [exc]
    while todo and len(seen) < _CHAIN_DEPTH:
        current = todo.pop(0)
        if current is None or id(current) in seen:
            continue
        seen.add(id(current))
        found = _one(current, root)
        if found is not None:
            return found
        todo.extend([current.__cause__, current.__context__])
    return None


class LearnerErrorLog(logging.Handler):
    """A logging handler that keeps the learner's exceptions the library caught and logged during one check.

    Args:
        root: The learner's files (see :func:`learner_root`); ``None`` keeps nothing.
    """

    def __init__(self, root: Path | None) -> None:
        super().__init__(level=logging.DEBUG)
        self.root = root
        self.found: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        exc = record.exc_info[1] if record.exc_info else None
        if exc is None:
            return
        where = learner_location(exc, self.root)
        if where is not None and where not in self.found:
            self.found.append(where)

    def clear(self) -> None:
        """Forget what was kept (a new check starts)."""
        self.found = []

    def first(self) -> str | None:
        """The first learner error kept, with how many others followed it, or ``None``."""
        if not self.found:
            return None
        more = len(self.found) - 1
        return self.found[0] + (f" (and {more} more error{'s' if more > 1 else ''} in your code after it)" if more else "")
