"""Task 12: the RRBot's bringup with injected parameters, as a launch file with arguments.

``start_rrbot(prefix="r1_", update_rate=50)`` is ``ros2 launch controlko_bringup rrbot.launch.py prefix:=r1_ ...``:
the prefix goes to the xacro (names in the description) and, by substitution, into the controllers YAML (the joints
the controllers use); a value given at bringup (the update rate) overrides the file without editing it.
"""

from __future__ import annotations

from pathlib import Path

import rrbot_workshop as rw
from rrbot_workshop.middleware.param_substitution import load_with_substitutions, override

__all__ = ["CONTROLLERS", "start_rrbot"]

#: The controllers YAML next to this file.
CONTROLLERS = Path(__file__).parent / "config" / "rrbot_controllers.yaml"
ROBOT_CONTROLLERS = ("forward_position_controller", "joint_trajectory_controller")


def start_rrbot(
    prefix: str = "",
    robot_controller: str = "forward_position_controller",
    update_rate: int | None = None,
    use_mock_hardware: bool = True,
) -> rw.System:
    """Start the RRBot with the broadcaster and ``robot_controller`` active, the other robot controller inactive.

    Args:
        prefix: Prefix of every name the robot brings (xacro argument and controllers' joints).
        robot_controller: ``"forward_position_controller"`` or ``"joint_trajectory_controller"``.
        update_rate: Controller manager rate in [Hz]; the file's value when None.
        use_mock_hardware: The xacro argument of the same name: ``mock_components/GenericSystem`` (True) or the
            RRBot's driver ``controlko_hardware_interface/RRBotHardwareInterface`` (False).

    Raises:
        ValueError: If ``robot_controller`` is not one of the two robot controllers; raised before anything
            starts, and its message names both valid controllers (as every error of this course names what would
            be valid).
    """
    if robot_controller not in ROBOT_CONTROLLERS:
        raise ValueError(f"robot_controller must be one of {ROBOT_CONTROLLERS}, got {robot_controller!r}")
    controllers = load_with_substitutions(CONTROLLERS, {"prefix": prefix})
    if update_rate is not None:
        controllers = override(controllers, "controller_manager", {"update_rate": update_rate})
    other = [name for name in ROBOT_CONTROLLERS if name != robot_controller]
    return rw.bringup("rrbot", controllers, xacro_args={"prefix": prefix, "use_mock_hardware": use_mock_hardware},
                      spawn=["joint_state_broadcaster", robot_controller], inactive=other)
