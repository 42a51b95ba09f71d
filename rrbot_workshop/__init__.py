"""rrbot_workshop: ros2_control, rebuilt in Python for a hands-on course.

The layers, lowest first: :mod:`~rrbot_workshop.description` (xacro, URDF, ``<ros2_control>``),
:mod:`~rrbot_workshop.hardware` (components), :mod:`~rrbot_workshop.resource_manager`,
:mod:`~rrbot_workshop.controllers`, :mod:`~rrbot_workshop.controller_manager`, and
:func:`bringup`, which wires a description and a controllers YAML into a running system.
Submodules are imported on first use so ``import rrbot_workshop`` stays fast.
"""

from __future__ import annotations

import importlib
from typing import Any

from .exceptions import (
    ControllerError,
    ControllerNotFound,
    DescriptionError,
    HardwareError,
    InterfaceAlreadyClaimed,
    InterfaceNotFound,
    LifecycleError,
    MessageError,
    ModeSwitchRejected,
    ParameterError,
    PluginNotFound,
    RRBotWorkshopError,
    SwitchError,
)

__version__ = "0.1.0"

__all__ = [
    "bringup",
    "System",
    "description",
    "hardware",
    "controllers",
    "msgs",
    "control_toolbox",
    "viz",
    "grading",
    "plugins",
    "params",
    "topics",
    "motion",
    "tuning",
    "RRBotWorkshopError",
    "DescriptionError",
    "HardwareError",
    "LifecycleError",
    "InterfaceNotFound",
    "InterfaceAlreadyClaimed",
    "ModeSwitchRejected",
    "ParameterError",
    "ControllerError",
    "ControllerNotFound",
    "SwitchError",
    "PluginNotFound",
    "MessageError",
]

_SUBMODULES = {
    "description", "hardware", "controllers", "msgs", "control_toolbox", "viz", "grading", "plugins",
    "params", "topics", "motion", "tuning", "lifecycle", "handles", "resource_manager", "controller_manager",
    "magics", "tracks",
}


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    if name in ("bringup", "System"):
        module = importlib.import_module(".bringup", __name__)
        return getattr(module, name)
    raise AttributeError(f"module 'rrbot_workshop' has no attribute '{name}'")


def load_ipython_extension(ipython: Any) -> None:
    """``%load_ext rrbot_workshop`` registers the ``%control`` and ``%topic`` magics."""
    from .magics import load_ipython_extension as _load

    _load(ipython)
