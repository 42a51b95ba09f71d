"""The ``<ros2_control>`` parser against ros2_control's own parser test cases (shared/conformance).

Each case of ``component_parser_cases.json`` says whether the real parser accepts or rejects its input.
A rejection must be a DescriptionError. The cases live outside the repository and are never copied into it;
without the folder these tests are skipped. The tally is printed at the end of the run (tests/conftest.py).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import pytest
from upstream import shared_folder

from rrbot_workshop.description import HardwareInfo, parse_ros2_control
from rrbot_workshop.exceptions import DescriptionError

REPO_ROOT = Path(__file__).resolve().parents[2]
CASES_DIR = (shared_folder() or REPO_ROOT.parent / "shared") / "conformance" / "ros2_control_parser"
CASES_FILE = CASES_DIR / "component_parser_cases.json"
SUITE = "ros2_control parser"

#: Cases where this course differs from ros2_control on purpose: case -> text the error must contain.
KNOWN_DIFFERENCES = {"successfully_parse_valid_sdf": "SDF is not supported"}

DOUBLE_MAX = sys.float_info.max


def _load_cases() -> list[Any]:
    if not CASES_FILE.is_file():
        return [pytest.param(None, marks=pytest.mark.skip(reason=f"conformance cases not found at {CASES_FILE}"),
                             id="no-conformance-data")]
    cases = json.loads(CASES_FILE.read_text())
    return [pytest.param(case, id=case["test"]) for case in cases]


def _inputs(test: str) -> list[Path]:
    """The input files of one case: ``<test>.*`` or ``<test>_0.*``, ``<test>_1.*`` in composed/ or inline/."""
    found: list[Path] = []
    for folder in ("composed", "inline"):
        base = CASES_DIR / folder
        found += [p for p in base.glob(f"{test}.*")]
        found += [p for p in base.glob(f"{test}_*.*") if p.stem[len(test) + 1:].isdigit()]
    return sorted(found)


def _parse(test: str) -> list[HardwareInfo]:
    (path,) = _inputs(test)
    return parse_ros2_control(path.read_text(), source=path.name)


@pytest.mark.parametrize("case", _load_cases())
def test_case_gives_the_same_verdict_as_ros2_control(case: dict[str, Any], conformance_tally: Any) -> None:
    """Accepted inputs parse; rejected inputs raise DescriptionError (never a bare KeyError/ValueError)."""
    test, expected = case["test"], case["expect"]
    paths = _inputs(test)
    assert paths, f"no input file for case '{test}' in {CASES_DIR}"
    verdicts: list[str] = []
    errors: list[DescriptionError] = []
    for path in paths:
        try:
            parse_ros2_control(path.read_text(), source=path.name)
            verdicts.append("accept")
        except DescriptionError as err:
            verdicts.append("reject")
            errors.append(err)
    got = verdicts[0] if len(set(verdicts)) == 1 else "mixed"
    note = KNOWN_DIFFERENCES.get(test, "")
    conformance_tally(SUITE, test, expected=expected, got=got, note=f"by design ({note})" if note else "")
    if test in KNOWN_DIFFERENCES:
        assert got == "reject" and all(note in str(e) for e in errors), f"{test}: expected '{note}' errors"
        return
    assert got == expected, f"{test}: ros2_control {expected}s it, we {got}: {[str(e) for e in errors]}"
    for error in errors:
        assert str(error).strip(), f"{test}: empty error message"


needs_cases = pytest.mark.skipif(not CASES_FILE.is_file(), reason=f"conformance cases not found at {CASES_FILE}")


@needs_cases
def test_system_one_interface_limits_match_the_reference_table() -> None:
    """URDF limits tightened by the command interfaces, and joint2's soft limits (reference A1 table)."""
    (info,) = _parse("successfully_parse_valid_urdf_system_one_interface")
    assert info.name == "RRBotSystemPositionOnly" and info.type == "system" and info.group == ""
    assert info.hardware_plugin_name == "ros2_control_demo_hardware/RRBotSystemPositionOnlyHardware"
    assert info.hardware_parameters["example_param_write_for_sec"] == "2"
    assert [j.name for j in info.joints] == ["joint1", "joint2"]
    assert info.joints[0].command_interfaces[0].min == "-1" and info.joints[0].command_interfaces[0].max == "1"
    assert set(info.limits) == {"joint1", "joint2"} and set(info.soft_limits) == {"joint2"}
    for joint in ("joint1", "joint2"):
        limits = info.limits[joint]
        assert limits.has_position_limits and limits.has_velocity_limits and limits.has_effort_limits
        assert (limits.min_position, limits.max_position) == pytest.approx((-1.0, 1.0))
        assert limits.max_velocity == pytest.approx(0.2) and limits.max_effort == pytest.approx(0.1)
    soft = info.soft_limits["joint2"]
    assert (soft.min_position, soft.max_position, soft.k_position, soft.k_velocity) == pytest.approx(
        (-1.0, 0.5, 10.0, 20.0)
    )


@needs_cases
def test_custom_interface_parameters_keep_min_max_initial_value_in_parameters() -> None:
    """min, max and initial_value are fields and also entries of ``parameters`` (5 in all)."""
    (info,) = _parse("successfully_parse_valid_urdf_system_multi_interface_custom_interface_parameters")
    joint = info.joints[0]
    assert joint.parameters == {
        "modbus_server_ip": "1.1.1.1", "modbus_server_port": "1234", "use_persistent_connection": "true",
    }
    position = joint.command_interfaces[0]
    assert (position.name, position.initial_value, position.min, position.max) == ("position", "1.2", "-1", "1")
    assert len(position.parameters) == 5
    assert position.parameters["register"] == "1" and position.parameters["register_size"] == "2"


@needs_cases
def test_sensor_interfaces_and_parameters_are_read() -> None:
    """The TCP force-torque sensor has six state interfaces and three parameters."""
    (info,) = _parse("successfully_parse_valid_urdf_system_robot_with_sensor")
    sensor = info.sensors[0]
    assert (sensor.name, sensor.type) == ("tcp_fts_sensor", "sensor")
    assert [i.name for i in sensor.state_interfaces] == ["fx", "fy", "fz", "tx", "ty", "tz"]
    assert sensor.command_interfaces == []
    assert sensor.parameters == {"frame_id": "kuka_tcp", "lower_limits": "-100", "upper_limits": "100"}


@needs_cases
def test_gpio_size_and_data_type_attributes() -> None:
    """``size`` and ``data_type`` are attributes with defaults 1 and double; unknown types still parse."""
    (info,) = _parse("successfully_parse_valid_urdf_system_with_size_and_data_type")
    gpio = info.gpios[0]
    assert [(i.name, i.data_type, i.size) for i in gpio.command_interfaces] == [("digital_output", "bool", 2)]
    assert [(i.name, i.data_type, i.size) for i in gpio.state_interfaces] == [
        ("analog_input", "double", 3), ("image", "cv::Mat", 1),
    ]


@needs_cases
def test_disabled_interface_limits_follow_the_reference() -> None:
    """``<limits enable="false"/>`` per joint and per interface; acceleration mirrors deceleration."""
    (info,) = _parse("successfully_parse_valid_urdf_system_and_disabled_interfaces")
    j1, j2, j3 = (info.limits[n] for n in ("joint1", "joint2", "joint3"))
    assert not j1.has_position_limits
    assert (j1.min_position, j1.max_position) == (-DOUBLE_MAX, DOUBLE_MAX)
    assert j1.has_velocity_limits and j1.max_velocity == pytest.approx(0.05)
    assert j1.has_acceleration_limits and j1.has_deceleration_limits and j1.has_jerk_limits
    assert (j1.max_acceleration, j1.max_deceleration, j1.max_jerk) == pytest.approx((0.5, 0.5, 5.0))
    assert not any((j2.has_position_limits, j2.has_velocity_limits, j2.has_effort_limits,
                    j2.has_acceleration_limits, j2.has_deceleration_limits, j2.has_jerk_limits))
    assert (j2.max_velocity, j2.max_effort) == pytest.approx((0.2, 0.1))
    assert (info.soft_limits["joint2"].min_position, info.soft_limits["joint2"].max_position) == pytest.approx(
        (-1.5, 0.5)
    )
    assert j3.has_position_limits and (j3.min_position, j3.max_position) == pytest.approx((-math.pi, math.pi))
    assert j3.has_acceleration_limits and not j3.has_deceleration_limits and not j3.has_jerk_limits
    assert (j3.max_acceleration, j3.max_deceleration) == pytest.approx((1.0, 1.0))


@needs_cases
def test_continuous_joint_without_urdf_limits_takes_interface_limits() -> None:
    """No URDF ``<limit>``: only the command interfaces' min/max apply."""
    (info,) = _parse("successfully_parse_urdf_system_continuous_missing_limits")
    j1, j2 = info.limits["joint1"], info.limits["joint2"]
    assert j1.has_position_limits and (j1.min_position, j1.max_position) == pytest.approx((-1.0, 1.0))
    assert (j1.max_velocity, j1.max_effort, j1.max_acceleration, j1.max_deceleration, j1.max_jerk) == pytest.approx(
        (0.05, 0.2, 0.5, 0.5, 5.0)
    )
    assert not any((j2.has_position_limits, j2.has_velocity_limits, j2.has_effort_limits,
                    j2.has_acceleration_limits, j2.has_deceleration_limits, j2.has_jerk_limits))


@needs_cases
def test_continuous_joint_with_urdf_limits_wraps_around() -> None:
    """A continuous joint with ``<limit>`` gets angle_wraparound and URDF velocity/effort limits."""
    (info,) = _parse("successfully_parse_urdf_system_continuous_with_limits")
    j1, j2 = info.limits["joint1"], info.limits["joint2"]
    assert j1.angle_wraparound and j2.angle_wraparound
    assert (j1.max_velocity, j1.max_effort) == pytest.approx((0.05, 0.1))
    assert not j2.has_position_limits and (j2.max_velocity, j2.max_effort) == pytest.approx((0.2, 0.1))


@needs_cases
def test_gripper_mimic_joint_is_recorded() -> None:
    """URDF ``<mimic>`` on a joint without command interfaces gives a MimicJoint (multiplier 2, offset 1)."""
    (info,) = _parse("gripper_mimic_true_valid_config")
    (mimic,) = info.mimic_joints
    assert (mimic.joint_index, mimic.mimicked_joint_index, mimic.multiplier, mimic.offset) == (1, 0, 2.0, 1.0)
    (no_mimic,) = _parse("gripper_mimic_false_valid_config")
    assert no_mimic.mimic_joints == []


@needs_cases
def test_rw_rate_and_async_attributes() -> None:
    """``rw_rate`` per component; ``is_async`` with thread priority and ``<properties><async>``."""
    assert [i.rw_rate for i in _parse("valid_rw_rate")] == [50, 20, 25]
    actuator, sensor, system = _parse("successfully_parse_valid_urdf_async_components")
    assert actuator.is_async and actuator.thread_priority == 30
    assert actuator.async_params["scheduling_policy"] == "detached"
    assert actuator.async_params["print_warnings"] == "false"
    assert sensor.is_async and sensor.thread_priority == 50 and sensor.async_params == {}
    assert system.async_params["scheduling_policy"] == "synchronized"


@needs_cases
def test_empty_hardware_parameter_is_kept_as_empty_string() -> None:
    """A ``<param>`` with no text is allowed and reads as ``""``."""
    (info,) = _parse("successfully_parse_parameter_empty")
    assert info.hardware_parameters == {"example_param_write_for_sec": "", "example_param_read_for_sec": "2"}
    assert info.limits["joint1"].max_position == pytest.approx(math.pi)
