"""ros2_control's controller_manager: the manager and the collaborators it owns (switching, chains, claims,
the control loop, services, introspection)."""

from rrbot_workshop.controller_manager.manager import ControllerManager

__all__ = ["ControllerManager"]
