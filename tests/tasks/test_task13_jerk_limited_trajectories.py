"""Grader of task 13: jerk-limited trajectories with ruckig, executed by the joint trajectory controller.

The specification (``jerk_limited.py``):

* ``joint_limits(urdf, joint_names)`` returns ``{joint: (min_position, max_position, max_velocity)}`` from the
  description's ``<limit>`` tags (as parsed for ``<ros2_control>``), and raises ``ValueError`` naming a joint that is in
  no ``<ros2_control>`` tag;
* ``plan(urdf, joint_names, start, goal, max_acceleration, max_jerk, sample_period=0.01)`` returns the time-optimal
  ruckig motion from rest to rest within the URDF's velocity limits and the given acceleration and jerk limits, all
  joints arriving together, sampled every ``sample_period`` with positions, velocities and accelerations, the last
  point the goal at rest at the motion's duration; a goal outside a joint's position limits raises ``ValueError``
  naming the joint; it is computed with ruckig directly (the library's ``rw.motion`` is not called);
* the joint trajectory controller accepts the result and the robot reaches the goal.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import process_xacro
from rrbot_workshop.description.xacro import descriptions_root

TASK = 13
FILE = "jerk_limited.py"
JOINTS = ["joint1", "joint2"]
LIMITS = {"joint1": (math.radians(-380), math.radians(380), math.radians(180)),
          "joint2": (math.radians(-60), math.radians(240), math.radians(180))}
MOVES = [  # start, goal, max_acceleration [rad/s^2], max_jerk [rad/s^3]
    ([0.0, 0.0], [1.2, -0.5], 4.0, 20.0),
    ([0.3, 1.0], [-5.0, 3.5], 10.0, 40.0),   # long enough for joint1 to cruise at the URDF's velocity limit
    ([0.0, 0.0], [0.05, 0.0], 2.0, 5.0),     # short: never reaches the acceleration limit
]


@pytest.fixture(scope="module")
def urdf() -> str:
    return process_xacro(descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro", use_mock_hardware=True)


@pytest.fixture(scope="module")
def learner(task_file: Callable[[int, str], Path]) -> ModuleType:
    task_file(TASK, FILE)
    module = rw.course.load_module(TASK, FILE, quiet=True)
    if module is None:
        pytest.fail(f"{FILE} does not import", pytrace=False)
    return module


@pytest.fixture()
def no_library_shortcut(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The task is to use ruckig: the library's reference planner is unavailable while grading."""
    import rrbot_workshop.motion as motion

    def refuse(*_args: Any, **_kwargs: Any) -> Any:
        raise AssertionError("plan() called rw.motion.jerk_limited_trajectory: write it with ruckig yourself")

    monkeypatch.setattr(motion, "jerk_limited_trajectory", refuse)
    yield


def _call(module: ModuleType, name: str, *args: Any, **kwargs: Any) -> Any:
    fn = getattr(module, name, None)
    if not callable(fn):
        pytest.fail(f"{FILE} has no function {name}()", pytrace=False)
    try:
        return fn(*args, **kwargs)
    except NotImplementedError:
        pytest.fail(f"{name}() is not written yet", pytrace=False)


def _reference_duration(urdf: str, start: list[float], goal: list[float], acc: float, jerk: float) -> float:
    from ruckig import InputParameter, Ruckig, Trajectory

    inp = InputParameter(2)
    inp.current_position, inp.target_position = start, goal
    inp.max_velocity = [LIMITS[j][2] for j in JOINTS]
    inp.max_acceleration, inp.max_jerk = [acc, acc], [jerk, jerk]
    traj = Trajectory(2)
    Ruckig(2).calculate(inp, traj)
    return float(traj.duration)


@graded(points=2, hint="Task 13.1: each joint's <limit> is parsed into the limits of the <ros2_control> tag that names it "
        "(rw.description.parse_ros2_control(urdf)[i].limits). Name an unknown joint in the ValueError.")
def test_joint_limits(learner: ModuleType, urdf: str) -> None:
    got = _call(learner, "joint_limits", urdf, JOINTS)
    assert set(got) == set(JOINTS), f"joint_limits() gave {sorted(got)}"
    for joint, expected in LIMITS.items():
        assert tuple(got[joint]) == pytest.approx(expected), f"{joint}: {got[joint]}, expected {expected}"
    with pytest.raises(ValueError, match="elbow"):
        learner.joint_limits(urdf, ["joint1", "elbow"])


@graded(points=1, hint="Task 13.2: check the goal against each joint's position limits before planning, and name the joint.")
def test_goal_outside_limits_is_refused(learner: ModuleType, urdf: str, no_library_shortcut: None) -> None:
    _call(learner, "plan", urdf, JOINTS, [0.0, 0.0], [0.5, 0.5], 4.0, 20.0)
    with pytest.raises(ValueError, match="joint2"):
        learner.plan(urdf, JOINTS, [0.0, 0.0], [0.5, 4.5], 4.0, 20.0)


@graded(points=3, hint="Task 13.2: every point within the URDF's velocity limit and the given acceleration; the jerk "
        "between points within max_jerk; points every sample_period, ending at the goal at rest.")
def test_limits_respected(learner: ModuleType, urdf: str, no_library_shortcut: None) -> None:
    for start, goal, acc, jerk in MOVES:
        traj = _call(learner, "plan", urdf, JOINTS, start, goal, acc, jerk, sample_period=0.01)
        assert list(traj.joint_names) == JOINTS, f"joint_names {traj.joint_names}"
        points = traj.points
        assert len(points) >= 2, f"move {start} -> {goal}: {len(points)} point(s)"
        times = [p.time_from_start for p in points]
        gaps = [b - a for a, b in zip([0.0, *times], times, strict=False)]
        assert all(0.0 < g <= 0.01 + 1e-9 for g in gaps[1:]), f"points must come every 0.01 s at most: {gaps[:5]}..."
        for p in points:
            assert len(p.velocities) == 2 and len(p.accelerations) == 2, "each point needs velocities and accelerations"
            for j, joint in enumerate(JOINTS):
                assert abs(p.velocities[j]) <= LIMITS[joint][2] + 1e-6, f"{joint} at {p.velocities[j]} rad/s"
                assert abs(p.accelerations[j]) <= acc + 1e-6, f"{joint} at {p.accelerations[j]} rad/s^2"
        for a, b in zip(points, points[1:], strict=False):
            dt = b.time_from_start - a.time_from_start
            for j in range(2):
                assert abs(b.accelerations[j] - a.accelerations[j]) <= jerk * dt * 1.001 + 1e-9, "jerk above max_jerk"
        last = points[-1]
        assert last.positions == pytest.approx(goal, abs=1e-9), f"last point {last.positions}, goal {goal}"
        assert last.velocities == pytest.approx([0, 0], abs=1e-9) and last.accelerations == pytest.approx([0, 0], abs=1e-9)


@graded(points=2, hint="Task 13.2: ruckig's motion is time-optimal: the last point's time_from_start is its duration, "
        "with the URDF's velocity limits (not smaller ones).")
def test_time_optimal(learner: ModuleType, urdf: str, no_library_shortcut: None) -> None:
    for start, goal, acc, jerk in MOVES:
        traj = _call(learner, "plan", urdf, JOINTS, start, goal, acc, jerk)
        expected = _reference_duration(urdf, start, goal, acc, jerk)
        assert traj.points[-1].time_from_start == pytest.approx(expected, abs=1e-6), (
            f"move {start} -> {goal} lasts {traj.points[-1].time_from_start:.4f} s; the optimum is {expected:.4f} s"
        )


@graded(points=3, hint="Task 13: the joint trajectory controller must accept your trajectory and the robot end at the goal.")
def test_jtc_executes_it(learner: ModuleType, urdf: str, no_library_shortcut: None) -> None:
    system = bringup("rrbot", "rrbot_controllers.yaml", xacro_args={"use_mock_hardware": True},
                     spawn=["joint_state_broadcaster", "joint_trajectory_controller"])
    try:
        goal = [1.2, -0.5]
        traj = _call(learner, "plan", urdf, JOINTS, [0.0, 0.0], goal, 4.0, 20.0)
        system.spin(0.1)
        system.publish("/joint_trajectory_controller/joint_trajectory", traj)
        system.spin(traj.points[-1].time_from_start + 0.5)
        msg = system.latest("/joint_states")
        final = [msg.position[msg.name.index(j)] for j in JOINTS]
    finally:
        system.shutdown()
    assert final == pytest.approx(goal, abs=1e-3), f"the robot ended at {final}, goal {goal}"
