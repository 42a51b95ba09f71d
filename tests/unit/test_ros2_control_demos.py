"""ros2_control_demos (jazzy), brought up as its examples' docs say, with mock hardware and documented options only.

The clone is kept outside the project: set ``RRBOT_WORKSHOP_DEMOS`` to its folder
(``git clone -b jazzy https://github.com/ros-controls/ros2_control_demos``) to run these; without it they skip.
Each example: its own description and controllers YAML from the clone (found through the package path), its hardware
plugins mocked (``mock_hardware="unknown"``), the controllers its launch file spawns, and a command on the topic its
docs use; the joints must move as commanded. Every controllers YAML of the clone must also lint with no error or
warning other than the ones listed (each one true).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop import msgs

D = Path(os.environ.get("RRBOT_WORKSHOP_DEMOS", "/nonexistent"))
pytestmark = pytest.mark.skipif(not (D / "example_1").is_dir(),
                                reason="set RRBOT_WORKSHOP_DEMOS to a clone of ros2_control_demos (jazzy)")


def twist(s, topic, vx, wz):  # noqa: ANN001, ANN201
    for _ in range(20):
        m = msgs.TwistStamped()
        m.header.stamp = s.clock.now()
        m.twist.linear.x = vx
        m.twist.angular.z = wz
        s.publish(topic, m)
        s.spin(0.1)


def val(s, name):  # noqa: ANN001, ANN201
    return s.resource_manager.get_interface_value(name)


def fwd(s, topic, values):  # noqa: ANN001, ANN201
    s.publish(topic, msgs.Float64MultiArray(data=list(values)))
    s.spin(1.0)


def traj(s, topic, joints, goal):  # noqa: ANN001, ANN201
    p = msgs.JointTrajectoryPoint(positions=list(goal), time_from_start=1.0)
    s.publish(topic, msgs.JointTrajectory(joint_names=joints, points=[p]))
    s.spin(2.0)


CASES = {
 1: dict(desc="example_1/description/urdf/rrbot.urdf.xacro", yaml="example_1/bringup/config/rrbot_controllers.yaml",
         launch_args={"joint_prefix": "joint"}, spawn=["joint_state_broadcaster", "forward_position_controller"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1],
         expect=[0.5, -0.5]),
 2: dict(desc="example_2/description/urdf/diffbot.urdf.xacro", yaml="example_2/bringup/config/diffbot_controllers.yaml",
         spawn=["joint_state_broadcaster", "diffbot_base_controller"],
         move=lambda s: (twist(s, "/diffbot_base_controller/cmd_vel", 0.5, 0.0), [val(s, "left_wheel_joint/velocity"), val(s, "right_wheel_joint/velocity")])[1]),
 3: dict(desc="example_3/description/urdf/rrbot_system_multi_interface.urdf.xacro", yaml="example_3/bringup/config/rrbot_multi_interface_forward_controllers.yaml",
         spawn=["joint_state_broadcaster", "forward_velocity_controller"],
         move=lambda s: (fwd(s, "/forward_velocity_controller/commands", [0.2, -0.2]), [val(s, "joint1/velocity"), val(s, "joint2/velocity")])[1], expect=[0.2, -0.2]),
 4: dict(desc="example_4/description/urdf/rrbot_system_with_sensor.urdf.xacro", yaml="example_4/bringup/config/rrbot_with_sensor_controllers.yaml",
         spawn=["joint_state_broadcaster", "forward_position_controller", "fts_broadcaster"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
 5: dict(xacro={"use_mock_hardware": "false"}, desc="example_5/description/urdf/rrbot_system_with_external_sensor.urdf.xacro", yaml="example_5/bringup/config/rrbot_with_external_sensor_controllers.yaml",
         spawn=["joint_state_broadcaster", "forward_position_controller", "fts_broadcaster"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
 6: dict(desc="example_6/description/urdf/rrbot_modular_actuators.urdf.xacro", yaml="example_6/bringup/config/rrbot_modular_actuators.yaml",
         spawn=["joint_state_broadcaster", "forward_position_controller"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
 7: dict(desc="example_7/description/urdf/r6bot.urdf.xacro", yaml="example_7/bringup/config/r6bot_controller.yaml",
         spawn=["joint_state_broadcaster", "r6bot_controller"],
         kw=dict(controller_types={"r6bot_controller": "joint_trajectory_controller/JointTrajectoryController"}),
         move=lambda s: (traj(s, "/r6bot_controller/joint_trajectory", [f"joint_{i}" for i in range(1, 7)], [0.3]*6), [val(s, f"joint_{i}/position") for i in range(1, 7)])[1], expect=[0.3]*6),
 8: dict(desc="example_8/description/urdf/rrbot_transmissions_system_position_only.urdf.xacro", yaml="example_8/bringup/config/rrbot_controllers.yaml",
         spawn=["joint_state_broadcaster", "forward_position_controller"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
 9: dict(xacro={"use_gazebo": "true"}, desc="example_9/description/urdf/rrbot.urdf.xacro", yaml="example_9/bringup/config/rrbot_controllers.yaml",
         spawn=["joint_state_broadcaster", "forward_position_controller"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
 10: dict(desc="example_10/description/urdf/rrbot.urdf.xacro", yaml="example_10/bringup/config/rrbot_controllers.yaml",
         spawn=["joint_state_broadcaster", "gpio_controller", "forward_position_controller"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
 11: dict(desc="example_11/description/urdf/carlikebot.urdf.xacro", yaml="example_11/bringup/config/carlikebot_controllers.yaml",
         spawn=["joint_state_broadcaster", "bicycle_steering_controller"],
         move=lambda s: (twist(s, "/bicycle_steering_controller/reference", 0.5, 0.2), [val(s, "virtual_front_wheel_joint/position"), val(s, "virtual_rear_wheel_joint/velocity")])[1]),
 12: dict(desc="example_12/description/urdf/rrbot.urdf.xacro", yaml="example_12/bringup/config/rrbot_chained_controllers.yaml",
         spawn=["joint_state_broadcaster", "joint1_position_controller", "joint2_position_controller", "position_controller", "forward_position_controller"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
 13: dict(desc="example_13/description/urdf/three_robots.urdf.xacro", yaml="example_13/bringup/config/three_robots_controllers.yaml",
         spawn=["joint_state_broadcaster", "rrbot_position_controller"],
         move=lambda s: (fwd(s, "/rrbot_position_controller/commands", [0.5, -0.5]), [val(s, "rrbot_joint1/position"), val(s, "rrbot_joint2/position")])[1], expect=[0.5, -0.5]),
 14: dict(desc="example_14/description/urdf/rrbot_modular_actuators_without_feedback_sensors_for_position_feedback.urdf.xacro",
         yaml="example_14/bringup/config/rrbot_modular_actuators_without_feedback_sensors_for_position_feedback.yaml",
         spawn=["joint_state_broadcaster", "forward_velocity_controller"],
         move=lambda s: (fwd(s, "/forward_velocity_controller/commands", [0.2, -0.2]), [val(s, "joint1/velocity"), val(s, "joint2/velocity")])[1]),
 16: dict(desc="example_16/description/urdf/diffbot.urdf.xacro", yaml="example_16/bringup/config/diffbot_chained_controllers.yaml",
         spawn=["joint_state_broadcaster", "pid_controller_left_wheel_joint", "pid_controller_right_wheel_joint", "diffbot_base_controller"],
         move=lambda s: (twist(s, "/diffbot_base_controller/cmd_vel", 0.5, 0.0), [val(s, "left_wheel_joint/velocity"), val(s, "right_wheel_joint/velocity")])[1]),
 17: dict(desc="example_17/description/urdf/rrbot.urdf.xacro", yaml="example_17/bringup/config/rrbot_controllers.yaml",
         spawn=["joint_state_broadcaster", "forward_position_controller"],
         move=lambda s: (fwd(s, "/forward_position_controller/commands", [0.5, -0.5]), [val(s, "joint1/position"), val(s, "joint2/position")])[1], expect=[0.5, -0.5]),
}



@pytest.mark.parametrize("number", sorted(CASES))
def test_example_comes_up_mocked_and_moves(number: int) -> None:
    c = CASES[number]
    s = rw.bringup(str(D / c["desc"]), str(D / c["yaml"]), spawn=c["spawn"], package_path=[str(D)],
                   mock_hardware="unknown", launch_args=c.get("launch_args"), xacro_args=c.get("xacro"),
                   **c.get("kw", {}))
    with s:
        out = c["move"](s)
        if c.get("expect") is None:
            assert all(math.isfinite(x) and abs(x) > 1e-3 for x in out), out
        else:
            assert out == pytest.approx(c["expect"], abs=1e-3)


def test_example_15_two_namespaced_controller_managers() -> None:
    assert ex15().startswith("MOVES")


def ex15() -> str:
    yaml = str(D / "example_15/bringup/config/multi_controller_manager_rrbot_generic_controllers.yaml")
    a = rw.bringup(str(D / "example_1/description/urdf/rrbot.urdf.xacro"), yaml, xacro_args={"prefix": "rrbot_1_"},
                   namespace="/rrbot_1", package_path=[str(D)], mock_hardware="unknown",
                   spawn=["joint_state_broadcaster", "forward_position_controller"])
    b = rw.bringup(str(D / "example_5/description/urdf/rrbot_system_with_external_sensor.urdf.xacro"), yaml,
                   xacro_args={"prefix": "rrbot_2_", "use_mock_hardware": "false"}, namespace="/rrbot_2",
                   package_path=[str(D)], mock_hardware="unknown",
                   spawn=["joint_state_broadcaster", "forward_position_controller"])
    try:
        a.publish("/rrbot_1/forward_position_controller/commands", msgs.Float64MultiArray(data=[0.3, 0.4]))
        b.publish("/rrbot_2/forward_position_controller/commands", msgs.Float64MultiArray(data=[-0.3, -0.4]))
        for _ in range(10):
            a.spin(0.1)
            b.spin(0.1)
        ra = [val(a, "rrbot_1_joint1/position"), val(a, "rrbot_1_joint2/position")]
        rb = [val(b, "rrbot_2_joint1/position"), val(b, "rrbot_2_joint2/position")]
        return f"{'MOVES' if ra == [0.3, 0.4] and rb == [-0.3, -0.4] else 'WRONG'} {ra} {rb}"
    finally:
        a.shutdown()
        b.shutdown()


#: The findings lint gives on the clone's YAML files, each one true (see the issue notes).
EXPECTED = {
    ("example_15", "state_publish_rate"),  # Jazzy's JTC declares no state_publish_rate: it is ignored
}


def test_lint_reports_nothing_false_on_the_demos_yaml() -> None:
    from rrbot_workshop.tools.lint import lint_controllers

    for yaml_file in sorted(D.glob("example_*/bringup/config/*.yaml")):
        example = yaml_file.parts[-4]
        descriptions = sorted((D / example / "description" / "urdf").glob("*.urdf.xacro"))
        findings = lint_controllers(yaml_file, descriptions[0] if descriptions else None,
                                    launch_args={"joint_prefix": "joint"}, package_path=[D])
        for f in findings:
            if f.level == "note":
                continue
            assert (example, f.where.rpartition(".")[2]) in EXPECTED, f"{yaml_file}: {f}"
