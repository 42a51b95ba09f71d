"""One learner's attempt logs, read so that nothing a learner puts in their workspace can stop, hang or skew a report.

A learner owns their workspace: anything can be in ``exercises/.progress/`` (see
:mod:`rrbot_workshop.course.grading.attempts` for what belongs there). :func:`read_logs` reads it as an instructor's
tool must:

* **only the learner's own regular files.** Every folder on the way (the workspace, ``exercises/``, ``.progress/``) is
  opened relative to the one before it, refusing links, so the path cannot be redirected between a check and a read;
  a log is opened without following links and without blocking, and read only if it is a regular file owned by the
  workspace's owner (a link, a hard link to another user's log, a FIFO, a device or a folder is left out). Links are
  never followed, not even links that stay inside the workspace. Where learners share one Unix user, a hard link
  between two workspaces is found by the report (:attr:`LearnerLogs.files`), which leaves that log out for both.
* **bounded.** Only the hundred names ``task00.json`` to ``task99.json`` are looked up (the folder is never listed);
  a log is read only up to :data:`MAX_LOG_BYTES`, a learner's logs together up to :data:`MAX_LEARNER_BYTES`; JSON
  nested deeper than :data:`MAX_JSON_DEPTH`, integers longer than :data:`MAX_INT_DIGITS` digits and logs of more
  than :data:`MAX_ATTEMPTS` attempts are refused or cut.
* **one note per file.** A log that is left out, or whose entries are partly not attempts, becomes one line naming
  the learner, the file and why; the learner's other logs and the rest of the room are still read.

Nothing is written and no file's times change (logs are read with ``O_NOATIME`` where the system allows it).
"""

from __future__ import annotations

import errno
import json
import os
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rrbot_workshop.classroom.task_status import Attempt

__all__ = ["LearnerLogs", "read_logs", "shown", "MAX_LOG_BYTES", "MAX_LEARNER_BYTES", "MAX_JSON_DEPTH",
           "MAX_INT_DIGITS", "MAX_ATTEMPTS", "LOG_FOLDER"]

#: Largest attempt log read [bytes] (a log grows by about 2 kB per self-check).
MAX_LOG_BYTES = 4 * 1024 * 1024
#: Most bytes read from one learner's logs together [bytes].
MAX_LEARNER_BYTES = 16 * 1024 * 1024
#: Deepest JSON nesting accepted (a log nests 3 levels).
MAX_JSON_DEPTH = 16
#: Longest integer accepted in a log [digits].
MAX_INT_DIGITS = 20
#: Most attempts kept from one log (the latest ones).
MAX_ATTEMPTS = 20_000
#: Where a workspace keeps its attempt logs, workspace-relative.
LOG_FOLDER = ("exercises", ".progress")

_DIR_FLAGS = os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_NOFOLLOW", 0)
_FILE_FLAGS = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
_STRING = re.compile(r'"(?:[^"\\]++|\\.)*+(?:"|\Z)', re.DOTALL)
_NOT_BRACKET = re.compile(r"[^\[\]{}]++")
_PAIR = re.compile(r"\[\]|\{\}")
_KINDS = {stat.S_IFDIR: "a folder", stat.S_IFIFO: "a FIFO", stat.S_IFLNK: "a link", stat.S_IFSOCK: "a socket",
          stat.S_IFCHR: "a device", stat.S_IFBLK: "a device"}


@dataclass
class LearnerLogs:
    """What one learner's logs hold.

    Attributes:
        attempts: Task number -> its attempts, in the log's order.
        notes: One line per file left out or partly read, and why.
        bytes_read: Bytes read from the learner's files.
        files: Task number -> the log's ``(device, inode)``, for each log read.
    """

    attempts: dict[int, list[Attempt]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    bytes_read: int = 0
    files: dict[int, tuple[int, int]] = field(default_factory=dict)


def shown(text: str, limit: int = 80) -> str:
    """``text`` fit for one line of a note or a terminal: control characters escaped, at most ``limit`` characters
    (a longer text is cut, with its length said)."""
    clean = "".join(c if c.isprintable() else f"\\x{ord(c):02x}" if ord(c) < 256 else f"\\u{ord(c):04x}"
                    for c in text[: limit + 1])
    return clean if len(text) <= limit else f"{clean[:limit]}… ({len(text)} characters)"


def _kind(mode: int) -> str:
    return _KINDS.get(stat.S_IFMT(mode), "not a regular file")


def read_logs(name: str, root: Path, inside: tuple[str, ...] = ()) -> LearnerLogs:
    """Read the attempt logs of the workspace ``root/inside...``.

    Args:
        name: The learner, for the notes.
        root: The folder the instructor named (a home or a course folder); it is opened as given.
        inside: Folders from ``root`` to the workspace (``("rrbot_workshop",)`` for a home), opened without following
            links.

    Returns:
        The attempts by task and the notes; a workspace without logs gives neither.
    """
    logs = LearnerLogs()
    who = shown(name, 60)
    opened: list[int] = []
    try:
        try:
            opened.append(os.open(root, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0)))
        except OSError as exc:
            logs.notes.append(f"{who}: {shown(str(root), 300)} could not be opened ({exc.strerror or exc}); no logs "
                              "read")
            return logs
        where = ""
        owner = -1
        for part in (*inside, *LOG_FOLDER):
            if part == LOG_FOLDER[0]:
                owner = os.fstat(opened[-1]).st_uid  # the workspace's
            where = f"{where}{part}/"
            try:
                opened.append(os.open(part, _DIR_FLAGS, dir_fd=opened[-1]))
            except FileNotFoundError:
                return logs  # no self-check yet
            except OSError as exc:
                why = _folder_problem(part, opened[-1], exc)
                logs.notes.append(f"{who}: {shown(where)} {why}; no logs read")
                return logs
        for task in range(100):
            _read_one(logs, who, opened[-1], task, owner)
    finally:
        for fd in opened:
            os.close(fd)
    return logs


def _folder_problem(part: str, parent: int, exc: OSError) -> str:
    try:
        mode = os.stat(part, dir_fd=parent, follow_symlinks=False).st_mode
    except OSError:
        return f"could not be opened ({exc.strerror or exc})"
    if stat.S_ISLNK(mode):
        return "is a link (links are never followed)"
    if not stat.S_ISDIR(mode):
        return f"is {_kind(mode)}, not a folder"
    return f"could not be opened ({exc.strerror or exc})"


def _read_one(logs: LearnerLogs, who: str, folder: int, task: int, owner: int) -> None:
    """Read ``taskNN.json`` in the open folder ``folder`` into ``logs``: its attempts, or one note."""
    filename = f"task{task:02d}.json"
    label = f"{who}: task {task}'s log {filename}"
    try:
        info = os.stat(filename, dir_fd=folder, follow_symlinks=False)
    except FileNotFoundError:
        return
    except OSError as exc:
        logs.notes.append(f"{label} could not be read ({exc.strerror or exc}); left out")
        return
    why = _file_problem(info, owner, logs.bytes_read)
    data = b""
    if not why:
        data, why = _read_bytes(filename, folder, owner, min(MAX_LOG_BYTES, MAX_LEARNER_BYTES - logs.bytes_read))
        logs.bytes_read += len(data)
    if not why:
        attempts, why = _attempts(data)
        if attempts is not None:
            logs.attempts[task] = attempts
            logs.files[task] = (info.st_dev, info.st_ino)
    if why:
        logs.notes.append(f"{label} {why}")


def _file_problem(info: os.stat_result, owner: int, read_so_far: int) -> str:
    if stat.S_ISLNK(info.st_mode):
        return "is a link (links are never followed); left out"
    if not stat.S_ISREG(info.st_mode):
        return f"is {_kind(info.st_mode)}, not a regular file; left out"
    if info.st_uid != owner:
        return f"belongs to another user (uid {info.st_uid}, the workspace's owner is {owner}); left out"
    if info.st_size > MAX_LOG_BYTES:
        return f"is larger than {MAX_LOG_BYTES // 1024 // 1024} MiB ({info.st_size} bytes); left out"
    if read_so_far + info.st_size > MAX_LEARNER_BYTES:
        return f"would take this learner's logs past {MAX_LEARNER_BYTES // 1024 // 1024} MiB read; left out"
    return ""


def _read_bytes(filename: str, folder: int, owner: int, limit: int) -> tuple[bytes, str]:
    """At most ``limit`` bytes of the regular file ``filename`` in ``folder``, or ``b""`` and why not."""
    try:
        try:
            fd = os.open(filename, _FILE_FLAGS | getattr(os, "O_NOATIME", 0), dir_fd=folder)
        except PermissionError:  # O_NOATIME needs the file's owner
            fd = os.open(filename, _FILE_FLAGS, dir_fd=folder)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return b"", "is a link (links are never followed); left out"
        return b"", f"could not be read ({exc.strerror or exc}); left out"
    try:
        info = os.fstat(fd)  # what was opened, which may not be what was looked at
        why = _file_problem(info, owner, 0)
        if why:
            return b"", why
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:
            return b"", f"grew past {limit} bytes while it was read; left out"
        return b"".join(chunks), ""
    except OSError as exc:
        return b"", f"could not be read ({exc.strerror or exc}); left out"
    finally:
        os.close(fd)


class _RefusedNumber(ValueError):
    """A number in a log that is not one a log holds."""


def _parse_int(text: str) -> int:
    if len(text.lstrip("-")) > MAX_INT_DIGITS:
        raise _RefusedNumber(f"an integer of {len(text.lstrip('-'))} digits")
    return int(text)


def _parse_constant(text: str) -> float:
    raise _RefusedNumber(f"{text}, which is not a number JSON allows")


def _too_deep(text: str) -> bool:
    """Whether the JSON ``text`` nests arrays and objects deeper than :data:`MAX_JSON_DEPTH` (in linear time, no
    recursion: strings are taken out, then innermost bracket pairs are removed once per level)."""
    brackets = _NOT_BRACKET.sub("", _STRING.sub("", text))
    for _ in range(MAX_JSON_DEPTH):
        if not brackets:
            return False
        brackets, found = _PAIR.subn("", brackets)
        if not found:
            return False  # unbalanced: the JSON parser says so
    return bool(_PAIR.search(brackets))


def _attempts(data: bytes) -> tuple[list[Attempt] | None, str]:
    """The attempts of a log's bytes, and a note's ending when some or all are left out (``""`` when none are)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return None, "could not be read (not UTF-8 text); left out"
    if _too_deep(text):
        return None, f"could not be read (nested deeper than {MAX_JSON_DEPTH} levels); left out"
    try:
        parsed: Any = json.loads(text, parse_int=_parse_int, parse_constant=_parse_constant)
    except _RefusedNumber as exc:
        return None, f"could not be read (it holds {exc}); left out"
    except (ValueError, RecursionError):
        return None, "could not be read (half-written or not JSON); left out"
    entries = parsed.get("attempts") if isinstance(parsed, dict) else None
    if not isinstance(entries, list):
        return None, "could not be read (not an attempt log: no list of attempts); left out"
    cut = max(0, len(entries) - MAX_ATTEMPTS)
    attempts: list[Attempt] = []
    bad: list[str] = []
    for entry in entries[cut:]:
        try:
            attempts.append(Attempt.from_record(entry))
        except ValueError as exc:
            bad.append(str(exc))
    why = []
    if cut:
        why.append(f"its {cut} oldest attempts are beyond the {MAX_ATTEMPTS} read")
    if bad:
        why.append(f"{len(bad)} of its {len(entries) - cut} entries are not attempts (the first: {bad[0]})")
    return attempts, ("; ".join(why) + "; they are left out") if why else ""
