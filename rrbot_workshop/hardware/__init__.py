"""Hardware components: base classes, the mock GenericSystem, MuJoCo and the RRBot device driver."""

from rrbot_workshop.hardware_interface.component_interface import (
    ActuatorInterface,
    HardwareComponentInterface,
    SensorInterface,
    SystemInterface,
)

__all__ = ["HardwareComponentInterface", "SystemInterface", "ActuatorInterface", "SensorInterface"]
