"""The order in which ``./workshop test`` hands files to its workers: longest first, from measured seconds."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from scheduling import UNKNOWN_SECONDS_PER_TEST, load_durations, longest_first, measured_durations

from rrbot_workshop.classroom.launcher import _longest_first, _workers
from rrbot_workshop.course.grading.references import MANIFEST, instructor_only


@dataclass
class Item:
    nodeid: str


def _items(*nodeids: str) -> list[Item]:
    return [Item(n) for n in nodeids]


def test_files_are_handed_out_longest_first_with_their_tests_in_their_own_order() -> None:
    """A long file with two tests goes before a short one with many; a file's tests stay together and in order."""
    items = _items("a.py::t1", "a.py::t2", "a.py::t3", "room.py::t1", "nb.ipynb::Cell 0", "nb.ipynb::Cell 1")
    ordered = longest_first(items, {"a.py": 2.0, "room.py": 120.0, "nb.ipynb": 30.0})
    assert [i.nodeid for i in ordered] == ["room.py::t1", "nb.ipynb::Cell 0", "nb.ipynb::Cell 1",
                                          "a.py::t1", "a.py::t2", "a.py::t3"]


def test_a_file_never_measured_counts_its_tests_and_ties_keep_the_collection_order() -> None:
    """New files cost ``UNKNOWN_SECONDS_PER_TEST`` a test; equal costs keep the order collected (every worker of a
    run must sort the same collection the same way)."""
    items = _items("new.py::a", "new.py::b", "old.py::a", "same1.py::a", "same2.py::a")
    durations = {"old.py": UNKNOWN_SECONDS_PER_TEST * 2 - 0.01, "same1.py": 1.0, "same2.py": 1.0}
    ordered = [i.nodeid for i in longest_first(items, durations)]
    assert ordered == ["same1.py::a", "same2.py::a", "new.py::a", "new.py::b", "old.py::a"]
    assert [i.nodeid for i in longest_first(list(reversed(items)), {})] == [
        "new.py::b", "new.py::a", "same2.py::a", "same1.py::a", "old.py::a"]


def test_durations_are_read_from_a_real_junit_report_file_by_file(tmp_path: Path) -> None:
    """pytest's own ``--junit-xml`` report: each test's seconds summed by its file (a test in a class too)."""
    tests = tmp_path / "tests"
    tests.mkdir()
    (tests / "test_slow.py").write_text("import time\n\ndef test_a():\n    time.sleep(0.2)\n\n"
                                        "class TestB:\n    def test_b(self):\n        time.sleep(0.1)\n")
    (tests / "test_fast.py").write_text("def test_c():\n    pass\n")
    report = tmp_path / "r.xml"
    subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-o", "addopts=",
                    f"--junit-xml={report}", "tests"], cwd=tmp_path, check=True,
                   capture_output=True)
    measured = measured_durations([report], root=tmp_path)
    assert set(measured) == {"tests/test_slow.py", "tests/test_fast.py"}
    assert measured["tests/test_slow.py"] >= 0.3 > measured["tests/test_fast.py"]
    assert list(measured) == ["tests/test_slow.py", "tests/test_fast.py"]


def test_the_committed_durations_name_files_that_exist() -> None:
    """Every file ``durations.json`` lists is a test file or notebook of this course (a renamed file is re-measured);
    a student copy lacks the instructor's files it lists and the tests its WITHHELD.json names, and nothing else."""
    root = Path(__file__).resolve().parents[2]
    durations = load_durations()
    assert durations, "tests/unit/durations.json is missing or empty"
    student_copy = not (root / "solutions").is_dir()
    withheld = json.loads((root / MANIFEST).read_text()).get("tests", []) if (root / MANIFEST).is_file() else []
    missing = [name for name in durations if not (root / name).is_file()
               and not (student_copy and (instructor_only(name) or name in withheld))]
    assert not missing, f"durations.json lists files that do not exist: {missing}"


def test_an_unreadable_durations_file_leaves_every_file_counted_by_its_tests(tmp_path: Path) -> None:
    bad = tmp_path / "durations.json"
    bad.write_text("[1, 2]")
    assert load_durations(bad) == {}
    assert load_durations(tmp_path / "missing.json") == {}


def test_the_launcher_gives_notebook_runs_longest_first_and_keeps_the_order_it_is_given(tmp_path: Path) -> None:
    """A run of notebooks alone is handed out in the order named on its command line: the launcher sorts it by the
    same measured seconds, and xdist is told not to reorder by number of tests."""
    (tmp_path / "tests" / "unit").mkdir(parents=True)
    (tmp_path / "tests" / "unit" / "durations.json").write_text(json.dumps({"n/02.ipynb": 40.0, "n/01.ipynb": 5.0}))
    assert _longest_first(tmp_path, ["n/01.ipynb", "n/02.ipynb", "n/03.ipynb"]) == ["n/02.ipynb", "n/01.ipynb",
                                                                                     "n/03.ipynb"]
    assert _longest_first(tmp_path / "elsewhere", ["n/01.ipynb", "n/02.ipynb"]) == ["n/01.ipynb", "n/02.ipynb"]
    options = _workers(Path(sys.executable))
    if options:
        assert options[options.index("--dist") + 1] == "loadfile" and "--no-loadscope-reorder" in options


def test_the_launcher_shares_work_through_the_folders_the_library_reads() -> None:
    """The launcher (standard library only) names the shared-work folders itself: the names the library reads."""
    from rrbot_workshop.classroom.launcher import SHARED_WORK_ENV
    from rrbot_workshop.course.grading.plugin import PYCACHE_ENV
    from rrbot_workshop.description.xacro_cache import SHARED_ENV

    assert set(SHARED_WORK_ENV) == {SHARED_ENV, PYCACHE_ENV}
