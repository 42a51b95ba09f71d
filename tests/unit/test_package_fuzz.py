"""Fuzz tests of the package path (Hypothesis, derandomized and bounded): random workspaces of packages, install
rules (overlapping, renamed, leaving the prefix, unclosed), files and links (to ``/``, to ``..``, in loops, dangling).

Whatever the workspace, crawling it and resolving every package through ``$(find)`` and ``package://`` changes
nothing outside the library's own folders (the workspace and a folder beside it are hashed), fails only with a
DescriptionError, and every view is made of real folders and links to files.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from package_trees import PACKAGE_XML, tree_state, view_files

from rrbot_workshop.description import packages
from rrbot_workshop.exceptions import DescriptionError

FUZZ = settings(derandomize=True, max_examples=60, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
POSIX_ONLY = pytest.mark.skipif(os.name == "nt", reason="links as POSIX has them")

SEGMENTS = ["config", "urdf", "sub", "a.yaml", "b.xacro", "params.yaml"]
_path = st.lists(st.sampled_from(SEGMENTS), min_size=1, max_size=3).map("/".join)
_source = st.one_of(_path, _path.map(lambda p: p + "/"), st.sampled_from([".", "./", "..", "../outside", "../../../outside/", ""]))
_destination = st.sampled_from([
    "share/${PROJECT_NAME}", "share/${PROJECT_NAME}/config", "share/${PROJECT_NAME}/sub/..", "../x",
    "share/${PROJECT_NAME}/../../..", "share/${PROJECT_NAME}/../other", "/tmp/abs", "include", "share/${UNKNOWN}",
    "share/${PROJECT_NAME}/../${PROJECT_NAME}/cfg",
])
_rename = st.one_of(st.none(), st.sampled_from(["params.yaml", "../../evil.yaml", "x/y.yaml", "config", ".."]))


@st.composite
def _rule(draw: st.DrawFn) -> str:
    kind = draw(st.sampled_from(["DIRECTORY", "FILES"]))
    sources = " ".join(draw(st.lists(_source, min_size=1, max_size=3)))
    rename = draw(_rename) if kind == "FILES" else None
    return f"install({kind} {sources} DESTINATION {draw(_destination)}{f' RENAME {rename}' if rename else ''})"


_garbage = st.sampled_from(["install(DIRECTORY config", 'set(A "unclosed', "if(((", "#[[ open", ")", "set(A ${A}${A})"])
_cmake = st.lists(st.one_of(_rule(), _rule(), _rule(), _garbage), max_size=6).map("\n".join)
_link_target = st.sampled_from(["/", "..", ".", "../..", "config", "a.yaml", "missing", "../../outside",
                                "../../outside/keep.txt", "sub/.."])
_package = st.fixed_dictionaries({
    "name": st.sampled_from(["alpha", "beta", "p"]),
    "files": st.lists(_path, max_size=6),
    "links": st.lists(st.tuples(_path, _link_target), max_size=4),
    "cmake": st.one_of(st.none(), _cmake),
})


def _write(root: Path, spec: list[dict]) -> Path:
    """The workspace ``root/ws/src`` of ``spec`` (one folder per package), and ``root/outside`` beside it."""
    outside = root / "outside"
    (outside / "inner").mkdir(parents=True)
    (outside / "keep.txt").write_text("keep")
    src = root / "ws" / "src"
    for i, package in enumerate(spec):
        folder = src / f"pkg{i}"
        folder.mkdir(parents=True)
        (folder / "package.xml").write_text(PACKAGE_XML.format(name=package["name"]))
        if package["cmake"] is not None:
            (folder / "CMakeLists.txt").write_text(package["cmake"])
        for rel in package["files"]:
            path = folder / rel
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                if not path.exists():
                    path.write_text(rel)
            except OSError:  # a segment already taken by a file: the spec's own clash
                continue
        for rel, target in package["links"]:
            path = folder / rel
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.symlink_to(target)
            except OSError:
                continue
    return src


def _resolve_everything(src: Path) -> None:
    """Crawl, then for each package: its share folder (checked to be made of real folders and links to files), and
    every path a rule names, through resolve() and package://. Only DescriptionError may come out."""
    try:
        index = packages.package_index([src], refresh=True)
    except DescriptionError:
        return
    for name in index.names():
        try:
            share = packages.share_directory(name, [src])
            if share.is_relative_to(packages.views_parent()) or not share.is_relative_to(src):
                view_files(share)
        except DescriptionError:
            continue
        for rel in SEGMENTS + ["config/a.yaml", "package.xml", "../outside/keep.txt"]:
            for lookup in (lambda r=rel, n=name: packages.resolve(n, r, [src]),
                           lambda r=rel, n=name: packages.resolve_uri(f"package://{n}/{r}", [src], must_exist=False)):
                try:
                    lookup()
                except DescriptionError:
                    pass


@POSIX_ONLY
@FUZZ
@given(st.lists(_package, min_size=1, max_size=3))
def test_random_workspaces_change_nothing_outside_the_librarys_folders(spec: list[dict]) -> None:
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        src = _write(root, spec)
        before = tree_state(root)
        packages.clear_cache()
        _resolve_everything(src)
        assert tree_state(root) == before


@FUZZ
@given(st.text(alphabet=st.sampled_from(list('()#[]=" \n\\$;{}abcINSTALLDIRECTORYSHARE/.')), max_size=400))
def test_random_cmake_text_is_read_or_refused_never_crashes(text: str) -> None:
    """Any text as CMakeLists.txt: rules and a completeness flag, or a DescriptionError (a DESTINATION out of the
    prefix); never another exception."""
    with tempfile.TemporaryDirectory() as folder:
        cmake = Path(folder) / "CMakeLists.txt"
        cmake.write_text("project(p)\n" + text)
        try:
            rules, complete = packages.parse_install_rules(cmake, "p")
        except DescriptionError as exc:
            assert "leaves the install prefix" in str(exc)
            return
        assert isinstance(complete, bool)
        for rule in rules:
            assert ".." not in rule.installed_as.parts and not rule.installed_as.is_absolute()
