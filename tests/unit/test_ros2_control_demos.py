"""ros2_control_demos (jazzy), brought up as its examples' docs say, with mock hardware and documented options only.

The demos come from ``shared/upstream``'s tarball, extracted once per session by the ``ros2_control_demos`` fixture
(``tests/unit/conftest.py``; in CI they are required, never skipped). Each example: its own description and
controllers YAML from the tree (found through the package path), its hardware plugins mocked
(``mock_hardware="unknown"``), the controllers its launch file spawns, and a command on the topic its docs use; the
joints must move as commanded. (How lint judges every controllers YAML of the tree, each manager against its own
description: ``test_ros2_control_demos_lint.py``.) For every package, ``lint``, the CLI's ``bringup`` and ``rw.bringup``
leave the tree unchanged (hashed: content, file types, modes, link targets), and ``$(find pkg)`` shows what colcon would install.
"""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import pytest
from package_trees import tree_state, view_files

import rrbot_workshop as rw
from rrbot_workshop import msgs
from rrbot_workshop.cli import main
from rrbot_workshop.description import packages


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
def test_example_comes_up_mocked_and_moves(number: int, ros2_control_demos: Path) -> None:
    D = ros2_control_demos  # noqa: N806 - the demos' root, as the cases name their files
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


def test_example_15_two_namespaced_controller_managers(ros2_control_demos: Path) -> None:
    assert ex15(ros2_control_demos).startswith("MOVES")


def ex15(D: Path) -> str:  # noqa: N803 - the demos' root, as the cases name it
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


# ============================================================================ the demos' files are never touched
#: example_15 has no description of its own: its launch file brings up example_1's and example_5's.
EX15 = dict(desc="example_1/description/urdf/rrbot.urdf.xacro",
            yaml="example_15/bringup/config/multi_controller_manager_rrbot_generic_controllers.yaml",
            xacro={"prefix": "rrbot_1_"}, namespace="/rrbot_1", spawn=["joint_state_broadcaster"])


@pytest.mark.parametrize("number", range(1, 18))
def test_lint_and_both_bringups_leave_the_demos_untouched(number: int, ros2_control_demos: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """``lint`` (YAML against the description), the CLI's ``bringup`` and ``rw.bringup`` of the example, each through
    the package path: the whole demos tree is as it was, byte for byte and type for type."""
    D = ros2_control_demos  # noqa: N806
    c = CASES.get(number, EX15)
    before = tree_state(D)
    args = {**c.get("launch_args", {}), **c.get("xacro", {})}
    pairs = [f"{k}:={v}" for k, v in args.items()]
    namespace = ["--namespace", c["namespace"]] if "namespace" in c else []
    lint = ["lint", str(D / c["yaml"]), "--description", str(D / c["desc"]), "--package-path", str(D), *namespace]
    lint += [f"--arg={p}" for p in pairs]
    # example_15's YAML holds both managers' sections: --namespace checks rrbot_1's manager alone, against its robot
    assert main(lint) == 0, capsys.readouterr()
    assert main(["bringup", str(D / c["desc"]), "--controllers", str(D / c["yaml"]), "--package-path", str(D),
                 "--mock-hardware", "unknown", "--spawn", "joint_state_broadcaster", "--seconds", "0.05",
                 *[f"--arg={p}" for p in pairs], *namespace]) == 0, capsys.readouterr()
    with rw.bringup(str(D / c["desc"]), str(D / c["yaml"]), spawn=["joint_state_broadcaster"], package_path=[D],
                    mock_hardware="unknown", launch_args=c.get("launch_args"), xacro_args=c.get("xacro"),
                    namespace=c.get("namespace")) as system:
        assert system.controller_manager.controllers["joint_state_broadcaster"].state.label == "active"
    assert tree_state(D) == before


#: Every package of the tree, by folder: the 17 examples, the shared descriptions, the meta and test packages.
PACKAGE_FOLDERS = [f"example_{n}" for n in range(1, 18)] + [
    "ros2_control_demo_description", "ros2_control_demos", "ros2_control_demo_test_utils"]
_INSTALL = re.compile(r"install\s*\(\s*DIRECTORY\s+([^)]*?)\s+DESTINATION\s+(share/\S+?)\s*\)", re.S)


def _colcon_install(package: Path, name: str, prefix: Path) -> Path:
    """The package's share folder as colcon installs it: a copy of each install(DIRECTORY ...) rule, in order, and
    package.xml (the demos use no other kind of share rule)."""
    share = prefix / "share" / name
    share.mkdir(parents=True)
    cmake = package / "CMakeLists.txt"
    for sources, destination in _INSTALL.findall(cmake.read_text() if cmake.is_file() else ""):
        target = prefix / destination.replace("${PROJECT_NAME}", name)
        for source in sources.split():
            shutil.copytree(package / source, target / Path(source).name, dirs_exist_ok=True)
    shutil.copy(package / "package.xml", share / "package.xml")
    return share


@pytest.mark.parametrize("folder", PACKAGE_FOLDERS)
def test_find_shows_what_colcon_installs_and_leaves_the_package_untouched(
        folder: str, ros2_control_demos: Path, tmp_path: Path) -> None:
    """``$(find pkg)`` of each demo package holds exactly the files colcon would install there, and
    ``package://pkg/<file>`` resolves to the source file each comes from."""
    D = ros2_control_demos  # noqa: N806
    before = tree_state(D)
    package = packages.package_of(D / folder, [D])
    assert package is not None and package.path == D / folder
    share = packages.share_directory(package.name, [D])
    expected = {str(p.relative_to(installed)): p.read_bytes()
                for installed in [_colcon_install(D / folder, package.name, tmp_path)]
                for p in installed.rglob("*") if p.is_file()}
    if package.maps_through_rules:
        assert view_files(share) == expected
    else:  # no share rules (ament_python, a meta package): the folder itself, as for an installed tree
        assert share == D / folder and expected.keys() == {"package.xml"}
    for rel, text in expected.items():
        assert packages.resolve_uri(f"package://{package.name}/{rel}", [D]).read_bytes() == text
    assert tree_state(D) == before
