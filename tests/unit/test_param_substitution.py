"""Parameter injection: $(var)/$(env) substitutions in a controllers YAML, merged parameter files, single overrides."""

from __future__ import annotations

from pathlib import Path

import pytest

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import param_substitution as ps


def test_var_and_env_are_substituted(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RRBOT_RATE", "250")
    text = "joints: [$(var prefix)joint1]\nrate: $(env RRBOT_RATE)\nmode: $(env RRBOT_UNSET_XYZ fast)\nmock: $(var mock)"
    out = ps.substitute(text, {"prefix": "r1_", "mock": True})
    assert out == "joints: [r1_joint1]\nrate: 250\nmode: fast\nmock: true"


def test_unknown_variable_names_file_line_and_close_names() -> None:
    with pytest.raises(ParameterError, match=r"ctrl.yaml:2: \$\(var prefx\) is not a launch argument .*did you mean \['prefix'\]"):
        ps.substitute("a: 1\nb: $(var prefx)\n", {"prefix": "r1_"}, source="ctrl.yaml")


def test_unset_environment_without_default_and_unknown_kinds_are_errors() -> None:
    with pytest.raises(ParameterError, match="is not set"):
        ps.substitute("x: $(env RRBOT_SURELY_NOT_SET_123)", {})
    with pytest.raises(ParameterError, match="unsupported substitution"):
        ps.substitute("x: $(find-pkg-share rrbot)", {})


def test_load_with_substitutions_reads_a_file(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("fpc:\n  ros__parameters:\n    joints: [$(var p)j1, $(var p)j2]\n")
    assert ps.load_with_substitutions(path, {"p": "a_"}) == {"fpc": {"ros__parameters": {"joints": ["a_j1", "a_j2"]}}}
    path.write_text("- just a list\n")
    with pytest.raises(ParameterError, match="must be a mapping"):
        ps.load_with_substitutions(path, {})
    with pytest.raises(ParameterError, match="cannot be read"):
        ps.load_with_substitutions(tmp_path / "missing.yaml", {})


def test_later_files_override_the_keys_they_set() -> None:
    base = {"cm": {"ros__parameters": {"update_rate": 100, "jsb": {"type": "x"}}}, "fpc": {"ros__parameters": {"joints": ["a", "b"]}}}
    extra = {"cm": {"ros__parameters": {"update_rate": 50}}, "fpc": {"ros__parameters": {"joints": ["c"]}}}
    merged = ps.merge(base, extra)
    assert merged["cm"]["ros__parameters"] == {"update_rate": 50, "jsb": {"type": "x"}}
    assert merged["fpc"]["ros__parameters"]["joints"] == ["c"]  # lists are replaced, not appended
    assert base["cm"]["ros__parameters"]["update_rate"] == 100  # inputs are not changed


def test_override_sets_dotted_names_on_a_copy() -> None:
    config = {"pid": {"ros__parameters": {"gains": {"j1": {"p": 1.0}}}}}
    out = ps.override(config, "pid", {"gains.j1.p": 5.0, "gains.j1.i": 0.5})
    assert out["pid"]["ros__parameters"]["gains"]["j1"] == {"p": 5.0, "i": 0.5}
    assert config["pid"]["ros__parameters"]["gains"]["j1"] == {"p": 1.0}
    with pytest.raises(ParameterError, match=r"has no ros__parameters section \(nodes: \['pid'\]\)"):
        ps.override(config, "jtc", {"x": 1})


def test_override_finds_the_node_under_a_wildcard_key() -> None:
    """``/**/controller_manager`` and ``/controller_manager`` address the controller manager as ``controller_manager``
    does in a parameters file: override changes that section."""
    for key in ("/**/controller_manager", "/controller_manager"):
        config = {key: {"ros__parameters": {"update_rate": 100}}}
        out = ps.override(config, "controller_manager", {"update_rate": 50})
        assert out == {key: {"ros__parameters": {"update_rate": 50}}}
        assert config[key]["ros__parameters"]["update_rate"] == 100
