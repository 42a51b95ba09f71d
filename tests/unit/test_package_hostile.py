"""The package path under hostile layouts: install destinations with ``..``, links to ``/`` and in loops, FIFOs,
huge folders, views left by killed processes. Nothing outside the library's own folders changes, every failure is a
DescriptionError that names what is at fault, and the work done is bounded (counted, never timed)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path, PurePosixPath

import pytest
from package_trees import CONTROL, CONTROLLERS, URDF, tree_state, view_files, write_package

import rrbot_workshop as rw
from rrbot_workshop.cli import main
from rrbot_workshop.description import packages
from rrbot_workshop.description.packages import crawl, installed, view
from rrbot_workshop.exceptions import DescriptionError

POSIX_ONLY = pytest.mark.skipif(os.name == "nt", reason="links, FIFOs and process ids as POSIX has them")
D = "DESTINATION share/${PROJECT_NAME}"


@pytest.fixture(autouse=True)
def _clean() -> None:
    packages.clear_cache()


def _robot(src: Path, name: str = "bot", rules: str = f"install(DIRECTORY urdf config {D})") -> Path:
    return write_package(src / name, name, {"urdf/bot.urdf.xacro": URDF.format(name=name), "urdf/control.xacro": CONTROL,
                                            "config/params.yaml": CONTROLLERS.format(rate=100)},
                         f"project({name})\n{rules}\n")


class _Scans:
    """Wraps os.scandir: the real folders it was asked to list below ``under`` (the work of a crawl or a walk), and
    whether it listed any folder outside ``allowed``."""

    def __init__(self, under: Path, allowed: list[Path]) -> None:
        self.wrapped, self.under = os.scandir, os.path.realpath(under)
        self.allowed = [os.path.realpath(a) for a in allowed]
        self.calls, self.outside = 0, []

    def __call__(self, path="."):  # noqa: ANN001, ANN204
        real = os.path.realpath(path)
        inside = [a for a in self.allowed if real == a or real.startswith(a + os.sep)]
        if not inside:
            self.outside.append(real)
        elif real == self.under or real.startswith(self.under + os.sep):
            self.calls += 1
        return self.wrapped(path)


def _scans(monkeypatch: pytest.MonkeyPatch, under: Path) -> _Scans:
    scans = _Scans(under, [under, packages.descriptions_root(), view.views_parent()])
    monkeypatch.setattr(os, "scandir", scans)
    return scans


# ============================================================================ destinations that leave the prefix
@pytest.mark.parametrize("destination", ["../outside", "share/${PROJECT_NAME}/../../../outside", "share/../..",
                                         ".."])
def test_a_destination_that_leaves_the_install_prefix_is_refused_with_file_line_and_rule(
        tmp_path: Path, destination: str) -> None:
    """``parse_install_rules`` raises; every use of the package (resolve, $(find), bringup, lint) fails with the same
    message, and the folder the rule aims at is untouched."""
    src = tmp_path / "ws" / "src"
    outside = tmp_path / "outside"
    (outside / "keep").mkdir(parents=True)
    (outside / "keep" / "data.txt").write_text("mine")
    pkg = _robot(src, rules=f"install(DIRECTORY urdf {D})\n\ninstall(DIRECTORY config DESTINATION {destination})")
    before = tree_state(tmp_path)
    with pytest.raises(DescriptionError) as info:
        packages.parse_install_rules(pkg / "CMakeLists.txt", "bot")
    text = str(info.value)
    assert str(pkg / "CMakeLists.txt") in text and "line 4" in text
    assert f"install(DIRECTORY config DESTINATION {destination})" in text and "leaves the install prefix" in text
    for use in (lambda: packages.resolve("bot", "urdf/bot.urdf.xacro", [src]),
                lambda: packages.share_directory("bot", [src]),
                lambda: rw.bringup("$(find bot)/urdf/bot.urdf.xacro", "package://bot/config/params.yaml",
                                   package_path=[src])):
        with pytest.raises(DescriptionError, match="leaves the install prefix"):
            use()
    assert main(["lint", str(pkg / "urdf" / "bot.urdf.xacro"), "--package-path", str(src)]) != 0
    assert tree_state(tmp_path) == before


def test_a_rename_that_leaves_the_prefix_is_refused_and_dotdot_inside_it_is_followed(tmp_path: Path) -> None:
    """``RENAME ../../../x`` leaves it; ``share/${PROJECT_NAME}/../${PROJECT_NAME}/cfg`` stays in share/<pkg>."""
    pkg = _robot(tmp_path, rules=f"install(FILES config/params.yaml {D} RENAME ../../../x.yaml)")
    with pytest.raises(DescriptionError, match=r"line 2: install\(FILES .* renames a file to '../../../x.yaml'"):
        packages.parse_install_rules(pkg / "CMakeLists.txt", "bot")
    (pkg / "CMakeLists.txt").write_text("install(DIRECTORY config DESTINATION share/${PROJECT_NAME}/../bot/cfg)\n")
    rules, complete = packages.parse_install_rules(pkg / "CMakeLists.txt", "bot")
    assert complete and [str(r.installed_as) for r in rules] == ["cfg/config"]


def test_a_refused_package_is_found_but_unusable_and_others_still_work(tmp_path: Path) -> None:
    """One bad CMakeLists.txt costs its own package, not the crawl: the package next to it resolves."""
    _robot(tmp_path, "bad", f"install(DIRECTORY config DESTINATION ../x)\ninstall(DIRECTORY urdf {D})")
    _robot(tmp_path, "good")
    assert {"bad", "good"} <= set(packages.package_index([tmp_path]).names())
    assert packages.resolve("good", "config/params.yaml", [tmp_path]).is_file()
    with pytest.raises(DescriptionError, match="leaves the install prefix"):
        packages.find_package("bad", [tmp_path])


# ============================================================================ links
@POSIX_ONLY
def test_a_link_to_the_root_inside_a_package_path_folder_is_not_walked(tmp_path: Path,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """The crawl looks at the few folders of the workspace only; a link out of it is taken only if it is a package."""
    src = tmp_path / "src"
    _robot(src)
    (src / "root").symlink_to("/")
    elsewhere = _robot(tmp_path / "elsewhere", "linked_in")
    (src / "linked_in").symlink_to(elsewhere)
    (src / "not_a_package").symlink_to(tmp_path / "elsewhere")
    scans = _scans(monkeypatch, src)
    names = packages.package_index([src], refresh=True).names()
    monkeypatch.undo()
    assert "bot" in names and "linked_in" in names
    assert scans.outside == [] and scans.calls == 2  # src/ and src/bot; never /, never tmp_path/elsewhere
    assert packages.find_package("linked_in", [src]).path == src / "linked_in"


@POSIX_ONLY
def test_link_loops_end_the_crawl_and_the_installed_tree(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A link to an enclosing folder is followed once at most, in the crawl and in an installed folder."""
    src = tmp_path / "src"
    pkg = _robot(src / "group" / "deeper")
    (src / "group" / "back").symlink_to(src)
    (src / "group" / "self").symlink_to(src / "group")
    (pkg / "config" / "loop").symlink_to(pkg / "config")
    (pkg / "config" / "up").symlink_to(pkg)
    (pkg / "config" / "root").symlink_to("/")
    scans = _scans(monkeypatch, src)
    assert "bot" in packages.package_index([src], refresh=True).names()
    assert scans.outside == [] and scans.calls == 4  # src, group, deeper, deeper/bot: each once
    scans.calls = 0
    tree = installed.install_tree(packages.find_package("bot", [src]))
    monkeypatch.undo()
    assert scans.outside == [] and scans.calls == 4  # urdf, config, the package once through config/up, its urdf
    assert any("(a loop)" in n for n in tree.not_followed) and any("/ (outside the package)" in n
                                                                    for n in tree.not_followed)
    view_files(packages.share_directory("bot", [src]))  # only real folders and links to files


@POSIX_ONLY
def test_fifos_are_never_opened(tmp_path: Path) -> None:
    """A FIFO as package.xml, CMakeLists.txt or an installed file: skipped or reported, never read (it would block)."""
    pkg = _robot(tmp_path / "src")
    os.mkfifo(pkg / "config" / "pipe.yaml")
    fifo_pkg = tmp_path / "src" / "fifo_pkg"
    fifo_pkg.mkdir()
    os.mkfifo(fifo_pkg / "package.xml")
    cmake_fifo = _robot(tmp_path / "src", "cmake_fifo")
    (cmake_fifo / "CMakeLists.txt").unlink()
    os.mkfifo(cmake_fifo / "CMakeLists.txt")
    index = packages.package_index([tmp_path / "src"])
    assert "not a regular file" in index.broken[fifo_pkg / "package.xml"]
    assert index.packages["cmake_fifo"].rules == ()  # not read: the package resolves from its folder
    assert "config/pipe.yaml" not in view_files(packages.share_directory("bot", [tmp_path / "src"]))
    with pytest.raises(DescriptionError, match="pipe.yaml, which is not a regular file"):
        packages.resolve("bot", "config/pipe.yaml", [tmp_path / "src"])


# ============================================================================ bounds
def test_a_folder_with_too_many_folders_is_refused_by_the_crawl(tmp_path: Path,
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(crawl, "MAX_FOLDERS", 20)
    for i in range(30):
        (tmp_path / f"d{i}").mkdir()
    with pytest.raises(DescriptionError, match="holds more than 20 folders outside packages"):
        packages.package_index([tmp_path])


def test_rules_that_install_too_many_files_name_the_rule(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(installed, "MAX_ENTRIES", 10)
    pkg = _robot(tmp_path, rules=f"install(DIRECTORY urdf {D})\ninstall(DIRECTORY many {D})")
    for i in range(20):
        (pkg / "many" / f"f{i}.txt").parent.mkdir(exist_ok=True)
        (pkg / "many" / f"f{i}.txt").write_text("x")
    with pytest.raises(DescriptionError, match=r"more than 10 files and folders \(reached at many -> share/bot/many "
                                               r"\(CMakeLists.txt:3\)\)"):
        packages.share_directory("bot", [tmp_path])


@POSIX_ONLY
def test_a_rule_that_installs_the_root_folder_stops_at_the_limit(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """``install(DIRECTORY / ...)``: the walk lists at most MAX_ENTRIES folders of the file system, then refuses."""
    monkeypatch.setattr(installed, "MAX_ENTRIES", 300)
    _robot(tmp_path, rules=f"install(DIRECTORY / {D})")
    package = packages.find_package("bot", [tmp_path])
    scans = _scans(monkeypatch, Path("/"))
    with pytest.raises(DescriptionError, match=r"more than 300 files and folders \(reached at / -> share/bot"):
        installed.install_tree(package)
    monkeypatch.undo()
    assert scans.calls <= 300


def test_a_file_and_a_folder_at_one_installed_path_is_an_error_naming_both_rules(tmp_path: Path) -> None:
    pkg = _robot(tmp_path, rules=f"install(DIRECTORY config {D})\ninstall(FILES urdf/control.xacro {D} RENAME config)")
    with pytest.raises(DescriptionError) as info:
        packages.share_directory("bot", [tmp_path])
    assert "installs a file at share/bot/config" in str(info.value)
    assert "config -> share/bot/config (CMakeLists.txt:2)" in str(info.value)
    assert str(pkg / "CMakeLists.txt") in str(info.value)


def test_a_5_mb_cmakelists_is_read_to_its_end(tmp_path: Path) -> None:
    """5 MB of commands, deep nesting and doubling set()s, then the rules: all read, the doubled value given up."""
    block = 'set(V_{0} "config") # c\nif(((((A)))))\nendif()\n'
    body = "".join(block.format(i) for i in range(60_000))
    cmake = ("project(bot)\nset(A x)\n" + "set(A ${A}${A})\n" * 40 + body + "(" * 0
             + f"install(DIRECTORY ${{V_7}} {D})\ninstall(DIRECTORY ${{A}} {D})\n")
    cmake += "#" + "x" * (5 * 1024 * 1024 - len(cmake)) + "\n"
    pkg = _robot(tmp_path, rules="")
    (pkg / "CMakeLists.txt").write_text(cmake)
    rules, complete = packages.parse_install_rules(pkg / "CMakeLists.txt", "bot")
    assert [r.source.name for r in rules] == ["config"] and not complete  # ${A} grew past the limit: unknown


# ============================================================================ the views' own folder
def _script(body: str) -> str:
    return "import os, signal, sys\nfrom rrbot_workshop.description import packages\n" + body


@POSIX_ONLY
def test_a_view_is_removed_at_exit_and_one_left_by_a_killed_process_at_the_next_start(tmp_path: Path) -> None:
    src = tmp_path / "src"
    _robot(src)
    env = {**os.environ, "TMPDIR": str(tmp_path / "tmp")}
    (tmp_path / "tmp").mkdir()
    show = "print(packages.share_directory('bot', [sys.argv[1]]), flush=True)"
    done = subprocess.run([sys.executable, "-c", _script(show), str(src)], env=env, capture_output=True, text=True,
                          timeout=120)
    left = Path(done.stdout.strip())
    assert done.returncode == 0 and left.name == "bot" and not left.exists()
    killed = subprocess.run([sys.executable, "-c", _script(show + "\nos.kill(os.getpid(), signal.SIGKILL)"), str(src)],
                            env=env, capture_output=True, text=True, timeout=120)
    left = Path(killed.stdout.strip())
    assert killed.returncode == -9 and left.is_dir()
    again = subprocess.run([sys.executable, "-c", _script("packages.package_index([sys.argv[1]])"), str(src)],
                           env=env, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert not left.exists() and list((tmp_path / "tmp").glob("rrbot_workshop_views-*/*")) == []


@POSIX_ONLY
def test_only_views_of_gone_processes_are_swept(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A live process's folder stays; a gone one's goes; anything not named <pid>-<random> stays."""
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    parent = view.views_parent()
    parent.mkdir(mode=0o700)
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    stale, live, other = parent / f"{gone.stdout.strip()}-abc", parent / f"{os.getppid()}-abc", parent / "notes"
    for folder in (stale, live, other):
        (folder / "0" / "share").mkdir(parents=True)
    (stale / "0" / "share" / "outside").symlink_to(tmp_path / "keep")  # rmtree never follows it
    (tmp_path / "keep").mkdir()
    (tmp_path / "keep" / "x").write_text("x")
    assert view.remove_stale_views() == [stale]
    assert live.is_dir() and other.is_dir() and (tmp_path / "keep" / "x").read_text() == "x"


@POSIX_ONLY
def test_a_planted_views_folder_is_never_swept_nor_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """If the shared parent is a link (or writable by others), the library takes a private folder of its own."""
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    victim = tmp_path / "victim"
    (victim / "1-abc").mkdir(parents=True)
    view.views_parent().symlink_to(victim)
    before = tree_state(victim)
    assert view.remove_stale_views() == []
    monkeypatch.setattr(view, "_FOLDER", None)
    _robot(tmp_path / "src")
    share = packages.share_directory("bot", [tmp_path / "src"], rebuild=True)
    folder = view.process_folder()
    assert folder.name.startswith("rrbot_workshop_view-") and folder in share.parents
    assert not folder.is_relative_to(victim) and tree_state(victim) == before


def test_build_view_refuses_a_name_that_is_not_a_folder_name() -> None:
    for name in ("..", "a/b", ""):
        with pytest.raises(DescriptionError, match="not a package name that can be a folder"):
            view.build_view(installed.InstallTree(name, {PurePosixPath("x"): Path(__file__)}))


def test_a_manifest_naming_a_path_is_not_a_package(tmp_path: Path) -> None:
    write_package(tmp_path / "evil", "../evil", {})
    index = packages.package_index([tmp_path])
    assert "is not a package name" in index.broken[tmp_path / "evil" / "package.xml"]


def test_a_folder_that_cannot_be_read_is_one_error_naming_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def denied(entry: Path) -> list[Path]:
        raise PermissionError(13, "Permission denied", str(entry / "secret"))

    monkeypatch.setattr(crawl, "_walk", denied)
    with pytest.raises(DescriptionError, match=f"'{tmp_path}' cannot be read: Permission denied .*secret"):
        packages.package_index([tmp_path])


def test_a_view_that_cannot_be_written_is_one_error_naming_the_package(tmp_path: Path,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    _robot(tmp_path)

    def full() -> Path:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(view, "process_folder", full)
    with pytest.raises(DescriptionError, match="cannot write the install view of package 'bot' .*No space left"):
        packages.share_directory("bot", [tmp_path], rebuild=True)
