"""The class report under hostile learners: nothing one learner puts in their workspace stops, hangs or skews the
report of the room, every file left out is one note for that learner, and no learner's file changes (every learner's
tree is hashed before and after). Then the outputs: formula-safe CSV and an escaped page."""

from __future__ import annotations

import csv
import json
import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from workspace_helpers import no_hang, tree

from rrbot_workshop.classroom.class_report import WORKSPACE_NAME, build_report
from rrbot_workshop.classroom.class_report_page import csv_cell, write_report
from rrbot_workshop.classroom.learner_logs import MAX_JSON_DEPTH, MAX_LEARNER_BYTES, MAX_LOG_BYTES, shown
from rrbot_workshop.classroom.task_status import PASSED, STATUSES, STUCK
from rrbot_workshop.cli import main

T0 = 1_800_000_000.0
NOW = T0 + 3600.0
GOOD = {"attempts": [{"time": T0, "score": 1, "max_score": 4, "failed": ["b"], "version": "v1", "reasons": {}},
                     {"time": T0 + 60, "score": 4, "max_score": 4, "failed": [], "version": "v2", "reasons": {}}]}


def _workspace(homes: Path, name: str) -> Path:
    progress = homes / name / WORKSPACE_NAME / "exercises" / ".progress"
    progress.mkdir(parents=True)
    return progress


@pytest.fixture
def homes(tmp_path: Path) -> Path:
    """The victim, ana: task 1 passed at her second check; task 2 failing check 'x' for an hour."""
    homes = tmp_path / "home"
    ana = _workspace(homes, "ana")
    (ana / "task01.json").write_text(json.dumps(GOOD))
    (ana / "task02.json").write_text(json.dumps({"attempts": [
        {"time": T0, "score": 0, "max_score": 4, "failed": ["x"], "reasons": {"x": "ana's own reason"}}]}))
    return homes


def _report(homes: Path, tmp_path: Path):
    """Report the room (with a guard against hangs) and check that no learner's tree changed; the report."""
    before = tree(homes)
    report = no_hang(build_report, [str(homes / "*")], now=NOW, course=tmp_path / "no-course", limit=120.0)
    write_report(report, tmp_path / "out")
    assert tree(homes) == before
    learners = {lr.name: lr for lr in report.learners}
    ana = learners["ana"]
    assert (ana.state(1).status, ana.state(2).status, ana.notes) == (PASSED, STUCK, []), "the victim is reported as is"
    return report, learners


def _notes_of(report, name: str) -> list[str]:
    return [n for n in report.notes if n.startswith(f"{name}: ")]


def test_json_nested_100000_deep_is_one_note(homes: Path, tmp_path: Path) -> None:
    (_workspace(homes, "eve") / "task01.json").write_text('{"attempts": ' + "[" * 100_000 + "]" * 100_000 + "}")
    report, learners = _report(homes, tmp_path)
    assert learners["eve"].tasks == {}
    assert _notes_of(report, "eve") == [f"eve: task 1's log task01.json could not be read (nested deeper than "
                                        f"{MAX_JSON_DEPTH} levels); left out"]


def test_unclosed_deep_json_is_one_note(homes: Path, tmp_path: Path) -> None:
    (_workspace(homes, "eve") / "task01.json").write_text("[" * 100_000 + "]")
    report, _ = _report(homes, tmp_path)
    assert len(_notes_of(report, "eve")) == 1


@pytest.mark.parametrize("number", ["9" * 400, "-" + "9" * 400, "9" * 400 + ".5", "1e400", "NaN", "-Infinity"])
def test_a_400_digit_or_infinite_number_is_a_note_not_an_overflow(homes: Path, tmp_path: Path, number: str) -> None:
    progress = _workspace(homes, "eve")
    (progress / "task01.json").write_text('{"attempts": [{"time": ' + number + ', "score": 1, "max_score": 1}]}')
    (progress / "task02.json").write_text('{"attempts": [{"time": 1800000000, "score": ' + number + '}]}')
    report, learners = _report(homes, tmp_path)
    assert learners["eve"].tasks.keys() <= {1, 2} and len(_notes_of(report, "eve")) == 2


def test_a_fifo_named_like_a_log_is_a_note_and_never_blocks(homes: Path, tmp_path: Path) -> None:
    os.mkfifo(_workspace(homes, "eve") / "task03.json")
    report, _ = _report(homes, tmp_path)
    assert _notes_of(report, "eve") == ["eve: task 3's log task03.json is a FIFO, not a regular file; left out"]


def test_a_link_to_dev_zero_is_never_read(homes: Path, tmp_path: Path) -> None:
    os.symlink("/dev/zero", _workspace(homes, "eve") / "task04.json")
    report, _ = _report(homes, tmp_path)
    assert _notes_of(report, "eve") == ["eve: task 4's log task04.json is a link (links are never followed); left out"]


def test_a_link_to_another_learners_log_does_not_report_their_attempts(homes: Path, tmp_path: Path) -> None:
    os.symlink(homes / "ana" / WORKSPACE_NAME / "exercises" / ".progress" / "task01.json",
               _workspace(homes, "eve") / "task01.json")
    report, learners = _report(homes, tmp_path)
    assert learners["eve"].tasks == {} and len(_notes_of(report, "eve")) == 1


def test_a_hard_link_between_learners_of_one_unix_user_is_left_out_for_both(tmp_path: Path) -> None:
    """Learners sharing a Unix user: the file is no one's own, so neither reports it, and both notes say why."""
    homes = tmp_path / "home"
    (_workspace(homes, "ana") / "task02.json").write_text(json.dumps(GOOD))
    os.link(homes / "ana" / WORKSPACE_NAME / "exercises" / ".progress" / "task02.json",
            _workspace(homes, "eve") / "task02.json")
    before = tree(homes)
    report = build_report([str(homes / "*")], now=NOW, course=tmp_path / "no-course")
    assert tree(homes) == before
    assert [lr.tasks for lr in report.learners] == [{}, {}]
    learner_notes = [n for n in report.notes if not n.startswith("the course's")]
    assert learner_notes == [f"{a}: task 2's log task02.json is the same file as a log of {b} (a hard link); left out "
                            "for each of them" for a, b in (("ana", "eve"), ("eve", "ana"))]


@pytest.mark.skipif(os.geteuid() != 0, reason="giving a workspace to another Unix user needs root (CI runs as root)")
def test_a_hard_link_to_another_users_log_is_left_out_and_the_owner_keeps_it(homes: Path, tmp_path: Path) -> None:
    for path in [homes / "ana", *(homes / "ana").rglob("*")]:
        os.chown(path, 4242, 4242)  # ana is her own Unix user; eve is this one
    os.link(homes / "ana" / WORKSPACE_NAME / "exercises" / ".progress" / "task02.json",
            _workspace(homes, "eve") / "task02.json")
    report, learners = _report(homes, tmp_path)
    assert learners["eve"].tasks == {}
    assert _notes_of(report, "eve") == [f"eve: task 2's log task02.json belongs to another user (uid 4242, the "
                                        f"workspace's owner is {os.geteuid()}); left out"]


@pytest.mark.parametrize("linked", [f"{WORKSPACE_NAME}/exercises/.progress", f"{WORKSPACE_NAME}/exercises",
                                    WORKSPACE_NAME])
def test_a_link_to_another_learners_folder_does_not_report_their_attempts(homes: Path, tmp_path: Path,
                                                                         linked: str) -> None:
    """.progress, exercises or the whole workspace as a link to ana's: one note, and none of ana's attempts."""
    link = homes / "eve" / linked
    link.parent.mkdir(parents=True)
    link.symlink_to(homes / "ana" / linked)
    report, learners = _report(homes, tmp_path)
    assert learners["eve"].tasks == {}
    assert _notes_of(report, "eve") == [f"eve: {linked}/ is a link (links are never followed); no logs read"]


def test_a_folder_a_device_name_or_a_huge_file_as_a_log_is_one_note_each(homes: Path, tmp_path: Path) -> None:
    progress = _workspace(homes, "eve")
    (progress / "task05.json").mkdir()
    with (progress / "task06.json").open("wb") as handle:  # sparse: 1 GiB long, nothing on disk
        handle.truncate(1 << 30)
    (progress / "task07.json").write_text(json.dumps(GOOD))
    report, learners = _report(homes, tmp_path)
    assert set(learners["eve"].tasks) == {7}
    assert _notes_of(report, "eve") == [
        "eve: task 5's log task05.json is a folder, not a regular file; left out",
        f"eve: task 6's log task06.json is larger than {MAX_LOG_BYTES >> 20} MiB ({1 << 30} bytes); left out"]


def test_a_learners_logs_are_read_up_to_a_total_and_the_rest_is_noted(homes: Path, tmp_path: Path) -> None:
    progress = _workspace(homes, "eve")
    pad = " " * (MAX_LOG_BYTES - len(json.dumps(GOOD)))
    count = MAX_LEARNER_BYTES // MAX_LOG_BYTES + 2
    for task in range(count):
        (progress / f"task{task:02d}.json").write_text(json.dumps(GOOD) + pad)
    report, learners = _report(homes, tmp_path)
    assert len(learners["eve"].tasks) == MAX_LEARNER_BYTES // MAX_LOG_BYTES
    assert all("would take this learner's logs past" in n for n in _notes_of(report, "eve"))


def test_a_room_of_attackers_is_reported_and_the_command_ends_well(homes: Path, tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """Every attack at once, one per learner: exit 0, one note per hostile file, every learner listed."""
    attacks = {
        "deep": lambda p: (p / "task01.json").write_text("[" * 100_000 + "]" * 100_000),
        "digits": lambda p: (p / "task01.json").write_text('{"attempts": [{"time": ' + "7" * 400 + "}]}"),
        "fifo": lambda p: os.mkfifo(p / "task01.json"),
        "zero": lambda p: os.symlink("/dev/zero", p / "task01.json"),
        "steal": lambda p: os.symlink(homes / "ana" / WORKSPACE_NAME / "exercises" / ".progress" / "task01.json",
                                      p / "task01.json"),
    }
    for name, attack in attacks.items():
        attack(_workspace(homes, name))
    before = tree(homes)
    code = no_hang(main, ["class-report", str(homes / "*"), "--out", str(tmp_path / "out")], limit=120.0)
    assert code == 0 and tree(homes) == before
    out = capsys.readouterr().out
    assert out.startswith(f"{len(attacks) + 1} learner(s); wrote ")
    noted = [line.split(":")[1].strip() for line in out.splitlines() if line.startswith("note: ")]
    assert sorted(noted) == sorted(attacks)


# --------------------------------------------------------------------------------------------- what is written


FORMULAS = ["=HYPERLINK(\"http://x\",\"y\")", "+1+2", "-2+3", "@SUM(A1)", "\tx", "\rx", "=1;=2", "\uff1d1+1"]


def test_csv_cell_prefixes_a_quote_to_text_a_spreadsheet_would_take_as_a_formula() -> None:
    assert [csv_cell(f) for f in FORMULAS] == ["'" + f for f in FORMULAS]
    assert [csv_cell(v) for v in ("link1_shape", 3.5, None, "", "a=b", "'already")] == [
        "link1_shape", "3.5", "", "", "a=b", "'already"]


def test_no_cell_of_report_csv_starts_a_formula(tmp_path: Path) -> None:
    """Learner folders and check names that start with =, +, -, @, tab or CR: every cell is quoted, and each such
    cell starts with a quote (OWASP's CSV injection advice)."""
    homes = tmp_path / "home"
    for i, name in enumerate(["=cmd", "+sum", "-neg", "@at"]):
        progress = _workspace(homes, name)
        failed = [FORMULAS[i], FORMULAS[4 + i]]
        (progress / "task01.json").write_text(json.dumps({"attempts": [
            {"time": T0, "score": 0, "max_score": 2, "failed": failed, "reasons": {c: c for c in failed},
             "version": "=v"}]}))
    paths = write_report(build_report([str(homes / "*")], now=NOW, course=tmp_path / "no-course", stuck_after=0),
                         tmp_path / "out")
    raw = paths[1].read_text(encoding="utf-8")
    cells = [cell for row in csv.reader(raw.splitlines(keepends=True)) for cell in row]
    assert len(cells) == 13 * 5
    assert raw.startswith('"learner","task","status"')  # every cell quoted
    assert not [c for c in cells if c[:1] in ("=", "+", "-", "@", "\t", "\r", "\uff1d")]
    assert {"'=cmd", "'+sum", "'-neg", "'@at"} <= set(cells)


def test_report_html_escapes_every_learner_text(tmp_path: Path) -> None:
    homes = tmp_path / "home"
    script = "<script>window.pwned=1</script>"
    progress = _workspace(homes, script.replace("/", "_"))
    (progress / "task01.json").write_text(json.dumps({"attempts": [
        {"time": T0, "score": 0, "max_score": 2, "failed": [script], "reasons": {script: '<img src=x onerror="1">'}}]}))
    paths = write_report(build_report([str(homes / "*")], now=NOW, course=tmp_path / "no-course"), tmp_path / "out")
    page = paths[2].read_text()
    assert "<script" not in page and "<img src=x" not in page
    assert "&lt;script&gt;window.pwned=1&lt;_script&gt;" in page and "&lt;img src=x onerror=&quot;1&quot;&gt;" in page


def test_notes_and_printed_names_carry_no_control_characters() -> None:
    assert shown("ana\x1b[2J\nrm") == "ana\\x1b[2J\\x0arm"
    assert shown("x" * 10_000) == "x" * 80 + "… (10000 characters)"


# --------------------------------------------------------------------------------------------- fuzz


def _json_values():
    leaves = (st.none() | st.booleans() | st.integers(min_value=-(10**500), max_value=10**500)
              | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=40)
              | st.sampled_from(["=cmd|' /C calc'!A0", "<script>x</script>", "\x1b[2J", "task01.json"]))
    return st.recursive(leaves, lambda inner: st.lists(inner, max_size=4)
                        | st.dictionaries(st.text(max_size=10), inner, max_size=4), max_leaves=25)


def _attempt_records():
    return st.fixed_dictionaries({}, optional={
        "time": st.one_of(st.floats(min_value=T0 - 1e4, max_value=T0 + 1e4), _json_values()),
        "score": st.one_of(st.integers(0, 10), _json_values()), "max_score": st.one_of(st.just(10), _json_values()),
        "failed": st.one_of(st.lists(st.text(max_size=30), max_size=5), _json_values()),
        "reasons": st.one_of(st.dictionaries(st.text(max_size=30), st.text(max_size=50), max_size=3), _json_values()),
        "version": st.one_of(st.text(max_size=20), _json_values())})


def _log_bytes():
    as_json = st.one_of(
        st.builds(lambda a: {"attempts": a}, st.lists(st.one_of(_attempt_records(), _json_values()), max_size=6)),
        _json_values()).map(lambda v: json.dumps(v).encode())
    crafted = st.one_of(
        st.integers(1, 60_000).map(lambda n: b"[" * n + b"]" * n),
        st.integers(1, 60_000).map(lambda n: b'{"attempts": ' + b"[" * n),
        st.integers(300, 4000).map(lambda n: b'{"attempts": [{"time": ' + b"9" * n + b"}]}"),
        st.integers(1, 5000).map(lambda n: b'{"attempts": [{"time": 1, "failed": ["' + b'\\"' * n),
    )
    return st.one_of(as_json, crafted, st.binary(max_size=300),
                     as_json.flatmap(lambda b: st.integers(0, len(b)).map(lambda cut: b[:cut])))


@settings(derandomize=True, max_examples=150, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(first=_log_bytes(), second=_log_bytes())
def test_fuzzed_logs_never_stop_the_report_and_each_costs_at_most_one_note(first: bytes, second: bytes) -> None:
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        homes = tmp / "home"
        (_workspace(homes, "ana") / "task01.json").write_text(json.dumps(GOOD))
        eve = _workspace(homes, "eve")
        (eve / "task01.json").write_bytes(first)
        (eve / "task02.json").write_bytes(second)
        before = tree(homes)
        report = no_hang(build_report, [str(homes / "*")], now=NOW, course=tmp / "no-course", limit=120.0)
        paths = write_report(report, tmp / "out")
        assert tree(homes) == before
        ana, fuzzed = report.learners
        assert ana.state(1).status == PASSED and ana.notes == []
        assert len(fuzzed.notes) <= 2 and all(n.startswith("eve: task ") for n in fuzzed.notes)
        for task in (1, 2):
            assert fuzzed.state(task).status in STATUSES
        cells = [c for row in csv.reader(paths[1].read_text(encoding="utf-8").splitlines(keepends=True)) for c in row]
        assert not [c for c in cells if c[:1] in ("=", "+", "-", "@", "\t", "\r")]
        assert "<script" not in paths[2].read_text(encoding="utf-8")
