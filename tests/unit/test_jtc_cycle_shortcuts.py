"""The shortcuts of the JTC's cycle give exactly what the long way gives.

A trajectory sampled cycle after cycle takes the segment it found last, and once it has played out it holds the last
waypoint without the search; the state error is a function prepared at configure; the commands are written by writers
prepared at activation. Each is compared here with the long way, number for number (``repr``, not approximately).
"""

from __future__ import annotations

import logging
import math

import pytest

from rrbot_workshop.controllers.jtc_interfaces import JointInterfaces
from rrbot_workshop.controllers.tolerances import (
    StateTolerances,
    check_state_tolerance_per_joint,
    compute_state_error,
    state_error_function,
)
from rrbot_workshop.controllers.trajectory import InterpolationMethod, Trajectory
from rrbot_workshop.hardware_interface.handles import (
    CommandInterface,
    LoanedCommandInterface,
    LoanedStateInterface,
    StateInterface,
)
from rrbot_workshop.msgs import Header, JointTrajectory, JointTrajectoryPoint

P = JointTrajectoryPoint
NOW = 10.0

#: Two-joint trajectories: linear, cubic, quintic, with efforts, velocity-only waypoints, one point.
TRAJECTORIES = {
    "linear": [P([0.3, 0.2], [], [], [], 0.4), P([0.6, -0.2], [], [], [], 0.9), P([0.1, 0.1], [], [], [], 1.3)],
    "cubic": [P([0.3, 0.2], [0.5, 0.1], [], [], 0.4), P([0.6, -0.2], [0.0, 0.0], [], [], 0.9)],
    "quintic": [P([-0.4, 0.5], [0.2, 0.2], [0.1, 0.0], [], 0.3), P([-0.2, 0.1], [0.0, 0.0], [0.0, 0.0], [], 0.8)],
    "effort": [P([0.3, 0.2], [], [], [1.0, 2.0], 0.4), P([0.6, -0.2], [], [], [3.0, -1.0], 0.9)],
    "velocities": [P([], [0.5, 0.5], [], [], 0.5), P([], [0.0, 0.0], [], [], 1.0)],
    "one point": [P([0.785, 0.785], [], [], [], 0.75)],
}


def _trajectory(points: list[JointTrajectoryPoint]) -> Trajectory:
    msg = JointTrajectory(Header(stamp=0.0), ["j1", "j2"], [p.copy() for p in points])
    return Trajectory(msg, NOW, P([0.1, -0.1], [0.0, 0.0]))


@pytest.mark.parametrize("method", list(InterpolationMethod))
@pytest.mark.parametrize("name", list(TRAJECTORIES))
def test_sampling_cycle_after_cycle_gives_the_samples_of_a_fresh_trajectory(name: str, method: InterpolationMethod,
                                                                             ) -> None:
    """Every 1 ms, at the cycle's time and one period ahead (as the JTC does), up to past the end. The other
    trajectory forgets its shortcuts before every sample, so it searches every time."""
    running, searching = _trajectory(TRAJECTORIES[name]), _trajectory(TRAJECTORIES[name])
    for k in range(1600):
        t = NOW + 0.001 * k
        for when in (t, t + 0.001):
            searching._hit, searching._ended_from, searching._last = None, math.inf, None
            assert repr(running.sample(when, method)) == repr(searching.sample(when, method)), (name, when)
    for when in (NOW + 0.2, NOW + 0.6, NOW + 5.0, NOW + 1.0, NOW + 0.45):  # back and forth, once it has played out
        searching._hit, searching._ended_from, searching._last = None, math.inf, None
        assert repr(running.sample(when, method)) == repr(searching.sample(when, method)), (name, when)


def test_a_new_message_after_the_end_is_sampled_from_its_own_waypoints() -> None:
    traj = _trajectory(TRAJECTORIES["linear"])
    traj.sample(NOW)
    held = traj.sample(NOW + 5.0)
    assert held is not None and held.point.positions == [0.1, 0.1]
    traj.update(JointTrajectory(Header(stamp=0.0), ["j1", "j2"], [P([0.5, 0.5], [], [], [], 10.0)]))
    traj.set_point_before_trajectory_msg(NOW + 5.0, P([0.1, 0.1]))
    traj.sample(NOW + 5.0)  # the new trajectory starts now: its waypoint is due 10 s from now
    moving = traj.sample(NOW + 6.0)
    assert moving is not None and (moving.start_index, moving.end_index) == (0, 0)
    assert moving.point.positions == pytest.approx([0.1 + 0.4 * 0.1, 0.1 + 0.4 * 0.1])


def test_a_nan_time_does_not_end_the_trajectory_early() -> None:
    """A NaN ``time_from_start`` (a message nobody validated) is in no segment; the others still are."""
    traj = _trajectory([P([0.3, 0.2], [], [], [], math.nan), P([0.6, -0.2], [], [], [], 2.0),
                        P([0.1, 0.1], [], [], [], 3.0)])
    traj.sample(NOW)
    assert traj.sample(NOW + 5.0) is not None  # past every waypoint
    inside = traj.sample(NOW + 2.5)  # in the last segment again: not "played out"
    assert inside is not None and (inside.start_index, inside.end_index) == (1, 2)


def _reference_error(current: P, desired: P, wraparound: list[bool], has_state: dict[str, bool],
                     has_command: dict[str, bool]) -> P:
    """The state error written out index by index (what :func:`compute_state_error` computed before)."""
    n = len(wraparound)

    def distance(a: float, b: float) -> float:
        diff = math.fmod(b - a, 2.0 * math.pi)
        return diff - 2.0 * math.pi if diff > math.pi else diff + 2.0 * math.pi if diff < -math.pi else diff

    positions = [distance(current.positions[i], desired.positions[i]) if wraparound[i]
                 else desired.positions[i] - current.positions[i] for i in range(n)]
    velocities: list[float] = []
    if has_state["velocity"]:
        velocities = ([desired.velocities[i] - current.velocities[i] for i in range(n)]
                      if has_command["velocity"] or has_command["effort"] else [0.0] * n)
    accelerations: list[float] = []
    if has_state["acceleration"]:
        accelerations = ([desired.accelerations[i] - current.accelerations[i] for i in range(n)]
                         if has_command["acceleration"] else [0.0] * n)
    return P(positions, velocities, accelerations, [], 0.0)


@pytest.mark.parametrize("wraparound", [[False, False], [True, False]])
@pytest.mark.parametrize("state", [("position",), ("position", "velocity"), ("position", "velocity", "acceleration")])
@pytest.mark.parametrize("command", [("position",), ("velocity",), ("effort",), ("position", "velocity", "acceleration")])
def test_the_prepared_state_error_is_the_error_written_out(wraparound: list[bool], state: tuple[str, ...],
                                                           command: tuple[str, ...]) -> None:
    kinds = ("position", "velocity", "acceleration", "effort")
    has_state = {k: k in state for k in kinds}
    has_command = {k: k in command for k in kinds}
    current = P([3.0, 0.25], [0.5, -0.125], [0.0625, 1.5])
    desired = P([-3.0, 1.0 / 3.0], [0.1, 0.2], [0.3, -0.7])
    expected = repr(_reference_error(current, desired, wraparound, has_state, has_command))
    assert repr(state_error_function(wraparound, has_state, has_command)(current, desired)) == expected
    assert repr(compute_state_error(current, desired, wraparound, has_state, has_command)) == expected


def test_the_prepared_state_error_takes_the_first_values_and_fails_on_too_few() -> None:
    no = dict.fromkeys(("position", "velocity", "acceleration", "effort"), False)
    error = state_error_function([False], no, no)
    assert error(P([1.0, 5.0]), P([3.0, 7.0])).positions == [2.0]  # one joint: the first value of each
    with pytest.raises(IndexError):
        error(P([]), P([1.0]))


def test_a_tolerance_check_logs_each_exceeded_field_in_order(caplog: pytest.LogCaptureFixture) -> None:
    error = P([0.5, 0.0], [math.nan, 0.0], [])
    with caplog.at_level(logging.ERROR):
        assert not check_state_tolerance_per_joint(error, 0, StateTolerances(0.1, 0.2, 0.3), True)
    assert [r.getMessage() for r in caplog.records] == [
        "joint 0: position error 0.5 exceeds the tolerance 0.1",
        "joint 0: velocity error nan exceeds the tolerance 0.2",
    ]  # a NaN error fails; a missing acceleration error counts as 0
    caplog.clear()
    assert check_state_tolerance_per_joint(error, 1, StateTolerances(0.1, 0.2, 0.3), True)
    assert not check_state_tolerance_per_joint(error, 0, StateTolerances(0.1), False)
    assert check_state_tolerance_per_joint(error, 0, StateTolerances()) and not caplog.records


def _interfaces(command_joints: list[str], cmd_to_joint: list[int]) -> tuple[JointInterfaces, list[LoanedCommandInterface]]:
    commands = [LoanedCommandInterface(CommandInterface(j, "position", initial_value=0.0)) for j in command_joints]
    states = [LoanedStateInterface(StateInterface(j, "position", initial_value=0.0)) for j in ("j1", "j2", "j3")]
    io = JointInterfaces(["j1", "j2", "j3"], command_joints, ["position"], ["position"], commands, states,
                         cmd_to_joint)
    return io, commands


@pytest.mark.parametrize(("command_joints", "cmd_to_joint"), [(["j1", "j2", "j3"], [0, 1, 2]), (["j3", "j1"], [2, 0])])
def test_a_prepared_writer_writes_what_write_writes(command_joints: list[str], cmd_to_joint: list[int]) -> None:
    io, commands = _interfaces(command_joints, cmd_to_joint)
    io.writer("position")([1.0, 2.0, 3.0])
    written = [c.get_value() for c in commands]
    io.write("position", [0.0, 0.0, 0.0])
    io.write("position", [1.0, 2.0, 3.0])
    assert written == [c.get_value() for c in commands] == [[1.0, 2.0, 3.0][j] for j in cmd_to_joint]


def test_command_values_leave_out_the_kinds_not_commanded_and_the_point_has_them_empty() -> None:
    io, _ = _interfaces(["j1", "j2", "j3"], [0, 1, 2])
    assert io.command_values_now() == ([0.0, 0.0, 0.0], None, None, None)
    assert io.command_point() == P([0.0, 0.0, 0.0], [], [], [])
    io, _ = _interfaces(["j3"], [2])
    assert repr(io.command_values_now()) == repr(([math.nan, math.nan, 0.0], None, None, None))
    assert repr(io.command_point()) == repr(P([math.nan, math.nan, 0.0], [], [], []))
