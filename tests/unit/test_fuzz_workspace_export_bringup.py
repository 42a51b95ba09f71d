"""Fuzz tests (Hypothesis, derandomized and bounded) of three commands under hostile input: ``init``/``singleuser``
on a workspace a learner has rearranged with hostile names, links, FIFOs and damaged records; ``export --ros2`` with
hostile controller, plugin and package names; ``bringup`` with hostile files and values. Every case ends with exit
status 0 or 2 and no raw traceback, within a guard against hangs, and changes nothing outside the command's own
folders (trees hashed before and after)."""

from __future__ import annotations

import ast
import logging
import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from workspace_helpers import contents, make_course, no_hang, tree

from rrbot_workshop import cli
from rrbot_workshop.classroom import commands as classroom_commands
from rrbot_workshop.course import tracks
from rrbot_workshop.middleware.names import node_name_problem
from rrbot_workshop.tools.ros2_package import package_name_problem, package_xml_values

FUZZ = settings(derandomize=True, max_examples=30, deadline=None, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@pytest.fixture(autouse=True)
def _quiet() -> Iterator[None]:
    logging.disable(logging.CRITICAL)
    yield
    logging.disable(logging.NOTSET)


def _answered(code: Any, err: str) -> None:
    """The command answered: a status of 0 or 2, and no raw traceback."""
    assert code in (0, 2), (code, err[-2000:])
    assert "Traceback" not in err, err[-2000:]


# ----------------------------------------------------------------------------------------------------- names
HOSTILE_NAMES = ["..", "...", "~", "-rf", "$(rm -rf x)", "<?pi?>", "]]>", "a\nb", "a\\b", " ", "x" * 250, "CON",
                 ".rrbot_workshop_workspace.json", ".pristine", "exercises.tar.gz", "exercises", "my_notebooks",
                 "backups", ".sources.json", "a.py", "a.py.course-update", "a.py.yours", ".a.py.rrbot-partial",
                 "task01_fake", "README.md", "descriptions", "notebooks", "tests", "config", "c.yaml"]
file_names = st.one_of(
    st.sampled_from(HOSTILE_NAMES),
    st.text(st.characters(codec="utf-8", exclude_characters="/\x00"), min_size=1, max_size=20),
).filter(lambda n: n not in (".", "..") and len(n.encode()) <= 250)
KINDS = ["file", "folder", "link to outside file", "link to outside folder", "link to /dev/zero", "link to itself",
         "dangling link", "fifo"]
PLACES = ["", "exercises", "exercises/task01_fake", "exercises/task01_fake/config", "my_notebooks",
          "my_notebooks/backups", ".pristine", "descriptions", "descriptions/robot", "tests", "tests/tasks", "notebooks"]


def _place(path: Path, kind: str, data: bytes, outside: Path) -> None:
    """Put a ``kind`` at ``path``, whatever stood there (the learner's doing)."""
    if path.is_symlink() or path.is_file() or (path.exists() and not path.is_dir()):
        path.unlink()
    elif path.is_dir():
        shutil.rmtree(path)
    if kind == "file":
        path.write_bytes(data)
    elif kind == "folder":
        path.mkdir()
        (path / "inside").write_bytes(data)
    elif kind == "fifo":
        os.mkfifo(path)
    else:
        target = {"link to outside file": outside / "theirs.txt", "link to outside folder": outside,
                  "link to /dev/zero": Path("/dev/zero"), "link to itself": path,
                  "dangling link": outside / "nothing here"}[kind]
        path.symlink_to(target)


edits = st.lists(st.tuples(st.sampled_from(PLACES), file_names, st.sampled_from(KINDS), st.binary(max_size=64)),
                 min_size=1, max_size=6)
damages = st.fixed_dictionaries({
    ".pristine/exercises.tar.gz": st.one_of(st.none(), st.binary(max_size=200)),
    ".rrbot_workshop_workspace.json": st.one_of(st.none(), st.binary(max_size=200),
                                                st.sampled_from([b"[]", b"{\"source\": 5}", b"{\"course_files\": 1}"])),
    "my_notebooks/.sources.json": st.one_of(st.none(), st.binary(max_size=100), st.just(b"{\"01_fake.ipynb\": 1}")),
})


@pytest.fixture
def room(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> dict[str, Path]:
    """An installed course, a folder outside everything, and where the examples make workspaces."""
    course = make_course(tmp_path / "course")
    outside = tmp_path / "outside"
    (outside / "sub").mkdir(parents=True)
    (outside / "theirs.txt").write_text("not the course's, not the learner's\n")
    for name in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv(tracks.ROOT_ENV, str(course))
    return {"course": course, "outside": outside, "homes": tmp_path / "homes"}


_count = iter(range(10**9))


def _hostile_workspace(room: dict[str, Path], changes: list[tuple[str, str, str, bytes]],
                       damaged: dict[str, bytes | None]) -> tuple[Path, set[bytes]]:
    """A workspace made from the course, then rearranged by ``changes`` and ``damaged``; and what the learner wrote."""
    ws = room["homes"] / f"h{next(_count)}" / "rrbot_workshop"
    assert cli.main(["init", str(ws), "--from", str(room["course"])]) == 0
    authored: set[bytes] = set()
    for n, (place, name, kind, data) in enumerate(changes):
        folder = ws / place
        if not folder.is_dir() or any(p.is_symlink() for p in (folder, *folder.parents)):
            continue
        unique = data + f"#learner{n}".encode()
        _place(folder / name, kind, unique, room["outside"])
        if kind in ("file", "folder"):
            authored.add(unique)
    for rel, data in damaged.items():
        path = ws / rel
        if data is not None and path.is_file() and not path.is_symlink():
            path.write_bytes(data)
    return ws, authored


@FUZZ
@given(changes=edits, damaged=damages, course_changes=st.booleans())
def test_init_on_a_hostile_workspace_starts_and_loses_nothing(
        changes: list[tuple[str, str, str, bytes]], damaged: dict[str, bytes | None], course_changes: bool,
        room: dict[str, Path], capsys: pytest.CaptureFixture[str]) -> None:
    ws, authored = _hostile_workspace(room, changes, damaged)
    if course_changes:
        (room["course"] / "exercises/task01_fake/b.py").write_text(f"y = {next(_count)}\n")
        (room["course"] / "descriptions/robot/r.urdf").write_text(f"<robot name='r{next(_count)}'/>")
    mine = contents(ws) & authored
    outside, course = tree(room["outside"]), tree(room["course"])
    capsys.readouterr()
    code = no_hang(cli.main, ["init", str(ws)], limit=120)
    err = capsys.readouterr().err
    _answered(code, err)
    assert code == 0, err  # a workspace always starts
    assert mine <= contents(ws), "the learner's writing was lost"
    assert tree(room["outside"]) == outside and tree(room["course"]) == course
    assert no_hang(cli.main, ["init", str(ws)], limit=120) == 0


home_kinds = st.sampled_from(["nothing", "file", "folder", "non-empty folder", "fifo", "link to outside folder",
                              "dangling link", "link to /dev/zero", "workspace"])


@FUZZ
@given(kind=home_kinds, damaged=damages, args=st.lists(st.text(max_size=10), max_size=3))
def test_singleuser_in_a_hostile_home_logs_one_line_each_and_starts_or_says_what_to_do(
        kind: str, damaged: dict[str, bytes | None], args: list[str], room: dict[str, Path],
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    home = room["homes"] / f"h{next(_count)}"
    home.mkdir(parents=True)
    spot = home / "rrbot_workshop"
    if kind == "workspace":
        ws, _ = _hostile_workspace(room, [], damaged)
        shutil.move(str(ws), str(spot))
    elif kind == "non-empty folder":
        _place(spot, "folder", b"my thesis", room["outside"])
    elif kind == "folder":
        spot.mkdir()  # an empty folder: made into the workspace
    elif kind != "nothing":
        _place(spot, kind, b"x", room["outside"])
    monkeypatch.setenv("HOME", str(home))
    started: list[list[str]] = []
    monkeypatch.setattr(classroom_commands.os, "execvp", lambda file, argv: started.append(list(argv)))
    outside = tree(room["outside"])
    capsys.readouterr()
    code = no_hang(cli.main, ["singleuser", *args], limit=120)
    err = capsys.readouterr().err
    _answered(code, err)
    lines = err.strip().splitlines()
    assert lines and all(line.startswith("rrbot-workshop singleuser: ") for line in lines), err
    assert (code == 0) == bool(started), err
    if kind in ("nothing", "folder", "workspace"):
        assert code == 0, err  # a usable workspace always starts
    if kind != "link to outside folder":  # a link of the learner's own is where they keep their workspace
        assert tree(room["outside"]) == outside


# ----------------------------------------------------------------------------------------------------- export
@pytest.fixture
def task_root(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Tasks 1-2 of the solutions as the graded task root, copied once per test (each example edits a copy)."""
    solutions = tracks.course_root() / "solutions"
    if not solutions.is_dir():
        pytest.skip("this copy of the course has no solutions/")
    root = tmp_path / "tasks"
    for task in (1, 2):
        shutil.copytree(solutions / tracks.task_name(task), root / tracks.task_name(task))
    return root


hostile_node_names = st.one_of(st.sampled_from(["x" * 300, "a b", "1abc", "ünï", "a/b", "a\nb", "<?pi?>", "]]>"]),
                               st.text(max_size=15))
node_names = st.one_of(st.from_regex(r"[a-z][a-z0-9_]{0,12}", fullmatch=True), hostile_node_names)
VALID_TYPES = ["joint_state_broadcaster/JointStateBroadcaster"]  # a type that needs no parameter of its own
hostile_plugins = st.one_of(
    st.sampled_from(["my_pkg/MyController", "x<?pi?>/Y", "<![CDATA[x]]>/Y", "a/b/C", "no_slash", "Pkg/C", "a__b/C",
                     "pkg/1C", "pkg/C\n", ""]),
    st.text(max_size=30))
controller_types = st.one_of(st.sampled_from(VALID_TYPES), st.sampled_from(VALID_TYPES), hostile_plugins)
hardware_plugins = st.one_of(st.just("controlko_hardware_interface/RRBotHardwareInterface"),
                             st.from_regex(r"[a-z][a-z0-9_]{1,8}/[A-Z][A-Za-z0-9]{0,8}", fullmatch=True),
                             hostile_plugins)
package_refs = st.one_of(st.sampled_from(["my_meshes", "Upper", "1digit", "a__b", "ok_pkg"]),
                         st.text(st.characters(categories=["Ll", "Lu", "Nd"], max_codepoint=127) | st.just("_"),
                                 min_size=1, max_size=12))


@FUZZ
@given(name=node_names, controller_type=controller_types, hardware=hardware_plugins,
       package=st.one_of(st.none(), st.none(), package_refs))
def test_export_with_hostile_names_writes_only_valid_names_or_refuses(
        name: str, controller_type: str, hardware: str, package: str | None, task_root: Path, tmp_path: Path,
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    work = tmp_path / f"e{next(_count)}"
    shutil.copytree(task_root, work / "tasks")
    monkeypatch.setenv(tracks.TASK_ROOT_ENV, str(work / "tasks"))
    task = work / "tasks" / tracks.task_name(2)
    config = task / "rrbot_bringup" / "config" / "rrbot_controllers.yaml"
    data = yaml.safe_load(config.read_text())
    data["controller_manager"]["ros__parameters"][name] = {"type": controller_type}
    config.write_text(yaml.safe_dump(data))
    xacro = task / "rrbot_description" / "urdf" / "rrbot" / "rrbot_macro.ros2_control.xacro"
    text = xacro.read_text().replace("controlko_hardware_interface/RRBotHardwareInterface", escape(hardware))
    if package is not None:  # a package the description finds (the export makes it a dependency)
        text = text.replace("</xacro:macro>", f"<xacro:property name='mesh' value='package://"
                            f"{escape(package, {chr(39): '&apos;'})}/m.stl'/></xacro:macro>", 1)
    xacro.write_text(text)
    inputs = tree(work / "tasks")
    target = work / "out"
    capsys.readouterr()
    code = no_hang(cli.main, ["export", "--ros2", str(target), "--task", "2"], limit=120)
    err = capsys.readouterr().err
    _answered(code, err)
    assert tree(work / "tasks") == inputs and sorted(p.name for p in work.iterdir()) == (
        ["out", "tasks"] if code == 0 else ["tasks"])
    if code == 2:
        if "export refused" in err:
            assert len(err.strip().splitlines()) == 1, err
        return
    for package_xml in target.rglob("package.xml"):
        values = package_xml_values(package_xml.read_text())
        assert all(not package_name_problem(d) for d in values["exec_depend"] + values["name"]), values
    launch = (target / "controlko_bringup" / "launch" / "rrbot.launch.py").read_text()
    assigned = {t.id: n.value for n in ast.parse(launch).body if isinstance(n, ast.Assign)
                for t in n.targets if isinstance(t, ast.Name)}
    assert all(not node_name_problem(c) for c in ast.literal_eval(assigned["ROBOT_CONTROLLERS"]))


# ----------------------------------------------------------------------------------------------------- bringup
_URDF = """<robot name="one">
  <link name="base"/><link name="arm"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <ros2_control name="one" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="j"><command_interface name="position"/><state_interface name="position"/></joint>
  </ros2_control>
</robot>
"""
_YAML = """controller_manager:
  ros__parameters:
    update_rate: {rate}
    jsb:
      type: joint_state_broadcaster/JointStateBroadcaster
"""
INPUT_KINDS = ["good", "fifo", "folder", "link to /dev/zero", "binary", "text", "missing", "link to itself"]


def _input(folder: Path, name: str, kind: str, good: str, data: bytes) -> str:
    path = folder / name
    if kind == "good":
        path.write_text(good)
    elif kind == "binary":
        path.write_bytes(b"\x00" + data)
    elif kind == "text":
        path.write_bytes(data)
    elif kind == "folder":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "link to /dev/zero":
        path.symlink_to("/dev/zero")
    elif kind == "link to itself":
        path.symlink_to(path)
    return str(path)


@settings(FUZZ, max_examples=120)
@given(description=st.one_of(st.just("good"), st.sampled_from(INPUT_KINDS)),
       suffix=st.sampled_from([".urdf", ".urdf.xacro", ".xml"]),
       controllers=st.one_of(st.none(), st.just("good"), st.sampled_from(INPUT_KINDS)), data=st.binary(max_size=64),
       rate=st.one_of(st.sampled_from([100, 1000, 10**7, 0, -5, "fast", 1e308]), st.integers(1, 10**4)),
       seconds=st.one_of(st.floats(0, 3).map(repr), st.floats(0, 3).map(repr), st.floats(-5, 5).map(repr),
                         st.sampled_from(["nan", "inf", "-inf", "1e6", "3600.5", "-0.0", "1e-9", "0x10", "abc"])),
       spawn=st.one_of(st.just([]), st.just(["jsb"]), st.lists(st.one_of(st.just("jsb"), node_names), max_size=2)),
       arg=st.one_of(st.just([]), st.lists(st.text(max_size=12), max_size=2)))
def test_bringup_with_hostile_files_and_values_answers_and_changes_nothing(
        description: str, suffix: str, controllers: str | None, data: bytes, rate: object, seconds: str,
        spawn: list[str], arg: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / f"b{next(_count)}"
    folder.mkdir()
    argv = ["bringup", _input(folder, f"robot{suffix}", description, _URDF, data), "--seconds", seconds]
    if controllers is not None:
        argv += ["--controllers", _input(folder, "controllers.yaml", controllers, _YAML.format(rate=rate), data)]
    for name in spawn:
        argv += ["--spawn", name]
    for pair in arg:
        argv += ["--arg", pair]
    before = tree(folder)

    def release() -> None:  # unblock a reader stuck on a FIFO so that a failing test ends
        for fifo in (p for p in folder.iterdir() if p.is_fifo()):
            try:
                os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
            except OSError:
                pass

    capsys.readouterr()
    code = no_hang(cli.main, argv, limit=120, release=release)
    _answered(code, capsys.readouterr().err)
    assert tree(folder) == before
