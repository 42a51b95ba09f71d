"""The saturation and soft limiters of Jazzy's ``joint_limits`` package, one joint each: every bound of position,
velocity, effort, acceleration and jerk, and the soft limits slowing a joint down. Expected values are computed by
hand from the limits below (comments give the arithmetic); tolerance 1e-12 unless stated.
"""

from __future__ import annotations

import math

import pytest

from rrbot_workshop.exceptions import JointLimitsError, ParameterError
from rrbot_workshop.joint_limits import (
    SOFT_LIMIT_REACH_VELOCITY,
    JointControlInterfacesData,
    JointLimits,
    JointSaturationLimiter,
    JointSoftLimiter,
    JointTrajectoryPointSaturationLimiter,
    SoftJointLimits,
)
from rrbot_workshop.msgs import JointTrajectoryPoint

DT = 0.01  # [s]
#: Hard limits: [-1, 1] rad, 2 rad/s, 5 N m.
LIMITS = JointLimits(has_position_limits=True, min_position=-1.0, max_position=1.0, has_velocity_limits=True,
                     max_velocity=2.0, has_effort_limits=True, max_effort=5.0)
#: Soft limits [-0.5, 0.5] rad, k_position 10 1/s, k_velocity 5 N m s/rad.
SOFT = SoftJointLimits(min_position=-0.5, max_position=0.5, k_position=10.0, k_velocity=5.0)
ABS = 1e-12


def data(**values: float | None) -> JointControlInterfacesData:
    return JointControlInterfacesData("j", **values)  # type: ignore[arg-type]


def saturation(limits: JointLimits = LIMITS) -> JointSaturationLimiter:
    return JointSaturationLimiter(["j"], [limits])


def soft(limits: JointLimits = LIMITS, soft_limits: SoftJointLimits = SOFT) -> JointSoftLimiter:
    return JointSoftLimiter(["j"], [limits], [soft_limits])


def enforce(limiter: JointSaturationLimiter, actual: JointControlInterfacesData,
            **desired: float | None) -> tuple[bool, JointControlInterfacesData]:
    command = data(**desired)
    return limiter.enforce(actual, command, DT), command


# ----------------------------------------------------------------------------------------------- init
def test_a_limiter_takes_exactly_one_joint_as_in_jazzy() -> None:
    with pytest.raises(ParameterError, match=r"exactly one joint .*\['a', 'b'\]"):
        JointSaturationLimiter(["a", "b"], [LIMITS, LIMITS])
    with pytest.raises(ParameterError, match="2 joint names .* but 1 limits"):
        JointSoftLimiter(["a", "b"], [LIMITS])
    limiter = JointSaturationLimiter()
    limiter.init(["j"], [LIMITS])
    assert limiter.joint_names == ["j"] and limiter.number_of_joints == 1


def test_init_from_parameters_overrides_the_given_limits() -> None:
    limiter = JointSoftLimiter()
    params = {"joint_limits": {"j": {"has_velocity_limits": True, "max_velocity": 0.5}}}
    limiter.init_from_parameters(["j"], params, {"j": LIMITS}, {"j": SOFT})
    assert limiter.joint_limits[0].max_velocity == 0.5 and limiter.joint_limits[0].max_position == 1.0
    assert limiter.soft_joint_limits == [SOFT]
    _, cmd = enforce(limiter, data(position=0.0), position=1.0)
    assert cmd.position == pytest.approx(0.005, abs=ABS)  # 0.5 rad/s * 10 ms


# ----------------------------------------------------------------------------------------------- position
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_position_is_clamped_to_both_position_limits(sign: float) -> None:
    limiter = saturation()
    limiter.configure(data(position=sign * 0.99))
    limited, cmd = enforce(limiter, data(position=sign * 0.99), position=sign * 5.0)
    assert limited and cmd.position == sign * 1.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_position_moves_at_most_max_velocity_times_dt_from_the_previous_command(sign: float) -> None:
    limiter = saturation()
    _, first = enforce(limiter, data(position=0.0), position=sign * 0.5)
    assert first.position == pytest.approx(sign * 0.02, abs=ABS)  # 2 rad/s * 10 ms from the measured 0
    _, second = enforce(limiter, data(position=0.0), position=sign * 0.5)
    assert second.position == pytest.approx(sign * 0.04, abs=ABS)  # from the previous command, not the measurement


def test_position_within_its_limits_is_left_alone() -> None:
    limited, cmd = enforce(saturation(), data(position=0.1), position=0.11)
    assert not limited and cmd.position == 0.11


def test_position_rate_with_an_acceleration_limit_grows_from_the_measured_velocity() -> None:
    limits = JointLimits(**{**LIMITS.__dict__, "has_acceleration_limits": True, "max_acceleration": 10.0})
    _, cmd = enforce(saturation(limits), data(position=0.0, velocity=0.0), position=0.5)
    assert cmd.position == pytest.approx(0.001, abs=ABS)  # min(2, 0 + 10 * 0.01) rad/s * 10 ms
    _, cmd = enforce(saturation(limits), data(position=0.0, velocity=1.0), position=0.5)
    assert cmd.position == pytest.approx(0.011, abs=ABS)  # (1 + 0.1) rad/s * 10 ms


def test_measured_position_beyond_a_limit_while_commanding_position_is_an_error() -> None:
    with pytest.raises(JointLimitsError, match=r"joint 'j': its position 1.01 is out of its limits \[-1, 1\]") as err:
        enforce(saturation(), data(position=1.01), position=0.0)
    assert err.value.joint == "j" and err.value.limits == (-1.0, 1.0)
    enforce(saturation(), data(position=1.008), position=0.0)  # within 0.0087 rad: no error


# ----------------------------------------------------------------------------------------------- velocity
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_velocity_is_clamped_to_plus_minus_max_velocity(sign: float) -> None:
    limited, cmd = enforce(saturation(), data(position=0.0), velocity=sign * 10.0)
    assert limited and cmd.velocity == sign * 2.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_velocity_does_not_leave_the_position_range_within_dt(sign: float) -> None:
    _, cmd = enforce(saturation(), data(position=sign * 0.995), velocity=sign * 1.5)
    assert cmd.velocity == pytest.approx(sign * 0.5, abs=1e-9)  # 5 mrad left in 10 ms
    _, back = enforce(saturation(), data(position=sign * 1.0), velocity=-sign * 1.0)
    assert back.velocity == -sign * 1.0  # back into the range is fine


def test_velocity_is_zero_far_beyond_a_position_limit() -> None:
    for desired in (1.0, -1.0):
        _, cmd = enforce(saturation(), data(position=1.01), velocity=desired)
        assert cmd.velocity == 0.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_velocity_changes_at_most_max_acceleration_times_dt(sign: float) -> None:
    limits = JointLimits(has_velocity_limits=True, max_velocity=2.0, has_acceleration_limits=True,
                         max_acceleration=10.0)
    limiter = saturation(limits)
    limiter.configure(data(velocity=0.0))
    _, cmd = enforce(limiter, data(), velocity=sign * 2.0)
    assert cmd.velocity == pytest.approx(sign * 0.1, abs=ABS)  # 10 rad/s^2 * 10 ms
    _, cmd = enforce(limiter, data(), velocity=sign * 2.0)
    assert cmd.velocity == pytest.approx(sign * 0.2, abs=ABS)


# ----------------------------------------------------------------------------------------------- effort
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_effort_is_clamped_to_plus_minus_max_effort(sign: float) -> None:
    limited, cmd = enforce(saturation(), data(position=0.0, velocity=0.0), effort=sign * 9.0)
    assert limited and cmd.effort == sign * 5.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_effort_does_not_push_further_out_at_a_position_limit(sign: float) -> None:
    _, out = enforce(saturation(), data(position=sign * 1.0, velocity=0.0), effort=sign * 3.0)
    assert out.effort == 0.0
    _, back = enforce(saturation(), data(position=sign * 1.0, velocity=0.0), effort=-sign * 3.0)
    assert back.effort == -sign * 3.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_effort_does_not_accelerate_a_joint_beyond_its_velocity_limit(sign: float) -> None:
    _, cmd = enforce(saturation(), data(position=0.0, velocity=sign * 2.5), effort=sign * 3.0)
    assert cmd.effort == 0.0
    _, at_limit = enforce(saturation(), data(position=0.0, velocity=sign * 2.0), effort=sign * 3.0)
    assert at_limit.effort == sign * 3.0  # Jazzy cuts only beyond the limit


def test_no_effort_limit_lets_any_effort_through() -> None:
    limits = JointLimits(has_position_limits=True, min_position=-1.0, max_position=1.0)
    limited, cmd = enforce(saturation(limits), data(position=1.0, velocity=0.0), effort=1e6)
    assert not limited and cmd.effort == 1e6


# ----------------------------------------------------------------------------------------------- acceleration, jerk
ACC = JointLimits(has_acceleration_limits=True, max_acceleration=10.0, has_deceleration_limits=True,
                  max_deceleration=4.0, has_jerk_limits=True, max_jerk=100.0)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_acceleration_is_clamped_to_plus_minus_max_acceleration(sign: float) -> None:
    _, cmd = enforce(saturation(ACC), data(velocity=sign * 1.0), acceleration=sign * 20.0)
    assert cmd.acceleration == sign * 10.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_braking_is_clamped_to_plus_minus_max_deceleration(sign: float) -> None:
    _, cmd = enforce(saturation(ACC), data(velocity=sign * 1.0), acceleration=-sign * 20.0)
    assert cmd.acceleration == -sign * 4.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_jerk_is_clamped_to_plus_minus_max_jerk(sign: float) -> None:
    limited, cmd = enforce(saturation(ACC), data(), jerk=sign * 500.0)
    assert limited and cmd.jerk == sign * 100.0
    limited, cmd = enforce(saturation(LIMITS), data(), jerk=sign * 500.0)  # no jerk limit
    assert not limited and cmd.jerk == sign * 500.0


# ----------------------------------------------------------------------------------------------- NaN, None, dt
def test_nan_and_missing_values_are_left_alone() -> None:
    limited, cmd = enforce(saturation(), data(position=0.0), position=math.nan, velocity=None, effort=99.0)
    assert limited and math.isnan(cmd.position or 0.0) and cmd.velocity is None and cmd.effort == 5.0


def test_a_period_that_is_not_positive_limits_nothing() -> None:
    command = data(position=5.0)
    assert not saturation().enforce(data(position=0.0), command, 0.0)
    assert command.position == 5.0


def test_reset_internals_starts_again_from_the_measured_position() -> None:
    limiter = saturation()
    enforce(limiter, data(position=0.0), position=0.5)
    limiter.reset_internals()
    _, cmd = enforce(limiter, data(position=0.3), position=0.5)
    assert cmd.position == pytest.approx(0.32, abs=ABS)


# ----------------------------------------------------------------------------------------------- soft limiter
def test_soft_limiter_slows_a_position_command_into_the_soft_upper_limit() -> None:
    """From 0.4 rad: at most 10 * (0.5 - p) rad/s, so each 10 ms cycle covers 10 % of what is left to 0.5 rad;
    the saturation limiter alone would go 20 mrad per cycle."""
    limiter = soft()
    expected, positions = 0.4, []
    for _ in range(50):
        _, cmd = enforce(limiter, data(position=0.4), position=1.0)
        assert cmd.position is not None
        positions.append(cmd.position)
    for p in positions:
        expected += 0.1 * (0.5 - expected)
        assert p == pytest.approx(expected, abs=ABS)
    assert positions[:2] == pytest.approx([0.41, 0.419], abs=ABS)
    assert positions[-1] == pytest.approx(0.5 - 0.1 * 0.9 ** 50, abs=ABS) and max(positions) < 0.5


def test_soft_limiter_slows_a_position_command_into_the_soft_lower_limit() -> None:
    _, cmd = enforce(soft(), data(position=-0.4), position=-1.0)
    assert cmd.position == pytest.approx(-0.41, abs=ABS)  # -0.4 + 10 * (-0.5 + 0.4) * 0.01


def test_far_from_the_soft_limits_only_the_hard_velocity_limit_counts() -> None:
    _, cmd = enforce(soft(), data(position=0.0), position=1.0)
    assert cmd.position == pytest.approx(0.02, abs=ABS)  # 10 * 0.5 = 5 rad/s > 2 rad/s


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_soft_limiter_bounds_velocity_by_k_position_times_the_distance(sign: float) -> None:
    _, cmd = enforce(soft(), data(position=sign * 0.45), velocity=sign * 2.0)
    assert cmd.velocity == pytest.approx(sign * 0.5, abs=ABS)  # 10 * (0.5 - 0.45)
    _, away = enforce(soft(), data(position=sign * 0.45), velocity=-sign * 5.0)
    assert away.velocity == pytest.approx(-sign * 2.0, abs=ABS)  # 10 * 0.95 = 9.5, clamped to 2


def test_outside_the_soft_range_the_joint_only_moves_back_at_one_degree_per_second() -> None:
    _, cmd = enforce(soft(), data(position=0.7), velocity=1.0)
    assert cmd.velocity == pytest.approx(-SOFT_LIMIT_REACH_VELOCITY, abs=ABS)
    assert SOFT_LIMIT_REACH_VELOCITY == pytest.approx(math.pi / 180, abs=ABS)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_soft_limiter_bounds_effort_by_k_velocity_times_the_velocity_excess(sign: float) -> None:
    """At 0.45 rad the soft velocity bound is 0.5 rad/s: moving at 0.3 rad/s the joint may get
    -5 * (0.3 - 0.5) = 1 N m more; at 0.8 rad/s it must brake with -5 * (0.8 - 0.5) = -1.5 N m or more."""
    _, cmd = enforce(soft(), data(position=sign * 0.45, velocity=sign * 0.3), effort=sign * 5.0)
    assert cmd.effort == pytest.approx(sign * 1.0, abs=ABS)
    _, brake = enforce(soft(), data(position=sign * 0.45, velocity=sign * 0.8), effort=sign * 5.0)
    assert brake.effort == pytest.approx(-sign * 1.5, abs=ABS)
    _, away = enforce(soft(), data(position=sign * 0.45, velocity=sign * 0.3), effort=-sign * 9.0)
    assert away.effort == -sign * 5.0  # -5 * (0.3 + 2) = -11.5, clamped to the hard 5 N m


def test_soft_limiter_without_soft_limits_limits_as_the_saturation_limiter() -> None:
    plain = JointSoftLimiter(["j"], [LIMITS])
    for actual, desired in ((data(position=0.4), {"position": 1.0}), (data(position=0.45), {"velocity": 2.0}),
                            (data(position=0.45, velocity=0.3), {"effort": 5.0})):
        assert enforce(plain, actual, **desired)[1] == enforce(saturation(), actual, **desired)[1]


def _effort_run(limiter: JointSaturationLimiter, steps: int = 3000, dt: float = 0.001) -> tuple[list[float], float]:
    """A unit inertia [kg m^2] pushed with 5 N m through ``limiter``: positions, final velocity."""
    x = v = 0.0
    xs = []
    for _ in range(steps):
        cmd = data(effort=5.0)
        limiter.enforce(data(position=x, velocity=v), cmd, dt)
        v += (cmd.effort or 0.0) * dt
        x += v * dt
        xs.append(x)
    return xs, v


def test_an_effort_driven_joint_is_slowed_by_its_soft_limits_not_by_saturation_alone() -> None:
    saturated, _ = _effort_run(saturation())
    softened, v = _effort_run(soft())
    assert max(saturated) > 1.0  # saturation only stops pushing at the limit: the joint coasts through it
    assert max(softened) < 0.75  # braked from the soft range on, well before the hard limit
    assert v == pytest.approx(-SOFT_LIMIT_REACH_VELOCITY, rel=1e-3)  # and brought back towards the soft range


# ----------------------------------------------------------------------------------------------- trajectory points
def _points(limits: JointLimits) -> JointTrajectoryPointSaturationLimiter:
    return JointTrajectoryPointSaturationLimiter(["a", "b"], [limits, limits])


WITH_ACC = JointLimits(**{**LIMITS.__dict__, "has_acceleration_limits": True, "max_acceleration": 10.0})


def test_trajectory_point_position_is_clamped_into_the_position_limits() -> None:
    desired = JointTrajectoryPoint(positions=[5.0, 0.0])
    assert _points(LIMITS).enforce(JointTrajectoryPoint(positions=[0.995, 0.0]), desired, DT)
    assert desired.positions == [1.0, 0.0]  # 5 mrad in 10 ms is 0.5 rad/s: within the velocity limit


def test_trajectory_point_steps_are_clamped_to_the_velocity_limit_for_each_joint() -> None:
    desired = JointTrajectoryPoint(positions=[0.5, -0.5])
    _points(LIMITS).enforce(JointTrajectoryPoint(positions=[0.0, 0.0]), desired, DT)
    assert desired.positions == pytest.approx([0.02, -0.02], abs=ABS)  # 2 rad/s * 10 ms


def test_trajectory_point_acceleration_limit_integrates_position_twice() -> None:
    desired = JointTrajectoryPoint(positions=[0.5, 0.0])
    _points(WITH_ACC).enforce(JointTrajectoryPoint(positions=[0.0, 0.0], velocities=[0.0, 0.0]), desired, DT)
    assert desired.positions == pytest.approx([0.0005, 0.0], abs=ABS)  # 0.5 * 10 rad/s^2 * (10 ms)^2


def test_trajectory_point_near_a_limit_brakes_every_joint() -> None:
    """Joint a at 0.9 rad and 2 rad/s needs 2^2 / (2 * 10) = 0.2 rad to stop: more than the 0.1 rad left."""
    desired = JointTrajectoryPoint(positions=[1.0, 0.3], velocities=[2.0, 1.0])
    current = JointTrajectoryPoint(positions=[0.9, 0.0], velocities=[2.0, 1.0])
    assert _points(WITH_ACC).enforce(current, desired, DT)
    assert desired.velocities == pytest.approx([1.9, 0.9], abs=ABS)  # both at -10 rad/s^2 for 10 ms
    assert desired.positions == pytest.approx([0.9 + 0.02 - 0.0005, 0.01 - 0.0005], abs=ABS)


def test_trajectory_point_without_a_current_position_is_not_limited() -> None:
    desired = JointTrajectoryPoint(positions=[5.0, 5.0])
    assert not _points(LIMITS).enforce(JointTrajectoryPoint(), desired, DT)
    assert desired.positions == [5.0, 5.0]
