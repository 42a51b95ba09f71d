"""The task-13 grader: wrong solutions, written as learners would, lose points; correct ones written differently get
full marks. Each is a copy of solutions/task13_jerk_limited_trajectories with changes (see grader_variants.py)."""

from __future__ import annotations

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

F = "jerk_limited.py"
GOAL_CHECK = "        if not low <= g <= high:\n"
SAMPLING = "    times = [k * sample_period for k in range(math.ceil(duration / sample_period - 1e-9))] + [duration]\n"
CALCULATE = ("    try:\n        result = Ruckig(n).calculate(inp, trajectory)\n"
             "    except RuckigError as exc:  # e.g. a zero limit: ruckig refuses the input itself\n")
ORDER = "    return JointTrajectory(joint_names=list(joint_names), points=points)\n"
LAST_POINT = ("    points[-1] = JointTrajectoryPoint(positions=list(goal), velocities=[0.0] * n, accelerations=[0.0] * n,\n"
              "                                      time_from_start=duration)\n")

WRONG = [
    Variant("goal_below_the_lower_limit_accepted", {F: [(GOAL_CHECK, "        if g > high:\n")]},
            fails={"goal_outside_limits_is_refused"}),
    Variant("goal_above_the_upper_limit_accepted", {F: [(GOAL_CHECK, "        if g < low:\n")]},
            fails={"goal_outside_limits_is_refused"}),
    Variant("goal_at_a_limit_refused", {F: [(GOAL_CHECK, "        if not low < g < high:\n")]},
            fails={"goal_at_a_limit_is_planned"}),
    Variant("joints_not_synchronized", {F: [
        ("from ruckig import InputParameter, Result, Ruckig, RuckigError, Trajectory",
         "from ruckig import InputParameter, Result, Ruckig, RuckigError, Synchronization, Trajectory"),
        ("    inp.max_jerk = [max_jerk] * n\n",
         "    inp.max_jerk = [max_jerk] * n\n    inp.synchronization = Synchronization.No\n")]},
        fails={"joints_arrive_together", "generated_moves_match_ruckig"}),
    Variant("each_joint_planned_alone", {F: [(
        "    if result not in (Result.Working, Result.Finished):\n"
        "        raise ValueError(f\"ruckig found no trajectory: {result.name}\")\n"
        "    duration = trajectory.duration\n",
        "    singles = []\n"
        "    for i in range(n):\n"
        "        one = InputParameter(1)\n"
        "        one.current_position, one.target_position = [start[i]], [goal[i]]\n"
        "        one.max_velocity, one.max_acceleration, one.max_jerk = [inp.max_velocity[i]], [max_acceleration], "
        "[max_jerk]\n"
        "        single = Trajectory(1)\n"
        "        Ruckig(1).calculate(one, single)\n"
        "        singles.append(single)\n"
        "    duration = max(s.duration for s in singles)\n"
        "\n"
        "    class _Joined:\n"
        "        def at_time(self, t):\n"
        "            states = [s.at_time(min(t, s.duration)) for s in singles]\n"
        "            return ([x[0][0] for x in states], [x[1][0] for x in states], [x[2][0] for x in states])\n"
        "\n"
        "    trajectory = _Joined()\n")]},
        fails={"joints_arrive_together"}),
    Variant("sample_period_hard_coded", {F: [(SAMPLING,
        "    times = [k * 0.01 for k in range(math.ceil(duration / 0.01))] + [duration]\n")]},
        fails={"sampled_every_sample_period", "generated_moves_match_ruckig"}),
    Variant("sampled_twice_as_often_to_be_safe", {F: [(SAMPLING,
        "    step = sample_period / 2\n    times = [k * step for k in range(math.ceil(duration / step))] + [duration]\n")]},
        fails={"sampled_every_sample_period"}),
    Variant("velocity_limit_hard_coded_to_pi", {F: [("    inp.max_velocity = [limits[name][2] for name in joint_names]\n",
                                                     "    inp.max_velocity = [math.pi] * n\n")]},
            fails={"time_optimal", "limits_respected"}),
    Variant("velocity_limits_in_sorted_joint_order", {F: [(
        "    inp.max_velocity = [limits[name][2] for name in joint_names]\n",
        "    inp.max_velocity = [limits[name][2] for name in sorted(joint_names)]\n")]},
        fails={"limits_respected"}),
    Variant("half_the_velocity_limit", {F: [("    inp.max_velocity = [limits[name][2] for name in joint_names]\n",
                                             "    inp.max_velocity = [0.5 * limits[name][2] for name in joint_names]\n")]},
            fails={"time_optimal"}),
    Variant("rrbot_limits_hard_coded", {F: [(
        "    limits = {name: lim for info in parse_ros2_control(urdf) for name, lim in info.limits.items()}\n",
        "    limits = {name: lim for info in parse_ros2_control(urdf) for name, lim in info.limits.items()}\n"
        "    rrbot = {\"joint1\": (-6.632251157578453, 6.632251157578453, math.pi),\n"
        "             \"joint2\": (-1.0471975511965976, 4.1887902047863905, math.pi)}\n"
        "    return {name: rrbot[name] for name in joint_names}\n")]},
        fails={"joint_limits", "goal_outside_limits_is_refused", "time_optimal"}),
    Variant("positions_only", {F: [(
        "        points.append(JointTrajectoryPoint(positions=list(position), velocities=list(velocity),\n"
        "                                           accelerations=list(acceleration), time_from_start=t))\n",
        "        points.append(JointTrajectoryPoint(positions=list(position), time_from_start=t))\n"), (
        LAST_POINT, "    points[-1] = JointTrajectoryPoint(positions=list(goal), time_from_start=duration)\n")]},
        fails={"limits_respected", "ends_at_the_goal_at_rest"}),
    Variant("velocities_left_at_zero", {F: [("velocities=list(velocity),", "velocities=[0.0] * n,")]},
            fails={"points_carry_the_motion", "generated_moves_match_ruckig"}),
    Variant("states_one_sample_late", {F: [("trajectory.at_time(t)", "trajectory.at_time(max(0.0, t - sample_period))")]},
            fails={"points_carry_the_motion"}),
    Variant("no_point_at_the_duration", {F: [(SAMPLING,
        "    times = [k * sample_period for k in range(math.ceil(duration / sample_period))]\n"), (LAST_POINT, "")]},
        fails={"ends_at_the_goal_at_rest", "time_optimal"}),
    Variant("limits_in_the_wrong_order", {F: [("out[name] = (lim.min_position, lim.max_position, lim.max_velocity)",
                                               "out[name] = (lim.max_velocity, lim.min_position, lim.max_position)")]},
            fails={"joint_limits"}),
    Variant("unknown_joint_raises_key_error", {F: [(
        "        if name not in limits:\n", "        if False:\n")]},
        fails={"joint_limits_refuses_unknown_and_unlimited_joints"}),
    Variant("joint_without_position_limits_accepted", {F: [(
        "        if not (lim.has_position_limits and lim.has_velocity_limits):\n", "        if False:\n")]},
        fails={"joint_limits_refuses_unknown_and_unlimited_joints"}),
    Variant("lengths_not_compared", {F: [(
        "    if not (len(start) == len(goal) == n):\n", "    if False:\n"), (
        "    for name, g in zip(joint_names, goal, strict=True):\n", "    for name, g in zip(joint_names, goal):\n")]},
        fails={"lengths_that_differ_are_refused"}),
    Variant("jerk_limit_given_the_acceleration", {F: [("    inp.max_jerk = [max_jerk] * n\n",
                                                       "    inp.max_jerk = [2 * max_jerk] * n\n")]},
            fails={"limits_respected", "time_optimal"}),
    Variant("calling_the_library_planner", {F: [("    inp = InputParameter(n)\n",
        "    import rrbot_workshop as rw\n"
        "    return rw.motion.jerk_limited_trajectory(joint_names, start, goal, [limits[j][2] for j in joint_names],\n"
        "                                             max_acceleration, max_jerk, sample_period)\n")]},
        fails={"limits_respected", "time_optimal", "jtc_executes_it"}, names_file=F),
    # a limit ruckig cannot use: the docstring promises ValueError
    Variant("ruckig_error_let_out_on_a_zero_limit", {F: [(CALCULATE,
        "    if True:\n        result = Ruckig(n).calculate(inp, trajectory)\n    if False:\n")]},
        fails={"impossible_limits_are_refused"}, only=True, names_file=F,
        says={"impossible_limits_are_refused": "let RuckigError out"}),
    Variant("empty_trajectory_on_a_zero_limit", {F: [(CALCULATE, CALCULATE.replace(
        "    except RuckigError as exc:", "    except RuckigError:\n"
        "        return JointTrajectory(joint_names=list(joint_names), points=[])\n    except ValueError as exc:"))]},
        fails={"impossible_limits_are_refused"}, only=True, says={"impossible_limits_are_refused": "without raising"}),
    # joints not in sorted order: the order asked is kept
    Variant("joint_names_sorted_values_not", {F: [(ORDER, ORDER.replace("list(joint_names)", "sorted(joint_names)"))]},
            fails={"joints_in_the_order_asked"},
            says={"joints_in_the_order_asked": "in the order asked", "goal_at_a_limit_is_planned": "fails because "
                  "joints_in_the_order_asked fails"}),
    Variant("planned_in_sorted_joint_order", {F: [("    limits = joint_limits(urdf, joint_names)\n",
        "    limits = joint_limits(urdf, joint_names)\n"
        "    order = sorted(range(n), key=lambda i: joint_names[i])\n"
        "    joint_names = [joint_names[i] for i in order]\n"
        "    start, goal = [start[i] for i in order], [goal[i] for i in order]\n")]},
        fails={"joints_in_the_order_asked"}, only=True, says={"joints_in_the_order_asked": "in the order asked"}),
    Variant("goals_checked_in_sorted_joint_order", {F: [(
        "    for name, g in zip(joint_names, goal, strict=True):\n",
        "    for name, g in zip(sorted(joint_names), goal, strict=True):\n")]},
        fails={"goal_outside_limits_is_refused", "joints_in_the_order_asked"},
        says={"goal_outside_limits_is_refused": "does not name the joint"}),
    # durations that are a whole number of sample periods, and ones that are not
    Variant("last_point_twice_on_a_whole_number_of_periods", {F: [(SAMPLING,
        "    times = [k * sample_period for k in range(int(duration / sample_period) + 1)] + [duration]\n")]},
        fails={"sampled_every_sample_period"}, only=True,
        says={"sampled_every_sample_period": "time_from_start must increase"}),
    Variant("last_gap_too_long_between_periods", {F: [(SAMPLING,
        "    times = [k * sample_period for k in range(int(duration / sample_period))] + [duration]\n")]},
        fails={"sampled_every_sample_period", "generated_moves_match_ruckig"}, only=True,
        says={"sampled_every_sample_period": "at most sample_period"}),
    # limits at both bounds
    Variant("goal_at_the_upper_limit_refused", {F: [(GOAL_CHECK, "        if not low <= g < high:\n")]},
            fails={"goal_at_a_limit_is_planned"}, only=True, says={"goal_at_a_limit_is_planned": "outside"}),
    Variant("goal_at_the_lower_limit_refused", {F: [(GOAL_CHECK, "        if not low < g <= high:\n")]},
            fails={"goal_at_a_limit_is_planned"}, only=True, says={"goal_at_a_limit_is_planned": "outside"}),
]

ALT_ELEMENT_TREE = '''"""Task 13: joint limits read from the URDF text, a phase-synchronized move sampled in a while loop."""

import xml.etree.ElementTree as ET

from ruckig import InputParameter, Ruckig, Synchronization, Trajectory

from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint


def joint_limits(urdf, joint_names):
    root = ET.fromstring(urdf.lstrip())
    controlled = {j.get("name") for tag in root.iter("ros2_control") for j in tag.iter("joint")}
    urdf_joints = {j.get("name"): j for j in root.findall("joint")}
    result = {}
    for name in joint_names:
        if name not in controlled:
            raise ValueError(f"{name}: no <ros2_control> tag names this joint")
        joint = urdf_joints.get(name)
        limit = None if joint is None else joint.find("limit")
        if limit is None or joint.get("type") not in ("revolute", "prismatic") or limit.get("velocity") is None:
            raise ValueError(f"{name}: no position or velocity limit")
        result[name] = (float(limit.get("lower")), float(limit.get("upper")), abs(float(limit.get("velocity"))))
    return result


def plan(urdf, joint_names, start, goal, max_acceleration, max_jerk, sample_period=0.01):
    count = len(joint_names)
    if len(start) != count or len(goal) != count:
        raise ValueError("start and goal need one position per joint")
    limits = joint_limits(urdf, joint_names)
    for i, name in enumerate(joint_names):
        lower, upper, _ = limits[name]
        if goal[i] < lower or goal[i] > upper:
            raise ValueError(f"the goal of {name} is out of [{lower}, {upper}]")
    request = InputParameter(count)
    request.current_position = list(start)
    request.target_position = list(goal)
    request.max_velocity = [limits[name][2] for name in joint_names]
    request.max_acceleration = [max_acceleration for _ in joint_names]
    request.max_jerk = [max_jerk for _ in joint_names]
    request.synchronization = Synchronization.Phase
    if not (max_acceleration > 0 and max_jerk > 0):
        raise ValueError("max_acceleration and max_jerk must be positive")
    motion = Trajectory(count)
    Ruckig(count).calculate(request, motion)
    points = []
    k = 0
    while k * sample_period < motion.duration:
        t = k * sample_period
        p, v, a = motion.at_time(t)
        points.append(JointTrajectoryPoint(positions=p, velocities=v, accelerations=a, time_from_start=t))
        k += 1
    p, v, a = motion.at_time(motion.duration)
    points.append(JointTrajectoryPoint(positions=p, velocities=v, accelerations=a, time_from_start=motion.duration))
    return JointTrajectory(joint_names=list(joint_names), points=points)
'''

ALT_LINSPACE = '''"""Task 13: evenly spread samples (never further apart than sample_period), numpy throughout."""

import math

import numpy as np
import ruckig

import rrbot_workshop as rw
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint


def joint_limits(urdf, joint_names):
    merged = {}
    for hardware in rw.description.parse_ros2_control(urdf):
        merged.update(hardware.limits)
    missing = [name for name in joint_names if name not in merged]
    if missing:
        raise ValueError(f"not in any <ros2_control> tag: {', '.join(missing)}")
    unlimited = [n for n in joint_names if not merged[n].has_position_limits or not merged[n].has_velocity_limits]
    if unlimited:
        raise ValueError(f"no position or velocity limit: {', '.join(unlimited)}")
    return {n: (merged[n].min_position, merged[n].max_position, merged[n].max_velocity) for n in joint_names}


def plan(urdf, joint_names, start, goal, max_acceleration, max_jerk, sample_period=0.01):
    names = list(joint_names)
    if not len(names) == len(start) == len(goal):
        raise ValueError(f"{len(names)} joints, {len(start)} starts, {len(goal)} goals")
    limits = joint_limits(urdf, names)
    outside = [n for n, g in zip(names, goal) if not limits[n][0] <= g <= limits[n][1]]
    if outside:
        raise ValueError(f"goal outside the position limits of {', '.join(outside)}")
    dofs = len(names)
    inp = ruckig.InputParameter(dofs)
    inp.current_position, inp.target_position = list(start), list(goal)
    inp.max_velocity = [limits[n][2] for n in names]
    inp.max_acceleration = [max_acceleration] * dofs
    inp.max_jerk = [max_jerk] * dofs
    inp.synchronization = ruckig.Synchronization.Time
    out = ruckig.Trajectory(dofs)
    try:
        found = ruckig.Ruckig(dofs).calculate(inp, out)
    except ruckig.RuckigError as exc:
        raise ValueError(f"ruckig refused the limits: {exc}") from None
    if found not in (ruckig.Result.Working, ruckig.Result.Finished):
        raise ValueError("ruckig found no trajectory")
    steps = max(1, math.ceil(out.duration / sample_period))
    points = []
    for t in np.linspace(0.0, out.duration, steps + 1)[1:]:
        p, v, a = out.at_time(float(t))
        points.append(JointTrajectoryPoint(positions=list(p), velocities=list(v), accelerations=list(a),
                                           time_from_start=float(t)))
    points[-1] = JointTrajectoryPoint(positions=list(goal), velocities=[0.0] * dofs, accelerations=[0.0] * dofs,
                                      time_from_start=out.duration)
    return JointTrajectory(joint_names=names, points=points)
'''

ALT_ARANGE = '''"""Task 13: a small planner object; times from numpy's arange."""

import numpy as np
from ruckig import InputParameter, Ruckig, Trajectory

from rrbot_workshop.description import parse_ros2_control
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint


def joint_limits(urdf, joint_names):
    table = {}
    for info in parse_ros2_control(urdf):
        for joint, lim in info.limits.items():
            table[joint] = lim
    answer = {}
    for joint in joint_names:
        lim = table.get(joint)
        if lim is None:
            raise ValueError("unknown joint " + joint)
        if not lim.has_position_limits:
            raise ValueError("joint " + joint + " has no position limits")
        if not lim.has_velocity_limits:
            raise ValueError("joint " + joint + " has no velocity limit")
        answer[joint] = (lim.min_position, lim.max_position, lim.max_velocity)
    return answer


class _Planner:
    def __init__(self, limits, joints):
        self.limits, self.joints = limits, list(joints)

    def check(self, start, goal):
        if len(start) != len(self.joints) or len(goal) != len(self.joints):
            raise ValueError("one start and one goal per joint, please")
        for joint, g in zip(self.joints, goal):
            low, high, _ = self.limits[joint]
            if g < low:
                raise ValueError(f"{joint}: goal {g} below {low}")
            if g > high:
                raise ValueError(f"{joint}: goal {g} above {high}")

    def solve(self, start, goal, acc, jerk):
        if min(acc, jerk) <= 0:
            raise ValueError(f"ruckig needs positive limits, not acceleration {acc} and jerk {jerk}")
        n = len(self.joints)
        inp = InputParameter(n)
        inp.current_position = list(start)
        inp.target_position = list(goal)
        inp.max_velocity = [self.limits[j][2] for j in self.joints]
        inp.max_acceleration = [acc] * n
        inp.max_jerk = [jerk] * n
        traj = Trajectory(n)
        Ruckig(n).calculate(inp, traj)
        return traj


def plan(urdf, joint_names, start, goal, max_acceleration, max_jerk, sample_period=0.01):
    planner = _Planner(joint_limits(urdf, joint_names), joint_names)
    planner.check(start, goal)
    traj = planner.solve(start, goal, max_acceleration, max_jerk)
    times = [float(t) for t in np.arange(sample_period, traj.duration - 1e-9, sample_period)] + [traj.duration]

    def point(t):
        p, v, a = traj.at_time(t)
        return JointTrajectoryPoint(positions=p, velocities=v, accelerations=a, time_from_start=t)

    return JointTrajectory(joint_names=list(joint_names), points=[point(t) for t in times])
'''

RIGHT = [
    Variant("urdf_text_phase_synchronized_while_loop", {F: ALT_ELEMENT_TREE}),
    Variant("evenly_spread_samples_with_numpy", {F: ALT_LINSPACE}),
    Variant("planner_object_and_arange", {F: ALT_ARANGE}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(13, WRONG + RIGHT, tmp_path_factory.mktemp("task13"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict, variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(13), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(13))


def test_there_are_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


def test_exercise_as_handed_out_gets_a_clear_reason() -> None:
    """The untouched exercise scores 0, and its first cause's reason says where to start: the learner's file and line,
    and the TODO still to write."""
    rubric = grade(13, track="exercises", record=False)
    assert rubric.score == 0, rubric.format()
    reasons = " ".join(check.detail for check in rubric.failed() if not check.blocked_by)
    for phrase in ("jerk_limited.py, line", "TODO(task 13.1)"):
        assert phrase in reasons, rubric.format()
