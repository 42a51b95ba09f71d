"""Joint limits from parameters: ``joint_limits.<joint>.*`` read as Jazzy's ``joint_limits_rosparam.hpp`` reads them,
over the URDF's limits; ``joint_limits.yaml`` in ROS 1 and ROS 2 layouts; the controller manager's ``joint_limits``
section in command limiting (``enforce_command_limits: true``), end to end on the RRBot mock.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.joint_limits import (
    HARD_LIMIT_PARAMETERS,
    SOFT_LIMIT_PARAMETERS,
    JointLimits,
    SoftJointLimits,
    declare_parameters,
    get_joint_limits,
    get_soft_joint_limits,
    joint_limits_parameters,
    load_joint_limits_yaml,
)
from rrbot_workshop.msgs import Float64MultiArray

#: What the URDF of a revolute joint gives: position, velocity and effort limits.
URDF = JointLimits(has_position_limits=True, min_position=-1.0, max_position=2.0, has_velocity_limits=True,
                   max_velocity=3.0, has_effort_limits=True, max_effort=100.0)
URDF_SOFT = SoftJointLimits(min_position=-0.9, max_position=1.9, k_position=20.0, k_velocity=2.0)


def _nested(joint: str = "j1", **values: Any) -> dict[str, Any]:
    return {"joint_limits": {joint: values}}


# ----------------------------------------------------------------------------------------------- hard limits
def test_no_parameters_for_the_joint_keep_the_urdf_limits_as_a_copy() -> None:
    for params in ({}, {"update_rate": 100}, _nested("other", has_velocity_limits=True, max_velocity=0.1)):
        got = get_joint_limits("j1", params, URDF)
        assert got == URDF and got is not URDF
    assert get_joint_limits("j1", {}) == JointLimits()


def test_parameters_override_the_urdf_values_and_may_widen_them() -> None:
    params = _nested(has_velocity_limits=True, max_velocity=0.5, has_effort_limits=True, max_effort=250.0,
                     has_position_limits=True, min_position=-0.5, max_position=0.5)
    got = get_joint_limits("j1", params, URDF)
    assert (got.max_velocity, got.max_effort, got.min_position, got.max_position) == (0.5, 250.0, -0.5, 0.5)
    assert URDF.max_velocity == 3.0  # the given limits are not modified


def test_keys_not_given_keep_the_urdf_values() -> None:
    got = get_joint_limits("j1", _nested(has_velocity_limits=True, max_velocity=0.5), URDF)
    assert got.has_position_limits and (got.min_position, got.max_position) == (-1.0, 2.0)
    assert got.has_effort_limits and got.max_effort == 100.0


def test_a_false_flag_removes_the_urdf_limit() -> None:
    got = get_joint_limits("j1", _nested(has_velocity_limits=False, has_effort_limits=False), URDF)
    assert not got.has_velocity_limits and not got.has_effort_limits
    assert got.has_position_limits


def test_a_true_flag_without_its_value_removes_the_limit_as_in_jazzy() -> None:
    got = get_joint_limits("j1", _nested(has_velocity_limits=True, has_position_limits=True, min_position=0.0), URDF)
    assert not got.has_velocity_limits
    assert not got.has_position_limits  # position limits need both min_position and max_position


def test_a_value_without_its_flag_is_ignored_with_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="rrbot_workshop.joint_limits"):
        got = get_joint_limits("j1", _nested(max_velocity=0.5, max_position=0.2), URDF)
    assert got == URDF
    assert "has_velocity_limits is not" in caplog.text and "has_position_limits is not" in caplog.text


def test_acceleration_deceleration_and_jerk_limits_come_from_parameters_only() -> None:
    got = get_joint_limits("j1", _nested(has_acceleration_limits=True, max_acceleration=5.0,
                                         has_deceleration_limits=True, max_deceleration=7.5,
                                         has_jerk_limits=True, max_jerk=100.0), URDF)
    assert (got.max_acceleration, got.max_deceleration, got.max_jerk) == (5.0, 7.5, 100.0)
    assert got.has_acceleration_limits and got.has_deceleration_limits and got.has_jerk_limits


def test_angle_wraparound_is_read_only_without_position_limits() -> None:
    assert get_joint_limits("j1", _nested(has_position_limits=False, angle_wraparound=True), URDF).angle_wraparound
    assert not get_joint_limits("j1", _nested(angle_wraparound=True), URDF).angle_wraparound
    assert not get_joint_limits("j1", _nested(has_position_limits=True, min_position=0.0, max_position=1.0,
                                              angle_wraparound=True), URDF).angle_wraparound


def test_integers_are_numbers_as_in_a_ros1_file() -> None:
    got = get_joint_limits("j1", _nested(has_effort_limits=True, max_effort=255), URDF)
    assert got.max_effort == 255.0 and isinstance(got.max_effort, float)


@pytest.mark.parametrize("params", [
    {"joint_limits": {"j1": {"has_velocity_limits": True, "max_velocity": 0.5}}},
    {"joint_limits.j1.has_velocity_limits": True, "joint_limits.j1.max_velocity": 0.5},
    {"joint_limits": {"j1.has_velocity_limits": True}, "joint_limits.j1": {"max_velocity": 0.5}},
], ids=["nested", "dotted", "mixed"])
def test_nested_dotted_and_mixed_spellings_read_the_same(params: dict[str, Any]) -> None:
    got = get_joint_limits("j1", params, URDF)
    assert got.has_velocity_limits and got.max_velocity == 0.5


def test_dotted_joint_names_are_kept_whole() -> None:
    params = {"joint_limits": {"arm.joint_1": {"has_velocity_limits": True, "max_velocity": 0.5}}}
    assert get_joint_limits("arm.joint_1", params, URDF).max_velocity == 0.5


def test_declare_parameters_gives_jazzys_defaults() -> None:
    declared = declare_parameters("j1")
    assert set(declared) == {f"joint_limits.j1.{k}" for k in {**HARD_LIMIT_PARAMETERS, **SOFT_LIMIT_PARAMETERS}}
    assert declared["joint_limits.j1.has_velocity_limits"] is False
    assert math.isnan(declared["joint_limits.j1.max_velocity"])


# ----------------------------------------------------------------------------------------------- errors
@pytest.mark.parametrize(("values", "key", "words"), [
    ({"max_velocity": "fast", "has_velocity_limits": True}, "max_velocity", "must be a number in [rad/s]"),
    ({"has_velocity_limits": 1, "max_velocity": 1.0}, "has_velocity_limits", "must be true or false, got 1"),
    ({"has_effort_limits": True, "max_effort": True}, "max_effort", "must be a number"),
    ({"has_soft_limits": "yes"}, "has_soft_limits", "must be true or false"),
    ({"has_position_limits": True, "min_position": [0.0], "max_position": 1.0}, "min_position", "must be a number"),
])
def test_a_wrong_type_names_the_joint_and_the_key(values: dict[str, Any], key: str, words: str) -> None:
    with pytest.raises(ParameterError, match=r"joint 'j1'") as err:
        get_joint_limits("j1", {"joint_limits": {"j1": values}}, URDF, source="my_node")
    assert err.value.parameter == f"joint_limits.j1.{key}" and err.value.owner == "my_node"
    assert words in str(err.value)


def test_an_unknown_key_names_the_joint_and_lists_the_valid_keys() -> None:
    with pytest.raises(ParameterError) as err:
        get_joint_limits("j1", _nested(has_velocity_limits=True, max_vel=1.0), URDF)
    message = str(err.value)
    assert err.value.parameter == "joint_limits.j1.max_vel"
    assert "joint 'j1'" in message and "did you mean 'max_velocity'" in message
    assert all(key in message for key in ("has_position_limits", "max_jerk", "soft_upper_limit"))


def test_an_unknown_key_of_another_joint_is_found_too() -> None:
    with pytest.raises(ParameterError, match="joint 'j2': 'min_velocity' is not a joint limits parameter"):
        get_joint_limits("j1", {"joint_limits": {"j1": {}, "j2": {"min_velocity": -1.0}}}, URDF)


@pytest.mark.parametrize(("params", "parameter", "words"), [
    ({"joint_limits": [1, 2]}, "joint_limits", "must be a mapping of joint names"),
    ({"joint_limits": {"j1": 5.0}}, "joint_limits.j1", "must be a mapping of limit parameters"),
    (_nested(has_position_limits=True, min_position=1.0, max_position=1.0), "joint_limits.j1.min_position",
     "must be below max_position"),
    (_nested(has_velocity_limits=True, max_velocity=-1.0), "joint_limits.j1.max_velocity", "must be 0 or more"),
    (_nested(has_soft_limits=True, soft_lower_limit=0.5, soft_upper_limit=0.1, k_position=1.0, k_velocity=1.0),
     "joint_limits.j1.soft_lower_limit", "must not be above soft_upper_limit"),
])
def test_malformed_sections_are_refused(params: dict[str, Any], parameter: str, words: str) -> None:
    with pytest.raises(ParameterError, match=words) as err:
        joint_limits_parameters(params)
    assert err.value.parameter == parameter


# ----------------------------------------------------------------------------------------------- soft limits
SOFT = {"has_soft_limits": True, "k_position": 10.0, "k_velocity": 5.0, "soft_lower_limit": -0.5,
        "soft_upper_limit": 0.5}


def test_complete_soft_limits_replace_the_urdf_ones() -> None:
    got = get_soft_joint_limits("j1", {"joint_limits": {"j1": SOFT}}, URDF_SOFT)
    assert got == SoftJointLimits(min_position=-0.5, max_position=0.5, k_position=10.0, k_velocity=5.0)
    assert get_soft_joint_limits("j1", {"joint_limits": {"j1": SOFT}}) == got


def test_without_soft_parameters_the_urdf_soft_limits_stay() -> None:
    assert get_soft_joint_limits("j1", _nested(has_velocity_limits=True, max_velocity=1.0), URDF_SOFT) == URDF_SOFT
    assert get_soft_joint_limits("j1", {}) is None


@pytest.mark.parametrize("drop", ["has_soft_limits", "k_position", "k_velocity", "soft_lower_limit", "soft_upper_limit"])
def test_incomplete_soft_limits_are_ignored_with_a_warning(drop: str, caplog: pytest.LogCaptureFixture) -> None:
    values = {k: v for k, v in SOFT.items() if k != drop}
    with caplog.at_level(logging.WARNING, logger="rrbot_workshop.joint_limits"):
        assert get_soft_joint_limits("j1", {"joint_limits": {"j1": values}}, URDF_SOFT) == URDF_SOFT
        assert get_soft_joint_limits("j1", {"joint_limits": {"j1": values}}) is None
    assert f"missing or false: {drop}" in caplog.text


def test_has_soft_limits_false_keeps_the_urdf_soft_limits_as_in_jazzy() -> None:
    assert get_soft_joint_limits("j1", {"joint_limits": {"j1": {**SOFT, "has_soft_limits": False}}},
                                 URDF_SOFT) == URDF_SOFT


# ----------------------------------------------------------------------------------------------- joint_limits.yaml
_ROS1 = """\
joint_limits:
  JointA:
    has_position_limits: false
    has_velocity_limits: true
    max_velocity: 2
    has_acceleration_limits: false
    max_acceleration: 0.0
    has_jerk_limits: false
    max_jerk: 0
    has_effort_limits: true
    max_effort: 255
  JointC:
    has_position_limits: true
    min_position: -1.57
    max_position: 1.57
    has_velocity_limits: true
    max_velocity: 1.0
    has_soft_limits: true
    k_position: 10.0
    k_velocity: 5.0
    soft_lower_limit: -1.4
    soft_upper_limit: 1.4
"""


def test_a_ros1_joint_limits_yaml_is_read(tmp_path: Path) -> None:
    path = tmp_path / "joint_limits.yaml"
    path.write_text(_ROS1)
    params = load_joint_limits_yaml(path)
    assert set(params) == {"joint_limits"} and set(params["joint_limits"]) == {"JointA", "JointC"}
    a = get_joint_limits("JointA", params)
    assert (a.has_velocity_limits, a.max_velocity, a.has_effort_limits, a.max_effort) == (True, 2.0, True, 255.0)
    assert not a.has_position_limits and not a.has_jerk_limits
    soft = get_soft_joint_limits("JointC", params)
    assert soft == SoftJointLimits(min_position=-1.4, max_position=1.4, k_position=10.0, k_velocity=5.0)


def test_a_ros2_parameter_file_is_read_and_a_node_chosen(tmp_path: Path) -> None:
    path = tmp_path / "limits.yaml"
    path.write_text(yaml.safe_dump({
        "controller_manager": {"ros__parameters": {"update_rate": 100,
                                                   "joint_limits": {"j1": {"has_velocity_limits": True,
                                                                           "max_velocity": 0.5}}}},
        "/my_controller": {"ros__parameters": {"joint_limits.j1.has_velocity_limits": True,
                                               "joint_limits.j1.max_velocity": 0.25}},
    }))
    with pytest.raises(ParameterError, match="several nodes have different joint_limits sections") as err:
        load_joint_limits_yaml(path)
    assert str(path) in str(err.value)
    assert load_joint_limits_yaml(path, node="controller_manager") == {
        "joint_limits": {"j1": {"has_velocity_limits": True, "max_velocity": 0.5}}}
    assert load_joint_limits_yaml(path, node="my_controller")["joint_limits"]["j1"]["max_velocity"] == 0.25
    with pytest.raises(ParameterError, match=r"no node 'other' .*\(nodes with one: /my_controller, controller_manager\)"):
        load_joint_limits_yaml(path, node="other")


@pytest.mark.parametrize(("text", "words"), [
    (None, "cannot read the joint limits file"),
    ("joint_limits: [\n", r"is not valid YAML \(line"),
    ("- 1\n- 2\n", "must be a mapping with a 'joint_limits:' section"),
    ("controller_manager:\n  ros__parameters:\n    update_rate: 100\n", "no 'joint_limits:' section"),
    ("joint_limits:\n  j1:\n    max_speed: 1.0\n", "'max_speed' is not a joint limits parameter"),
])
def test_file_errors_name_the_file(tmp_path: Path, text: str | None, words: str) -> None:
    path = tmp_path / "joint_limits.yaml"
    if text is not None:
        path.write_text(text)
    with pytest.raises(ParameterError, match=words) as err:
        load_joint_limits_yaml(path)
    assert str(path) in str(err.value)


# ----------------------------------------------------------------------------------------------- RRBot end to end
def _config(manager_extra: dict[str, Any]) -> dict[str, Any]:
    config = yaml.safe_load((rw.description.descriptions_root() / "rrbot/config/rrbot_controllers.yaml").read_text())
    config["controller_manager"]["ros__parameters"].update(manager_extra)
    return config


def _move_joint1(config: dict[str, Any], target: float, seconds: float) -> tuple[float, float]:
    """joint1 after the first cycle that wrote the command, and after ``seconds`` more."""
    with rw.bringup("rrbot", config, xacro_args={"use_mock_hardware": True},
                    spawn=["joint_state_broadcaster", "forward_position_controller"]) as system:
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[target, 0.0]))
        system.spin(0.02)
        early = system.latest("/joint_states").position[0]
        system.spin(seconds)
        return early, system.latest("/joint_states").position[0]


def test_rrbot_position_command_is_rate_limited_by_the_parameter_not_the_urdf() -> None:
    """The URDF allows 180 degrees/s; ``joint_limits.joint1.max_velocity: 0.5`` [rad/s] is what the joint gets."""
    config = _config({"enforce_command_limits": True,
                      "joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": 0.5}}})
    early, later = _move_joint1(config, 1.0, 1.0)
    assert early == pytest.approx(0.5 * 0.01, rel=1e-9)  # one 10 ms cycle at 0.5 rad/s (the URDF: pi * 0.01)
    assert later == pytest.approx(0.5 * 0.01 * 101, rel=1e-6)  # 101 cycles in all, still on its way to 1.0


def test_rrbot_joint_limits_yaml_merged_into_the_manager_parameters(tmp_path: Path) -> None:
    path = tmp_path / "joint_limits.yaml"
    path.write_text("joint_limits:\n  joint1:\n    has_velocity_limits: true\n    max_velocity: 0.25\n")
    config = _config({"enforce_command_limits": True, **load_joint_limits_yaml(path)})
    early, _ = _move_joint1(config, 1.0, 0.0)
    assert early == pytest.approx(0.25 * 0.01, rel=1e-9)


def test_rrbot_soft_limits_from_parameters_slow_the_joint_down() -> None:
    """Each cycle joint1 may go ``k_position * (soft_upper_limit - p) * dt`` further: 10 % of the way left."""
    config = _config({"enforce_command_limits": True, "joint_limits": {"joint1": {
        "has_soft_limits": True, "k_position": 10.0, "k_velocity": 1.0, "soft_lower_limit": -0.5,
        "soft_upper_limit": 0.5}}})
    with rw.bringup("rrbot", config, xacro_args={"use_mock_hardware": True},
                    spawn=["joint_state_broadcaster", "forward_position_controller"]) as system:
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[1.0, 0.0]))
        positions = []
        for _ in range(120):
            system.spin(0.01)
            positions.append(system.latest("/joint_states").position[0])
    steps = [b - a for a, b in zip(positions, positions[1:], strict=False) if b != a]
    assert max(positions) <= 0.5  # never past the soft limit
    assert positions[-1] == pytest.approx(0.5, abs=1e-4)
    assert max(steps) <= math.pi * 0.01 + 1e-12  # and never faster than the URDF's 180 degrees/s
    # close to the soft limit the steps shrink geometrically: p' = p + 0.1 (0.5 - p)
    late = [p for p in positions if p > 0.3][:3]
    assert late[1] == pytest.approx(late[0] + 0.1 * (0.5 - late[0]), rel=1e-9)
    assert late[2] == pytest.approx(late[1] + 0.1 * (0.5 - late[1]), rel=1e-9)


def test_rrbot_manager_limits_reported_by_the_resource_manager() -> None:
    config = _config({"enforce_command_limits": True,
                      "joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": 0.5}}})
    with rw.bringup("rrbot", config, xacro_args={"use_mock_hardware": True}) as system:
        hard = system.resource_manager.get_hard_joint_limits()
    assert hard["joint1"].max_velocity == 0.5 and hard["joint2"].max_velocity == pytest.approx(math.pi)


def test_rrbot_wrong_joint_limits_parameter_fails_the_bringup_with_its_name() -> None:
    config = _config({"enforce_command_limits": True,
                      "joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": "slow"}}})
    with pytest.raises(ParameterError, match="joint 'joint1': 'max_velocity' must be a number") as err:
        rw.bringup("rrbot", config, xacro_args={"use_mock_hardware": True})
    assert err.value.owner == "controller_manager"


def test_rrbot_joint_limits_without_enforcement_change_nothing(caplog: pytest.LogCaptureFixture) -> None:
    config = _config({"joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": 0.5}}})
    with caplog.at_level(logging.INFO):
        early, _ = _move_joint1(config, 1.0, 0.0)
    assert early == 1.0
    assert "joint_limits parameters are not applied: enforce_command_limits is false" in caplog.text


# ----------------------------------------------------------------------------------------------- lint
_LINT_YAML = """\
controller_manager:
  ros__parameters:
    update_rate: 100
    enforce_command_limits: true
    joint_limits:
      joint1:
        has_velocity_limits: true
        max_velocity: 0.5
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
"""


def test_lint_notes_the_managers_joint_limits_and_finds_their_mistakes(tmp_path: Path) -> None:
    from rrbot_workshop.tools.lint import lint_controllers

    path = tmp_path / "controllers.yaml"
    path.write_text(_LINT_YAML)
    findings = lint_controllers(path)
    assert [f.level for f in findings] == ["note"]
    assert "Jazzy's controller manager does not apply 'joint_limits'" in findings[0].message
    path.write_text(_LINT_YAML.replace("max_velocity: 0.5", "max_vel: 0.5"))
    errors = [f for f in lint_controllers(path) if f.level == "error"]
    assert len(errors) == 1 and "'max_vel' is not a joint limits parameter (did you mean 'max_velocity'?)" in (
        errors[0].message)
    assert errors[0].line == 8


def test_rrbot_joint_beyond_a_parameter_position_limit_is_logged_once_and_left_alone(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """joint1 starts at 0 rad, below ``min_position: 0.2``: Jazzy's limiter throws; here the error is logged once and
    the command passes as it is, until the joint is back within its limits and limiting resumes."""
    config = _config({"enforce_command_limits": True, "joint_limits": {"joint1": {
        "has_position_limits": True, "min_position": 0.2, "max_position": 0.5}}})
    with caplog.at_level(logging.ERROR), rw.bringup(
            "rrbot", config, xacro_args={"use_mock_hardware": True},
            spawn=["joint_state_broadcaster", "forward_position_controller"]) as system:
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.3, 0.0]))
        system.spin(0.05)
        first = system.latest("/joint_states").position[0]
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.9, 0.0]))
        system.spin(0.02)
        step = system.latest("/joint_states").position[0]
        system.spin(0.2)
        second = system.latest("/joint_states").position[0]
    assert first == pytest.approx(0.3)  # not limited while the joint was out of its limits
    assert step == pytest.approx(0.3 + math.pi * 0.01, rel=1e-9)  # limited again once inside: from 0.3 at pi rad/s
    assert second == pytest.approx(0.5)  # up to max_position
    errors = [r.getMessage() for r in caplog.records if "its position 0 is out of its limits [0.2, 0.5]" in r.getMessage()]
    assert len(errors) == 1 and "joint 'joint1'" in errors[0]


def test_rrbot_joint_limits_for_a_joint_no_component_has_are_warned_about(caplog: pytest.LogCaptureFixture) -> None:
    config = _config({"enforce_command_limits": True,
                      "joint_limits": {"elbow": {"has_velocity_limits": True, "max_velocity": 0.5}}})
    with caplog.at_level(logging.WARNING), rw.bringup("rrbot", config, xacro_args={"use_mock_hardware": True}):
        pass
    assert "name joints that no hardware component has: elbow (joints: joint1, joint2)" in caplog.text


def test_rrbot_joint_limits_under_slash_star_star_reach_the_manager_and_its_own_win() -> None:
    config = _config({"enforce_command_limits": True,
                      "joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": 0.5}}})
    config["/**"] = {"ros__parameters": {"joint_limits": {
        "joint1": {"has_velocity_limits": True, "max_velocity": 0.1},
        "joint2": {"has_velocity_limits": True, "max_velocity": 0.2}}}}
    with rw.bringup("rrbot", config, xacro_args={"use_mock_hardware": True}) as system:
        hard = system.resource_manager.get_hard_joint_limits()
    assert (hard["joint1"].max_velocity, hard["joint2"].max_velocity) == (0.5, 0.2)
