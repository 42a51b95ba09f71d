"""``diff_drive_controller/DiffDriveController``: drive a two-sided wheeled base from a twist.

A chainable controller. Its two reference interfaces, ``<name>/linear/velocity`` [m/s] and
``<name>/angular/velocity`` [rad/s], are set from ``~/cmd_vel`` (``TwistStamped``) when nothing is
chained in front of it, or written directly by a preceding controller. Each cycle it updates the
odometry from the wheel feedback (positions by default), publishes ``~/odom`` at ``publish_rate``,
limits the twist, and commands every wheel's ``velocity`` [rad/s]:
``v_left = (v - w*s/2) / r_left`` and ``v_right = (v + w*s/2) / r_right``.
"""

from __future__ import annotations

import math
from typing import Any

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.controllers.odometry import Odometry as OdometryModel
from rrbot_workshop.controllers.odometry import SpeedLimiter
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.hardware_interface.handles import CommandInterface, LoanedCommandInterface, LoanedStateInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.msgs import Header, Odometry, Quaternion, TwistStamped

__all__ = ["DiffDriveController"]

_LIMITS = """
      has_velocity_limits: {type: bool, default_value: true, description: "Deprecated in Jazzy: set limits to NaN instead."}
      has_acceleration_limits: {type: bool, default_value: true, description: "Deprecated in Jazzy."}
      has_jerk_limits: {type: bool, default_value: true, description: "Deprecated in Jazzy."}
      max_velocity: {type: double, default_value: .nan, description: "Highest velocity; NaN is no limit."}
      min_velocity: {type: double, default_value: .nan, description: "Lowest velocity; NaN means -max_velocity."}
      max_acceleration: {type: double, default_value: .nan, description: "Largest speed-up forwards."}
      min_acceleration: {type: double, default_value: .nan, description: "Deprecated in Jazzy and not used: set max_deceleration and max_acceleration_reverse."}
      max_deceleration: {type: double, default_value: .nan, description: "Largest slow-down forwards (magnitude)."}
      max_acceleration_reverse: {type: double, default_value: .nan, description: "Largest speed-up backwards (magnitude)."}
      max_deceleration_reverse: {type: double, default_value: .nan, description: "Largest slow-down backwards (magnitude)."}
      max_jerk: {type: double, default_value: .nan, description: "Highest jerk."}
      min_jerk: {type: double, default_value: .nan, description: "Lowest jerk; NaN means -max_jerk."}
"""

_PARAMETERS = """
diff_drive_controller:
  left_wheel_names: {type: string_array, default_value: [], description: "Left wheel joints.", validation: {size_gt<>: [0], unique<>: null}}
  right_wheel_names: {type: string_array, default_value: [], description: "Right wheel joints.", validation: {size_gt<>: [0], unique<>: null}}
  wheel_separation: {type: double, default_value: 0.0, description: "Distance between the left and right wheels in [m].", validation: {gt<>: [0.0]}}
  wheels_per_side: {type: int, default_value: 0, description: "Deprecated: the wheel name lists give the count."}
  wheel_radius: {type: double, default_value: 0.0, description: "Wheel radius in [m].", validation: {gt<>: [0.0]}}
  wheel_separation_multiplier: {type: double, default_value: 1.0, description: "Correction factor of the separation."}
  left_wheel_radius_multiplier: {type: double, default_value: 1.0, description: "Correction factor of the left radius."}
  right_wheel_radius_multiplier: {type: double, default_value: 1.0, description: "Correction factor of the right radius."}
  tf_frame_prefix_enable: {type: bool, default_value: true, description: "Prefix the frame ids."}
  tf_frame_prefix: {type: string, default_value: "", description: "Frame prefix; empty uses the namespace."}
  odom_frame_id: {type: string, default_value: odom, description: "Frame of the odometry."}
  base_frame_id: {type: string, default_value: base_link, description: "Frame of the base."}
  pose_covariance_diagonal: {type: double_array, default_value: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], description: "Pose covariance diagonal.", validation: {fixed_size<>: [6]}}
  twist_covariance_diagonal: {type: double_array, default_value: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], description: "Twist covariance diagonal.", validation: {fixed_size<>: [6]}}
  open_loop: {type: bool, default_value: false, description: "Integrate the commands instead of the wheel feedback."}
  position_feedback: {type: bool, default_value: true, description: "Feedback is wheel position (true) or velocity (false)."}
  enable_odom_tf: {type: bool, default_value: true, description: "Publish odom -> base (not modelled: no /tf here)."}
  cmd_vel_timeout: {type: double, default_value: 0.5, description: "Age in [s] after which a twist counts as stale and the base stops; 0 disables."}
  publish_limited_velocity: {type: bool, default_value: false, description: "Publish the limited twist on ~/cmd_vel_out."}
  velocity_rolling_window_size: {type: int, default_value: 10, description: "Steps averaged for the odometry twist.", validation: {gt<>: [0]}}
  publish_rate: {type: double, default_value: 50.0, description: "Odometry publishing rate in [Hz].", validation: {gt<>: [0.0]}}
  linear:
    x:""" + _LIMITS + """
  angular:
    z:""" + _LIMITS


def _limiter(group: Any) -> SpeedLimiter:
    nan = math.nan
    vel = (group.min_velocity, group.max_velocity) if group.has_velocity_limits else (nan, nan)
    acc = ((group.max_acceleration_reverse, group.max_acceleration, group.max_deceleration,
            group.max_deceleration_reverse) if group.has_acceleration_limits else (nan,) * 4)
    jerk = (group.min_jerk, group.max_jerk) if group.has_jerk_limits else (nan, nan)
    return SpeedLimiter(vel[0], vel[1], *acc, *jerk)


class DiffDriveController(ChainableControllerInterface):
    """Differential drive; see the module docstring."""

    PARAMETERS = _PARAMETERS

    def __init__(self) -> None:
        super().__init__()
        self.odometry = OdometryModel()
        self._p: Any = None
        self._sub: Any = None
        self._odom_pub: Any = None
        self._limited_pub: Any = None
        self._received = TwistStamped()
        self._subscriber_active = False
        self._left: list[tuple[LoanedStateInterface, LoanedCommandInterface]] = []
        self._right: list[tuple[LoanedStateInterface, LoanedCommandInterface]] = []
        self._previous = [(0.0, 0.0), (0.0, 0.0)]
        self._last_publish: float | None = None

    # ----------------------------------------------------------------- configuration
    def _check_sides(self, params: Any) -> None:
        if len(params.left_wheel_names) != len(params.right_wheel_names):
            raise ParameterError(
                self.get_name(), "right_wheel_names",
                f"has {len(params.right_wheel_names)} wheels but left_wheel_names has {len(params.left_wheel_names)};"
                " both sides need the same number",
            )

    def on_init(self) -> CallbackReturn:
        """Check that both sides have as many wheels.

        Raises:
            ParameterError: If the wheel name lists differ in length.
        """
        assert self.param_listener is not None
        self._check_sides(self.param_listener.get_params())
        return CallbackReturn.SUCCESS

    def _feedback(self) -> str:
        return "position" if self._params().position_feedback else "velocity"

    def _params(self) -> Any:
        return self._p or self.param_listener.get_params()  # type: ignore[union-attr]

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """``<wheel>/velocity`` of every left, then every right wheel."""
        p = self._params()
        names = [f"{w}/velocity" for w in [*p.left_wheel_names, *p.right_wheel_names]]
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """``<wheel>/position`` (or ``velocity`` without position feedback) of every wheel."""
        p = self._params()
        names = [f"{w}/{self._feedback()}" for w in [*p.left_wheel_names, *p.right_wheel_names]]
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read parameters, set up odometry, limiters and topics."""
        assert self.param_listener is not None
        p = self._p = self.param_listener.get_params()
        try:
            self._check_sides(p)
        except ParameterError as exc:
            self.logger.error("%s", exc)
            return CallbackReturn.FAILURE
        self.odometry.set_wheel_params(*self._geometry())
        self.odometry.set_velocity_rolling_window_size(p.velocity_rolling_window_size)
        self.odometry.reset_odometry()
        self._limit_linear = _limiter(p.linear.x)
        self._limit_angular = _limiter(p.angular.z)
        node = self.get_node()
        if self._sub is None:
            self._sub = node.create_subscription(TwistStamped, "~/cmd_vel", self._on_cmd_vel)
        if self._odom_pub is None:
            self._odom_pub = node.create_publisher(Odometry, "~/odom")
        if p.publish_limited_velocity and self._limited_pub is None:
            self._limited_pub = node.create_publisher(TwistStamped, "~/cmd_vel_out")
        prefix = ""
        if p.tf_frame_prefix_enable:
            prefix = (p.tf_frame_prefix or node.get_namespace()).strip("/")
            prefix = f"{prefix}/" if prefix else ""
        self._odom_frame, self._base_frame = prefix + p.odom_frame_id, prefix + p.base_frame_id
        self._reset_buffers()
        return CallbackReturn.SUCCESS

    def _geometry(self) -> tuple[float, float, float]:
        p = self._p
        return (p.wheel_separation_multiplier * p.wheel_separation, p.left_wheel_radius_multiplier * p.wheel_radius,
                p.right_wheel_radius_multiplier * p.wheel_radius)

    def on_export_reference_interfaces(self) -> list[CommandInterface]:
        """``<name>/linear/velocity`` and ``<name>/angular/velocity``, NaN until commanded."""
        name = self.get_name()
        return [CommandInterface(f"{name}/linear", "velocity", initial_value=math.nan),
                CommandInterface(f"{name}/angular", "velocity", initial_value=math.nan)]

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Pair each wheel's feedback and command loans."""
        p = self._p
        states = {s.name: s for s in self.state_interfaces}
        cmds = {c.name: c for c in self.command_interfaces}
        try:
            self._left = [(states[f"{w}/{self._feedback()}"], cmds[f"{w}/velocity"]) for w in p.left_wheel_names]
            self._right = [(states[f"{w}/{self._feedback()}"], cmds[f"{w}/velocity"]) for w in p.right_wheel_names]
        except KeyError as exc:
            self.logger.error("'%s': wheel interface %s was not assigned", self.get_name(), exc)
            return CallbackReturn.ERROR
        self._subscriber_active = True
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Stop the wheels."""
        self._subscriber_active = False
        for _, cmd in [*self._left, *self._right]:
            cmd.set_value(0.0)
        self._reset_buffers()
        self._left, self._right = [], []
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Forget the odometry and the subscription."""
        self.odometry.reset_odometry()
        if self._sub is not None:
            self._sub.destroy()
            self._sub = None
        return CallbackReturn.SUCCESS

    def _reset_buffers(self) -> None:
        for ref in self.reference_interfaces:
            ref.set_value(math.nan)
        self._previous = [(0.0, 0.0), (0.0, 0.0)]
        nan_twist = TwistStamped(Header(stamp=self.get_node().now()))
        nan_twist.twist.linear.x = nan_twist.twist.angular.z = math.nan
        self._received = nan_twist

    # ----------------------------------------------------------------- running
    def _on_cmd_vel(self, msg: TwistStamped) -> None:
        if not self._subscriber_active:
            self.logger.warning("'%s': cannot accept commands while inactive", self.get_name())
            return
        now = self.get_node().now()
        if msg.header.stamp == 0.0:
            msg = TwistStamped(Header(stamp=now, frame_id=msg.header.frame_id), msg.twist)
        timeout = self._p.cmd_vel_timeout
        if timeout == 0.0 or now - msg.header.stamp < timeout:
            self._received = msg
        else:
            self.logger.warning("'%s': ignoring a twist %.3f s old (cmd_vel_timeout %.3f s)", self.get_name(),
                                now - msg.header.stamp, timeout)

    def update_reference_from_subscribers(self, time: float, period: float) -> ReturnType:
        """Copy the last twist into the references, or 0 if it is older than ``cmd_vel_timeout``."""
        msg = self._received
        timeout = self._p.cmd_vel_timeout
        # Jazzy treats cmd_vel_timeout 0 as "no timeout" when receiving but as "always stale" here;
        # 0 disables the timeout in both places.
        if timeout > 0.0 and time - msg.header.stamp > timeout:
            self.reference_interfaces[0].set_value(0.0)
            self.reference_interfaces[1].set_value(0.0)
        elif math.isfinite(msg.twist.linear.x) and math.isfinite(msg.twist.angular.z):
            self.reference_interfaces[0].set_value(msg.twist.linear.x)
            self.reference_interfaces[1].set_value(msg.twist.angular.z)
        return ReturnType.OK

    def update_and_write_commands(self, time: float, period: float) -> ReturnType:
        """Odometry, limits and wheel commands."""
        linear = self.reference_interfaces[0].get_value()
        angular = self.reference_interfaces[1].get_value()
        if not (math.isfinite(linear) and math.isfinite(angular)):
            return ReturnType.OK  # nothing commanded yet
        separation, r_left, r_right = self._geometry()
        p = self._p
        # limits first: open-loop odometry integrates what the wheels are told, the limited twist (as Jazzy)
        (last_lin, last_ang), (prev_lin, prev_ang) = self._previous[1], self._previous[0]
        linear = self._limit_linear.limit(linear, last_lin, prev_lin, period)
        angular = self._limit_angular.limit(angular, last_ang, prev_ang, period)
        self._previous = [self._previous[1], (linear, angular)]
        if p.open_loop:
            self.odometry.update_open_loop(linear, angular, time)
        else:
            left = [s.get_value() for s, _ in self._left]
            right = [s.get_value() for s, _ in self._right]
            if any(math.isnan(v) for v in [*left, *right]):
                self.logger.error("'%s': a wheel %s is NaN", self.get_name(), self._feedback())
                return ReturnType.ERROR
            left_mean, right_mean = sum(left) / len(left), sum(right) / len(right)
            if p.position_feedback:
                self.odometry.update(left_mean, right_mean, time)
            else:
                self.odometry.update_from_velocity(left_mean * r_left * period, right_mean * r_right * period, time)
        if self._last_publish is None or self._last_publish + 1.0 / p.publish_rate < time:
            self._last_publish = time if self._last_publish is None else self._last_publish + 1.0 / p.publish_rate
            self._publish_odometry(time)
        if self._limited_pub is not None:
            out = TwistStamped(Header(stamp=time))
            out.twist.linear.x, out.twist.angular.z = linear, angular
            self._limited_pub.publish(out)
        v_left = (linear - angular * separation / 2.0) / r_left
        v_right = (linear + angular * separation / 2.0) / r_right
        for _, cmd in self._left:
            cmd.set_value(v_left)
        for _, cmd in self._right:
            cmd.set_value(v_right)
        return ReturnType.OK

    def _publish_odometry(self, time: float) -> None:
        odom = self.odometry
        msg = Odometry(Header(stamp=time, frame_id=self._odom_frame), self._base_frame)
        msg.pose.pose.position.x, msg.pose.pose.position.y = odom.x, odom.y
        msg.pose.pose.orientation = Quaternion(0.0, 0.0, math.sin(odom.heading / 2.0), math.cos(odom.heading / 2.0))
        msg.twist.twist.linear.x, msg.twist.twist.angular.z = odom.linear, odom.angular
        for k in range(6):
            msg.pose.covariance[7 * k] = self._p.pose_covariance_diagonal[k]
            msg.twist.covariance[7 * k] = self._p.twist_covariance_diagonal[k]
        self._odom_pub.publish(msg)
