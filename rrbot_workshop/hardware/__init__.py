"""Hardware components: base classes, the mock GenericSystem, MuJoCo and the RRBot device driver."""

from .base import ActuatorInterface, HardwareComponentInterface, SensorInterface, SystemInterface

__all__ = ["HardwareComponentInterface", "SystemInterface", "ActuatorInterface", "SensorInterface"]
