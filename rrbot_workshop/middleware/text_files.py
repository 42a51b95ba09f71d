"""Reading a learner's text file (YAML, xacro, URDF) whatever it holds, and saying in one line why it cannot be read.

A file the course reads may be missing, a folder, binary, in another encoding, start with a byte order mark, or be
nested deeper than a parser can follow. :func:`read_text` and :func:`load_yaml` never raise for those: they return
the text (or data) and ``""``, or a problem sentence the caller puts in its own exception (``ParameterError`` for a
controllers file, ``DescriptionError`` for a description), so each layer keeps its error type.
"""

from __future__ import annotations

import contextlib
import gc
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

__all__ = ["read_text", "load_yaml", "nesting_depth", "paused_gc", "MAX_BYTES", "MAX_DEPTH", "SAFE_LOADER"]

#: The largest file read [bytes]; a course file is a few kB, a generated one a few MB.
MAX_BYTES = 256 * 1024 * 1024


def read_text(path: str | Path) -> tuple[str, str]:
    """The UTF-8 text of ``path`` (a leading byte order mark dropped) and ``""``, or ``""`` and why not.

    Args:
        path: The file.
    """
    try:
        p = Path(path)
        if p.is_dir():
            return "", "is a folder, not a file"
        # opened without blocking and checked once open: a FIFO or a device is never read (it would block or never end)
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as file:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                return "", "is not a regular file (a FIFO, a device or a socket); give the file itself"
            if info.st_size > MAX_BYTES:
                return "", f"is {info.st_size} bytes, more than the {MAX_BYTES} a course file may have"
            data = file.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            return "", f"is more than the {MAX_BYTES} bytes a course file may have"
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the path
        return "", f"cannot be read: {getattr(exc, 'strerror', None) or exc}"
    if b"\x00" in data:
        return "", "is a binary file (it holds NUL bytes), not text"
    try:
        return data.decode("utf-8-sig"), ""
    except UnicodeDecodeError as exc:
        return "", (f"is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); save it as UTF-8")


#: The deepest nesting of mappings and lists a file may have (a controllers file has five or six levels).
MAX_DEPTH = 100
_TOO_DEEP = f"is nested too deeply to read (more than {MAX_DEPTH} levels; a controllers file needs a few)"

#: libyaml's loader when PyYAML has it (about ten times faster on a large file), else PyYAML's own; both safe.
SAFE_LOADER: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def load_yaml(text: str) -> tuple[Any, str]:
    """Safe-load ``text`` and return the data and ``""``, or None and why it cannot be used (with the line and column
    of a syntax error; a nesting deeper than :data:`MAX_DEPTH`)."""
    try:
        with paused_gc():
            data = yaml.load(text, Loader=SAFE_LOADER)  # noqa: S506 - a safe loader
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        return None, f"is not valid YAML{where}: {problem}"
    except RecursionError:
        return None, _TOO_DEEP
    if nesting_depth(data) > MAX_DEPTH:
        return None, _TOO_DEEP
    return data, ""


@contextlib.contextmanager
def paused_gc() -> Iterator[None]:
    """No cyclic garbage collection while a parser builds a large tree of new objects (each full collection walks
    every object built so far, which makes a large file cost the square of its size); restored afterwards."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def nesting_depth(data: Any) -> int:
    """How deep mappings and lists nest in ``data`` (0 for a scalar), counted without recursion."""
    deepest = 0
    stack = [(data, 1)]
    seen: set[int] = set()  # YAML anchors can make the same object appear twice (or contain itself)
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict | list):
            if id(item) in seen:
                continue
            seen.add(id(item))
            deepest = max(deepest, depth)
            if deepest > MAX_DEPTH:
                return deepest
            children = item.values() if isinstance(item, dict) else item
            stack.extend((child, depth + 1) for child in children)
    return deepest
