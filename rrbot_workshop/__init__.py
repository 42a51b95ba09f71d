"""rrbot_workshop: ros2_control, rebuilt in Python for a hands-on course.

One package per ros2_control layer, each importing only the ones below it: :mod:`~rrbot_workshop.middleware`
(clock, parameters, topics, plugins), :mod:`~rrbot_workshop.description` (xacro, URDF, ``<ros2_control>``),
:mod:`~rrbot_workshop.hardware_interface` (handles, component interfaces, resource manager),
:mod:`~rrbot_workshop.hardware` (GenericSystem, MuJoCo), :mod:`~rrbot_workshop.controller_interface`,
:mod:`~rrbot_workshop.controllers`, :mod:`~rrbot_workshop.controller_manager`, and :func:`bringup`, which
wires a description and a controllers YAML into a running system. :mod:`~rrbot_workshop.viz` and
:mod:`~rrbot_workshop.course` sit on top.
Submodules are imported on first use so ``import rrbot_workshop`` stays fast.
"""

from __future__ import annotations

import importlib
from typing import Any

from rrbot_workshop.exceptions import (
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
    "joint_limits",
    "viz",
    "grading",
    "plugins",
    "params",
    "topics",
    "motion",
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

#: Attribute -> module, imported on first use.
_SUBMODULES = {
    "description": "description",
    "middleware": "middleware",
    "hardware_interface": "hardware_interface",
    "hardware": "hardware",
    "controller_interface": "controller_interface",
    "controller_manager": "controller_manager",
    "controllers": "controllers",
    "control_toolbox": "control_toolbox",
    "joint_limits": "joint_limits",
    "msgs": "msgs",
    "motion": "motion",
    "tuning": "tuning",
    "viz": "viz",
    "course": "course",
    "testing": "testing",
    # shortcuts to the modules learners use most
    "params": "middleware.params",
    "topics": "middleware.topics",
    "plugins": "middleware.plugins",
    "lifecycle": "middleware.lifecycle",
    "grading": "course.grading",
    "tracks": "course.tracks",
}


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f".{_SUBMODULES[name]}", __name__)
    if name in ("bringup", "System"):
        module = importlib.import_module(".bringup", __name__)
        return getattr(module, name)
    raise AttributeError(f"module 'rrbot_workshop' has no attribute '{name}'")


def load_ipython_extension(ipython: Any) -> None:
    """``%load_ext rrbot_workshop``: the ``%control``, ``%topic`` and ``%%pytest`` magics, and short tracebacks for
    library errors.

    A :class:`RRBotWorkshopError` raised in a notebook cell then shows its message first and the learner's
    own frames only; ``%tb`` prints the full traceback.
    """
    from rrbot_workshop.course.magics import load_ipython_extension as _load

    _load(ipython)
