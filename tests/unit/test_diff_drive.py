"""DiffDriveController, its odometry and speed limiter (after diff_drive_controller's tests)."""

from __future__ import annotations

import math
from typing import Any

import pytest

from rrbot_workshop.controllers.diff_drive import DiffDriveController
from rrbot_workshop.controllers.odometry import Odometry, SpeedLimiter
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.lifecycle import ReturnType, State
from rrbot_workshop.msgs import Header, TwistStamped
from rrbot_workshop.testing import ControllerHarness

# ----------------------------------------------------------------------------- odometry (test_odometry.cpp numbers)


def _odom() -> Odometry:
    odom = Odometry(10)
    odom.set_wheel_params(1.0, 1.0, 1.0)
    return odom


def test_odometry_starts_at_the_origin() -> None:
    odom = _odom()
    assert (odom.x, odom.y, odom.heading, odom.linear, odom.angular) == (0.0, 0.0, 0.0, 0.0, 0.0)


def test_odometry_straight_line() -> None:
    odom = _odom()
    assert odom.update_from_velocity(1.0, 1.0, 1.0)
    assert (odom.x, odom.y, odom.heading, odom.linear, odom.angular) == pytest.approx((1.0, 0.0, 0.0, 1.0, 0.0))


def test_odometry_turn_in_place() -> None:
    odom = _odom()
    assert odom.update_from_velocity(-1.0, 1.0, 1.0)
    assert (odom.x, odom.y, odom.heading, odom.linear, odom.angular) == pytest.approx((0.0, 0.0, 2.0, 0.0, 2.0))


def test_odometry_exact_arc() -> None:
    odom = _odom()
    assert odom.update_from_velocity(1.0, 2.0, 1.0)
    assert odom.x == pytest.approx(1.5 * math.sin(1.0), abs=1e-5)
    assert odom.y == pytest.approx(-1.5 * (math.cos(1.0) - 1.0), abs=1e-5)
    assert odom.heading == pytest.approx(1.0)


def test_odometry_rejects_a_tiny_interval() -> None:
    odom = _odom()
    assert not odom.update_from_velocity(1.0, 1.0, 1e-7)
    assert odom.x == 0.0


def test_odometry_open_loop_integrates_the_command() -> None:
    odom = _odom()
    odom.update_open_loop(2.0, 0.5, 1.0)
    assert odom.x == pytest.approx(4.0 * math.sin(0.5), abs=1e-5)
    assert odom.y == pytest.approx(-4.0 * (math.cos(0.5) - 1.0), abs=1e-5)
    assert (odom.heading, odom.linear, odom.angular) == pytest.approx((0.5, 2.0, 0.5))


def test_odometry_from_positions_uses_the_first_sample_as_baseline() -> None:
    odom = _odom()
    assert not odom.update(1.0, 1.0, 1.0)
    assert odom.x == 0.0
    assert odom.update(2.0, 2.0, 2.0)
    assert (odom.x, odom.linear) == pytest.approx((1.0, 1.0))


def test_odometry_velocity_is_a_rolling_mean() -> None:
    odom = Odometry(2)
    odom.set_wheel_params(1.0, 1.0, 1.0)
    odom.update_from_velocity(1.0, 1.0, 1.0)
    odom.update_from_velocity(3.0, 3.0, 2.0)
    odom.update_from_velocity(3.0, 3.0, 3.0)
    assert odom.linear == pytest.approx(3.0)
    odom.reset_odometry()
    assert (odom.x, odom.y, odom.heading) == (0.0, 0.0, 0.0)


# ----------------------------------------------------------------------------- speed limiter


def test_limiter_with_nan_limits_passes_through() -> None:
    assert SpeedLimiter().limit(5.0, 0.0, 0.0, 0.01) == 5.0


def test_limiter_clamps_velocity_symmetrically() -> None:
    lim = SpeedLimiter(max_velocity=1.0)
    assert (lim.limit(2.0, 1.0, 1.0, 0.01), lim.limit(-2.0, -1.0, -1.0, 0.01)) == (1.0, -1.0)


def test_limiter_bounds_acceleration() -> None:
    lim = SpeedLimiter(max_acceleration=1.0)
    assert lim.limit(1.0, 0.0, 0.0, 0.1) == pytest.approx(0.1)
    assert lim.limit(0.0, 1.0, 1.0, 0.1) == pytest.approx(0.9)  # deceleration defaults to the acceleration


def test_limiter_bounds_jerk() -> None:
    lim = SpeedLimiter(max_jerk=1.0)
    assert lim.limit(1.0, 0.0, 0.0, 0.1) == pytest.approx(0.02)


# ----------------------------------------------------------------------------- controller

PARAMS = {"left_wheel_names": ["left_wheel_joint"], "right_wheel_names": ["right_wheel_joint"],
          "wheel_separation": 0.1, "wheel_radius": 0.015}


def make(**overrides: Any) -> ControllerHarness:
    params = {**PARAMS, **overrides}
    h = ControllerHarness(
        DiffDriveController(), "diff_drive", params,
        state_values={"left_wheel_joint/position": 0.0, "right_wheel_joint/position": 0.0,
                      "left_wheel_joint/velocity": 0.0, "right_wheel_joint/velocity": 0.0},
        command_values={"left_wheel_joint/velocity": 0.0, "right_wheel_joint/velocity": 0.0},
    )
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    return h


def twist(linear: float, angular: float, stamp: float = 0.0) -> TwistStamped:
    msg = TwistStamped(Header(stamp=stamp))
    msg.twist.linear.x, msg.twist.angular.z = linear, angular
    return msg


def wheels(h: ControllerHarness) -> list[float]:
    return h.values(["left_wheel_joint/velocity", "right_wheel_joint/velocity"])


def drive(h: ControllerHarness, cycles: int) -> None:
    """Step like mock hardware with dynamics: wheel positions integrate the velocity commands."""
    for _ in range(cycles):
        h.update()
        for side in ("left", "right"):
            v = h.commands[f"{side}_wheel_joint/velocity"].get_value()
            h.states[f"{side}_wheel_joint/position"].set_value(h.states[f"{side}_wheel_joint/position"].get_value()
                                                                + v * h.period)


@pytest.mark.parametrize(
    "overrides",
    [{"wheel_radius": 0.0}, {"wheel_separation": -1.0}, {"left_wheel_names": []},
     {"right_wheel_names": ["a", "b"]}, {"pose_covariance_diagonal": [0.0]}],
)
def test_invalid_parameters_raise_parameter_error(overrides: dict[str, Any]) -> None:
    with pytest.raises(ParameterError):
        ControllerHarness(DiffDriveController(), "diff_drive", {**PARAMS, **overrides})


def test_exports_linear_and_angular_velocity_references() -> None:
    h = make()
    assert [r.name for r in h.controller.reference_interfaces] == [
        "diff_drive/linear/velocity", "diff_drive/angular/velocity"]


def test_twist_becomes_wheel_velocities() -> None:
    h = make()
    h.publish("~/cmd_vel", twist(0.1, 1.0))
    h.update()
    assert wheels(h) == pytest.approx([(0.1 - 0.05) / 0.015, (0.1 + 0.05) / 0.015])


def test_multipliers_scale_separation_and_radii() -> None:
    h = make(wheel_separation_multiplier=2.0, left_wheel_radius_multiplier=0.5)
    h.publish("~/cmd_vel", twist(0.1, 1.0))
    h.update()
    assert wheels(h) == pytest.approx([(0.1 - 0.1) / 0.0075, (0.1 + 0.1) / 0.015])


def test_no_command_leaves_the_wheels_alone() -> None:
    h = make()
    h.update(5)
    assert wheels(h) == [0.0, 0.0]


def test_stale_twist_stops_the_base() -> None:
    h = make()
    h.publish("~/cmd_vel", twist(0.1, 0.0))
    h.update(10)
    assert wheels(h)[0] > 0.0
    h.update(50)
    assert wheels(h) == [0.0, 0.0]


def test_old_twist_is_ignored() -> None:
    h = make()
    h.update(100)
    h.publish("~/cmd_vel", twist(0.1, 0.0, stamp=0.1))
    h.update()
    assert wheels(h) == [0.0, 0.0]


def test_zero_timeout_never_goes_stale() -> None:
    h = make(cmd_vel_timeout=0.0)
    h.publish("~/cmd_vel", twist(0.1, 0.0))
    h.update(200)
    assert wheels(h)[0] == pytest.approx(0.1 / 0.015)


def test_odometry_follows_the_wheels_and_is_published() -> None:
    """0.1 m/s for 1 s: the odometry says about 0.1 m forwards."""
    h = make(cmd_vel_timeout=2.0)
    h.publish("~/cmd_vel", twist(0.1, 0.0))
    drive(h, 100)
    odom = h.latest("~/odom")
    assert odom.pose.pose.position.x == pytest.approx(0.1, abs=0.003)
    assert odom.twist.twist.linear.x == pytest.approx(0.1)
    assert odom.header.frame_id == "odom" and odom.child_frame_id == "base_link"


def test_odometry_is_published_at_publish_rate() -> None:
    h = make(publish_rate=10.0)
    h.publish("~/cmd_vel", twist(0.1, 0.0))
    h.update(100)
    assert 9 <= len(h.bus.history("/diff_drive/odom")) <= 11


def test_open_loop_odometry_integrates_the_command() -> None:
    h = make(open_loop=True)
    h.publish("~/cmd_vel", twist(0.2, 0.0))
    h.update(51)
    assert h.controller.odometry.x == pytest.approx(0.2 * 0.5, abs=0.003)


def test_open_loop_odometry_integrates_the_limited_command() -> None:
    """Jazzy: with open_loop the odometry follows what the wheels are told, the twist after the speed limiter."""
    h = make(open_loop=True, linear={"x": {"max_velocity": 0.05}})
    h.publish("~/cmd_vel", twist(0.2, 0.0))
    h.update(51)
    assert h.controller.odometry.x == pytest.approx(0.05 * 0.5, abs=0.003)


def test_speed_limit_applies_to_the_wheels() -> None:
    h = make(linear={"x": {"max_velocity": 0.05}})
    h.publish("~/cmd_vel", twist(0.1, 0.0))
    h.update()
    assert wheels(h) == pytest.approx([0.05 / 0.015, 0.05 / 0.015])


def test_nan_wheel_feedback_is_an_error() -> None:
    h = make()
    h.publish("~/cmd_vel", twist(0.1, 0.0))
    h.set("left_wheel_joint/position", math.nan)
    assert h.update() is ReturnType.ERROR


def test_chained_mode_reads_the_references() -> None:
    h = make()
    h.deactivate()
    assert h.set_chained_mode(True)
    assert h.activate() is State.ACTIVE
    h.commands["diff_drive/linear/velocity"].set_value(0.03)
    h.commands["diff_drive/angular/velocity"].set_value(0.0)
    h.update()
    assert wheels(h) == pytest.approx([2.0, 2.0])


def test_deactivate_stops_the_wheels() -> None:
    h = make()
    h.publish("~/cmd_vel", twist(0.1, 0.0))
    h.update()
    h.deactivate()
    assert wheels(h) == [0.0, 0.0]
