"""Parameter files at load: ``ros2 control load_controller NAME [PARAM_FILE] [--set-state STATE]`` and the spawner's
``--param-file``; library controllers standing in for a package's own (``bringup(..., controller_types=...)``).

Jazzy: the CLI and the spawner look for the controller's section in the file (``<name>``, ``/<ns>/<name>``,
``/**/<name>``, ``/**/<ns>/<name>``, ``<name>`` inside ``/**``, or ``/**`` itself), set the manager's
``<name>.type`` from it and ``<name>.params_file``; the controller node then reads the file, matched to its fully
qualified name, over the manager's own parameter files. The load_controller service itself takes only the name.
"""

from __future__ import annotations

import logging
from pathlib import Path

import pytest
from test_namespaces import TWO_ARMS_YAML, arm_urdf

import rrbot_workshop as rw
from rrbot_workshop.course.magics import control
from rrbot_workshop.exceptions import ControllerError, ParameterError
from rrbot_workshop.msgs import Float64MultiArray

BASE = """\
controller_manager:
  ros__parameters:
    update_rate: 50
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    forward_position_controller:
      type: forward_command_controller/ForwardCommandController

forward_position_controller:
  ros__parameters:
    joints: [j1, j2]
    interface_name: velocity
"""

OWN_FILE = """\
forward_position_controller:
  ros__parameters:
    interface_name: position
slow_controller:
  ros__parameters:
    type: forward_command_controller/ForwardCommandController
    joints: [j2]
    interface_name: position
"""


@pytest.fixture
def system():
    s = rw.bringup(arm_urdf(""), BASE, spawn=["joint_state_broadcaster"])
    yield s
    s.shutdown()


@pytest.fixture
def own_file(tmp_path: Path) -> Path:
    path = tmp_path / "config" / "my_params.yaml"
    path.parent.mkdir()
    path.write_text(OWN_FILE)
    return path


def test_the_file_overrides_the_yaml_and_gives_the_type(system: rw.System, own_file: Path) -> None:
    cm = system.controller_manager
    fwd = cm.load_controller("forward_position_controller", param_file=own_file)
    assert fwd.get_node().get_parameter("interface_name") == "position"  # the file wins over the YAML's velocity
    assert fwd.get_node().get_parameter("joints") == ["j1", "j2"]  # the YAML's, kept
    slow = cm.load_controller("slow_controller", param_file=own_file)  # type only in the file
    assert cm.controllers["slow_controller"].type == "forward_command_controller/ForwardCommandController"
    assert slow.get_node().get_parameter("joints") == ["j2"]
    assert cm.params.param_files["slow_controller"] == [str(own_file)]


def test_the_magic_loads_with_a_file_and_sets_the_state(system: rw.System, own_file: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    control(f"load_controller slow_controller {own_file} --set-state active")
    out = capsys.readouterr().out
    assert "Successfully loaded controller slow_controller" in out
    assert "Successfully set controller slow_controller to active" in out
    system.publish("/slow_controller/commands", Float64MultiArray(data=[0.6]))
    system.spin(0.2)
    assert list(system.latest("/joint_states").position) == pytest.approx([0.0, 0.6])
    control(f"load_controller slow_controller {own_file}")
    assert "already loaded, skipping load_controller" in capsys.readouterr().out
    control("load_controller other /no/such/file.yaml")
    assert "does not exist" in capsys.readouterr().out
    assert "other" not in system.controller_manager.controllers


def test_the_service_loads_by_name_as_jazzy(system: rw.System, own_file: Path) -> None:
    system.controller_manager.params.use_param_file("slow_controller", own_file)  # what the CLI sets beforehand
    response = system.call_service("/controller_manager/load_controller", {"name": "slow_controller"})
    assert response.ok, response.message
    assert system.controller_manager.get_controller("slow_controller").get_node().get_parameter("joints") == ["j2"]


def test_a_file_without_the_controller_changes_nothing(system: rw.System, tmp_path: Path,
                                                       caplog: pytest.LogCaptureFixture) -> None:
    other = tmp_path / "other.yaml"
    other.write_text("someone_else:\n  ros__parameters:\n    x: 1\n")
    with caplog.at_level(logging.WARNING):
        fwd = system.controller_manager.load_controller("forward_position_controller", param_file=other)
    assert "has no section for 'forward_position_controller'" in caplog.text
    assert fwd.get_node().get_parameter("interface_name") == "velocity"


def test_a_relative_key_for_a_namespaced_controller_stops_as_the_spawner_does(tmp_path: Path) -> None:
    plain = tmp_path / "plain.yaml"
    plain.write_text(OWN_FILE)
    system = rw.bringup(arm_urdf("arm_a_"), TWO_ARMS_YAML, namespace="/arm_a")
    try:
        with pytest.raises(ParameterError, match=r"write '/arm_a/slow_controller:' or '/\*\*/slow_controller:'"):
            system.spawn(["slow_controller"], param_file=plain)
        assert "slow_controller" not in system.controller_manager.controllers
    finally:
        system.shutdown()


def test_spawner_param_file_with_a_wildcard_type_in_a_namespace(tmp_path: Path) -> None:
    """Example 15's inactive spawner: the JTC's type is only in the file's ``/**/<name>`` section."""
    path = tmp_path / "two_arms.yaml"
    path.write_text(TWO_ARMS_YAML + """
/**/position_trajectory_controller:
  ros__parameters:
    type: joint_trajectory_controller/JointTrajectoryController
    command_interfaces: [position]
    state_interfaces: [position]
/arm_a/position_trajectory_controller:
  ros__parameters:
    joints: [arm_a_j1, arm_a_j2]
""")
    system = rw.bringup(arm_urdf("arm_a_"), path, namespace="/arm_a", spawn=["joint_state_broadcaster"])
    try:
        system.spawn(["position_trajectory_controller"], inactive=True, param_file=path)
        spec = system.controller_manager.controllers["position_trajectory_controller"]
        assert (spec.type, spec.state.label) == ("joint_trajectory_controller/JointTrajectoryController", "inactive")
        node = spec.controller.get_node()
        assert node.get_parameter("joints") == ["arm_a_j1", "arm_a_j2"]
        assert node.get_fully_qualified_name() == "/arm_a/position_trajectory_controller"
    finally:
        system.shutdown()


STAND_IN_YAML = """\
controller_manager:
  ros__parameters:
    update_rate: 50
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster

arm_controller:
  ros__parameters:
    type: my_robot_package/RobotController
    joints: [j1, j2]
    command_interfaces: [position]
    state_interfaces: [position, velocity]
"""


def test_an_unknown_type_names_the_stand_in_option() -> None:
    with pytest.raises(ControllerError) as info:
        rw.bringup(arm_urdf(""), STAND_IN_YAML, spawn=["arm_controller"])
    assert "my_robot_package/RobotController" in str(info.value)
    assert "controller_types=" in str(info.value)


@pytest.mark.parametrize("key", ["arm_controller", "my_robot_package/RobotController"])
def test_a_library_controller_stands_in_with_the_same_parameters(key: str, caplog: pytest.LogCaptureFixture) -> None:
    from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint

    with caplog.at_level(logging.WARNING):
        system = rw.bringup(arm_urdf(""), STAND_IN_YAML, spawn=["joint_state_broadcaster", "arm_controller"],
                            controller_types={key: "joint_trajectory_controller/JointTrajectoryController"})
    try:
        assert "in place of 'my_robot_package/RobotController'" in caplog.text
        spec = system.controller_manager.controllers["arm_controller"]
        assert (spec.type, spec.state.label) == ("joint_trajectory_controller/JointTrajectoryController", "active")
        system.publish("/arm_controller/joint_trajectory", JointTrajectory(
            joint_names=["j1", "j2"], points=[JointTrajectoryPoint(positions=[0.3, -0.3], time_from_start=0.5)]))
        system.spin(1.0)
        assert list(system.latest("/joint_states").position) == pytest.approx([0.3, -0.3], abs=1e-6)
    finally:
        system.shutdown()
