"""BicycleSteeringController: kinematics, a car-like robot on mock hardware, odometry, parameters.

The robot (tests/unit/data/carlike.urdf) has a driven rear wheel and a steered front axle, 0.4 m apart, wheel radius
0.05 m; its controllers file (carlike_controllers.yaml) is in the demos' layout.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import core_helpers  # noqa: F401  (registers the test controllers)
import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.controllers.bicycle_steering import BicycleSteeringController, bicycle_commands, steering_angle
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import Header, TwistStamped
from rrbot_workshop.testing import ControllerHarness

DATA = Path(__file__).parent / "data"
URDF = DATA / "carlike.urdf"
YAML = DATA / "carlike_controllers.yaml"
NAME = "bicycle_steering_controller"
WHEELBASE, RADIUS = 0.4, 0.05
TRACTION, STEERING = "rear_wheel_joint/velocity", "front_steering_joint/position"


def _twist(v: float, w: float, stamp: float = 0.0) -> TwistStamped:
    msg = TwistStamped(Header(stamp=stamp))
    msg.twist.linear.x, msg.twist.angular.z = v, w
    return msg


def _params(**over: object) -> dict:
    params = yaml.safe_load(YAML.read_text())[NAME]["ros__parameters"]
    params.update(over)
    return {k: v for k, v in params.items() if v is not None}


def _harness(**over: object) -> ControllerHarness:
    return ControllerHarness(
        BicycleSteeringController(), NAME, _params(**over), update_rate=50,
        state_values={"rear_wheel_joint/velocity": 0.0, "rear_wheel_joint/position": 0.0, STEERING: 0.0},
        command_values={TRACTION: 0.0, STEERING: 0.0})


# ----------------------------------------------------------------------------- kinematics


@pytest.mark.parametrize(("v", "w", "phi"), [
    (0.5, 0.5, math.atan(0.4)),
    (0.5, -0.5, -math.atan(0.4)),
    (-0.5, 0.5, -math.atan(0.4)),  # backwards, turning left: the wheel steers the other way
    (1.0, 0.0, 0.0),
    (0.0, 0.0, 0.0),  # atan(0/0) is NaN in Jazzy, replaced by 0
    (0.0, 0.3, math.pi / 2),  # atan(+inf): Jazzy turns the wheel across
    (0.0, -0.3, -math.pi / 2),
])
def test_steering_angle_is_atan_of_wheelbase_times_omega_over_v(v: float, w: float, phi: float) -> None:
    assert steering_angle(v, w, WHEELBASE) == pytest.approx(phi)


def test_wheel_speed_is_v_over_r_and_slows_while_steering_is_far() -> None:
    assert bicycle_commands(0.5, 0.5, WHEELBASE, RADIUS) == pytest.approx((10.0, math.atan(0.4)))
    slowed, _ = bicycle_commands(0.5, 0.0, WHEELBASE, RADIUS, measured_angle=1.0)
    assert slowed == pytest.approx(10.0 * math.cos(1.0) / math.cos(math.pi / 6))
    assert bicycle_commands(0.5, 0.0, WHEELBASE, RADIUS, measured_angle=0.1)[0] == pytest.approx(10.0)


# ----------------------------------------------------------------------------- the car-like robot


@pytest.fixture
def car():  # noqa: ANN201
    with rw.bringup(URDF, YAML, spawn=["joint_state_broadcaster", NAME]) as system:
        yield system


def _drive(system: rw.System, v: float, w: float, seconds: float) -> None:
    for _ in range(round(seconds / 0.1)):
        system.publish(f"/{NAME}/reference", _twist(v, w, stamp=system.time))
        system.spin_cycles(5)


def test_registered_and_exports_its_references(car: rw.System) -> None:
    assert plugins.resolve("controller", "bicycle_steering_controller/BicycleSteeringController") \
        is BicycleSteeringController
    rm = car.resource_manager
    assert rm.command_interface_exists(f"{NAME}/linear/velocity")
    assert rm.command_interface_exists(f"{NAME}/angular/velocity")


def test_a_twist_turns_the_wheel_and_steers(car: rw.System) -> None:
    _drive(car, 0.5, 0.5, 1.0)
    rm = car.resource_manager
    assert rm.get_interface_value(TRACTION, kind="command") == pytest.approx(0.5 / RADIUS)
    assert rm.get_interface_value(STEERING, kind="command") == pytest.approx(math.atan(WHEELBASE * 0.5 / 0.5))
    js = car.latest("/joint_states")
    assert dict(zip(js.name, js.velocity, strict=True))["rear_wheel_joint"] == pytest.approx(10.0)


def test_closed_loop_odometry_integrates_the_arc(car: rw.System) -> None:
    _drive(car, 0.5, 0.5, 2.0)
    odom = car.latest(f"/{NAME}/odometry")
    assert odom.header.frame_id == "odom" and odom.child_frame_id == "base_link"
    # from the mirrored wheel speed and angle: v = w r, omega = tan(phi) v / L
    assert odom.twist.twist.linear.x == pytest.approx(0.5) and odom.twist.twist.angular.z == pytest.approx(0.5)
    heading = 2.0 * math.atan2(odom.pose.pose.orientation.z, odom.pose.pose.orientation.w)
    assert heading == pytest.approx(0.5 * 2.0, abs=0.5 * 0.05)  # within a cycle or two of the arc
    radius = 0.5 / 0.5
    assert odom.pose.pose.position.x == pytest.approx(radius * math.sin(heading), abs=1e-6)
    assert odom.pose.pose.position.y == pytest.approx(radius * (1 - math.cos(heading)), abs=1e-6)
    assert odom.pose.covariance[35] == 0.2


def test_a_stale_reference_stops_the_wheel(car: rw.System) -> None:
    _drive(car, 0.5, 0.5, 0.5)
    car.spin(1.0)  # no twist for longer than reference_timeout 0.5 s
    rm = car.resource_manager
    assert rm.get_interface_value(TRACTION, kind="command") == 0.0
    assert rm.get_interface_value(STEERING, kind="command") == pytest.approx(math.atan(0.4))  # steering is kept


def test_an_old_twist_is_dropped(car: rw.System, caplog: pytest.LogCaptureFixture) -> None:
    car.spin(2.0)
    with caplog.at_level(logging.ERROR):
        car.publish(f"/{NAME}/reference", _twist(0.5, 0.0, stamp=car.time - 1.0))
        car.spin_cycles(2)
    assert "reference_timeout" in caplog.text
    assert car.resource_manager.get_interface_value(TRACTION, kind="command") == 0.0


def test_chained_a_preceding_controller_drives_it() -> None:
    config = yaml.safe_load(YAML.read_text())
    config["controller_manager"]["ros__parameters"]["pre"] = {"type": "test_controller/TestController"}
    config["pre"] = {"ros__parameters": {"command_interfaces": [f"{NAME}/linear/velocity", f"{NAME}/angular/velocity"]}}
    with rw.bringup(URDF, config, spawn=[NAME, "pre"]) as system:
        cm = system.controller_manager
        assert cm.get_controller(NAME).is_in_chained_mode()
        assert cm.update_order().index("pre") < cm.update_order().index(NAME)
        cm.get_controller("pre").command_value = 0.4  # v = omega = 0.4
        system.spin_cycles(3)
        rm = system.resource_manager
        assert rm.get_interface_value(TRACTION, kind="command") == pytest.approx(0.4 / RADIUS)
        assert rm.get_interface_value(STEERING, kind="command") == pytest.approx(math.atan(WHEELBASE))


# ----------------------------------------------------------------------------- unit cases and parameters


def test_open_loop_odometry_integrates_the_references() -> None:
    h = _harness(open_loop=True)
    assert h.configure() is State.INACTIVE and h.activate() is State.ACTIVE
    for _ in range(50):
        h.publish("~/reference", _twist(1.0, 0.0, stamp=h.time))
        h.update()
    odom = h.latest("~/odometry")
    assert odom.pose.pose.position.x == pytest.approx(1.0) and odom.pose.pose.position.y == 0.0


def test_position_feedback_reads_the_wheel_position() -> None:
    h = _harness(position_feedback=True)
    h.configure()
    assert h.controller.state_interface_configuration().names == ["rear_wheel_joint/position", STEERING]
    h.activate()
    for k in range(1, 11):
        h.set("rear_wheel_joint/position", 0.2 * k)  # 10 rad/s at 50 Hz
        h.update()
    assert h.latest("~/odometry").twist.twist.linear.x == pytest.approx(10.0 * RADIUS)


def test_the_demos_layout_has_no_undeclared_parameter() -> None:
    h = _harness()
    assert h.controller.param_listener is not None and h.controller.param_listener.undeclared == []


def test_deprecated_names_still_work_with_warnings(caplog: pytest.LogCaptureFixture) -> None:
    h = _harness(traction_joints_names=None, steering_joints_names=None, traction_wheel_radius=None,
                 rear_wheels_names=["rear_wheel_joint"], front_wheels_names=["front_steering_joint"],
                 rear_wheel_radius=RADIUS)
    with caplog.at_level(logging.WARNING):
        assert h.configure() is State.INACTIVE
    assert "'rear_wheels_names' is deprecated" in caplog.text and "'rear_wheel_radius' is deprecated" in caplog.text
    assert h.controller.command_interface_configuration().names == [TRACTION, STEERING]


def test_zero_wheelbase_is_refused_at_load() -> None:
    with pytest.raises(ParameterError, match="wheelbase"):
        _harness(wheelbase=0.0)


@pytest.mark.parametrize(("over", "named"), [
    ({"traction_joints_names": ["a", "b"]}, "'traction_joints_names' must name exactly one joint"),
    ({"steering_joints_names": []}, "'steering_joints_names' must name exactly one joint"),
    ({"traction_wheel_radius": 0.0}, "'traction_wheel_radius' must be > 0"),
    ({"velocity_rolling_window_size": 0}, "'velocity_rolling_window_size' must be >= 1"),
])
def test_bad_parameters_fail_configure_naming_them(over: dict, named: str, caplog: pytest.LogCaptureFixture) -> None:
    h = _harness(**over)
    with caplog.at_level(logging.ERROR):
        assert h.configure() is not State.INACTIVE
    assert named in caplog.text
