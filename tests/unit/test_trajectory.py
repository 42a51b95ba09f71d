"""Trajectory sampling and interpolation, ported from ros2_controllers' test_trajectory.cpp (EPS 1e-8)."""

from __future__ import annotations

import math

import pytest

from rrbot_workshop.controllers.joint_trajectory import interpolate_between_points as public_interpolate
from rrbot_workshop.controllers.trajectory import (
    InterpolationMethod,
    Trajectory,
    interpolate_between_points,
    shortest_angular_distance,
)
from rrbot_workshop.msgs import Header, JointTrajectory, JointTrajectoryPoint

EPS = 1e-8
NOW = 10.0


def _msg(*points: JointTrajectoryPoint) -> JointTrajectory:
    return JointTrajectory(Header(stamp=0.0), ["j"], list(points))


def _pos_traj() -> Trajectory:
    msg = _msg(*(JointTrajectoryPoint(positions=[float(k)], time_from_start=float(k)) for k in (1, 2, 3)))
    return Trajectory(msg, NOW, JointTrajectoryPoint(positions=[0.0]))


def test_public_function_is_the_trajectory_one() -> None:
    """The DESIGN contract name points at the implementation."""
    assert public_interpolate is interpolate_between_points


def test_linear_sampling_at_start_interpolates_from_the_state_before() -> None:
    s = _pos_traj().sample(NOW)
    assert s is not None and (s.start_index, s.end_index) == (0, 0)
    assert s.point.positions[0] == pytest.approx(0.0, abs=EPS)
    assert s.point.velocities[0] == pytest.approx(1.0, abs=EPS)
    assert s.point.accelerations[0] == pytest.approx(0.0, abs=EPS)


def test_sampling_before_the_state_before_gives_none() -> None:
    traj = _pos_traj()
    traj.sample(NOW)
    assert traj.sample(NOW - 0.5) is None


@pytest.mark.parametrize(
    ("dt", "expected", "segment"),
    [(0.5, 0.5, (0, 0)), (1.0, 1.0, (0, 1)), (1.5, 1.5, (0, 1)), (2.5, 2.5, (1, 2)), (3.0, 3.0, (2, 3)),
     (3.125, 3.0, (2, 3))],
)
def test_linear_sampling_positions_and_segments(dt: float, expected: float, segment: tuple[int, int]) -> None:
    traj = _pos_traj()
    traj.sample(NOW)
    s = traj.sample(NOW + dt)
    assert s is not None
    assert s.point.positions[0] == pytest.approx(expected, abs=EPS)
    assert (s.start_index, s.end_index) == segment


def _cubic_ends() -> tuple[JointTrajectoryPoint, JointTrajectoryPoint]:
    # x^3 - 2x sampled at x = 0 and x = 2
    return (JointTrajectoryPoint(positions=[0.0], velocities=[-2.0]),
            JointTrajectoryPoint(positions=[4.0], velocities=[10.0], accelerations=[0.0]))


def test_cubic_at_start_end_and_zero_crossing() -> None:
    """x^3 - 2x: (0, -2, 0) at 0; (0, 4, 6*sqrt(2)) at sqrt(2); acceleration 12 at the end."""
    a, b = _cubic_ends()
    start = interpolate_between_points(1.0, a, 3.0, b, 1.0)
    assert (start.positions[0], start.velocities[0], start.accelerations[0]) == pytest.approx((0.0, -2.0, 0.0), abs=EPS)
    mid = interpolate_between_points(1.0, a, 3.0, b, 1.0 + math.sqrt(2.0))
    assert mid.positions[0] == pytest.approx(0.0, abs=EPS)
    assert mid.velocities[0] == pytest.approx(4.0, abs=EPS)
    assert mid.accelerations[0] == pytest.approx(6.0 * math.sqrt(2.0), abs=EPS)
    end = interpolate_between_points(1.0, a, 3.0, b, 3.0)
    assert (end.positions[0], end.velocities[0], end.accelerations[0]) == pytest.approx((4.0, 10.0, 12.0), abs=EPS)


def test_quintic_midpoint() -> None:
    """x(x-1)(x-2)(x-3)(x-4): (0, -6, 10) at x = 2, and the end state is met."""
    a = JointTrajectoryPoint(positions=[0.0], velocities=[24.0], accelerations=[-100.0])
    b = JointTrajectoryPoint(positions=[0.0], velocities=[4.0], accelerations=[0.0])
    mid = interpolate_between_points(1.0, a, 3.0, b, 2.0)
    assert (mid.positions[0], mid.velocities[0], mid.accelerations[0]) == pytest.approx((0.0, -6.0, 10.0), abs=EPS)
    end = interpolate_between_points(1.0, a, 3.0, b, 3.0)
    assert (end.positions[0], end.velocities[0], end.accelerations[0]) == pytest.approx((0.0, 4.0, 0.0), abs=EPS)


def test_interpolation_outside_the_segment_clamps_time_and_goes_linear() -> None:
    a, b = _cubic_ends()
    after = interpolate_between_points(1.0, a, 3.0, b, 5.0)
    assert after.positions[0] == pytest.approx(4.0, abs=EPS)
    assert after.velocities[0] == pytest.approx(2.0, abs=EPS)  # linear slope 4 / 2


def test_velocity_only_waypoints_are_integrated_with_trapezoids() -> None:
    """Velocities 1, 2, 1 at t = 1, 2, 3 from rest: positions 0.5, 2.0, 3.5 and accelerations as upstream."""
    msg = _msg(*(JointTrajectoryPoint(velocities=[v], time_from_start=t) for v, t in ((1.0, 1.0), (2.0, 2.0), (1.0, 3.0))))
    traj = Trajectory(msg, NOW, JointTrajectoryPoint(positions=[0.0], velocities=[0.0]))
    s0 = traj.sample(NOW)
    assert s0 is not None and s0.point.accelerations[0] == pytest.approx(1.0, abs=EPS)
    half = traj.sample(NOW + 0.5)
    assert half is not None
    assert half.point.positions[0] == pytest.approx(0.125, abs=EPS)
    assert half.point.velocities[0] == pytest.approx(0.5, abs=EPS)
    expected = {1.0: (0.5, 1.0, 1.0), 2.0: (2.0, 2.0, -1.0), 3.0: (3.5, 1.0, 0.0)}
    for dt, (p, v, a) in expected.items():
        s = traj.sample(NOW + dt)
        assert s is not None
        assert (s.point.positions[0], s.point.velocities[0], s.point.accelerations[0]) == pytest.approx((p, v, a), abs=EPS)


def test_velocity_only_without_state_velocity_starts_from_rest() -> None:
    msg = _msg(JointTrajectoryPoint(velocities=[1.0], time_from_start=1.0))
    traj = Trajectory(msg, NOW, JointTrajectoryPoint(positions=[0.0]))
    traj.sample(NOW)  # the first sample fixes the start time (stamp 0)
    s = traj.sample(NOW + 0.5)
    assert s is not None
    assert (s.point.positions[0], s.point.velocities[0], s.point.accelerations[0]) == pytest.approx((0.125, 0.5, 1.0), abs=EPS)


def test_acceleration_only_waypoints_are_integrated_twice() -> None:
    msg = _msg(*(JointTrajectoryPoint(accelerations=[a], time_from_start=t) for a, t in ((1.0, 1.0), (2.0, 2.0), (1.0, 3.0))))
    traj = Trajectory(msg, NOW, JointTrajectoryPoint(positions=[0.0], velocities=[0.0]))
    s0 = traj.sample(NOW)
    assert s0 is not None and s0.point.positions[0] == pytest.approx(0.0, abs=EPS)
    v1 = 0.5
    p1 = 0.25
    v2 = v1 + 1.5
    p2 = p1 + (v1 + v2) / 2
    v3 = v2 + 1.5
    p3 = p2 + (v2 + v3) / 2
    for dt, (p, v, a) in {1.0: (p1, v1, 1.0), 2.0: (p2, v2, 2.0), 3.0: (p3, v3, 1.0), 3.125: (p3, v3, 1.0)}.items():
        s = traj.sample(NOW + dt)
        assert s is not None
        assert (s.point.positions[0], s.point.velocities[0], s.point.accelerations[0]) == pytest.approx((p, v, a), abs=EPS)


def test_skip_interpolation_forwards_the_next_waypoint() -> None:
    traj = _pos_traj()
    none = InterpolationMethod.NONE
    s = traj.sample(NOW, none)
    assert s is not None and s.point.positions[0] == pytest.approx(0.0, abs=EPS)
    assert s.point.velocities == [] and s.point.accelerations == []
    expected = {0.5: 0.0, 1.0: 2.0, 1.5: 2.0, 2.5: 3.0, 3.0: 3.0, 3.125: 3.0}
    for dt, p in expected.items():
        s = traj.sample(NOW + dt, none)
        assert s is not None and s.point.positions[0] == pytest.approx(p, abs=EPS)


def test_after_the_end_missing_fields_are_zero_filled() -> None:
    traj = _pos_traj()
    traj.sample(NOW)
    s = traj.sample(NOW + 10.0)
    assert s is not None
    assert s.point.velocities == [0.0] and s.point.accelerations == [0.0] and s.point.effort == [0.0]


def test_header_stamp_sets_the_start_time() -> None:
    msg = _msg(JointTrajectoryPoint(positions=[1.0], time_from_start=1.0))
    msg.header.stamp = 20.0
    traj = Trajectory(msg, NOW, JointTrajectoryPoint(positions=[0.0]))
    s = traj.sample(NOW)
    assert traj.time_from_start == 20.0
    assert s is not None and s.point.positions[0] == pytest.approx(0.0, abs=EPS)
    s = traj.sample(15.5)
    assert s is not None and s.point.positions[0] == pytest.approx(0.5, abs=EPS)


def test_empty_trajectory_samples_nothing() -> None:
    assert Trajectory(_msg()).sample(NOW) is None


def test_sampling_does_not_modify_the_callers_message() -> None:
    msg = _msg(JointTrajectoryPoint(velocities=[1.0], time_from_start=1.0))
    traj = Trajectory(msg, NOW, JointTrajectoryPoint(positions=[0.0]))
    traj.sample(NOW + 0.5)
    assert msg.points[0].positions == []


def test_continuous_joint_starts_from_the_nearest_turn() -> None:
    """State 3.0 rad, goal -3.0 rad on a continuous joint: the state is moved to -3.283 rad (short way)."""
    msg = _msg(JointTrajectoryPoint(positions=[-3.0], time_from_start=1.0))
    traj = Trajectory(msg, NOW, JointTrajectoryPoint(positions=[3.0]), [True])
    assert traj.state_before_trajectory.positions[0] == pytest.approx(-3.0 - (2 * math.pi - 6.0), abs=EPS)


def test_shortest_angular_distance_wraps() -> None:
    assert shortest_angular_distance(3.0, -3.0) == pytest.approx(2 * math.pi - 6.0)
    assert shortest_angular_distance(0.0, 1.0) == pytest.approx(1.0)
