"""Xacro processing without ROS: arguments, $(find), package:// URIs, and errors that name the file."""

from __future__ import annotations

from pathlib import Path

import pytest
import xacro.substitution_args as subst

from rrbot_workshop.description import descriptions_root, process_xacro, resolve_package_uri
from rrbot_workshop.description.packages import DESCRIPTIONS_ENV
from rrbot_workshop.description.xacro import available_packages, find_package
from rrbot_workshop.exceptions import DescriptionError

_HEAD = '<?xml version="1.0"?>\n<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


@pytest.fixture
def packages(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A descriptions root with packages ``alpha`` and ``beta`` (beta holds a macro)."""
    (tmp_path / "alpha" / "urdf").mkdir(parents=True)
    (tmp_path / "beta" / "urdf").mkdir(parents=True)
    (tmp_path / "beta" / "urdf" / "m.xacro").write_text(
        _HEAD + '<xacro:macro name="m" params="p"><link name="${p}from_beta"/></xacro:macro>\n</robot>\n'
    )
    monkeypatch.setenv(DESCRIPTIONS_ENV, str(tmp_path))
    return tmp_path


def _write(packages: Path, name: str, body: str) -> Path:
    path = packages / "alpha" / "urdf" / name
    path.write_text(_HEAD + body + "\n</robot>\n")
    return path


def test_descriptions_root_is_the_repository_folder_with_rrbot() -> None:
    """Without an override, packages live in ``descriptions/`` at the repository root."""
    root = descriptions_root()
    assert root == Path(__file__).resolve().parents[2] / "descriptions"
    assert "rrbot" in available_packages()


def test_environment_variable_overrides_descriptions_root(packages: Path) -> None:
    """``RRBOT_WORKSHOP_DESCRIPTIONS`` points the lookup elsewhere."""
    assert descriptions_root() == packages.resolve()
    assert available_packages() == ["alpha", "beta"]


def test_arguments_are_substituted_and_booleans_become_lowercase(packages: Path) -> None:
    """Mappings reach ``$(arg)``; True/False are passed as ``true``/``false``, numbers as text."""
    path = _write(packages, "a.xacro", """
      <xacro:arg name="prefix" default=""/>
      <xacro:arg name="flag" default="false"/>
      <xacro:arg name="count" default="0"/>
      <link name="$(arg prefix)base"/>
      <xacro:if value="$(arg flag)"><link name="flag_$(arg flag)"/></xacro:if>
      <link name="n$(arg count)"/>""")
    urdf = process_xacro(path, prefix="r1_", flag=True, count=3)
    assert '<link name="r1_base"/>' in urdf
    assert '<link name="flag_true"/>' in urdf
    assert '<link name="n3"/>' in urdf
    assert "flag_" not in process_xacro(path)


def test_find_resolves_to_the_package_folder(packages: Path) -> None:
    """``$(find beta)`` is ``<descriptions>/beta``, so includes across packages work."""
    path = _write(packages, "b.xacro", """
      <xacro:include filename="$(find beta)/urdf/m.xacro"/>
      <xacro:m p="x_"/>
      <link name="$(find beta)"/>""")
    urdf = process_xacro(path)
    assert '<link name="x_from_beta"/>' in urdf
    assert f'<link name="{packages.resolve() / "beta"}"/>' in urdf


def test_find_hook_is_removed_after_processing(packages: Path) -> None:
    """xacro's own ``$(find)`` lookup is restored after success and after failure."""
    original = subst._eval_find
    process_xacro(_write(packages, "ok.xacro", '<link name="a"/>'))
    assert subst._eval_find is original and subst._eval_dict["find"] is original
    with pytest.raises(DescriptionError):
        process_xacro(_write(packages, "bad.xacro", '<link name="${nope}"/>'))
    assert subst._eval_find is original and subst._eval_dict["find"] is original


def test_missing_file_raises_description_error_naming_it(tmp_path: Path) -> None:
    """A path that does not exist is reported with the path."""
    missing = tmp_path / "nowhere" / "robot.urdf.xacro"
    with pytest.raises(DescriptionError, match="not found") as info:
        process_xacro(missing)
    assert str(missing) in str(info.value) and info.value.source == str(missing)


def test_xacro_error_raises_description_error_naming_the_file(packages: Path) -> None:
    """An undefined property fails with the file and xacro's reason."""
    path = _write(packages, "undef.xacro", '<link name="${undefined_property}"/>')
    with pytest.raises(DescriptionError, match="undefined_property") as info:
        process_xacro(path)
    assert str(path) in str(info.value)


def test_undefined_argument_names_the_argument(packages: Path) -> None:
    """``$(arg x)`` without a declaration or mapping says which argument is missing."""
    path = _write(packages, "arg.xacro", '<link name="$(arg not_declared)"/>')
    with pytest.raises(DescriptionError, match="undefined xacro argument 'not_declared'"):
        process_xacro(path)


def test_malformed_xml_raises_description_error(packages: Path) -> None:
    """Broken XML is a DescriptionError, not an ExpatError."""
    path = packages / "alpha" / "urdf" / "broken.xacro"
    path.write_text("<robot><link></robot>")
    with pytest.raises(DescriptionError, match="malformed XML") as info:
        process_xacro(path)
    assert str(path) in str(info.value)


def test_unknown_package_lists_the_valid_ones(packages: Path) -> None:
    """``$(find nope)`` names the package and lists those that exist."""
    path = _write(packages, "find.xacro", '<xacro:include filename="$(find nope)/urdf/x.xacro"/>')
    with pytest.raises(DescriptionError, match=r"unknown package 'nope' \(valid: alpha, beta\)") as info:
        process_xacro(path)
    assert str(path) in str(info.value)


def test_find_package_rejects_unknown_names(packages: Path) -> None:
    """``find_package`` raises for a folder that does not exist."""
    assert find_package("alpha") == packages.resolve() / "alpha"
    with pytest.raises(DescriptionError, match="valid: alpha, beta"):
        find_package("gamma")


def test_resolve_package_uri_forms(packages: Path) -> None:
    """package://, file:// and relative paths (with a base) become file paths."""
    assert resolve_package_uri("package://beta/meshes/x.stl") == packages.resolve() / "beta" / "meshes" / "x.stl"
    assert resolve_package_uri("file:///tmp/a.stl") == Path("/tmp/a.stl")
    assert resolve_package_uri("meshes/a.stl", base=packages) == packages / "meshes" / "a.stl"


def test_resolve_package_uri_rejects_unknown_package(packages: Path) -> None:
    """An unknown package in a package:// URI is a DescriptionError listing the valid ones."""
    with pytest.raises(DescriptionError, match="unknown package 'gamma'"):
        resolve_package_uri("package://gamma/meshes/x.stl")


def test_resolve_package_uri_without_package_name_raises() -> None:
    """``package:///x`` has no package name."""
    with pytest.raises(DescriptionError, match="no package name"):
        resolve_package_uri("package:///meshes/x.stl")


def test_malformed_xml_names_the_element_left_open(tmp_path) -> None:  # noqa: ANN001
    """A forgotten closing tag: the error gives line and column and the element that was left open, not only the
    place where the parser noticed."""
    import pytest

    from rrbot_workshop.description import process_xacro
    from rrbot_workshop.exceptions import DescriptionError

    path = tmp_path / "robot.urdf.xacro"
    path.write_text('<?xml version="1.0"?>\n<robot name="r">\n  <link name="base">\n    <visual>\n'
                    '      <geometry><box size="1 1 1"/></geometry>\n  </link>\n</robot>\n')
    with pytest.raises(DescriptionError, match=r"line 6, column \d+: mismatched tag; <visual> opened at line 4 is not closed"):
        process_xacro(path)
