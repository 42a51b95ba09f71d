"""Reading a learner's text file (YAML, xacro, URDF) whatever it holds, and saying in one line why it cannot be read.

A file the course reads may be missing, a folder, binary, in another encoding, start with a byte order mark, or be
nested deeper than a parser can follow. :func:`read_text` and :func:`load_yaml` never raise for those: they return
the text (or data) and ``""``, or a problem sentence the caller puts in its own exception (``ParameterError`` for a
controllers file, ``DescriptionError`` for a description), so each layer keeps its error type.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

__all__ = ["read_text", "load_yaml", "MAX_BYTES"]

#: The largest file read [bytes]; a course file is a few kB, a generated one a few MB.
MAX_BYTES = 256 * 1024 * 1024


def read_text(path: str | Path) -> tuple[str, str]:
    """The UTF-8 text of ``path`` (a leading byte order mark dropped) and ``""``, or ``""`` and why not.

    Args:
        path: The file.
    """
    try:
        p = Path(path)
        size = p.stat().st_size
        if p.is_dir():
            return "", "is a folder, not a file"
        if size > MAX_BYTES:
            return "", f"is {size} bytes, more than the {MAX_BYTES} a course file may have"
        data = p.read_bytes()
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the path
        return "", f"cannot be read: {getattr(exc, 'strerror', None) or exc}"
    if b"\x00" in data:
        return "", "is a binary file (it holds NUL bytes), not text"
    try:
        return data.decode("utf-8-sig"), ""
    except UnicodeDecodeError as exc:
        return "", (f"is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); save it as UTF-8")


def load_yaml(text: str) -> tuple[Any, str]:
    """``yaml.safe_load(text)`` and ``""``, or None and why it does not parse (with the line and column)."""
    try:
        return yaml.safe_load(text), ""
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        return None, f"is not valid YAML{where}: {problem}"
    except RecursionError:
        return None, "is nested too deeply to read (keep it to a few dozen levels)"
