"""Grader of task 13: jerk-limited trajectories with ruckig, executed by the joint trajectory controller.

The specification (``jerk_limited.py``, its docstrings and TODOs, and notebook 13):

* ``joint_limits(urdf, joint_names)`` returns ``{joint: (min_position, max_position, max_velocity)}`` from the
  description's ``<limit>`` tags, as parsed for ``<ros2_control>`` (to 1e-9), for any description and any joints of
  it; a joint that is in no ``<ros2_control>`` tag, or has no position or velocity limit, raises ``ValueError`` naming
  the joint;
* ``plan(urdf, joint_names, start, goal, max_acceleration, max_jerk, sample_period=0.01)``:

  - raises ``ValueError`` if the lists' lengths differ, and ``ValueError`` naming the joint if a goal is outside the
    joint's position limits, below the lower as above the upper (a goal at a limit is within them);
  - raises ``ValueError`` when ruckig finds no trajectory: a zero jerk or acceleration limit, which ruckig refuses with
    its own ``RuckigError`` (the docstring promises ``ValueError``);
  - returns ruckig's time-optimal motion from rest to rest within the description's velocity limits and the given
    acceleration and jerk limits: it lasts ruckig's duration (to 1e-6 s);
  - respects every limit at every point (to 1e-6 in the limit's unit; the jerk as the change of acceleration between
    consecutive points, at most ``max_jerk * dt + 1e-6``);
  - is one motion: each point's positions, velocities and accelerations are ruckig's at its time (between two points
    the state follows from the first within what ``max_jerk`` allows, to 1e-6);
  - synchronizes the joints: each joint that moves arrives at its goal at the end of the move, not before (ruckig's
    default); a joint at rest at its goal (within 1e-9 rad and 1e-9 rad/s) before the last sample period is not
    synchronized;
  - has points at most ``sample_period`` apart (to 1e-9 s), as many as the move needs (``ceil(duration /
    sample_period)`` after t = 0; a point at t = 0 may be added), each with positions, velocities and accelerations
    for the joints in the order asked (``joint_names`` as given, not sorted); the last is the goal at rest (to 1e-6)
    at the motion's duration, whether or not the duration is a whole number of sample periods;
  - is computed with ruckig itself: the library's ``rw.motion.jerk_limited_trajectory`` is unavailable while grading;

* the joint trajectory controller accepts the result and the robot ends at the goal (within 1 mrad).

The descriptions: RRBot and a pan-tilt head with other joint names and other limits (so a hard-coded limit, joint
name or joint order fails). A trajectory whose joints come in another order than asked loses the order's point only
when its values follow its own joint_names (the joint trajectory controller reads them by name): the other checks read
it in the order asked. The sample periods: the default and others. Generated moves (Hypothesis) compare the
learner's trajectory with the reference planner (ruckig through the library's ``rw.motion``) on the same move.
"""

from __future__ import annotations

import math
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType, SimpleNamespace
from typing import Any

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import rrbot_workshop as rw
import rrbot_workshop.motion as motion
from rrbot_workshop.bringup import bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.description.xacro import descriptions_root

TASK = 13
FILE = "jerk_limited.py"
#: The reference planner, kept before grading makes it unavailable to the learner's code.
REFERENCE = motion.jerk_limited_trajectory
DEFAULT_PERIOD = 0.01
POSITION_TOL = 1e-6
LIMIT_TOL = 1e-6
TIME_TOL = 1e-6
SAMPLE_TOL = 1e-9
REST_TOL = 1e-9
FINAL_TOL = 1e-3
#: Calls of the learner's plan() the shrinking of a generated failure may take (bounds the grading time).
SHRINK_BUDGET = 25

#: A second description: other joint names, other limits, a continuous joint (no position limits) and a fixed joint.
PAN_TILT = """<?xml version="1.0"?>
<robot name="pan_tilt">
  <link name="base"/><link name="pan_link"/><link name="tilt_link"/><link name="wheel_link"/><link name="tool"/>
  <joint name="pan" type="revolute"><parent link="base"/><child link="pan_link"/><axis xyz="0 0 1"/>
    <limit lower="-1.0" upper="2.0" velocity="1.5" effort="10"/></joint>
  <joint name="tilt" type="revolute"><parent link="pan_link"/><child link="tilt_link"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="0.5" velocity="0.8" effort="10"/></joint>
  <joint name="wheel" type="continuous"><parent link="tilt_link"/><child link="wheel_link"/><axis xyz="0 1 0"/>
    <limit velocity="2.0" effort="10"/></joint>
  <joint name="tool_mount" type="fixed"><parent link="wheel_link"/><child link="tool"/></joint>
  <ros2_control name="PanTilt" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="pan"><command_interface name="position"/><state_interface name="position"/></joint>
    <joint name="tilt"><command_interface name="position"/><state_interface name="position"/></joint>
    <joint name="wheel"><command_interface name="velocity"/><state_interface name="position"/></joint>
  </ros2_control>
</robot>
"""


@dataclass(frozen=True)
class Move:
    """One call of ``plan``: a description, joints in the order asked, start, goal, limits, sample period."""

    robot: str
    joints: tuple[str, ...]
    start: tuple[float, ...]
    goal: tuple[float, ...]
    acc: float
    jerk: float
    period: float | None = None  # None: plan() is called without sample_period (its default)

    @property
    def sample_period(self) -> float:
        return DEFAULT_PERIOD if self.period is None else self.period

    def __str__(self) -> str:
        """The call, as the learner would write it."""
        period = "" if self.period is None else f", sample_period={_num(self.period)}"
        return (f"plan(<{self.robot} URDF>, {list(self.joints)}, {_nums(self.start)}, {_nums(self.goal)}, "
                f"{_num(self.acc)}, {_num(self.jerk)}{period})")


def _num(x: float) -> str:
    return f"{x:.6g}"


def _nums(values: Sequence[float]) -> str:
    return "[" + ", ".join(_num(v) for v in values) + "]"


MOVES = [
    Move("RRBot", ("joint1", "joint2"), (0.0, 0.0), (1.2, -0.5), 4.0, 20.0),
    # long enough for joint1 to cruise at the URDF's velocity limit
    Move("RRBot", ("joint1", "joint2"), (0.3, 1.0), (-5.0, 3.5), 10.0, 40.0, 0.02),
    # joints asked in the other order; joint1 moves little
    Move("RRBot", ("joint2", "joint1"), (0.0, 0.0), (2.0, 0.1), 3.0, 10.0, 0.005),
    # the other description: tilt cruises at its 0.8 rad/s
    Move("pan-tilt", ("tilt", "pan"), (0.0, 0.0), (-2.0, 1.5), 2.0, 6.0, 1 / 30),
    Move("pan-tilt", ("pan", "tilt"), (1.0, -1.0), (-0.9, 0.4), 5.0, 50.0, 0.0125),
    # one joint, a short move that never reaches the acceleration limit
    Move("RRBot", ("joint2",), (0.0,), (0.05,), 2.0, 5.0),
    # a duration that is a whole number of sample periods: joint1 moves 1 rad within jerk 32 alone (four jerk phases
    # of 0.25 s), 1.0 s exactly, 20 periods of 0.05 s
    Move("RRBot", ("joint1", "joint2"), (0.0, 0.0), (1.0, 0.3), 10.0, 32.0, 0.05),
]
#: The move of ``MOVES`` whose duration is a whole number of sample periods (1.0 s, 20 x 0.05 s).
WHOLE_PERIODS = MOVES[-1]


# ----------------------------------------------------------------------------------------------------------- fixtures
@pytest.fixture(scope="module")
def urdfs() -> dict[str, str]:
    rrbot = process_xacro(descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro", use_mock_hardware=True)
    return {"RRBot": rrbot, "pan-tilt": PAN_TILT}


@pytest.fixture(scope="module")
def limits(urdfs: dict[str, str]) -> dict[str, dict[str, Any]]:
    return {robot: {name: lim for info in parse_ros2_control(urdf) for name, lim in info.limits.items()}
            for robot, urdf in urdfs.items()}


@pytest.fixture(scope="module")
def learner(task_file: Callable[[int, str], Path]) -> Iterator[ModuleType]:
    """The learner's module, loaded while the library's planner is unavailable (the task is to use ruckig)."""
    task_file(TASK, FILE)

    def refuse(*_args: Any, **_kwargs: Any) -> Any:
        raise AssertionError(f"your {FILE} called rw.motion.jerk_limited_trajectory: the task is to plan with ruckig "
                             "yourself (from ruckig import InputParameter, Ruckig, Trajectory)")

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(motion, "jerk_limited_trajectory", refuse)
        module = rw.course.load_module(TASK, FILE, quiet=True)
        if module is None:
            _fail(f"your {FILE} does not import: run it in notebook 13 to see the error")
        yield module


def _fail(message: str) -> None:
    pytest.fail(message, pytrace=False)


def _function(module: ModuleType, name: str) -> Callable[..., Any]:
    fn = getattr(module, name, None)
    if not callable(fn):
        _fail(f"your {FILE} has no function {name}()")
    return fn  # type: ignore[return-value]


def _call(module: ModuleType, name: str, *args: Any, **kwargs: Any) -> Any:
    try:
        return _function(module, name)(*args, **kwargs)
    except NotImplementedError:
        _fail(f"{name}() in your {FILE} is not written yet (it raises NotImplementedError)")


def _plan(learner: ModuleType, urdfs: dict[str, str], move: Move) -> Any:
    args = (urdfs[move.robot], list(move.joints), list(move.start), list(move.goal), move.acc, move.jerk)
    if move.period is None:
        return _call(learner, "plan", *args)
    return _call(learner, "plan", *args, sample_period=move.period)


_DURATIONS: dict[Move, float] = {}


def _reference_duration(limits: dict[str, dict[str, Any]], move: Move) -> float:
    """The duration of the reference planner's move (ruckig through ``rw.motion``), sampled coarsely: only its last
    point's time is used."""
    if move not in _DURATIONS:
        lims = limits[move.robot]
        reference = REFERENCE(list(move.joints), list(move.start), list(move.goal),
                              [lims[j].max_velocity for j in move.joints], move.acc, move.jerk, sample_period=1e3)
        _DURATIONS[move] = float(reference.points[-1].time_from_start)
    return _DURATIONS[move]


def _expect_value_error(fn: Callable[[], Any], refused: str, name: str | None = None) -> None:
    """``fn()`` must raise ValueError (naming ``name``); other exceptions are the learner's and propagate."""
    function = refused.split("(", 1)[0]
    try:
        fn()
    except NotImplementedError:
        _fail(f"{function}() in your {FILE} is not written yet (it raises NotImplementedError)")
    except ValueError as exc:
        if name is None or name in str(exc):
            return
        message = f"{refused}: your ValueError says {str(exc)!r}, which does not name the joint '{name}'"
    else:
        message = f"{refused}: your code returned without raising ValueError"
    _fail(message)  # outside the except: the reason is this one, not the learner's ValueError


# ---------------------------------------------------------------------------------------------- what a plan must be
def _shape_problem(traj: Any, move: Move, order: bool = True) -> str | None:
    """What is wrong with the trajectory's shape (joint names, one value per joint in each field), or None.

    Args:
        traj: The learner's trajectory.
        move: The call that made it.
        order: Whether the joint names must come in the order asked (else any order of the joints asked).
    """
    names = list(getattr(traj, "joint_names", None) or [])
    if sorted(names) != sorted(move.joints) or len(set(names)) != len(names):
        return f"{move}: the trajectory's joint_names are {names}; they must be the joints asked, in that order"
    if order and names != list(move.joints):
        return (f"{move}: the trajectory's joint_names are {names}; they must be the joints asked, in the order asked "
                f"({list(move.joints)}), with every point's values in that order")
    points = list(getattr(traj, "points", None) or [])
    if not points:
        return f"{move}: the trajectory has no points"
    n = len(move.joints)
    for k, p in enumerate(points):
        for field in ("positions", "velocities", "accelerations"):
            values = list(getattr(p, field, None) or [])
            if len(values) != n:
                return (f"{move}: point {k} has {len(values)} {field} for {n} joint(s); every point must carry "
                        "positions, velocities and accelerations, so the JTC follows ruckig's motion (quintic splines)")
    return None


def _points(traj: Any, move: Move) -> list[Any]:
    """The trajectory's points, after checking its shape, with their values in the order of the joints asked.

    A trajectory that names the joints in another order is read by its names, as the joint trajectory controller reads
    it: the order asked is a rule of its own (:func:`test_joints_in_the_order_asked`).
    """
    problem = _shape_problem(traj, move, order=False)
    if problem:
        _fail(problem)
    names = list(traj.joint_names)
    if names == list(move.joints):
        return list(traj.points)
    index = [names.index(j) for j in move.joints]
    return [SimpleNamespace(time_from_start=p.time_from_start, **{
        field: [list(getattr(p, field))[i] for i in index] for field in ("positions", "velocities", "accelerations")})
        for p in traj.points]


def _sampling_problem(points: list[Any], move: Move) -> str | None:
    period = move.sample_period
    times = [float(p.time_from_start) for p in points]
    if times[0] < -SAMPLE_TOL or times[0] > period + SAMPLE_TOL:
        return f"{move}: the first point is at {_num(times[0])} s; it must be at 0 s or one sample_period later"
    for k, (a, b) in enumerate(zip(times, times[1:], strict=False)):
        if not b - a > 0.0:
            return (f"{move}: points {k} and {k + 1} are at {_num(a)} s and {_num(b)} s; time_from_start must "
                    "increase from point to point (the JTC refuses such a trajectory)")
        if b - a > period + SAMPLE_TOL:
            return (f"{move}: points {k} and {k + 1} are {_num(b - a)} s apart; they must be at most sample_period = "
                    f"{_num(period)} s apart")
    after_zero = sum(1 for t in times if t > SAMPLE_TOL)
    duration = times[-1]
    needed = {math.ceil(duration / period - 1e-6), math.ceil(duration / period + 1e-6)}
    if after_zero not in needed:
        return (f"{move}: the move lasts {_num(duration)} s and has {after_zero} points after t = 0; sampled every "
                f"sample_period = {_num(period)} s it has {min(needed)}")
    return None


def _limits_problem(points: list[Any], move: Move, lims: dict[str, Any]) -> str | None:
    for p in points:
        for j, joint in enumerate(move.joints):
            vmax = lims[joint].max_velocity
            if not abs(p.velocities[j]) <= vmax + LIMIT_TOL:
                return (f"{move}: at {_num(p.time_from_start)} s {joint} moves at {_num(p.velocities[j])} rad/s; its "
                        f"URDF velocity limit is {_num(vmax)} rad/s")
            if not abs(p.accelerations[j]) <= move.acc + LIMIT_TOL:
                return (f"{move}: at {_num(p.time_from_start)} s {joint} accelerates at {_num(p.accelerations[j])} "
                        f"rad/s², beyond max_acceleration")
    for a, b in zip(points, points[1:], strict=False):
        dt = b.time_from_start - a.time_from_start
        for j, joint in enumerate(move.joints):
            change = b.accelerations[j] - a.accelerations[j]
            if not abs(change) <= move.jerk * dt + LIMIT_TOL:
                return (f"{move}: between {_num(a.time_from_start)} s and {_num(b.time_from_start)} s the acceleration "
                        f"of {joint} changes by {_num(change)} rad/s², a jerk of {_num(change / dt)} rad/s³, beyond "
                        "max_jerk")
    return None


def _motion_problem(points: list[Any], move: Move) -> str | None:
    """Positions, velocities and accelerations must be one jerk-limited motion: between two points, the position and
    velocity reached follow from the first point's state within what max_jerk allows (Taylor's bound)."""
    for a, b in zip(points, points[1:], strict=False):
        dt = b.time_from_start - a.time_from_start
        for j, joint in enumerate(move.joints):
            p = a.positions[j] + a.velocities[j] * dt + a.accelerations[j] * dt**2 / 2
            v = a.velocities[j] + a.accelerations[j] * dt
            if abs(b.positions[j] - p) > move.jerk * dt**3 / 6 + LIMIT_TOL or \
                    abs(b.velocities[j] - v) > move.jerk * dt**2 / 2 + LIMIT_TOL:
                return (f"{move}: {joint} from {_num(a.time_from_start)} s to {_num(b.time_from_start)} s "
                        f"({_num(a.positions[j])} rad, {_num(a.velocities[j])} rad/s, {_num(a.accelerations[j])} rad/s² "
                        f"to {_num(b.positions[j])} rad, {_num(b.velocities[j])} rad/s) is no motion within max_jerk: "
                        "give each point ruckig's state at its time")
    return None


def _sync_problem(points: list[Any], move: Move) -> str | None:
    end = points[-1].time_from_start
    for j, joint in enumerate(move.joints):
        if abs(move.goal[j] - move.start[j]) <= REST_TOL:
            continue
        for p in points[:-1]:
            if p.time_from_start >= end - move.sample_period / 2:
                break
            if abs(p.positions[j] - move.goal[j]) <= REST_TOL and abs(p.velocities[j]) <= REST_TOL:
                return (f"{move}: {joint} is at rest at its goal from {_num(p.time_from_start)} s, but the move lasts "
                        f"until {_num(end)} s; the joints must arrive together, synchronized in time (ruckig's default)")
    return None


def _end_problem(points: list[Any], move: Move) -> str | None:
    last = points[-1]
    for j, joint in enumerate(move.joints):
        if abs(last.positions[j] - move.goal[j]) > POSITION_TOL:
            return f"{move}: the last point puts {joint} at {_num(last.positions[j])} rad; it must be the goal"
        if abs(last.velocities[j]) > POSITION_TOL or abs(last.accelerations[j]) > POSITION_TOL:
            return (f"{move}: the last point gives {joint} velocity {_num(last.velocities[j])} rad/s and acceleration "
                    f"{_num(last.accelerations[j])} rad/s²; the move ends at rest (both 0)")
    return None


def _duration_problem(points: list[Any], move: Move, expected: float) -> str | None:
    got = float(points[-1].time_from_start)
    if abs(got - expected) > TIME_TOL:
        slower = " (is every velocity limit the description's?)" if got > expected else ""
        return (f"{move}: the last point is at {_num(got)} s; ruckig's time-optimal move within these limits lasts "
                f"{_num(expected)} s{slower}")
    return None


def _each_move(learner: ModuleType, urdfs: dict[str, str], check: Callable[[list[Any], Move], str | None]) -> None:
    for move in MOVES:
        problem = check(_points(_plan(learner, urdfs, move), move), move)
        if problem:
            _fail(problem)


# ------------------------------------------------------------------------------------------------------------ checks
@graded(points=2, hint=(
    "Task 13.1: the limits come from each joint's URDF <limit> (lower, upper, velocity), as parsed for "
    "<ros2_control>; read them from the description you are given, for the joints you are asked, never as constants.",
    "rw.description.parse_ros2_control(urdf) returns one HardwareInfo per <ros2_control> tag; its .limits maps a "
    "joint name to JointLimits with min_position, max_position and max_velocity.",
    "limits = {name: lim for info in parse_ros2_control(urdf) for name, lim in info.limits.items()}\n"
    "return {name: (limits[name].min_position, limits[name].max_position, limits[name].max_velocity) "
    "for name in joint_names}"))
def test_joint_limits(learner: ModuleType, urdfs: dict[str, str], limits: dict[str, dict[str, Any]]) -> None:
    for robot, joints in (("RRBot", ["joint2", "joint1"]), ("pan-tilt", ["pan", "tilt"]), ("pan-tilt", ["tilt"])):
        got = _call(learner, "joint_limits", urdfs[robot], joints)
        if not isinstance(got, dict) or sorted(got) != sorted(joints):
            _fail(f"joint_limits() on the {robot} description for {joints} returned {got!r}; it must return a dict "
                  "with exactly those joints as keys")
        for joint in joints:
            lim = limits[robot][joint]
            expected = (lim.min_position, lim.max_position, lim.max_velocity)
            value = got[joint]
            try:
                values = [float(v) for v in value]
            except (TypeError, ValueError):
                values = []
            if len(values) != 3 or any(abs(a - b) > 1e-9 for a, b in zip(values, expected, strict=True)):
                _fail(f"joint_limits() on the {robot} description gives {joint} {value!r}; its <limit> gives "
                      f"(min_position, max_position, max_velocity) = ({_num(expected[0])}, {_num(expected[1])}, "
                      f"{_num(expected[2])})")


@graded(points=1, after=("test_joint_limits",), hint=(
    "Task 13.1: a joint that no <ros2_control> tag names, or that has no position or velocity limit (a continuous "
    "joint has no position limits), cannot be planned for: refuse it with a ValueError that names it.",
    "JointLimits has has_position_limits and has_velocity_limits; a name missing from every HardwareInfo.limits is "
    "in no <ros2_control> tag.",
    "if name not in limits: raise ValueError(f\"joint '{name}' is in no <ros2_control> tag\")\n"
    "if not (lim.has_position_limits and lim.has_velocity_limits): raise ValueError(f\"joint '{name}' has no ...\")"))
def test_joint_limits_refuses_unknown_and_unlimited_joints(learner: ModuleType, urdfs: dict[str, str]) -> None:
    fn = _function(learner, "joint_limits")
    _expect_value_error(lambda: fn(urdfs["RRBot"], ["joint1", "elbow"]),
                        "joint_limits() on RRBot for ['joint1', 'elbow'] (no joint 'elbow')", "elbow")
    _expect_value_error(lambda: fn(urdfs["pan-tilt"], ["tool_mount"]),
                        "joint_limits() on the pan-tilt description for the fixed joint 'tool_mount' (in no "
                        "<ros2_control> tag)", "tool_mount")
    _expect_value_error(lambda: fn(urdfs["pan-tilt"], ["pan", "wheel"]),
                        "joint_limits() on the pan-tilt description for the continuous joint 'wheel' (no position "
                        "limits)", "wheel")


_GOAL_HINT = (
    "Task 13.2: before planning, compare each joint's goal with its position limits, on both sides: a goal below "
    "min_position is as invalid as one above max_position; a goal exactly at a limit is within them.",
    "joint_limits(urdf, joint_names)[name] gives (min_position, max_position, max_velocity); raise ValueError with the "
    "joint's name in the message.",
    "for name, g in zip(joint_names, goal):\n    low, high, _ = limits[name]\n    if not low <= g <= high:\n"
    "        raise ValueError(f\"goal {g} of joint '{name}' is outside [{low}, {high}]\")")


@graded(points=2, after=("test_joint_limits",),
        hint=_GOAL_HINT)
def test_goal_outside_limits_is_refused(learner: ModuleType, urdfs: dict[str, str],
                                        limits: dict[str, dict[str, Any]]) -> None:
    fn = _function(learner, "plan")
    cases = [("RRBot", ["joint1", "joint2"], "joint2", +0.3), ("RRBot", ["joint1", "joint2"], "joint2", -0.3),
             ("RRBot", ["joint2", "joint1"], "joint1", +0.2), ("RRBot", ["joint1", "joint2"], "joint1", -0.2),
             ("pan-tilt", ["tilt", "pan"], "pan", -0.1), ("pan-tilt", ["pan", "tilt"], "tilt", +0.1)]
    for robot, joints, bad, beyond in cases:
        lim = limits[robot][bad]
        goal = [0.0 if j != bad else (lim.max_position + beyond if beyond > 0 else lim.min_position + beyond)
                for j in joints]
        side = (f"above its upper limit {_num(lim.max_position)} rad" if beyond > 0
                else f"below its lower limit {_num(lim.min_position)} rad")
        _expect_value_error(lambda r=robot, js=joints, g=goal: fn(urdfs[r], js, [0.0] * len(js), g, 4.0, 20.0),
                            f"plan() on the {robot} description with joint_names {joints} and goal "
                            f"{[round(x, 4) for x in goal]} ({bad} {side})", bad)


@graded(points=1, after=("test_joints_in_the_order_asked",), hint=(
    "Task 13.2: ruckig cannot plan with a zero jerk or acceleration limit; it refuses with its own RuckigError. The "
    "docstring promises a ValueError when ruckig finds no trajectory, so a caller needs to catch one error only.",
    "Ruckig(n).calculate raises ruckig.RuckigError for limits it cannot use, and returns a Result that is neither "
    "Result.Working nor Result.Finished when it finds nothing; turn both into ValueError.",
    "try:\n    result = Ruckig(n).calculate(inp, trajectory)\nexcept RuckigError as exc:\n"
    "    raise ValueError(f\"ruckig found no trajectory: {exc}\") from exc"))
def test_impossible_limits_are_refused(learner: ModuleType, urdfs: dict[str, str]) -> None:
    fn = _function(learner, "plan")
    for acc, jerk in ((4.0, 0.0), (0.0, 20.0)):
        call = f"plan(<RRBot URDF>, ['joint1', 'joint2'], [0, 0], [1.2, -0.5], {_num(acc)}, {_num(jerk)})"
        try:
            fn(urdfs["RRBot"], ["joint1", "joint2"], [0.0, 0.0], [1.2, -0.5], acc, jerk)
        except NotImplementedError:
            _fail(f"plan() in your {FILE} is not written yet (it raises NotImplementedError)")
        except ValueError:
            continue
        except Exception as exc:  # noqa: BLE001 - which error the learner's plan() lets out is what is graded
            first = next((line.strip() for line in str(exc).splitlines() if line.strip()), "")
            lines = [f.lineno for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename).name == FILE]
            where = f"your {FILE}, line {lines[-1]}" if lines else f"your {FILE}"
            message = (f"{where}: {call} let {type(exc).__name__} out ({first}); ruckig finds no trajectory with a "
                       "zero limit, and the docstring promises ValueError then")
        else:
            message = (f"your {FILE}: {call} returned without raising ValueError; ruckig finds no trajectory with a "
                       "zero limit, and the docstring promises ValueError then")
        _fail(message)  # outside the except: the reason is this one, not the learner's exception


@graded(points=1, after=("test_joint_limits", "test_goal_outside_limits_is_refused"),
        hint=(
    "Task 13.2: the trajectory names the joints in the order they were asked (joint_names as given, not sorted), and "
    "every point's positions, velocities and accelerations follow that order.",
    "JointTrajectory(joint_names=list(joint_names), ...); start, goal and the limits are given in that order too.",
    "return JointTrajectory(joint_names=list(joint_names), points=points)"))
def test_joints_in_the_order_asked(learner: ModuleType, urdfs: dict[str, str]) -> None:
    for move in MOVES:
        problem = _shape_problem(_plan(learner, urdfs, move), move)
        if problem:
            _fail(problem)


@graded(points=1, after=("test_joints_in_the_order_asked", "test_ends_at_the_goal_at_rest"),
        hint=(
    "Task 13.2: position limits are inclusive: a goal exactly at min_position or max_position is within them and "
    "must be planned.",
    "Compare with <= on both sides, not <.",
    "if not low <= g <= high: raise ValueError(...)"))
def test_goal_at_a_limit_is_planned(learner: ModuleType, urdfs: dict[str, str],
                                    limits: dict[str, dict[str, Any]]) -> None:
    for robot, joints, goals in (
        ("RRBot", ("joint1", "joint2"), ("max", "min")),
        ("pan-tilt", ("tilt", "pan"), ("max", "min")),
        ("RRBot", ("joint2",), ("max",)),
    ):
        lims = limits[robot]
        goal = tuple(getattr(lims[j], f"{side}_position") for j, side in zip(joints, goals, strict=True))
        move = Move(robot, joints, (0.0,) * len(joints), goal, 6.0, 30.0)
        points = _points(_plan(learner, urdfs, move), move)
        problem = _end_problem(points, move)
        if problem:
            _fail(problem)


@graded(points=1, hint=(
    "Task 13.2: one start and one goal position per joint: lists of other lengths cannot be planned (ruckig would "
    "take them without complaint).",
    "Compare len(joint_names), len(start) and len(goal) first, and raise ValueError.",
    "if not len(start) == len(goal) == len(joint_names):\n"
    "    raise ValueError(f\"{len(joint_names)} joints, {len(start)} start and {len(goal)} goal positions\")"))
def test_lengths_that_differ_are_refused(learner: ModuleType, urdfs: dict[str, str]) -> None:
    fn = _function(learner, "plan")
    urdf = urdfs["RRBot"]
    _expect_value_error(lambda: fn(urdf, ["joint1", "joint2"], [0.0], [0.5, 0.5], 4.0, 20.0),
                        "plan() with two joints and one start position")
    _expect_value_error(lambda: fn(urdf, ["joint1", "joint2"], [0.0, 0.0], [0.5, 0.5, 0.5], 4.0, 20.0),
                        "plan() with two joints and three goal positions")
    _expect_value_error(lambda: fn(urdf, ["joint1"], [0.0, 0.0], [0.5, 0.5], 4.0, 20.0),
                        "plan() with one joint and two start and goal positions")


@graded(points=3, after=("test_joints_in_the_order_asked",),
        hint=(
    "Task 13.2: ruckig keeps velocity, acceleration and jerk within the limits it is given: give it the description's "
    "velocity limit of each joint (in the order asked) and the acceleration and jerk limits you are given, and copy "
    "its velocities and accelerations into every point.",
    "InputParameter(n): max_velocity, max_acceleration and max_jerk take one value per joint; trajectory.at_time(t) "
    "returns (positions, velocities, accelerations).",
    "inp.max_velocity = [limits[name][2] for name in joint_names]\ninp.max_acceleration = [max_acceleration] * n\n"
    "inp.max_jerk = [max_jerk] * n"))
def test_limits_respected(learner: ModuleType, urdfs: dict[str, str], limits: dict[str, dict[str, Any]]) -> None:
    _each_move(learner, urdfs, lambda points, move: _limits_problem(points, move, limits[move.robot]))


@graded(points=2, after=("test_joints_in_the_order_asked", "test_limits_respected", "test_sampled_every_sample_period"),
        hint=(
    "Task 13.2: the JTC interpolates between points with quintics from their positions, velocities and accelerations: "
    "they must be ruckig's, all three at the point's time, so that the JTC follows ruckig's motion.",
    "trajectory.at_time(t) returns (positions, velocities, accelerations) at t; use all three, at the same t as "
    "time_from_start.",
    "position, velocity, acceleration = trajectory.at_time(t)\n"
    "JointTrajectoryPoint(positions=list(position), velocities=list(velocity), accelerations=list(acceleration), "
    "time_from_start=t)"))
def test_points_carry_the_motion(learner: ModuleType, urdfs: dict[str, str]) -> None:
    _each_move(learner, urdfs, _motion_problem)


@graded(points=2, after=("test_joints_in_the_order_asked",),
        hint=(
    "Task 13.2: a jerk-limited move of several joints is synchronized: every joint arrives at its goal at the same "
    "time, the slower joints' duration. ruckig does it when it plans all joints in one InputParameter with its default "
    "synchronization; planning each joint alone lets the short moves end early.",
    "One Ruckig(n) and one InputParameter(n) for all joints; leave inp.synchronization at Synchronization.Time (or "
    "Phase), not None.",
    "inp = InputParameter(n)  # all joints together\ntrajectory = Trajectory(n)\nRuckig(n).calculate(inp, trajectory)"))
def test_joints_arrive_together(learner: ModuleType, urdfs: dict[str, str]) -> None:
    _each_move(learner, urdfs, _sync_problem)


@graded(points=2, after=("test_joints_in_the_order_asked",),
        hint=(
    "Task 13.2: sample the motion every sample_period, whatever value it has (not only 0.01 s): points at most "
    "sample_period apart, as many as the duration needs, then a last point at the motion's duration.",
    "Times k * sample_period for k = 1 .. ceil(duration / sample_period) - 1 (0 may be included), then duration "
    "itself; trajectory.duration is the motion's length in [s].",
    "times = [k * sample_period for k in range(1, math.ceil(duration / sample_period))] + [duration]"))
def test_sampled_every_sample_period(learner: ModuleType, urdfs: dict[str, str]) -> None:
    _each_move(learner, urdfs, _sampling_problem)


@graded(points=1, after=("test_joints_in_the_order_asked", "test_limits_respected", "test_sampled_every_sample_period"),
        hint=(
    "Task 13.2: the move ends where it was asked to, at rest: the last point is the goal with zero velocity and "
    "acceleration.",
    "trajectory.at_time(trajectory.duration) is ruckig's final state; or write the goal itself with zeros.",
    "points[-1] = JointTrajectoryPoint(positions=list(goal), velocities=[0.0] * n, accelerations=[0.0] * n, "
    "time_from_start=duration)"))
def test_ends_at_the_goal_at_rest(learner: ModuleType, urdfs: dict[str, str]) -> None:
    _each_move(learner, urdfs, _end_problem)


@graded(points=2, after=("test_joints_in_the_order_asked", "test_limits_respected",
               "test_sampled_every_sample_period", "test_ends_at_the_goal_at_rest"),
        hint=(
    "Task 13.2: ruckig's motion is the fastest within the limits; the last point's time_from_start is its duration. "
    "Slower means a smaller limit than the description's (or a hard-coded one).",
    "trajectory.duration after Ruckig(n).calculate(inp, trajectory); each joint's velocity limit is "
    "joint_limits(urdf, joint_names)[name][2].",
    "inp.max_velocity = [limits[name][2] for name in joint_names]\n...\nduration = trajectory.duration"))
def test_time_optimal(learner: ModuleType, urdfs: dict[str, str], limits: dict[str, dict[str, Any]]) -> None:
    for move in MOVES:
        points = _points(_plan(learner, urdfs, move), move)
        expected = _reference_duration(limits, move)
        problem = _duration_problem(points, move, expected)
        if problem:
            _fail(problem)


def _candidates(lim: Any) -> list[float]:
    """Positions a generated move may use for a joint: a 0.05 rad grid from 0 outwards, strictly within the limits (a
    goal at a limit is graded by :func:`test_goal_at_a_limit_is_planned` alone, both bounds: one slip, one rule)."""
    grid = sorted((round(k * 0.05, 2) for k in range(math.ceil(lim.min_position / 0.05),
                                                     math.floor(lim.max_position / 0.05) + 1)), key=abs)
    return [x for x in grid if lim.min_position < x < lim.max_position]


def _moves(limits: dict[str, dict[str, Any]]) -> st.SearchStrategy[Move]:
    """Moves the task allows: either description, one or two joints in any order, goals up to the limits, at least
    one joint moving. Each choice is one draw, and the simplest is a brisk move of RRBot's joint1 from 0."""
    orders = {"RRBot": [("joint1",), ("joint1", "joint2"), ("joint2",), ("joint2", "joint1")],
              "pan-tilt": [("pan",), ("tilt", "pan"), ("tilt",), ("pan", "tilt")]}
    positions = {robot: {j: _candidates(lim) for j, lim in lims.items() if lim.has_position_limits}
                 for robot, lims in limits.items()}

    @st.composite
    def moves(draw: st.DrawFn) -> Move:
        robot = draw(st.sampled_from(["RRBot", "pan-tilt"]))
        joints = draw(st.sampled_from(orders[robot]))
        start = tuple(draw(st.sampled_from(positions[robot][j])) for j in joints)
        goal = tuple(draw(st.sampled_from(positions[robot][j])) for j in joints)
        if all(abs(g - s) < 0.01 for g, s in zip(goal, start, strict=True)):  # a move moves something
            room = limits[robot][joints[0]].max_position
            goal = (start[0] + (0.05 if start[0] + 0.05 <= room else -0.05), *start[1:])
        acc = 20.0 - draw(st.integers(0, 38)) * 0.5
        jerk = 100.0 - draw(st.integers(0, 39)) * 2.5
        period = draw(st.sampled_from([None, 0.02, 0.005, 0.025]))
        return Move(robot, joints, start, goal, acc, jerk, period)

    return moves()


@graded(points=3, after=("test_limits_respected", "test_points_carry_the_motion", "test_joints_arrive_together",
               "test_sampled_every_sample_period", "test_ends_at_the_goal_at_rest", "test_time_optimal"),
        hint=(
    "Task 13.2: on any move the task allows (either description, joints in any order, goals up to the limits, other "
    "acceleration and jerk limits and sample periods), your trajectory must do what ruckig's does: same duration, "
    "joints arriving together, limits respected, sampled every sample_period, ending at the goal at rest.",
    "Read the move named in the reason and call plan() with it in notebook 13; compare with "
    "rw.motion.jerk_limited_trajectory(joint_names, start, goal, max_velocity, max_acceleration, max_jerk, "
    "sample_period).",
    "No constants in plan(): the velocity limits from joint_limits(urdf, joint_names), one InputParameter for all "
    "joints, times from sample_period and trajectory.duration."))
def test_generated_moves_match_ruckig(learner: ModuleType, urdfs: dict[str, str],
                                      limits: dict[str, dict[str, Any]]) -> None:
    seen: dict[Move, Exception] = {}  # the failures found, by move: replayed as they were
    failed: list[Move] = []  # every failing move tried; the smallest (see _size) is reported
    calls = {"plan": 0, "first_failure": -1}

    @settings(derandomize=True, database=None, deadline=None, max_examples=20,
              suppress_health_check=list(HealthCheck))
    @given(_moves(limits))
    @example(Move("RRBot", ("joint1",), (0.0,), (0.05,), 20.0, 100.0))  # small moves first: reported as they are
    @example(Move("RRBot", ("joint1", "joint2"), (0.0, 0.0), (0.1, 0.05), 20.0, 100.0))
    @example(Move("pan-tilt", ("tilt",), (0.0,), (-0.4,), 20.0, 100.0, 0.02))
    @example(Move("pan-tilt", ("tilt", "pan"), (0.0, 0.0), (-0.5, 0.4), 20.0, 100.0, 0.005))
    def same_as_ruckig(move: Move) -> None:
        if move in seen:
            raise seen[move]
        if calls["first_failure"] >= 0 and calls["plan"] - calls["first_failure"] >= SHRINK_BUDGET:
            raise _Enough  # stops Hypothesis at once (not an Exception): the smallest failure so far is reported
        calls["plan"] += 1
        try:
            traj = _plan(learner, urdfs, move)
            problem = _shape_problem(traj, move, order=False)
            if problem is None:
                points = _points(traj, move)
                problems = (_duration_problem(points, move, _reference_duration(limits, move)),
                            _sync_problem(points, move), _limits_problem(points, move, limits[move.robot]),
                            _sampling_problem(points, move), _end_problem(points, move), _motion_problem(points, move))
                problem = next((p for p in problems if p), None)
            if problem:
                raise _Differs(problem)
        except Exception as exc:  # a difference, or the learner's error on a move the task allows
            if calls["first_failure"] < 0:
                calls["first_failure"] = calls["plan"]
            if not isinstance(exc, _Differs):
                exc.add_note(f"on the generated move {move}")
            seen[move] = exc
            failed.append(move)
            raise

    try:
        same_as_ruckig()
        return
    except _Enough:
        pass
    except Exception as exc:  # Hypothesis's report of the failures: replaced by the smallest failure itself
        if not failed:
            raise
        del exc
    smallest: Exception = seen[min(failed, key=_size)]
    if isinstance(smallest, _Differs):
        _fail(f"Smallest generated move unlike ruckig's: {smallest}")
    smallest.__notes__ = [n for n in getattr(smallest, "__notes__", []) if n.startswith("on the generated move")][-1:]
    raise smallest  # the learner's own error, on the smallest move that raised it


def _size(move: Move) -> tuple[Any, ...]:
    """How big a move is to read: fewer joints, RRBot, the default period, a shorter way, brisker limits first."""
    way = sum(abs(g - s) for g, s in zip(move.goal, move.start, strict=True))
    return (len(move.joints), move.robot != "RRBot", move.period is not None, round(way, 6), -move.acc, -move.jerk)


class _Enough(BaseException):  # noqa: N818 - a signal, like StopIteration
    """Ends the shrinking of a generated failure (a BaseException, so Hypothesis does not take it as a failure)."""


class _Differs(Exception):
    """A generated move on which the learner's trajectory is not what ruckig's is."""


@graded(points=3, after=("test_limits_respected", "test_points_carry_the_motion", "test_sampled_every_sample_period",
               "test_ends_at_the_goal_at_rest", "test_time_optimal"),
        hint=(
    "Task 13: the joint trajectory controller must accept your trajectory and the robot must end at the goal "
    "(within 1 mrad): strictly increasing times, every field one value per joint, the joints in the order you "
    "name them.",
    "Publish the JointTrajectory on /joint_trajectory_controller/joint_trajectory and spin for its duration; "
    "/joint_states shows where the joints end.",
    "traj = plan(urdf, joint_names, start, goal, max_acceleration, max_jerk, sample_period)\n"
    "system.publish(\"/joint_trajectory_controller/joint_trajectory\", traj)"))
def test_jtc_executes_it(learner: ModuleType, urdfs: dict[str, str]) -> None:
    move = Move("RRBot", ("joint2", "joint1"), (0.0, 0.0), (-0.5, 1.2), 4.0, 20.0, 0.02)
    traj = _plan(learner, urdfs, move)
    system = bringup("rrbot", "rrbot_controllers.yaml", xacro_args={"use_mock_hardware": True},
                     spawn=["joint_state_broadcaster", "joint_trajectory_controller"])
    try:
        system.spin(0.1)
        system.publish("/joint_trajectory_controller/joint_trajectory", traj)
        end = float(traj.points[-1].time_from_start) if getattr(traj, "points", None) else 0.0
        system.spin(min(end, 10.0) + 0.5)
        msg = system.latest("/joint_states")
        final = {j: msg.position[msg.name.index(j)] for j in move.joints}
    finally:
        system.shutdown()
    for joint, goal in zip(move.joints, move.goal, strict=True):
        if abs(final[joint] - goal) > FINAL_TOL:
            _fail(f"{move}: the joint trajectory controller ran your trajectory and {joint} ended at "
                  f"{_num(final[joint])} rad, not at its goal {_num(goal)} rad (within 1 mrad)")
