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

Processes can share their expansions: when ``$RRBOT_WORKSHOP_XACRO_CACHE`` names a folder (a test session sets it for
its workers, the gradings it forks and the notebooks' kernels), each expansion is also written there, one JSON file
per file and arguments, and a process that has not expanded that file with those arguments reads it from there. An
expansion read from the folder is checked exactly as a kept one (every file's digest, package folder, wildcard match
and variable, as this process sees them now) and is used only if all of them are unchanged; otherwise the file is
expanded again and the folder's entry replaced. Entries are written whole (a temporary file, then renamed), and one
that cannot be read or parsed is ignored.
"""

from __future__ import annotations

import contextlib
import glob as _glob
import hashlib
import json
import os
import tempfile
import threading
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Recorder", "Expansion", "ExpansionCache", "EXPANSIONS", "SHARED_ENV", "digest_of", "clear"]

#: Expansions kept per process (the least recently used goes first).
MAX_ENTRIES = 64
#: Names a folder where processes share their expansions (see the module docstring); unset: none shared.
SHARED_ENV = "RRBOT_WORKSHOP_XACRO_CACHE"

Key = tuple[str, tuple[tuple[str, str], ...]]


def _key_json(key: Key) -> list[object]:
    """``key`` as JSON holds it (lists for tuples): what a shared entry names and what its file name is hashed from."""
    return [key[0], [list(pair) for pair in key[1]]]


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

    def to_json(self, key: Key) -> str:
        """The expansion and its key as JSON, for the shared folder."""
        return json.dumps({"key": _key_json(key), "text": self.text, "files": self.files,
                           "finds": self.finds, "globs": {p: list(m) for p, m in self.globs.items()},
                           "env": self.env})

    @classmethod
    def from_json(cls, data: str, key: Key) -> Expansion | None:
        """The expansion of ``key`` kept in ``data``; None if ``data`` is not one (another key, damaged, cut short)."""
        try:
            loaded = json.loads(data)
            if loaded["key"] != _key_json(key):
                return None
            return cls(str(loaded["text"]), {str(p): str(d) for p, d in loaded["files"].items()},
                       {str(p): str(f) for p, f in loaded["finds"].items()},
                       {str(p): tuple(str(m) for m in matched) for p, matched in loaded["globs"].items()},
                       {str(n): None if v is None else str(v) for n, v in loaded["env"].items()})
        except (ValueError, KeyError, TypeError, AttributeError):
            return None

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
        self._entries: OrderedDict[Key, Expansion] = OrderedDict()
        self._lock = threading.Lock()
        #: Lookups answered from the cache (``shared_hits`` of them from the shared folder), and expansions made (for
        #: benchmarks and tests).
        self.hits = 0
        self.shared_hits = 0
        self.misses = 0

    @staticmethod
    def key(file: Path, mappings: Mapping[str, str]) -> Key:
        """The cache key of an expansion of ``file`` with ``mappings``."""
        return str(file), tuple(sorted(mappings.items()))

    @staticmethod
    def shared_path(key: Key) -> Path | None:
        """The file of ``key`` in the folder named by :data:`SHARED_ENV`; None when it names none."""
        folder = os.environ.get(SHARED_ENV, "")
        if not folder:
            return None
        name = hashlib.sha256(json.dumps(_key_json(key)).encode()).hexdigest()
        return Path(folder) / f"{name}.json"

    def _shared(self, key: Key, find: Callable[[str], str]) -> Expansion | None:
        """The expansion of ``key`` another process left in the shared folder, if it is still valid here."""
        path = self.shared_path(key)
        if path is None:
            return None
        try:
            data = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return None
        entry = Expansion.from_json(data, key)
        return entry if entry is not None and entry.still_valid(find) else None

    @staticmethod
    def _share(key: Key, entry: Expansion) -> None:
        """Write ``entry`` whole into the shared folder (nothing if none is named or it cannot be written)."""
        path = ExpansionCache.shared_path(key)
        if path is None:
            return
        with contextlib.suppress(OSError):
            path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
            handle, tmp = tempfile.mkstemp(dir=path.parent, prefix=".", suffix=".tmp")
            try:
                with os.fdopen(handle, "w", encoding="utf-8") as out:
                    out.write(entry.to_json(key))
                os.replace(tmp, path)
            except BaseException:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
                raise

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
        shared = self._shared(key, find)
        with self._lock:
            if shared is not None:
                self._keep(key, shared)
                self.hits += 1
                self.shared_hits += 1
                return shared.text
            self.misses += 1
        return None

    def put(self, file: Path, mappings: Mapping[str, str], text: str, recorder: Recorder) -> None:
        """Keep an expansion with what it read."""
        entry = Expansion(text, dict(recorder.files), dict(recorder.finds), dict(recorder.globs), dict(recorder.env))
        key = self.key(file, mappings)
        with self._lock:
            self._keep(key, entry)
        self._share(key, entry)

    def _keep(self, key: Key, entry: Expansion) -> None:
        """Keep ``entry`` in this process (under the lock), dropping the least recently used beyond :attr:`size`."""
        self._entries[key] = entry
        self._entries.move_to_end(key)
        while len(self._entries) > self.size:
            self._entries.popitem(last=False)

    def clear(self) -> None:
        """Forget every expansion."""
        with self._lock:
            self._entries.clear()
            self.hits = self.shared_hits = self.misses = 0

    def __len__(self) -> int:
        return len(self._entries)


#: The process's cache, used by :func:`~rrbot_workshop.description.process_xacro`.
EXPANSIONS = ExpansionCache()


def clear() -> None:
    """Forget every kept expansion of this process."""
    EXPANSIONS.clear()
