"""Parameters: the controllers YAML layout and generate_parameter_library-style schemas."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.params import (
    ParameterSchema,
    ParamListener,
    flatten,
    load_controllers_yaml,
    register_validator,
)

YAML = """
controller_manager:
  ros__parameters:
    update_rate: 200
    handle_exceptions: true
    jsb:
      type: joint_state_broadcaster/JointStateBroadcaster
    fwd:
      type: forward_command_controller/ForwardCommandController
/**:
  ros__parameters:
    shared: 1
fwd:
  ros__parameters:
    joints: [joint1, joint2]
    interface_name: position
"""

SCHEMA = """
my_controller:
  joints:
    type: string_array
    default_value: []
    validation:
      not_empty<>: []
      unique<>: []
  interface_name:
    type: string
    validation:
      one_of<>: [["position", "velocity"]]
  gain:
    type: double
    default_value: 1.0
    validation:
      gt<>: [0.0]
  gains:
    __map_joints:
      p:
        type: double
        default_value: 0.0
"""


def test_controllers_yaml_layout() -> None:
    cfg = load_controllers_yaml(YAML)
    assert cfg.update_rate == 200 and cfg.manager_parameters == {"update_rate": 200, "handle_exceptions": True}
    assert cfg.controller_types == {
        "jsb": "joint_state_broadcaster/JointStateBroadcaster",
        "fwd": "forward_command_controller/ForwardCommandController",
    }
    assert cfg.parameters_for("fwd") == {"shared": 1, "joints": ["joint1", "joint2"], "interface_name": "position"}
    assert cfg.parameters_for("jsb") == {"shared": 1}


def test_parameters_for_is_a_copy() -> None:
    cfg = load_controllers_yaml(YAML)
    cfg.parameters_for("fwd")["joints"].append("x")
    assert cfg.parameters_for("fwd")["joints"] == ["joint1", "joint2"]


def test_yaml_from_file_and_mapping(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text(YAML)
    assert load_controllers_yaml(path).source == str(path)
    assert load_controllers_yaml({"controller_manager": {"ros__parameters": {}}}).update_rate == 100


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("fwd: {joints: []}", "ros__parameters"),
        ("controller_manager:\n  ros__parameters:\n    update_rate: -5", "positive integer"),
        ("controller_manager:\n  ros__parameters:\n    c: {type: NoSlash}", "plugin type string"),
        ("[1, 2", "not valid YAML"),
        ("- a\n- b", "mapping"),
    ],
)
def test_malformed_yaml_is_rejected(text: str, match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        load_controllers_yaml(text)


def test_missing_file_is_rejected() -> None:
    with pytest.raises(ParameterError, match="cannot be read"):
        load_controllers_yaml("/no/such/file.yaml")


def test_schema_validates_and_maps_joints() -> None:
    values = {"joints": ["j1", "j2"], "interface_name": "position", "gains": {"j1": {"p": 2}}}
    params = ParamListener(ParameterSchema(SCHEMA), values, "ctrl").get_params()
    assert params.joints == ["j1", "j2"] and params.gain == 1.0
    assert params.gains.joints_map["j1"].p == 2.0 and params.gains.joints_map["j2"].p == 0.0


@pytest.mark.parametrize(
    ("values", "match"),
    [
        ({"joints": [], "interface_name": "position"}, "'joints'.*must not be empty"),
        ({"joints": ["a", "a"], "interface_name": "position"}, "unique"),
        ({"joints": ["a"], "interface_name": "effort"}, "one of"),
        ({"joints": ["a"]}, "'interface_name'.*required"),
        ({"joints": ["a"], "interface_name": "position", "gain": -1.0}, "> 0.0"),
        ({"joints": ["a"], "interface_name": "position", "gain": "high"}, "type double"),
        ({"joints": ["a"], "interface_name": True}, "type string"),
    ],
)
def test_schema_errors_name_controller_and_parameter(values: dict, match: str) -> None:
    with pytest.raises(ParameterError, match=match) as err:
        ParamListener(ParameterSchema(SCHEMA), values, "my_ctrl")
    assert err.value.owner == "my_ctrl"


def test_params_are_read_only() -> None:
    params = ParamListener(ParameterSchema(SCHEMA), {"joints": ["a"], "interface_name": "position"}, "c").get_params()
    with pytest.raises(AttributeError, match="read-only"):
        params.gain = 2.0
    with pytest.raises(AttributeError, match="no parameter 'nope'"):
        _ = params.nope


def test_refresh_rereads_live_values_and_undeclared_are_warned(caplog: pytest.LogCaptureFixture) -> None:
    values = {"joints": ["a"], "interface_name": "position"}
    listener = ParamListener(ParameterSchema(SCHEMA), values, "c")
    values["gain"] = 3.0
    values["typo"] = 1
    with caplog.at_level(logging.WARNING):
        assert listener.refresh().gain == 3.0
    assert listener.undeclared == ["typo"] and "typo" in caplog.text


def test_custom_validator() -> None:
    register_validator("even", lambda value: None if value % 2 == 0 else f"must be even, got {value}")
    schema = ParameterSchema({"ns": {"n": {"type": "int", "default_value": 2, "validation": {"even": []}}}})
    assert ParamListener(schema, {}, "c").get_params().n == 2
    with pytest.raises(ParameterError, match="must be even"):
        ParamListener(schema, {"n": 3}, "c")


def test_bad_schema_is_rejected() -> None:
    with pytest.raises(ParameterError, match="unknown type"):
        ParameterSchema({"ns": {"x": {"type": "complex"}}})
    with pytest.raises(ParameterError, match="needs a 'type'"):
        ParameterSchema({"ns": {"x": 3}})


def test_flatten_nested_values() -> None:
    assert flatten({"gains": {"j1": {"p": 1}}, "a": 2}) == {"gains.j1.p": 1, "a": 2}
