"""ros2_control's controller_interface: the base classes of every controller, chainable or not."""

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType

__all__ = [
    "CallbackReturn",
    "ReturnType",
    "ControllerInterface",
    "ChainableControllerInterface",
    "InterfaceConfiguration",
    "InterfaceConfigurationType",
]
