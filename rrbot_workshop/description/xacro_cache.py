"""A per-process cache of xacro expansions, valid only while everything the expansion read is unchanged.

A grader, a notebook or a test brings the same robot up many times: the same xacro file with the same arguments is
expanded again and again, and the expansion is a large share of the time. :func:`~rrbot_workshop.description.
process_xacro` keeps the URDF text of each expansion here, keyed by the file and its arguments, together with
everything the result depended on, as it was read:

* the contents (SHA-256) of every file xacro opened: the description, each include, each YAML file it loaded;
* the folder each ``$(find pkg)`` gave (the package path may change between calls);
* the files each wildcard include matched (a file added to the folder changes the result);
* the value of each environment variable read by ``$(env)`` or ``$(optenv)``.

A lookup reads those files again and compares their digests, resolves those packages and globs again and reads those
variables: a learner who edits an included file between two runs in the same kernel gets a fresh expansion. A failed
expansion is never kept.
"""

from __future__ import annotations

import glob as _glob
import hashlib
import os
import threading
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Recorder", "Expansion", "ExpansionCache", "EXPANSIONS", "digest_of", "clear"]

#: Expansions kept per process (the least recently used goes first).
MAX_ENTRIES = 64


def digest_of(path: str) -> str | None:
    """SHA-256 of a file's bytes, or None if it cannot be read now."""
    try:
        with open(path, "rb") as handle:
            return hashlib.sha256(handle.read()).hexdigest()
    except OSError:
        return None


@dataclass
class Recorder:
    """What one expansion read, filled in while it runs (see the module docstring).

    Attributes:
        files: Absolute path -> SHA-256 of the bytes xacro read from it.
        finds: Package -> the folder ``$(find)`` gave.
        globs: Wildcard pattern -> the sorted files it matched.
        env: Environment variable -> its value (None: not set).
    """

    files: dict[str, str] = field(default_factory=dict)
    finds: dict[str, str] = field(default_factory=dict)
    globs: dict[str, tuple[str, ...]] = field(default_factory=dict)
    env: dict[str, str | None] = field(default_factory=dict)

    def read(self, path: str, data: bytes) -> None:
        """xacro read ``data`` from ``path``."""
        self.files[os.path.abspath(path)] = hashlib.sha256(data).hexdigest()

    def glob(self, pattern: str, *args: object, **kwargs: object) -> list[str]:
        """``glob.glob`` for xacro's wildcard includes, remembering what matched."""
        found = _glob.glob(pattern, *args, **kwargs)  # type: ignore[arg-type]
        self.globs[pattern] = tuple(sorted(found))
        return found


@dataclass(frozen=True)
class Expansion:
    """One kept expansion: the URDF text and what it depended on."""

    text: str
    files: Mapping[str, str]
    finds: Mapping[str, str]
    globs: Mapping[str, tuple[str, ...]]
    env: Mapping[str, str | None]

    def still_valid(self, find: Callable[[str], str]) -> bool:
        """True if every file, package, glob and variable it read is as it was.

        Args:
            find: The current ``$(find)`` lookup (raises for an unknown package).
        """
        for path, digest in self.files.items():
            if digest_of(path) != digest:
                return False
        for name, value in self.env.items():
            if os.environ.get(name) != value:
                return False
        for pattern, matched in self.globs.items():
            if tuple(sorted(_glob.glob(pattern))) != matched:
                return False
        for package, folder in self.finds.items():
            try:
                if find(package) != folder:
                    return False
            except Exception:  # noqa: BLE001 - a package that no longer resolves: expand again (and fail there)
                return False
        return True


class ExpansionCache:
    """Expansions by ``(file, arguments)``, least recently used first out, safe across threads."""

    def __init__(self, size: int = MAX_ENTRIES) -> None:
        self.size = size
        self._entries: OrderedDict[tuple[str, tuple[tuple[str, str], ...]], Expansion] = OrderedDict()
        self._lock = threading.Lock()
        #: Lookups answered from the cache, and expansions made (for benchmarks and tests).
        self.hits = 0
        self.misses = 0

    @staticmethod
    def key(file: Path, mappings: Mapping[str, str]) -> tuple[str, tuple[tuple[str, str], ...]]:
        """The cache key of an expansion of ``file`` with ``mappings``."""
        return str(file), tuple(sorted(mappings.items()))

    def get(self, file: Path, mappings: Mapping[str, str], find: Callable[[str], str]) -> str | None:
        """The kept URDF text, if an expansion is kept and still valid; else None (and a stale one is dropped)."""
        key = self.key(file, mappings)
        with self._lock:
            entry = self._entries.get(key)
        if entry is not None and entry.still_valid(find):
            with self._lock:
                if key in self._entries:
                    self._entries.move_to_end(key)
                self.hits += 1
            return entry.text
        with self._lock:
            if entry is not None and self._entries.get(key) is entry:
                del self._entries[key]
            self.misses += 1
        return None

    def put(self, file: Path, mappings: Mapping[str, str], text: str, recorder: Recorder) -> None:
        """Keep an expansion with what it read."""
        entry = Expansion(text, dict(recorder.files), dict(recorder.finds), dict(recorder.globs), dict(recorder.env))
        key = self.key(file, mappings)
        with self._lock:
            self._entries[key] = entry
            self._entries.move_to_end(key)
            while len(self._entries) > self.size:
                self._entries.popitem(last=False)

    def clear(self) -> None:
        """Forget every expansion."""
        with self._lock:
            self._entries.clear()
            self.hits = self.misses = 0

    def __len__(self) -> int:
        return len(self._entries)


#: The process's cache, used by :func:`~rrbot_workshop.description.process_xacro`.
EXPANSIONS = ExpansionCache()


def clear() -> None:
    """Forget every kept expansion of this process."""
    EXPANSIONS.clear()
