"""Bring the simulated RRBot up: the Python twin of the workshop's ``rrbot_sim_*.launch.py``.

The simulation launch file of the original does what ``rrbot.launch.py`` does, with the simulator in place of the
robot: xacro with ``sim_...:=true`` (the ``<ros2_control>`` tag now names the simulator's hardware plugin), the
controller manager with the simulation's controllers YAML, then the spawners in order: the joint state broadcaster
first, the robot controller after it, ``joint_trajectory_controller`` by default. Here MuJoCo is the simulator and runs
inside the controller manager's ``read()``, in lockstep with it.
"""

from __future__ import annotations

from pathlib import Path

from rrbot_workshop.bringup import System, bringup  # noqa: F401 - you will use them
from rrbot_workshop.exceptions import ParameterError  # noqa: F401

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
    # TODO(task 5.3): as start_rrbot() of task 2, with the simulator: the description with sim_mujoco, the
    #   simulation's controllers YAML (CONTROLLERS_FILE), the joint state broadcaster first, then the robot controller
    #   (refuse a name that is not one of ROBOT_CONTROLLERS with ParameterError(owner, parameter, message), before
    #   anything is up), the other one loaded and configured but inactive. Return the system without spinning it
    #   (at time 0). If a step fails after the system is up, shut it down before raising.
    raise NotImplementedError("TODO(task 5.3): start_rrbot_sim() - bring the simulated RRBot up")
