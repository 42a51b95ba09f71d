"""Install rules that overlap, in both orders: the package's files are never touched, and each path resolves to the
file CMake would install last.

The package ``overlap_bot`` installs ``urdf/`` first, then two of these rules (every ordered pair), then ament's
``package.xml``:

* ``directory``: ``install(DIRECTORY config ...)`` (the folder ``config`` with ``params.yaml`` and ``other.yaml``);
* ``same_file``: ``install(FILES config/params.yaml ... /config)``, the same file again;
* ``same_name``: ``install(FILES extra/params.yaml ... /config)``, another file of the same name;
* ``new_file``: ``install(FILES extra/new.yaml ... /config)``, a new file into the installed folder;
* ``contents``: ``install(DIRECTORY overlay/ ... /config)``, a folder's contents into the installed folder;
* ``rename``: ``install(FILES alt/controllers.yaml ... /config RENAME params.yaml)``, onto an existing name.

Each ``params.yaml`` has its own update rate, so a bringup shows which file it read. The workspace is hashed (content,
file types, modes, link targets) before and after ``lint``, the CLI's ``bringup`` and ``rw.bringup``.
"""

from __future__ import annotations

import itertools
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from package_trees import CONTROL, CONTROLLERS, URDF, tree_state, view_files, write_package

import rrbot_workshop as rw
from rrbot_workshop.bringup import systems
from rrbot_workshop.cli import main
from rrbot_workshop.description import packages

NAME = "overlap_bot"
RATES = {"config/params.yaml": 100, "extra/params.yaml": 50, "overlay/params.yaml": 25, "alt/controllers.yaml": 20}
SOURCES = {
    "urdf/bot.urdf.xacro": URDF.format(name=NAME),
    "urdf/control.xacro": CONTROL,
    **{path: CONTROLLERS.format(rate=rate) for path, rate in RATES.items()},
    "config/other.yaml": "other: 1\n",
    "extra/new.yaml": "new: 1\n",
    "overlay/overlay_only.yaml": "overlay_only: 1\n",
}
D = "DESTINATION share/${PROJECT_NAME}"
#: Each rule: its CMake text, and what it installs (installed path -> source file), as CMake does.
RULES: dict[str, tuple[str, dict[str, str]]] = {
    "directory": (f"install(DIRECTORY config {D})",
                  {"config/params.yaml": "config/params.yaml", "config/other.yaml": "config/other.yaml"}),
    "same_file": (f"install(FILES config/params.yaml {D}/config)", {"config/params.yaml": "config/params.yaml"}),
    "same_name": (f"install(FILES extra/params.yaml {D}/config)", {"config/params.yaml": "extra/params.yaml"}),
    "new_file": (f"install(FILES extra/new.yaml {D}/config)", {"config/new.yaml": "extra/new.yaml"}),
    "contents": (f"install(DIRECTORY overlay/ {D}/config)",
                 {"config/params.yaml": "overlay/params.yaml", "config/overlay_only.yaml": "overlay/overlay_only.yaml"}),
    "rename": (f"install(FILES alt/controllers.yaml {D}/config RENAME params.yaml)",
               {"config/params.yaml": "alt/controllers.yaml"}),
}
FIRST = (f"install(DIRECTORY urdf {D})", {"urdf/bot.urdf.xacro": "urdf/bot.urdf.xacro",
                                         "urdf/control.xacro": "urdf/control.xacro"})
LAST = (f"install(FILES package.xml {D})", {"package.xml": "package.xml"})  # what ament_package() adds
PAIRS = list(itertools.permutations(RULES, 2))


@pytest.fixture(autouse=True)
def _clean() -> None:
    packages.clear_cache()
    for system in list(systems().values()):
        system.shutdown()


def _workspace(tmp_path: Path, first: str, second: str) -> tuple[Path, Path, dict[str, str]]:
    """The workspace's src/, the package, and what its install folder holds (installed path -> source file)."""
    src = tmp_path / "ws" / "src"
    rules = [FIRST, RULES[first], RULES[second], LAST]
    cmake = "cmake_minimum_required(VERSION 3.8)\nproject(overlap_bot NONE)\n" + "\n".join(r[0] for r in rules) + "\n"
    pkg = write_package(src / NAME, NAME, SOURCES, cmake)
    installed: dict[str, str] = {}
    for _, files in rules:
        installed.update(files)  # a later rule overwrites what an earlier one installed
    return src, pkg, installed


def _expected_rate(installed: dict[str, str]) -> int:
    return RATES[installed["config/params.yaml"]]


@pytest.mark.parametrize(("first", "second"), PAIRS, ids=[f"{a}-then-{b}" for a, b in PAIRS])
def test_overlapping_rules_resolve_as_cmake_installs_and_leave_the_package_untouched(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], first: str, second: str) -> None:
    """The view and resolve() give the file installed last; lint, the CLI's bringup and rw.bringup read it, and the
    workspace is byte for byte, type for type, as it was."""
    src, pkg, installed = _workspace(tmp_path, first, second)
    before = tree_state(tmp_path / "ws")
    view = packages.share_directory(NAME, [src])
    assert view_files(view) == {rel: (pkg / source).read_bytes() for rel, source in installed.items()}
    for rel, source in installed.items():
        assert packages.resolve(NAME, rel, [src]) == pkg / source
    rate = _expected_rate(installed)

    assert main(["lint", str(pkg / installed["config/params.yaml"]), "--description",
                 str(pkg / "urdf" / "bot.urdf.xacro"), "--package-path", str(src)]) == 0
    assert main(["bringup", f"package://{NAME}/urdf/bot.urdf.xacro", "--controllers",
                 f"$(find {NAME})/config/params.yaml", "--package-path", str(src), "--spawn",
                 "joint_state_broadcaster", "--seconds", "0.05"]) == 0
    assert f"(simulated clock, {rate} Hz)" in capsys.readouterr().out
    with rw.bringup(f"$(find {NAME})/urdf/bot.urdf.xacro", f"package://{NAME}/config/params.yaml",
                    package_path=[src], spawn=["joint_state_broadcaster"]) as system:
        assert round(1 / system.period) == rate
    assert tree_state(tmp_path / "ws") == before


def test_the_workshop_script_brings_the_package_up_without_touching_it(tmp_path: Path) -> None:
    """``./workshop bringup`` as a learner runs it, in its own process, on the layout that lost a file before."""
    src, _, installed = _workspace(tmp_path, "directory", "same_file")
    before = tree_state(tmp_path / "ws")
    repo = Path(__file__).resolve().parents[2]
    done = subprocess.run([str(repo / "workshop"), "bringup", f"package://{NAME}/urdf/bot.urdf.xacro",
                           "--controllers", f"$(find {NAME})/config/params.yaml", "--package-path", str(src),
                           "--spawn", "joint_state_broadcaster", "--seconds", "0.05"],
                          capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert f"(simulated clock, {_expected_rate(installed)} Hz)" in done.stdout
    assert tree_state(tmp_path / "ws") == before


@pytest.mark.skipif(shutil.which("cmake") is None, reason="CMake is not installed here")
@pytest.mark.parametrize(("first", "second"), PAIRS[::3], ids=[f"{a}-then-{b}" for a, b in PAIRS[::3]])
def test_real_cmake_installs_what_the_view_shows(tmp_path: Path, first: str, second: str) -> None:
    """CMake itself, run on the same CMakeLists.txt, installs exactly the files of the view (a check of the model
    the other tests state). The sources' times are set apart: CMake leaves an installed file in place when the next
    one's time is within a second of it (docs/differences.md)."""
    src, pkg, _ = _workspace(tmp_path, first, second)
    for i, source in enumerate(sorted(SOURCES)):  # CMake skips a file whose time is within 1 s of the installed one
        os.utime(pkg / source, (1_700_000_000 + 10 * i, 1_700_000_000 + 10 * i))
    before = tree_state(src)
    build, prefix = tmp_path / "build", tmp_path / "install"
    for command in (["cmake", "-S", str(src / NAME), "-B", str(build)],
                    ["cmake", "--install", str(build), "--prefix", str(prefix)]):
        done = subprocess.run(command, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
    installed = {str(p.relative_to(prefix / "share" / NAME)): p.read_bytes()
                 for p in (prefix / "share" / NAME).rglob("*") if p.is_file()}
    assert view_files(packages.share_directory(NAME, [src])) == installed
    assert tree_state(src) == before
