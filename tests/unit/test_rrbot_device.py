"""The simulated RRBot device keeps the contract of the workshop's comms library, on simulated time, seeded."""

from __future__ import annotations

import math

import pytest

from rrbot_workshop.hardware.rrbot_device import INITIAL_POSITION, MAX_VELOCITY, SENSOR_MAX, ControlMode, RRBotDevice


def test_a_new_device_is_at_0_1_at_rest_in_position_mode_and_disabled() -> None:
    device = RRBotDevice(2)
    assert device.read_joint_states() == ([INITIAL_POSITION] * 2, [0.0, 0.0], [0.0, 0.0])
    assert device.get_control_mode() is ControlMode.POSITION and not device.movement_enabled
    assert device.read_gpio()[1] == [False, False]


def test_nothing_moves_before_init_or_after_stop() -> None:
    device = RRBotDevice(2)
    device.write_joint_commands([1.0, 1.0], [0.0, 0.0], 0.01)
    assert device.read_joint_states()[0] == [0.1, 0.1]
    device.init()
    device.write_joint_commands([1.0, 1.0], [0.0, 0.0], 0.01)
    moved = device.read_joint_states()[0]
    device.stop()
    device.write_joint_commands([1.0, 1.0], [0.0, 0.0], 0.01)
    assert device.read_joint_states()[0] == moved and moved != [0.1, 0.1]


def test_position_mode_heads_for_the_target_at_most_at_0_5_rad_per_s() -> None:
    device = RRBotDevice(1)
    device.init()
    positions = []
    for _ in range(300):
        device.write_joint_commands([1.0], [0.0], 0.01)
        positions.append(device.read_joint_states()[0][0])
    steps = [b - a for a, b in zip([0.1, *positions], positions, strict=False)]
    assert max(steps) == pytest.approx(MAX_VELOCITY * 0.01)
    assert positions[-1] == pytest.approx(1.0) and positions[179] == pytest.approx(1.0)  # 0.9 rad at 0.5 rad/s: 180 cycles of 10 ms
    assert positions[100] == pytest.approx(0.1 + 101 * 0.005)


@pytest.mark.parametrize(("command", "expected"), [(0.2, 0.2), (-0.2, -0.2), (0.9, 0.5), (-3.0, -0.5), (0.0, 0.0)])
def test_velocity_mode_clamps_to_plus_minus_0_5(command: float, expected: float) -> None:
    """The original clamped every command below +0.5 (0.2 included) to -0.5; the device here clamps to [-0.5, 0.5]."""
    device = RRBotDevice(1)
    device.init()
    assert device.set_control_mode(ControlMode.VELOCITY) is True
    device.write_joint_commands([math.nan], [command], 0.1)
    positions, velocities, accelerations = device.read_joint_states()
    assert velocities == [pytest.approx(expected)]
    assert positions == [pytest.approx(0.1 + expected * 0.1)]
    assert accelerations == [pytest.approx(expected / 0.1)]


def test_a_nan_command_holds_the_joint() -> None:
    device = RRBotDevice(2)
    device.init()
    device.write_joint_commands([math.nan, 0.3], [0.0, 0.0], 0.1)
    assert device.read_joint_states()[0] == [pytest.approx(0.1), pytest.approx(0.15)]


def test_motion_depends_on_the_time_passed_in_not_on_the_wall_clock() -> None:
    runs = []
    for _ in range(2):
        device = RRBotDevice(2)
        device.init()
        for k in range(50):
            device.write_joint_commands([0.5, -0.5], [0.0, 0.0], 0.01 if k % 2 else 0.02)
        runs.append(device.read_joint_states())
    assert runs[0] == runs[1]


def test_outputs_read_back_and_inputs_are_bits() -> None:
    device = RRBotDevice(2)
    device.write_gpios([True, False])
    inputs, outputs = device.read_gpio()
    assert outputs == [True, False] and len(inputs) == 2 and all(isinstance(b, bool) for b in inputs)
    with pytest.raises(ValueError, match="3 outputs for a device with 2"):
        device.write_gpios([True, True, True])


def test_sensor_values_are_within_range_seeded_and_constant_within_a_second() -> None:
    a, b, c = RRBotDevice(2, seed=7), RRBotDevice(2, seed=7), RRBotDevice(2, seed=8)
    first = a.read_sensor_values(6)
    assert all(0.0 <= v <= SENSOR_MAX for v in first) and len(set(first)) == 6
    assert first == b.read_sensor_values(6) and first != c.read_sensor_values(6)
    a.write_joint_commands([0.1, 0.1], [0.0, 0.0], 0.5)
    assert a.read_sensor_values(6) == first
    a.write_joint_commands([0.1, 0.1], [0.0, 0.0], 0.6)
    assert a.read_sensor_values(6) != first


def test_wrong_sizes_and_negative_time_are_refused() -> None:
    device = RRBotDevice(2)
    with pytest.raises(ValueError, match="1 positions for 2 joints"):
        device.write_joint_commands([0.0], [0.0, 0.0], 0.01)
    with pytest.raises(ValueError, match="dt must not be negative"):
        device.write_joint_commands([0.0, 0.0], [0.0, 0.0], -0.01)
    with pytest.raises(ValueError, match="at least one joint"):
        RRBotDevice(0)
