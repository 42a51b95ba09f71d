"""The order in which a test run spread over the cores hands out its files: the longest first.

``./workshop test`` runs the tests with pytest-xdist, a whole file (or notebook) to a worker at a time, so a file's
module-scoped fixtures (a grader test module grades all its variants once) are made once. pytest-xdist hands the files
out in collection order, after sorting them by their number of tests; a file with few tests and minutes of work (two
JupyterHubs, a notebook) then comes last and one core works alone at the end while the other waits. Handing out the
longest files first (with ``--no-loadscope-reorder``) lets the short ones fill in around them.

How long a file takes is read from :data:`DURATIONS`: the seconds a worker spent on each file in a measured run (tests
and their fixtures), refreshed with ``python tests/unit/scheduling.py <junit.xml>`` from a run's ``--junit-xml``
report. A file it does not list is taken as :data:`UNKNOWN_SECONDS_PER_TEST` a test. The order changes only when the
files run, never what runs or what a test sees.
"""

from __future__ import annotations

import json
import sys
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Protocol

from rrbot_workshop.classroom.launcher import read_durations

__all__ = ["DURATIONS", "UNKNOWN_SECONDS_PER_TEST", "load_durations", "longest_first", "measured_durations"]

#: Seconds a worker spent on each test file (path from the repository's root) in a measured run.
DURATIONS = Path(__file__).with_name("durations.json")
#: The repository's root, which the files are named from.
ROOT = Path(__file__).resolve().parents[2]
#: A file missing from :data:`DURATIONS` (a new one) is taken to cost this much per test.
UNKNOWN_SECONDS_PER_TEST = 0.2


class _Item(Protocol):
    nodeid: str


def load_durations(path: Path = DURATIONS) -> dict[str, float]:
    """File -> measured seconds from ``path``, read as the launcher reads it; empty if missing or unreadable (each
    file then counts its tests)."""
    return read_durations(path)


def _file_of(nodeid: str) -> str:
    return nodeid.split("::", 1)[0]


def longest_first(items: list[_Item], durations: Mapping[str, float]) -> list[_Item]:
    """``items`` grouped by file, the files by expected seconds, longest first; tests keep their order in a file.

    Ties keep the collection's order, so every worker sorts the same collection the same way (pytest-xdist requires it).
    """
    files: dict[str, list[_Item]] = {}
    for item in items:
        files.setdefault(_file_of(item.nodeid), []).append(item)
    first_seen = {name: i for i, name in enumerate(files)}

    def cost(name: str) -> float:
        return durations.get(name, UNKNOWN_SECONDS_PER_TEST * len(files[name]))

    ordered = sorted(files, key=lambda name: (-cost(name), first_seen[name]))
    return [item for name in ordered for item in files[name]]


def measured_durations(reports: Iterable[Path], root: Path = ROOT) -> dict[str, float]:
    """File -> seconds from JUnit XML reports (pytest ``--junit-xml``: each test's setup, call and teardown).

    A test case names its file in ``file`` (pytest's xunit1 family), otherwise in its dotted ``classname``: the longest
    prefix that names a ``.py`` file under ``root``, or a notebook's path.
    """
    totals: dict[str, float] = {}
    for report in reports:
        for case in ET.parse(report).getroot().iter("testcase"):
            name = case.get("file") or _classname_file(case.get("classname", ""), root)
            if name:
                totals[name] = totals.get(name, 0.0) + float(case.get("time", 0) or 0)
    return {k: round(v, 1) for k, v in sorted(totals.items(), key=lambda kv: -kv[1])}


def _classname_file(classname: str, root: Path) -> str:
    """``tests.unit.test_x`` -> ``tests/unit/test_x.py``; ``notebooks.02_mock_hardware.ipynb`` -> its path."""
    if ".ipynb" in classname:
        return classname.split(".ipynb", 1)[0].replace(".", "/") + ".ipynb"
    parts = classname.split(".")
    # a class inside the module: the module is the longest prefix that names a file
    for end in range(len(parts), 0, -1):
        candidate = "/".join(parts[:end]) + ".py"
        if (root / candidate).is_file():
            return candidate
    return ""


if __name__ == "__main__":  # python tests/unit/scheduling.py run0.xml [run1.xml ...]
    if len(sys.argv) < 2:
        sys.exit("usage: python tests/unit/scheduling.py REPORT.xml ... (writes tests/unit/durations.json)")
    measured = measured_durations(Path(p) for p in sys.argv[1:])
    DURATIONS.write_text(json.dumps(measured, indent=1) + "\n", encoding="utf-8")
    print(f"{len(measured)} files, {sum(measured.values()):.0f} s in all, written to {DURATIONS}")
