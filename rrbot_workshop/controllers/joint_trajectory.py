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
import xml.etree.ElementTree as ET
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
    controller_state_message,
    fill_partial_goal,
    hold_position_trajectory,
    last_waypoint_trajectory,
    sort_to_joint_order,
)
from rrbot_workshop.controllers.tolerances import (
    SegmentTolerances,
    check_state_tolerance_per_joint,
    compute_state_error,
    get_segment_tolerances,
)
from rrbot_workshop.controllers.trajectory import InterpolationMethod, Trajectory, interpolate_between_points
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryControllerState, JointTrajectoryPoint

__all__ = ["JointTrajectoryController", "interpolate_between_points"]

_KINDS = ("position", "velocity", "acceleration", "effort")


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

    # ----------------------------------------------------------------- configuration
    def on_init(self) -> CallbackReturn:
        """Check the interface combinations and find continuous joints in the URDF.

        Raises:
            ParameterError: For an interface combination the controller cannot drive.
        """
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        check_interface_combinations(params, self.get_name())
        continuous: set[str] = set()
        if self.get_robot_description():
            try:
                continuous = _continuous_joints(self.get_robot_description())
            except ET.ParseError as exc:
                self.logger.error("'%s': cannot parse the robot description: %s", self.get_name(), exc)
                return CallbackReturn.ERROR
        self._wraparound = [j in continuous for j in params.joints]
        return CallbackReturn.SUCCESS

    @property
    def _dof(self) -> int:
        return len(self._p.joints)

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
        if self._pending is not None and self._trajectory is not None:
            msg, self._pending = self._pending, None
            if len(msg.joint_names) != self._dof:
                fill_partial_goal(msg, self._p.joints, io.positions_to_hold())
            sort_to_joint_order(msg, self._p.joints)
            self._trajectory.update(msg)
        self.state_current = io.read_state()
        traj = self._trajectory
        if traj is not None and traj.has_trajectory_msg():
            first_sample = False
            if not traj.is_sampled_already():
                first_sample = True
                if self._p.interpolate_from_desired_state or self._p.open_loop_control:
                    if abs(self._last_cmd_time) < 1.2e-7:
                        self._last_cmd_time = time
                    traj.set_point_before_trajectory_msg(self._last_cmd_time, self._last_cmd_state, self._wraparound)
                else:
                    traj.set_point_before_trajectory_msg(time, self.state_current, self._wraparound)
                self._traj_time = time
            else:
                self._traj_time += period
            desired = traj.sample(self._traj_time, self._method)
            nxt = traj.sample(self._traj_time + self._update_period, self._method)
            if desired is not None and nxt is not None:
                self.state_desired, self.command_next = desired.point, nxt.point
                running = traj.trajectory_msg
                assert running is not None
                segment_start = traj.time_from_start + running.points[nxt.start_index].time_from_start
                time_difference = self._traj_time - segment_start
                before_last_point = nxt.end_index != len(running.points)
                tol = self._active_tol
                if not before_last_point and not self._is_holding and self._cmd_timeout > 0.0 \
                        and time_difference > self._cmd_timeout:
                    self.logger.warning("'%s': aborted due to command timeout", self.get_name())
                    self._pending = self._hold_position()
                self.state_error = err = compute_state_error(self.state_current, self.state_desired, self._wraparound,
                                                             self._has_state, self._has_cmd)
                violated, outside_goal, within_goal_time = False, False, True
                if not self._is_holding:  # only joints with a tolerance above 0 can fail a check
                    state_checked, goal_checked = self._checked_joints(tol)
                    if before_last_point or first_sample:
                        for i in state_checked:
                            if not check_state_tolerance_per_joint(err, i, tol.state_tolerance[i], True):
                                violated = True
                    if not before_last_point:
                        for i in goal_checked:
                            if not check_state_tolerance_per_joint(err, i, tol.goal_state_tolerance[i]):
                                outside_goal = True
                                if tol.goal_time_tolerance != 0.0 and time_difference > tol.goal_time_tolerance:
                                    within_goal_time = False
                if not violated and within_goal_time:
                    self._write_commands(io, time, period)
                if self._active_goal is not None or violated or not (before_last_point or within_goal_time):
                    # a goal to report on, or a tolerance to act on (without either, the outcome is "carry on")
                    self._handle_outcome(time, violated, before_last_point, outside_goal, within_goal_time,
                                         time_difference)
        self._publish_state(io, time)
        return ReturnType.OK

    def _checked_joints(self, tol: SegmentTolerances) -> tuple[list[int], list[int]]:
        """The joints whose state and goal tolerances check anything, worked out once per tolerance set (a goal's
        tolerances replace the set; they are never changed in place)."""
        cached = self._checked
        if cached is None or cached[0] is not tol:
            def checked(tolerances: list[Any]) -> list[int]:
                return [i for i, t in enumerate(tolerances[:self._dof])
                        if t.position > 0.0 or t.velocity > 0.0 or t.acceleration > 0.0]

            cached = self._checked = (tol, checked(tol.state_tolerance), checked(tol.goal_state_tolerance))
        return cached[1], cached[2]

    def _write_commands(self, io: JointInterfaces, time: float, period: float) -> None:
        nxt = self.command_next
        pid_out: list[float] = []
        if self._use_pid:
            pid_out = [0.0] * self._dof
            vel_err = self.state_error.velocities or [0.0] * self._dof
            for k, idx in enumerate(self._map_cmd_to_joints):
                ff_effort = nxt.effort[idx] if self._has_cmd["effort"] and nxt.effort else 0.0
                ff_vel = nxt.velocities[idx] if nxt.velocities else 0.0
                pid_out[idx] = ff_vel * self._ff[k] + ff_effort + self._pids[k].compute_command(
                    self.state_error.positions[idx], vel_err[idx], period)
        if self._has_cmd["position"]:
            io.write("position", nxt.positions)
        if self._has_cmd["velocity"]:
            io.write("velocity", pid_out if self._use_pid else nxt.velocities)
        if self._has_cmd["acceleration"]:
            io.write("acceleration", nxt.accelerations)
        if self._has_cmd["effort"]:
            # with [position, effort] upstream writes the effort sampled at `time`, not one period ahead
            io.write("effort", pid_out if self._use_pid else self.state_desired.effort)
        # the sample is a new point every cycle and nothing changes it afterwards (a new trajectory starts from a copy
        # of it), so it is kept as it is
        self._last_cmd_state = nxt
        self._last_cmd_time = time

    def _publish_state(self, io: JointInterfaces, time: float) -> None:
        if self._pub is None:
            return
        # built when someone reads it: this cycle's points are never changed afterwards (each cycle makes new ones)
        self._pub.publish_lazy(_state_message, time, self._p.joints, self.state_desired, self.state_current,
                               self.state_error, io.command_values_now())  # the commands now, not when it is read

    # ----------------------------------------------------------------- introspection
    @property
    def is_holding(self) -> bool:
        """True while the controller holds a position (after activation, success, abort or cancel)."""
        return self._is_holding

    @property
    def current_trajectory(self) -> Trajectory | None:
        """The trajectory being sampled (None while inactive)."""
        return self._trajectory


def _state_message(time: float, joints: list[str], desired: JointTrajectoryPoint, current: JointTrajectoryPoint,
                   error: JointTrajectoryPoint, commands: tuple[list[float], list[float], list[float], list[float]],
                   ) -> JointTrajectoryControllerState:
    """:func:`controller_state_message` from the command values a cycle read (the output point is made here)."""
    positions, velocities, accelerations, effort = commands
    output = JointTrajectoryPoint(positions, velocities, accelerations, effort)
    return controller_state_message(time, joints, desired, current, error, output)
