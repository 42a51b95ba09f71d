"""Bring the RRBot up: the Python twin of the workshop's ``rrbot.launch.py``.

The ROS 2 launch file does four things, and :func:`start_rrbot` does them in the same order:

1. run xacro on ``rrbot.urdf.xacro`` with the launch arguments (``use_mock_hardware:=true ...``): the text it
   produces is the ``robot_description``;
2. start ``ros2_control_node`` with that description and ``rrbot_controllers.yaml``: the controller manager
   loads the hardware named in ``<ros2_control>`` and reads which controllers exist;
3. spawn ``joint_state_broadcaster``: from then on ``/joint_states`` is published (RViz starts after this);
4. spawn the robot controller chosen by the ``robot_controller`` argument.

In the launch file, the spawners are delayed by event handlers (the broadcaster 1 s after the control node
starts, the robot controller 3 s after the broadcaster's spawner exits). The delays give the controller manager
time to come up and keep the order: first the joint states are published, then something may move the robot.
Here each step finishes before the next starts, so the order alone is enough.

One addition to the original: the robot controller that was *not* chosen is loaded and configured too
(``spawner --inactive``), so switching to it later is one ``switch_controllers`` call.
"""

from __future__ import annotations

from pathlib import Path

from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.exceptions import ParameterError

__all__ = ["ROBOT_CONTROLLERS", "DESCRIPTION_FILE", "CONTROLLERS_FILE", "start_rrbot"]

#: The choices of the launch argument ``robot_controller``.
ROBOT_CONTROLLERS = ("forward_position_controller", "joint_trajectory_controller")

_TASK_DIR = Path(__file__).resolve().parents[1]
#: The robot description (the task's own copy of it).
DESCRIPTION_FILE = _TASK_DIR / "rrbot_description" / "urdf" / "rrbot.urdf.xacro"
#: The controllers YAML next to this file.
CONTROLLERS_FILE = Path(__file__).resolve().parent / "config" / "rrbot_controllers.yaml"


def start_rrbot(
    robot_controller: str = "forward_position_controller",
    use_mock_hardware: bool = True,
    mock_sensor_commands: bool = False,
) -> System:
    """Start the RRBot with its controllers, as ``ros2 launch controlko_bringup rrbot.launch.py`` does.

    Args:
        robot_controller: Controller that drives the robot: ``"forward_position_controller"`` or
            ``"joint_trajectory_controller"``. The other one is loaded and configured but stays inactive.
        use_mock_hardware: Use ``mock_components/GenericSystem`` instead of the robot's driver.
        mock_sensor_commands: Give the mock a command interface per sensor state, to fake readings.

    Returns:
        The running system, at time 0 [s], with ``joint_state_broadcaster`` and ``robot_controller`` active.

    Raises:
        ParameterError: If ``robot_controller`` is not one of :data:`ROBOT_CONTROLLERS`.
    """
    if robot_controller not in ROBOT_CONTROLLERS:
        raise ParameterError(
            "start_rrbot", "robot_controller", f"is '{robot_controller}'; valid choices: {list(ROBOT_CONTROLLERS)}"
        )

    # 1 + 2: xacro -> robot_description; the controller manager with the hardware and the YAML;
    # 3: the joint_state_broadcaster's spawner (load, configure, activate).
    system = bringup(
        DESCRIPTION_FILE,
        CONTROLLERS_FILE,
        xacro_args={"use_mock_hardware": use_mock_hardware, "mock_sensor_commands": mock_sensor_commands},
        spawn=["joint_state_broadcaster"],
    )

    # 4: the robot controller's spawner, run after the broadcaster's has finished.
    cm = system.controller_manager
    try:
        cm.load_controller(robot_controller)
        cm.configure_controller(robot_controller)
        cm.switch_controllers(activate=[robot_controller], strictness="strict")

        # `spawner <other> --inactive`: ready to be switched to.
        other = next(name for name in ROBOT_CONTROLLERS if name != robot_controller)
        cm.load_controller(other)
        cm.configure_controller(other)
    except Exception:
        system.shutdown()
        raise
    return system
