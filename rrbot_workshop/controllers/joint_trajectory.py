"""``joint_trajectory_controller/JointTrajectoryController``: follow time-stamped joint waypoints.

The controller takes a ``JointTrajectory`` from ``~/joint_trajectory`` (or a FollowJointTrajectory
goal from :meth:`JointTrajectoryController.send_goal`), samples it every cycle and writes the sample
to the command interfaces. As in ros2_controllers Jazzy:

* on activation it *holds* the current position (a one-point trajectory at ``time_from_start`` 0);
* a new message replaces the running trajectory entirely; partial goals are padded with the last
  position command of the missing joints;
* what it writes is sampled one control period ahead (``time + period``), what it checks the
  tolerances against is sampled at ``time``;
* with the single command interface ``velocity`` or ``effort`` a PID per joint turns the position
  and velocity errors into the command.

This module holds the lifecycle and the control loop; the parts live next to it: :mod:`.trajectory`
(sampling), :mod:`.tolerances` (errors and tolerances), :mod:`.joint_trajectory_parameters` (parameters
and input checks), :mod:`.jtc_interfaces` (the loaned interfaces), :mod:`.jtc_messages` (the messages it
reshapes and builds) and :mod:`.jtc_action_server` (FollowJointTrajectory goals).
"""

from __future__ import annotations

import copy
import operator
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from typing import Any

from rrbot_workshop.controller_interface.base import (
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.controllers.follow_joint_trajectory import FollowJointTrajectoryResult as Result
from rrbot_workshop.controllers.follow_joint_trajectory import GoalHandle, GoalStatus
from rrbot_workshop.controllers.joint_trajectory_parameters import (
    JTC_PARAMETERS,
    check_interface_combinations,
    validate_trajectory_msg,
)
from rrbot_workshop.controllers.jtc_action_server import FollowJointTrajectoryServer
from rrbot_workshop.controllers.jtc_interfaces import JointInterfaces
from rrbot_workshop.controllers.jtc_messages import (
    controller_state_from_commands,
    fill_partial_goal,
    hold_position_trajectory,
    last_waypoint_trajectory,
    sort_to_joint_order,
)
from rrbot_workshop.controllers.tolerances import (
    SegmentTolerances,
    check_state_tolerance_per_joint,
    checked_joints,
    get_segment_tolerances,
    state_error_function,
)
from rrbot_workshop.controllers.trajectory import InterpolationMethod, Trajectory, interpolate_between_points
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryControllerState, JointTrajectoryPoint

__all__ = ["JointTrajectoryController", "interpolate_between_points"]

_KINDS = ("position", "velocity", "acceleration", "effort")
#: Per command kind, the field of a sample it is written from.
_FIELDS = ("positions", "velocities", "accelerations", "effort")
#: ``ReturnType.OK``, looked up once (an enum member costs a class attribute lookup every time).
_OK = ReturnType.OK


def _continuous_joints(urdf: str) -> set[str]:
    root = ET.fromstring(urdf)
    return {j.get("name", "") for j in root.iter("joint") if j.get("type") == "continuous"}


class JointTrajectoryController(ControllerInterface, FollowJointTrajectoryServer):
    """Follows joint trajectories; see the module docstring. Goals: :meth:`send_goal` (from the mixin).

    Attributes:
        last_rejection: Why the last trajectory message or goal was rejected, or None.
    """

    PARAMETERS = JTC_PARAMETERS

    def __init__(self) -> None:
        super().__init__()
        self.last_rejection: str | None = None
        self._p: Any = None
        self._dof = 0  # the number of joints, once configured
        self._wraparound: list[bool] = []
        self._trajectory: Trajectory | None = None
        self._pending: JointTrajectory | None = None
        self._is_holding = True
        self._subscriber_active = False
        self._sub: Any = None
        self._pub: Any = None
        self._io: JointInterfaces | None = None
        self._pids: list[Any] = []
        self._ff: list[float] = []
        self._active_goal: GoalHandle | None = None
        self._default_tol = SegmentTolerances()
        self._active_tol = SegmentTolerances()
        self._traj_time = 0.0
        self._update_period = 0.01
        self._cmd_timeout = 0.0
        self._last_cmd_state = JointTrajectoryPoint()
        self._last_cmd_time = 0.0
        self.state_current = JointTrajectoryPoint()
        self.state_desired = JointTrajectoryPoint()
        self.state_error = JointTrajectoryPoint()
        self.command_next = JointTrajectoryPoint()
        self._checked: tuple[SegmentTolerances, list[int], list[int]] | None = None
        # prepared at configure and activation, used in every cycle
        self._from_desired = False
        self._state_error_of = state_error_function((), dict.fromkeys(_KINDS, False), dict.fromkeys(_KINDS, False))
        self._writes: list[tuple[Callable[[Sequence[float]], None], Callable[[JointTrajectoryPoint], list[float]],
                                 bool]] = []

    # ----------------------------------------------------------------- configuration
    def on_init(self) -> CallbackReturn:
        """Find continuous joints in the URDF (interface combinations are checked at configure, as in Jazzy)."""
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        continuous: set[str] = set()
        if self.get_robot_description():
            try:
                continuous = _continuous_joints(self.get_robot_description())
            except ET.ParseError as exc:
                self.logger.error("'%s': cannot parse the robot description: %s", self.get_name(), exc)
                return CallbackReturn.ERROR
        self._wraparound = [j in continuous for j in params.joints]
        return CallbackReturn.SUCCESS

    def _command_joints(self, params: Any) -> list[str]:
        return list(params.command_joints) or list(params.joints)

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """``<command_joint>/<interface>`` for every command joint and command interface."""
        p = self._p or self.param_listener.get_params()  # type: ignore[union-attr]
        names = [f"{j}/{i}" for j in self._command_joints(p) for i in p.command_interfaces]
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """``<joint>/<interface>`` for every joint and state interface."""
        p = self._p or self.param_listener.get_params()  # type: ignore[union-attr]
        names = [f"{j}/{i}" for j in p.joints for i in p.state_interfaces]
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read the parameters, set up PIDs, tolerances, topics."""
        assert self.param_listener is not None
        p = self._p = self.param_listener.get_params()
        self._dof = len(p.joints)
        try:
            check_interface_combinations(p, self.get_name())
        except ParameterError as exc:
            self.logger.error("%s", exc)
            return CallbackReturn.FAILURE
        if p.open_loop_control:
            self.logger.warning("'%s': open_loop_control is deprecated; use interpolate_from_desired_state", self.get_name())
        if len(self._wraparound) != self._dof:
            self._wraparound = [False] * self._dof
        cmd_joints = self._command_joints(p)
        self._map_cmd_to_joints = (
            list(range(len(cmd_joints))) if len(cmd_joints) == self._dof else [list(p.joints).index(j) for j in cmd_joints]
        )
        self._has_cmd = {k: k in p.command_interfaces for k in _KINDS}
        self._has_state = {k: k in p.state_interfaces for k in _KINDS}
        self._use_pid = list(p.command_interfaces) in (["velocity"], ["effort"]) and not (
            p.command_interfaces == ["velocity"] and p.open_loop_control
        )
        self._pids, self._ff = [], []
        if self._use_pid:
            from rrbot_workshop.control_toolbox.pid import Pid  # written alongside; imported only when a PID is needed

            for idx in self._map_cmd_to_joints:
                g = p.gains.joints_map[p.joints[idx]]
                try:
                    self._pids.append(Pid(g.p, g.i, g.d, g.u_clamp_max, g.u_clamp_min, g.i_clamp_max,
                                          g.i_clamp_min, g.antiwindup_strategy, g.tracking_time_constant,
                                          antiwindup=g.antiwindup))
                except ParameterError as exc:
                    self.logger.error("'%s': gains of '%s': %s", self.get_name(), p.joints[idx], exc)
                    return CallbackReturn.FAILURE
                self._ff.append(g.ff_velocity_scale)
        self._default_tol = self._active_tol = get_segment_tolerances(p)
        self._method = InterpolationMethod(p.interpolation_method)
        self._from_desired = bool(p.interpolate_from_desired_state or p.open_loop_control)
        self._state_error_of = state_error_function(self._wraparound, self._has_state, self._has_cmd)
        node = self.get_node()
        if self._sub is None:
            self._sub = node.create_subscription(JointTrajectory, "~/joint_trajectory", self._topic_callback)
        if self._pub is None:
            self._pub = node.create_publisher(JointTrajectoryControllerState, "~/controller_state")
        self._update_period = 1.0 / float(self.get_update_rate() or self._cm_update_rate)
        self._trajectory = None
        self.logger.info("'%s': command interfaces %s, state interfaces %s, interpolation '%s'", self.get_name(),
                         list(p.command_interfaces), list(p.state_interfaces), p.interpolation_method)
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Drop the subscription."""
        if self._sub is not None:
            self._sub.destroy()
            self._sub = None
        self._trajectory = None
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Sort the loaned interfaces, reset the PIDs and start holding the current position."""
        p = self._p
        try:
            io = self._io = JointInterfaces(p.joints, self._command_joints(p), p.command_interfaces, p.state_interfaces,
                                            self.command_interfaces, self.state_interfaces, self._map_cmd_to_joints)
        except KeyError as exc:
            self.logger.error("'%s': interface %s was not assigned", self.get_name(), exc)
            return CallbackReturn.ERROR
        # without a PID, each command kind is written from its field of the sample one period ahead; with
        # [position, effort] upstream writes the effort sampled at `time` (the desired state), not one period ahead
        self._writes = [(io.writer(kind), operator.attrgetter(field), kind == "effort")
                        for kind, field in zip(_KINDS, _FIELDS, strict=True) if self._has_cmd[kind]]
        for pid in self._pids:
            pid.reset()
        self._trajectory = Trajectory()
        self._pending = None
        self._subscriber_active = True
        state = io.state_from_commands()
        if p.set_last_command_interface_value_as_state_on_activation and len(self._map_cmd_to_joints) == self._dof \
                and state is not None:
            self.state_current = state
            self._last_cmd_state = state.copy()
        else:
            self.state_current = io.read_state()
            self._last_cmd_state = io.read_state()
        self._last_cmd_time = 0.0
        self._pending = self._hold_position()
        goal_time = self._default_tol.goal_time_tolerance
        self._cmd_timeout = p.cmd_timeout if p.cmd_timeout > goal_time else 0.0
        if 0.0 < p.cmd_timeout <= goal_time:
            self.logger.warning("'%s': cmd_timeout (%g s) must exceed constraints.goal_time (%g s); it is ignored",
                                self.get_name(), p.cmd_timeout, goal_time)
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Abort a running goal and leave commands that stop the joints (velocity/acceleration/effort 0)."""
        if self._active_goal is not None:
            self._active_goal._finish(GoalStatus.ABORTED, Result.INVALID_GOAL,
                                      "Current goal cancelled during deactivate transition.")
            self._active_goal = None
        if self._io is not None:
            self._io.stop_motion()
        self._io = None
        self._writes = []
        self._subscriber_active = False
        self._trajectory = None
        self._pending = None
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- holding
    def _hold_position(self) -> JointTrajectory:
        """A one-point trajectory at the current position, starting now; tolerances are not checked."""
        self._is_holding = True
        return hold_position_trajectory(self._p.joints, self.state_current.positions, self._has_cmd)

    def _success_point(self) -> JointTrajectory:
        """Hold the last waypoint of the finished trajectory (whatever its velocity)."""
        self._is_holding = True
        assert self._trajectory is not None and self._trajectory.trajectory_msg is not None
        return last_waypoint_trajectory(self._trajectory.trajectory_msg, self._p.joints)

    # ----------------------------------------------------------------- incoming trajectories
    def _reject(self, reason: str) -> None:
        self.last_rejection = reason
        self.logger.error("'%s' rejected a trajectory: %s", self.get_name(), reason)

    def _topic_callback(self, msg: JointTrajectory) -> None:
        problem = validate_trajectory_msg(msg, self._p, self._has_cmd["effort"], self.get_node().now())
        if problem is not None:
            self._reject(problem[1])
            return
        if self._subscriber_active:  # a message to an inactive controller is dropped silently, as upstream
            self._pending = copy.deepcopy(msg)
            self._is_holding = False

    # ----------------------------------------------------------------- control loop
    def update(self, time: float, period: float) -> ReturnType:  # noqa: C901 - mirrors upstream's single loop
        """Sample the trajectory, check tolerances, write commands, publish the state."""
        io = self._io
        assert io is not None, "update() runs only while active"
        traj = self._trajectory
        if self._pending is not None and traj is not None:
            msg, self._pending = self._pending, None
            if len(msg.joint_names) != self._dof:
                fill_partial_goal(msg, self._p.joints, io.positions_to_hold())
            sort_to_joint_order(msg, self._p.joints)
            traj.update(msg)
        self.state_current = current = io.read_state()
        if traj is not None and traj.has_trajectory_msg():
            first_sample = not traj.is_sampled_already()
            if first_sample:
                if self._from_desired:
                    if abs(self._last_cmd_time) < 1.2e-7:
                        self._last_cmd_time = time
                    traj.set_point_before_trajectory_msg(self._last_cmd_time, self._last_cmd_state, self._wraparound)
                else:
                    traj.set_point_before_trajectory_msg(time, current, self._wraparound)
                self._traj_time = traj_time = time
            else:
                self._traj_time = traj_time = self._traj_time + period
            desired = traj.sample(traj_time, self._method)
            nxt = traj.sample(traj_time + self._update_period, self._method)
            if desired is not None and nxt is not None:
                self.state_desired, self.command_next = desired_point, nxt_point = desired.point, nxt.point
                running = traj.trajectory_msg
                assert running is not None
                points = running.points
                time_difference = traj_time - (traj.time_from_start + points[nxt.start_index].time_from_start)
                before_last_point = nxt.end_index != len(points)
                tol = self._active_tol
                if not before_last_point and not self._is_holding and self._cmd_timeout > 0.0 \
                        and time_difference > self._cmd_timeout:
                    self.logger.warning("'%s': aborted due to command timeout", self.get_name())
                    self._pending = self._hold_position()
                self.state_error = err = self._state_error_of(current, desired_point)
                violated, outside_goal, within_goal_time = False, False, True
                if not self._is_holding:  # only joints with a tolerance above 0 can fail a check
                    checked = self._checked
                    if checked is None or checked[0] is not tol:  # a goal's tolerances replace the set, never change
                        checked = self._checked = (tol, checked_joints(tol.state_tolerance, self._dof),
                                                   checked_joints(tol.goal_state_tolerance, self._dof))
                    if before_last_point or first_sample:
                        for i in checked[1]:
                            if not check_state_tolerance_per_joint(err, i, tol.state_tolerance[i], True):
                                violated = True
                    if not before_last_point:
                        for i in checked[2]:
                            if not check_state_tolerance_per_joint(err, i, tol.goal_state_tolerance[i]):
                                outside_goal = True
                                if tol.goal_time_tolerance != 0.0 and time_difference > tol.goal_time_tolerance:
                                    within_goal_time = False
                if not violated and within_goal_time:
                    if self._use_pid:
                        self._write_pid_commands(io, nxt_point, period)
                    else:
                        dof = self._dof
                        for write, field, from_desired in self._writes:
                            values = field(desired_point if from_desired else nxt_point)
                            if len(values) >= dof:  # e.g. interpolation 'none' and a waypoint without that field
                                write(values)
                    # the sample is a new point every cycle and nothing changes it afterwards (a new trajectory starts
                    # from a copy of it), so it is kept as it is
                    self._last_cmd_state = nxt_point
                    self._last_cmd_time = time
                if self._active_goal is not None or violated or not (before_last_point or within_goal_time):
                    # a goal to report on, or a tolerance to act on (without either, the outcome is "carry on")
                    self._handle_outcome(time, violated, before_last_point, outside_goal, within_goal_time,
                                         time_difference)
        pub = self._pub
        if pub is not None:
            # built when someone reads it: this cycle's points are never changed afterwards (each cycle makes new ones)
            pub.publish_lazy(controller_state_from_commands, time, self._p.joints, self.state_desired, current,
                             self.state_error, io.command_values_now())  # the commands now, not when it is read
        return _OK

    def _write_pid_commands(self, io: JointInterfaces, nxt: JointTrajectoryPoint, period: float) -> None:
        """Write what the PIDs make of the errors, with the sample's velocity (and effort) as feed-forward."""
        pid_out = [0.0] * self._dof
        vel_err = self.state_error.velocities or [0.0] * self._dof
        for k, idx in enumerate(self._map_cmd_to_joints):
            ff_effort = nxt.effort[idx] if self._has_cmd["effort"] and nxt.effort else 0.0
            ff_vel = nxt.velocities[idx] if nxt.velocities else 0.0
            pid_out[idx] = ff_vel * self._ff[k] + ff_effort + self._pids[k].compute_command(
                self.state_error.positions[idx], vel_err[idx], period)
        io.write("velocity" if self._has_cmd["velocity"] else "effort", pid_out)

    # ----------------------------------------------------------------- introspection
    @property
    def is_holding(self) -> bool:
        """True while the controller holds a position (after activation, success, abort or cancel)."""
        return self._is_holding

    @property
    def current_trajectory(self) -> Trajectory | None:
        """The trajectory being sampled (None while inactive)."""
        return self._trajectory

