"""Launch arguments for ``$(var name)`` in a controllers YAML (``bringup(..., launch_args=...)``).

Jazzy: a launch file hands the controllers YAML to a node as ``ParameterFile(path, allow_substs=True)``, which
replaces ``$(var name)`` with the launch argument ``name`` (``$(var name default)`` falls back to ``default``, as
launch's ``var`` substitution takes one or two arguments). A file read by rcl directly (``--params-file``) keeps the
text as it is. The files here are this project's own, in the layout of ros2_control_demos' example 1.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from test_namespaces import arm_urdf

import rrbot_workshop as rw
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.controllers_yaml import load_controllers_yaml
from rrbot_workshop.msgs import Float64MultiArray

PREFIXED_YAML = """\
controller_manager:
  ros__parameters:
    update_rate: 50

joint_state_broadcaster:
  ros__parameters:
    type: joint_state_broadcaster/JointStateBroadcaster

forward_position_controller:
  ros__parameters:
    type: forward_command_controller/ForwardCommandController
    joints:
      - $(var joint_prefix)j1
      - $(var joint_prefix)j2
    interface_name: $(var interface position)
"""


@pytest.fixture
def controllers_file(tmp_path: Path) -> Path:
    path = tmp_path / "bringup" / "config" / "arm_controllers.yaml"
    path.parent.mkdir(parents=True)
    path.write_text(PREFIXED_YAML)
    return path


def test_launch_args_fill_the_yaml_and_the_robot_moves(controllers_file: Path) -> None:
    system = rw.bringup(arm_urdf("left_"), controllers_file, launch_args={"joint_prefix": "left_"},
                        spawn=["joint_state_broadcaster", "forward_position_controller"])
    try:
        fwd = system.controller_manager.get_controller("forward_position_controller")
        assert fwd.get_node().get_parameter("joints") == ["left_j1", "left_j2"]
        assert fwd.get_node().get_parameter("interface_name") == "position"  # the default of $(var interface ...)
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.5, 0.25]))
        system.spin(0.2)
        assert list(system.latest("/joint_states").position) == pytest.approx([0.5, 0.25])
    finally:
        system.shutdown()


def test_a_given_argument_wins_over_the_default(controllers_file: Path) -> None:
    cfg = load_controllers_yaml(controllers_file, launch_args={"joint_prefix": "", "interface": "velocity"})
    assert cfg.parameters_for("forward_position_controller")["interface_name"] == "velocity"


def test_a_missing_argument_names_the_file_the_line_and_what_to_pass(controllers_file: Path) -> None:
    with pytest.raises(ParameterError) as info:
        rw.bringup(arm_urdf("left_"), controllers_file, spawn=["forward_position_controller"])
    text = str(info.value)
    line = PREFIXED_YAML.splitlines().index("      - $(var joint_prefix)j1") + 1
    assert f"{controllers_file}:{line}" in text
    assert "$(var joint_prefix)" in text
    assert "launch_args={'joint_prefix': ...}" in text
    from rrbot_workshop.bringup import systems

    assert systems() == {}  # nothing was left running


def test_a_misspelt_argument_gets_the_closest_name(controllers_file: Path) -> None:
    with pytest.raises(ParameterError, match=r"did you mean \['joint_prefix'\]"):
        load_controllers_yaml(controllers_file.read_text().replace("$(var joint_prefix)", "$(var joint_prefx)"),
                              launch_args={"joint_prefix": "x_"})


def test_without_launch_args_the_text_is_read_as_rcl_reads_it(controllers_file: Path) -> None:
    cfg = load_controllers_yaml(controllers_file)
    assert cfg.parameters_for("forward_position_controller")["joints"] == ["$(var joint_prefix)j1",
                                                                          "$(var joint_prefix)j2"]


def test_yaml_text_takes_launch_args_too() -> None:
    cfg = load_controllers_yaml(PREFIXED_YAML, launch_args={"joint_prefix": "r_"})
    assert cfg.parameters_for("forward_position_controller")["joints"] == ["r_j1", "r_j2"]


def test_a_parameter_file_given_to_the_spawner_takes_the_system_launch_args(tmp_path: Path) -> None:
    """Example 1's second spawner gets the file as ``ParameterFile(..., allow_substs=True)``."""
    base = "controller_manager:\n  ros__parameters:\n    update_rate: 50\n"
    spawner_file = tmp_path / "spawner_params.yaml"
    spawner_file.write_text(PREFIXED_YAML.split("forward_position_controller:", 1)[0].replace(
        "controller_manager:\n  ros__parameters:\n    update_rate: 50\n", "") +
        "forward_position_controller:" + PREFIXED_YAML.split("forward_position_controller:", 1)[1])
    system = rw.bringup(arm_urdf("right_"), base, launch_args={"joint_prefix": "right_"})
    try:
        system.spawn(["forward_position_controller"], param_file=spawner_file)
        fwd = system.controller_manager.get_controller("forward_position_controller")
        assert fwd.get_node().get_parameter("joints") == ["right_j1", "right_j2"]
        assert system.controller_manager.controllers["forward_position_controller"].state.label == "active"
    finally:
        system.shutdown()
