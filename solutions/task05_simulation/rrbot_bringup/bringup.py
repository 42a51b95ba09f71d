"""Bring the simulated RRBot up: the Python twin of the workshop's ``rrbot_sim_*.launch.py``.

The simulation launch file of the original does what ``rrbot.launch.py`` does, with the simulator in place of the
robot: xacro with ``sim_...:=true`` (the ``<ros2_control>`` tag now names the simulator's hardware plugin), the
controller manager with the simulation's controllers YAML, then the spawners in order: the joint state broadcaster
first, the robot controller after it, ``joint_trajectory_controller`` by default. Here MuJoCo is the simulator and runs
inside the controller manager's ``read()``, in lockstep with it.
"""

from __future__ import annotations

from pathlib import Path

from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.exceptions import ParameterError

__all__ = ["ROBOT_CONTROLLERS", "DESCRIPTION_FILE", "CONTROLLERS_FILE", "start_rrbot_sim"]

#: The choices of the launch argument ``robot_controller``.
ROBOT_CONTROLLERS = ("forward_position_controller", "joint_trajectory_controller")

_TASK_DIR = Path(__file__).resolve().parents[1]
#: The robot description (the task's own copy of it).
DESCRIPTION_FILE = _TASK_DIR / "rrbot_description" / "urdf" / "rrbot.urdf.xacro"
#: The simulation's controllers YAML next to this file.
CONTROLLERS_FILE = Path(__file__).resolve().parent / "config" / "rrbot_sim_controllers.yaml"


def start_rrbot_sim(robot_controller: str = "joint_trajectory_controller") -> System:
    """Start the RRBot in MuJoCo with its controllers, as ``ros2 launch controlko_bringup rrbot_sim_*.launch.py``.

    Args:
        robot_controller: The controller that drives the robot; the other of :data:`ROBOT_CONTROLLERS` is loaded and
            configured, inactive.

    Returns:
        The running system at time 0 [s] (not spun), with ``joint_state_broadcaster`` active no later than
        ``robot_controller`` (before it, or in the same switch), ``robot_controller`` active, and the other controller
        inactive.

    Raises:
        ParameterError: If ``robot_controller`` is not one of :data:`ROBOT_CONTROLLERS`; nothing is brought up. Its
            signature is ``ParameterError(owner, parameter, message)`` (``rrbot_workshop/exceptions.py``), e.g.
            ``ParameterError("start_rrbot_sim", "robot_controller", "is 'x'; valid choices: [...]")``.
        Exception: Whatever a step raises once the system is up (a controller that fails to configure, a rejected
            switch); the system is shut down first, so nothing is left running.
    """
    if robot_controller not in ROBOT_CONTROLLERS:
        raise ParameterError("start_rrbot_sim", "robot_controller",
                             f"is '{robot_controller}'; valid choices: {list(ROBOT_CONTROLLERS)}")
    system = bringup(DESCRIPTION_FILE, CONTROLLERS_FILE, xacro_args={"sim_mujoco": True},
                     spawn=["joint_state_broadcaster"])
    cm = system.controller_manager
    try:
        cm.load_controller(robot_controller)
        cm.configure_controller(robot_controller)
        cm.switch_controllers(activate=[robot_controller], strictness="strict")
        other = next(name for name in ROBOT_CONTROLLERS if name != robot_controller)
        cm.load_controller(other)
        cm.configure_controller(other)
    except Exception:
        system.shutdown()
        raise
    return system
