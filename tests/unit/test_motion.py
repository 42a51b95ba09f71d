"""Jerk-limited trajectories from ruckig."""

from __future__ import annotations

import pytest

from rrbot_workshop.controllers.joint_trajectory import JointTrajectoryController
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.motion import jerk_limited_trajectory
from rrbot_workshop.testing import ControllerHarness

JOINTS = ["joint1", "joint2"]


def _traj():  # type: ignore[no-untyped-def]
    return jerk_limited_trajectory(JOINTS, [0.0, 0.0], [0.785, -0.4], 1.0, 2.0, 10.0, sample_period=0.01)


def test_trajectory_ends_at_rest_at_the_goal() -> None:
    t = _traj()
    last = t.points[-1]
    assert last.positions == [0.785, -0.4] and last.velocities == [0.0, 0.0] and last.accelerations == [0.0, 0.0]
    assert t.points[0].positions == pytest.approx([0.0, 0.0]) and t.points[0].time_from_start == 0.0


def test_times_strictly_increase_by_the_sample_period() -> None:
    times = [p.time_from_start for p in _traj().points]
    steps = [b - a for a, b in zip(times, times[1:], strict=False)]
    assert all(s > 0 for s in steps) and all(s <= 0.01 + 1e-12 for s in steps)


def test_limits_are_respected() -> None:
    t = _traj()
    assert max(abs(v) for p in t.points for v in p.velocities) <= 1.0 + 1e-9
    assert max(abs(a) for p in t.points for a in p.accelerations) <= 2.0 + 1e-9
    jerks = [abs(b.accelerations[i] - a.accelerations[i]) / (b.time_from_start - a.time_from_start)
             for a, b in zip(t.points, t.points[1:], strict=False) for i in range(2)]
    assert max(jerks) <= 10.0 + 1e-6


def test_joints_arrive_together() -> None:
    t = _traj()
    almost = t.points[-2]
    assert all(abs(v) > 0.0 or abs(g - p) < 1e-3 for v, g, p in zip(almost.velocities, [0.785, -0.4],
                                                                    almost.positions, strict=True))


def test_no_motion_gives_one_point() -> None:
    t = jerk_limited_trajectory(JOINTS, [0.1, 0.2], [0.1, 0.2], 1.0, 1.0, 1.0)
    assert len(t.points) == 1


def test_start_velocity_is_honoured() -> None:
    t = jerk_limited_trajectory(["j"], [0.0], [1.0], 1.0, 2.0, 10.0, start_velocities=[0.5])
    assert t.points[0].velocities == pytest.approx([0.5])


@pytest.mark.parametrize(
    ("kwargs", "parameter"),
    [({"goal_positions": [1.0]}, "goal_positions"), ({"max_velocity": 0.0}, "max_velocity"),
     ({"max_jerk": [1.0, float("nan")]}, "max_jerk"), ({"sample_period": 0.0}, "sample_period"),
     ({"joint_names": []}, "joint_names")],
)
def test_bad_arguments_raise_parameter_error(kwargs: dict, parameter: str) -> None:
    args = {"joint_names": JOINTS, "start_positions": [0.0, 0.0], "goal_positions": [1.0, 1.0], "max_velocity": 1.0,
            "max_acceleration": 1.0, "max_jerk": 1.0, **kwargs}
    with pytest.raises(ParameterError) as info:
        jerk_limited_trajectory(**args)
    assert info.value.parameter == parameter


def test_jtc_accepts_and_follows_it() -> None:
    h = ControllerHarness(JointTrajectoryController(), "jtc",
                          {"joints": JOINTS, "command_interfaces": ["position"], "state_interfaces": ["position"]},
                          {"joint1/position": 0.0, "joint2/position": 0.0},
                          {"joint1/position": float("nan"), "joint2/position": float("nan")})
    assert h.configure() is State.INACTIVE and h.activate() is State.ACTIVE
    t = _traj()
    goal = h.controller.send_goal(t)
    assert goal.accepted, goal.result
    h.update(int(t.points[-1].time_from_start * 100) + 5)
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([0.785, -0.4])
