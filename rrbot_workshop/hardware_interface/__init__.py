"""ros2_control's hardware_interface: handles, the component interfaces, their lifecycle wrapper and the
resource manager that owns the interface storage and the claims on it."""

from rrbot_workshop.hardware_interface.component_interface import (
    ActuatorInterface,
    HardwareComponentInterface,
    SensorInterface,
    SystemInterface,
)

__all__ = ["HardwareComponentInterface", "SystemInterface", "ActuatorInterface", "SensorInterface"]
