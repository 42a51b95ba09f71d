"""process_xacro remembers expansions, and never gives an old one: files compared by contents, variables by value."""

from __future__ import annotations

from pathlib import Path

import pytest
import xacro

from rrbot_workshop.description import xacro as course_xacro
from rrbot_workshop.description.xacro import process_xacro

_TOP = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="cell">
  <xacro:arg name="side" default="left"/>
  <xacro:include filename="$(cwd)/part.xacro"/>
  <link name="$(arg side)_$(optenv RRBOT_TEST_SUFFIX plain)"/>
  <xacro:part/>
</robot>
"""
_PART = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="part"><link name="part_a"/></xacro:macro>
</robot>
"""


@pytest.fixture
def counted(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, list[str]]:
    """A two-file description, and the list of files xacro itself expanded."""
    (tmp_path / "top.urdf.xacro").write_text(_TOP.replace("$(cwd)", str(tmp_path)))
    (tmp_path / "part.xacro").write_text(_PART)
    runs: list[str] = []
    real = xacro.process_file

    def process_file(path: str, **kwargs: object) -> object:
        runs.append(path)
        return real(path, **kwargs)

    monkeypatch.setattr(xacro, "process_file", process_file)
    monkeypatch.setattr(course_xacro, "_CACHE", type(course_xacro._CACHE)())
    monkeypatch.delenv("RRBOT_TEST_SUFFIX", raising=False)
    return tmp_path / "top.urdf.xacro", runs


def test_the_same_expansion_is_made_once(counted: tuple[Path, list[str]]) -> None:
    top, runs = counted
    assert process_xacro(top) == process_xacro(top)
    assert len(runs) == 1


def test_an_edited_include_is_expanded_again_even_at_the_same_size(counted: tuple[Path, list[str]]) -> None:
    top, runs = counted
    assert 'name="part_a"' in process_xacro(top)
    (top.parent / "part.xacro").write_text(_PART.replace("part_a", "part_b"))  # same size, same second
    assert 'name="part_b"' in process_xacro(top)
    assert len(runs) == 2


def test_other_arguments_are_another_expansion(counted: tuple[Path, list[str]]) -> None:
    top, runs = counted
    assert 'name="left_plain"' in process_xacro(top)
    assert 'name="right_plain"' in process_xacro(top, side="right")
    assert 'name="left_plain"' in process_xacro(top)
    assert len(runs) == 2


def test_a_variable_the_files_read_is_part_of_the_expansion(counted: tuple[Path, list[str]],
                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    top, runs = counted
    assert 'name="left_plain"' in process_xacro(top)
    monkeypatch.setenv("RRBOT_TEST_SUFFIX", "fancy")
    assert 'name="left_fancy"' in process_xacro(top)
    monkeypatch.setenv("UNRELATED_VARIABLE", "x")  # one the files do not read changes nothing
    assert 'name="left_fancy"' in process_xacro(top)
    assert len(runs) == 2


def test_the_cache_keeps_only_so_many_expansions(counted: tuple[Path, list[str]],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    top, runs = counted
    monkeypatch.setattr(course_xacro, "CACHE_SIZE", 2)
    for side in ("a", "b", "c", "a"):
        process_xacro(top, side=side)
    assert len(course_xacro._CACHE) == 2 and len(runs) == 4  # "a" was pushed out by "c"


def test_an_include_by_pattern_is_never_remembered(counted: tuple[Path, list[str]]) -> None:
    """xacro expands a glob in an include's filename: a file added later changes the result."""
    top, runs = counted
    top.write_text(_TOP.replace("$(cwd)/part.xacro", f"{top.parent}/par*.xacro"))
    assert 'name="part_a"' in process_xacro(top)
    (top.parent / "part.xacro").write_text(_PART.replace("part_a", "part_b"))
    (top.parent / "parts_more.xacro").write_text(_PART.replace("part", "more"))
    assert 'name="part_b"' in process_xacro(top) and len(runs) == 2
