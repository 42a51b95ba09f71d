"""``bicycle_steering_controller/BicycleSteeringController``: a car-like base as one driven and one steered wheel.

Jazzy's ``steering_controllers_library`` in its bicycle configuration. A chainable controller: its two reference
interfaces ``<name>/linear/velocity`` [m/s] and ``<name>/angular/velocity`` [rad/s] are set from ``~/reference``
(``geometry_msgs/TwistStamped``) when not chained, or written by a preceding controller. Each cycle it:

1. integrates the odometry, from the traction wheel (``velocity``, or ``position`` with ``position_feedback``) and the
   steering angle (``position``), or from the references with ``open_loop``; published on ``~/odometry``;
2. commands ``<traction joint>/velocity`` and ``<steering joint>/position``::

       steering angle  phi = atan(wheelbase * omega / v)      (0 when v and omega are 0; +-pi/2 when only v is 0)
       wheel speed     w   = v / traction_wheel_radius        [rad/s]

   (with ``reduce_wheel_speed_until_steering_reached``, closed loop: ``w`` shrinks by
   ``cos(min(|phi - measured|, 1.5608)) / cos(pi/6)`` while the angle is more than pi/6 off);
3. sets its references back to NaN: a preceding controller writes them every cycle, and without references the
   traction wheel is commanded 0 (the steering keeps its angle).

A twist older than ``reference_timeout`` is dropped (the wheel stops); with 0 each twist is used for one cycle. A
twist with a zero stamp is stamped on receipt.

Differences from Jazzy, on purpose: ``~/tf_odometry`` and ``~/controller_state`` are not published (the library has
no tf); a traction wheel radius that is not > 0 is refused at configure (Jazzy divides by it).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.controllers.bicycle_steering_parameters import BICYCLE_STEERING_CONTROLLER_PARAMETERS
from rrbot_workshop.controllers.odometry import Odometry as _DiffDriveOdometry
from rrbot_workshop.hardware_interface.handles import CommandInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.msgs import Header, Odometry, Quaternion, TwistStamped

__all__ = ["BicycleSteeringController", "BicycleOdometry", "steering_angle", "bicycle_commands"]

_MIN_PHI_DELTA = math.pi / 6.0
_MAX_PHI_DELTA = 1.5608


def steering_angle(linear: float, angular: float, wheelbase: float) -> float:
    """The bicycle's steering angle in [rad] for a twist: ``atan(wheelbase * angular / linear)``.

    As Jazzy computes it in floating point: 0 when both velocities are 0, +-pi/2 (turning on the spot about the
    rear axle, which the traction wheel cannot do: its speed is 0) when only ``linear`` is 0.
    """
    numerator = angular * wheelbase
    if linear == 0.0:
        if numerator == 0.0 or math.isnan(numerator):
            return 0.0
        return math.copysign(math.pi / 2, numerator) * math.copysign(1.0, linear)
    phi = math.atan(numerator / linear)
    return phi if math.isfinite(phi) else 0.0


def bicycle_commands(linear: float, angular: float, wheelbase: float, wheel_radius: float,
                     measured_angle: float | None = None) -> tuple[float, float]:
    """Traction wheel speed [rad/s] and steering angle [rad] for a twist (``v`` [m/s], ``omega`` [rad/s]).

    Args:
        linear: Forward velocity of the rear axle in [m/s].
        angular: Yaw rate in [rad/s].
        wheelbase: Distance between the axles in [m].
        wheel_radius: Traction wheel radius in [m].
        measured_angle: The current steering angle; given, the wheel slows while the steering is far from its target
            (``reduce_wheel_speed_until_steering_reached``).
    """
    phi = steering_angle(linear, angular, wheelbase)
    speed = linear / wheel_radius
    if measured_angle is not None:
        delta = abs(measured_angle - phi)
        if delta >= _MIN_PHI_DELTA:
            speed *= math.cos(min(delta, _MAX_PHI_DELTA)) / math.cos(_MIN_PHI_DELTA)
    return speed, phi


class BicycleOdometry(_DiffDriveOdometry):
    """Pose and twist of a bicycle base, integrated per period (the diff drive's integration, another kinematics).

    Args:
        velocity_rolling_window_size: Number of steps averaged for the reported velocities.
    """

    def __init__(self, velocity_rolling_window_size: int = 10) -> None:
        super().__init__(velocity_rolling_window_size)
        self.wheelbase = 0.0
        self.wheel_radius = 0.0
        self._traction_old = 0.0

    def set_bicycle_params(self, wheel_radius: float, wheelbase: float) -> None:
        """Traction wheel radius and wheelbase in [m]."""
        self.wheel_radius, self.wheelbase = wheel_radius, wheelbase

    def reset_odometry(self) -> None:
        """Pose back to the origin, velocities cleared (the traction wheel baseline is kept, as Jazzy)."""
        super().reset_odometry()

    def update_twist(self, linear: float, angular: float, dt: float) -> bool:
        """Integrate a body twist (``linear`` [m/s], ``angular`` [rad/s]) over ``dt`` [s].

        Returns:
            False if ``dt`` is under 0.1 ms: the pose moves but the velocity means do not.
        """
        self._integrate_exact(linear * dt, angular * dt)
        if dt < 0.0001:
            return False
        self._lin_acc.append(linear)
        self._ang_acc.append(angular)
        self.linear = sum(self._lin_acc) / len(self._lin_acc)
        self.angular = sum(self._ang_acc) / len(self._ang_acc)
        return True

    def update_from_wheel_velocity(self, traction_velocity: float, steering: float, dt: float) -> bool:
        """From the traction wheel speed [rad/s] and steering angle [rad]: ``v = w r``, ``omega = tan(phi) v / L``."""
        linear = traction_velocity * self.wheel_radius
        return self.update_twist(linear, math.tan(steering) * linear / self.wheelbase, dt)

    def update_from_wheel_position(self, traction_position: float, steering: float, dt: float) -> bool:
        """From the traction wheel position [rad] (its change over ``dt``) and the steering angle [rad]."""
        change = traction_position - self._traction_old
        self._traction_old = traction_position
        return self.update_from_wheel_velocity(change / dt, steering, dt) if dt > 0.0 else False

    def update_open_loop_twist(self, linear: float, angular: float, dt: float) -> None:
        """Integrate the commanded twist over ``dt`` [s]; the reported velocities are the command."""
        self.linear, self.angular = linear, angular
        self._integrate_exact(linear * dt, angular * dt)


class BicycleSteeringController(ChainableControllerInterface):
    """Bicycle steering controller; see the module docstring.

    Attributes:
        odometry: The integrated pose and twist.
        traction_joint: The traction joint commanded (``traction_joints_names``, or a deprecated name).
        steering_joint: The steering joint commanded.
    """

    PARAMETERS: ClassVar[str | None] = BICYCLE_STEERING_CONTROLLER_PARAMETERS

    def __init__(self) -> None:
        super().__init__()
        self.odometry = BicycleOdometry()
        self.traction_joint = ""
        self.steering_joint = ""
        self._traction_state = ""
        self._steering_state = ""
        self._p: Any = None
        self._wheel_radius = 0.0
        self._reference: TwistStamped = TwistStamped()
        self._sub: Any = None
        self._odom_pub: Any = None

    # ----------------------------------------------------------------- configuration
    def _resolve_names(self, p: Any, log: bool = True) -> tuple[dict[str, list[str]], str | None]:
        """Jazzy's reading of the deprecated names; returns the joint lists, or the parameter that is wrong."""
        names = {
            "traction_joints_names": list(p.traction_joints_names),
            "steering_joints_names": list(p.steering_joints_names),
            "traction_joints_state_names": list(p.traction_joints_state_names),
            "steering_joints_state_names": list(p.steering_joints_state_names),
        }
        front = "steering" if p.front_steering else "traction"
        rear = "traction" if p.front_steering else "steering"
        if not p.front_steering and log:
            self.logger.warning("'%s': parameter 'front_steering' is deprecated; set 'traction_joints_names' and "
                                "'steering_joints_names'", self.get_name())
        for old, new in (("front_wheels_names", f"{front}_joints_names"), ("rear_wheels_names", f"{rear}_joints_names"),
                         ("front_wheels_state_names", f"{front}_joints_state_names"),
                         ("rear_wheels_state_names", f"{rear}_joints_state_names")):
            value = list(getattr(p, old))
            if value:
                if log:
                    self.logger.warning("'%s': parameter '%s' is deprecated; set '%s' instead", self.get_name(), old,
                                        new)
                names[new] = value
        for key in ("traction_joints_names", "steering_joints_names"):
            if len(names[key]) != 1:
                return names, key
        for key in ("traction_joints_state_names", "steering_joints_state_names"):
            if names[key] and len(names[key]) != 1:
                return names, key
        return names, None

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read and check the parameters, set up the odometry and the topics."""
        assert self.param_listener is not None
        self._p = None
        p = self.param_listener.get_params()
        names, wrong = self._resolve_names(p)
        if wrong is not None:
            self.logger.error("'%s': parameter '%s' must name exactly one joint for a bicycle, got %s",
                              self.get_name(), wrong, names[wrong])
            return CallbackReturn.ERROR
        radius = p.traction_wheel_radius
        for old in ("front_wheel_radius", "rear_wheel_radius"):
            if getattr(p, old) > 0.0:
                self.logger.warning("'%s': parameter '%s' is deprecated; set 'traction_wheel_radius' instead",
                                    self.get_name(), old)
                radius = getattr(p, old)
        if not radius > 0.0:
            self.logger.error("'%s': parameter 'traction_wheel_radius' must be > 0 [m], got %s", self.get_name(), radius)
            return CallbackReturn.ERROR
        if p.velocity_rolling_window_size < 1:
            self.logger.error("'%s': parameter 'velocity_rolling_window_size' must be >= 1, got %d", self.get_name(),
                              p.velocity_rolling_window_size)
            return CallbackReturn.ERROR
        for key in ("pose_covariance_diagonal", "twist_covariance_diagonal"):
            if len(getattr(p, key)) != 6:
                self.logger.error("'%s': parameter '%s' needs 6 values, got %d", self.get_name(), key,
                                  len(getattr(p, key)))
                return CallbackReturn.ERROR
        self._p = p
        self._wheel_radius = radius
        self.traction_joint = names["traction_joints_names"][0]
        self.steering_joint = names["steering_joints_names"][0]
        self._traction_state = (names["traction_joints_state_names"] or [self.traction_joint])[0]
        self._steering_state = (names["steering_joints_state_names"] or [self.steering_joint])[0]
        self.odometry.set_bicycle_params(radius, p.wheelbase)
        self.odometry.set_velocity_rolling_window_size(p.velocity_rolling_window_size)
        self.odometry.reset_odometry()
        node = self.get_node()
        if self._sub is None:
            self._sub = node.create_subscription(TwistStamped, "~/reference", self._on_reference)
        if self._odom_pub is None:
            self._odom_pub = node.create_publisher(Odometry, "~/odometry")
        self._reference = self._empty_reference()
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Drop the subscription and forget the odometry."""
        if self._sub is not None:
            self._sub.destroy()
            self._sub = None
        self.odometry.reset_odometry()
        self._p = None
        return CallbackReturn.SUCCESS

    def _joints(self) -> tuple[str, str, str, str, Any]:
        """Traction, steering, traction state and steering state joints, and the parameters (read now if the
        controller is not configured yet, as a tool may ask before configure)."""
        if self._p is not None:
            return self.traction_joint, self.steering_joint, self._traction_state, self._steering_state, self._p
        assert self.param_listener is not None
        p = self.param_listener.get_params()
        names, _ = self._resolve_names(p, log=False)
        first = [(names[k] or [""])[0] for k in ("traction_joints_names", "steering_joints_names")]
        states = [(names[k] or [j])[0] for k, j in zip(("traction_joints_state_names", "steering_joints_state_names"),
                                                        first, strict=True)]
        return first[0], first[1], states[0], states[1], p

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """``<traction>/velocity``, then ``<steering>/position``."""
        traction, steering, _, _, _ = self._joints()
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL,
                                      [f"{traction}/velocity", f"{steering}/position"])

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """``<traction state>/velocity`` (or ``/position`` with position feedback), then ``<steering state>/position``."""
        _, _, traction, steering, p = self._joints()
        feedback = "position" if p.position_feedback else "velocity"
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL,
                                      [f"{traction}/{feedback}", f"{steering}/position"])

    def on_export_reference_interfaces(self) -> list[CommandInterface]:
        """``<name>/linear/velocity`` and ``<name>/angular/velocity``, NaN until commanded."""
        name = self.get_name()
        return [CommandInterface(f"{name}/linear", "velocity", initial_value=math.nan),
                CommandInterface(f"{name}/angular", "velocity", initial_value=math.nan)]

    def on_set_chained_mode(self, chained_mode: bool) -> bool:
        """Either mode is fine."""
        return True

    # ----------------------------------------------------------------- lifecycle
    def _empty_reference(self) -> TwistStamped:
        msg = TwistStamped(Header(stamp=self.get_node().now()))
        msg.twist.linear.x = msg.twist.angular.z = math.nan
        return msg

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Forget any twist received before."""
        self._reference = self._empty_reference()
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Command NaN to both joints, as Jazzy does."""
        for cmd in self.command_interfaces:
            cmd.set_value(math.nan)
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- topic (non-real-time side)
    def _on_reference(self, msg: TwistStamped) -> None:
        now = self.get_node().now()
        if msg.header.stamp == 0.0:
            self.logger.warning("'%s': the twist on ~/reference has no stamp; using the time of receipt",
                                self.get_name())
            msg = TwistStamped(Header(stamp=now, frame_id=msg.header.frame_id), msg.twist)
        timeout = self._p.reference_timeout
        age = now - msg.header.stamp
        if timeout == 0.0 or age <= timeout:
            self._reference = msg
        else:
            self.logger.error("'%s': dropped a twist on ~/reference %.4f s old (reference_timeout %.4f s)",
                              self.get_name(), age, timeout)

    # ----------------------------------------------------------------- cycle
    def update_reference_from_subscribers(self, time: float, period: float) -> ReturnType:
        """The last twist becomes the references until it is ``reference_timeout`` old."""
        msg = self._reference
        timeout = self._p.reference_timeout
        linear, angular = msg.twist.linear.x, msg.twist.angular.z
        if timeout == 0.0 or time - msg.header.stamp <= timeout:
            if math.isfinite(linear) and math.isfinite(angular):
                self.reference_interfaces[0].set_value(linear)
                self.reference_interfaces[1].set_value(angular)
                if timeout == 0.0:
                    self._reference = self._stale(msg)
        elif not (math.isnan(linear) or math.isnan(angular)):
            self.reference_interfaces[0].set_value(math.nan)
            self.reference_interfaces[1].set_value(math.nan)
            self._reference = self._stale(msg)
        return ReturnType.OK

    @staticmethod
    def _stale(msg: TwistStamped) -> TwistStamped:
        out = TwistStamped(Header(stamp=msg.header.stamp, frame_id=msg.header.frame_id))
        out.twist.linear.x = out.twist.angular.z = math.nan
        return out

    def update_and_write_commands(self, time: float, period: float) -> ReturnType:
        """Odometry, then the wheel speed and steering angle; the references are used up."""
        p = self._p
        linear = self.reference_interfaces[0].get_value()
        angular = self.reference_interfaces[1].get_value()
        if p.open_loop:
            self.odometry.update_open_loop_twist(linear if math.isfinite(linear) else 0.0,
                                                 angular if math.isfinite(angular) else 0.0, period)
        else:
            traction = float(self.state_interfaces[0].get_value())
            steering = float(self.state_interfaces[1].get_value())
            if math.isfinite(traction) and math.isfinite(steering):
                if p.position_feedback:
                    self.odometry.update_from_wheel_position(traction, steering, period)
                else:
                    self.odometry.update_from_wheel_velocity(traction, steering, period)
        if not (math.isnan(linear) or math.isnan(angular)):
            measured = None
            if not p.open_loop and p.reduce_wheel_speed_until_steering_reached:
                measured = float(self.state_interfaces[1].get_value())
            speed, phi = bicycle_commands(linear, angular, p.wheelbase, self._wheel_radius, measured)
            self.command_interfaces[0].set_value(speed)
            self.command_interfaces[1].set_value(phi)
        else:
            self.command_interfaces[0].set_value(0.0)
        self._publish_odometry(time)
        self.reference_interfaces[0].set_value(math.nan)
        self.reference_interfaces[1].set_value(math.nan)
        return ReturnType.OK

    def _publish_odometry(self, time: float) -> None:
        odom, p = self.odometry, self._p
        msg = Odometry(Header(stamp=time, frame_id=p.odom_frame_id), p.base_frame_id)
        msg.pose.pose.position.x, msg.pose.pose.position.y = odom.x, odom.y
        msg.pose.pose.orientation = Quaternion(0.0, 0.0, math.sin(odom.heading / 2.0), math.cos(odom.heading / 2.0))
        msg.twist.twist.linear.x, msg.twist.twist.angular.z = odom.linear, odom.angular
        for k in range(6):
            msg.pose.covariance[7 * k] = p.pose_covariance_diagonal[k]
            msg.twist.covariance[7 * k] = p.twist_covariance_diagonal[k]
        self._odom_pub.publish(msg)
