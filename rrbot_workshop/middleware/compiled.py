"""Functions compiled from source at run time: how the control cycle becomes straight-line code.

The hardware cycle and the controller loop know, between two state changes, exactly which components and controllers
a cycle calls. They write that down as the source of one Python function (a block per component or controller, the
objects it uses bound by name) and compile it here. The function is then what the cycle calls, until the next state
change makes a new one. Its source is kept in :mod:`linecache` under a name of its own, so a traceback through it (a
learner's ``update`` that raises) shows the line it stopped at, like any other Python file.
"""

from __future__ import annotations

import functools
import linecache
import zlib
from collections.abc import Callable
from types import CodeType
from typing import Any

__all__ = ["FILENAME_PREFIX", "compile_function"]

#: How the file name of every compiled function starts (tracebacks tell the library's frames from a learner's by it).
FILENAME_PREFIX = "<rrbot_workshop "


def compile_function(source: str, kind: str, name: str, namespace: dict[str, Any]) -> Callable[..., Any]:
    """Compile ``source``, which defines the function ``name``, with the globals ``namespace``; return the function.

    Args:
        source: Python source of one ``def name(...)``, written by this package (never text from outside).
        kind: What it is, for its file name in tracebacks (``"controller loop"`` ->
            ``<rrbot_workshop controller loop 1a2b3c4d>``).
        name: The function's name in ``source``.
        namespace: The function's globals: the objects its source names (it is extended, not copied).
    """
    code = _code(source, kind)
    # (again on every call: someone may have cleared the cache since; mtime None keeps it through checkcache)
    linecache.cache[code.co_filename] = (len(source), None, source.splitlines(keepends=True), code.co_filename)
    exec(code, namespace)  # noqa: S102 - our own template, see Args
    function: Callable[..., Any] = namespace[name]
    return function


@functools.lru_cache(maxsize=256)
def _code(source: str, kind: str) -> CodeType:
    """The code of ``source``. Plans come back (a switch and its reverse), and so does their code."""
    return compile(source, f"{FILENAME_PREFIX}{kind} {zlib.crc32(source.encode()):08x}>", "exec")
