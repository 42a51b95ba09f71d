"""Plugin registry: type strings such as ``"joint_state_broadcaster/JointStateBroadcaster"`` -> classes.

ros2_control finds controllers and hardware components through pluginlib. Here three sources feed one
registry per kind (``"hardware"``, ``"controller"``):

* the library's built-in table (``_BUILTIN``), imported lazily so that importing the package stays cheap;
* entry points in the group ``rrbot_workshop.middleware.plugins`` whose name is ``"<kind>:<type string>"``;
* :func:`register`, for classes defined in a notebook or resolved per course track.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from importlib import metadata
from typing import Any

from rrbot_workshop.exceptions import PluginNotFound, UnfinishedExercise

__all__ = ["KINDS", "register", "unregister", "resolve", "available", "register_resolver", "describe_unfinished"]

KINDS = ("hardware", "controller")

#: Built-in plugins: kind -> type string -> "module:ClassName".
_BUILTIN: dict[str, dict[str, str]] = {
    "hardware": {
        "mock_components/GenericSystem": "rrbot_workshop.hardware.mock:GenericSystem",
        # the library's stand-ins for unknown actuator/sensor plugins (bringup's mock_hardware); not in Jazzy
        "rrbot_workshop/MockActuator": "rrbot_workshop.hardware.mock_substitutes:MockActuator",
        "rrbot_workshop/MockSensor": "rrbot_workshop.hardware.mock_substitutes:MockSensor",
        "rrbot_workshop/MujocoSystem": "rrbot_workshop.hardware.mujoco_system:MujocoSystem",
        # the library's task-7 driver under its own name, never re-mapped to a learner's file (notebook 07's fallback)
        "rrbot_workshop/RRBotHardwareInterface": "rrbot_workshop.hardware.rrbot:RRBotHardwareInterface",
        # MyRobot's external tool sensor (notebook 15); its arm's component is the learner's class of task 15
        "my_robot/ToolForceTorqueSensor": "rrbot_workshop.hardware.my_robot:ToolForceTorqueSensor",
    },
    "controller": {
        "joint_state_broadcaster/JointStateBroadcaster":
            "rrbot_workshop.controllers.joint_state_broadcaster:JointStateBroadcaster",
        "forward_command_controller/ForwardCommandController":
            "rrbot_workshop.controllers.forward_command:ForwardCommandController",
        "forward_command_controller/MultiInterfaceForwardCommandController":
            "rrbot_workshop.controllers.forward_command:MultiInterfaceForwardCommandController",
        "position_controllers/JointGroupPositionController":
            "rrbot_workshop.controllers.forward_command:JointGroupPositionController",
        "velocity_controllers/JointGroupVelocityController":
            "rrbot_workshop.controllers.forward_command:JointGroupVelocityController",
        "effort_controllers/JointGroupEffortController":
            "rrbot_workshop.controllers.forward_command:JointGroupEffortController",
        "joint_trajectory_controller/JointTrajectoryController":
            "rrbot_workshop.controllers.joint_trajectory:JointTrajectoryController",
        "pid_controller/PidController": "rrbot_workshop.controllers.pid:PidController",
        "diff_drive_controller/DiffDriveController": "rrbot_workshop.controllers.diff_drive:DiffDriveController",
        "force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster":
            "rrbot_workshop.controllers.force_torque_sensor_broadcaster:ForceTorqueSensorBroadcaster",
        "gpio_controllers/GpioCommandController": "rrbot_workshop.controllers.gpio_command:GpioCommandController",
        # The reference solution of task 8; the course tracks re-map "controlko_controllers/DisplacementController".
        "displacement_controller/DisplacementController":
            "rrbot_workshop.controllers.displacement:DisplacementController",
        "controlko_controllers/DisplacementController":
            "rrbot_workshop.controllers.displacement:DisplacementController",
        # the library's reference under its own name, never re-mapped to a learner's file (notebook 08's fallback)
        "rrbot_workshop/DisplacementController": "rrbot_workshop.controllers.displacement:DisplacementController",
        # the chainable pass-through of ros2_control_demos' example 12 (its name there), and under the library's own
        "passthrough_controller/PassthroughController": "rrbot_workshop.controllers.passthrough:PassthroughController",
        "rrbot_workshop/PassthroughController": "rrbot_workshop.controllers.passthrough:PassthroughController",
        "bicycle_steering_controller/BicycleSteeringController":
            "rrbot_workshop.controllers.bicycle_steering:BicycleSteeringController",
    },
}

_registered: dict[str, dict[str, Any]] = {k: {} for k in KINDS}
_resolvers: dict[str, dict[str, Callable[[], Any]]] = {k: {} for k in KINDS}
_ENTRY_POINT_GROUP = "rrbot_workshop.plugins"
#: Entry-point group of functions that register resolvers (the course tracks declare one in pyproject.toml).
_RESOLVER_GROUP = "rrbot_workshop.plugin_resolvers"
_resolvers_installed = False


def _check_kind(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"unknown plugin kind '{kind}' (valid: {', '.join(KINDS)})")


def register(kind: str, type_name: str, cls: Any) -> None:
    """Make ``cls`` loadable under ``type_name`` (overrides built-ins and entry points)."""
    _check_kind(kind)
    _registered[kind][type_name] = cls


def unregister(kind: str, type_name: str) -> None:
    """Forget a class registered with :func:`register` (no error if absent)."""
    _check_kind(kind)
    _registered[kind].pop(type_name, None)


def register_resolver(kind: str, type_name: str, resolver: Callable[[], Any]) -> None:
    """Resolve ``type_name`` by calling ``resolver()`` at load time (used for course tracks)."""
    _check_kind(kind)
    _resolvers[kind][type_name] = resolver


def _install_resolvers() -> None:
    """Run, once, every installer declared in the ``rrbot_workshop.plugin_resolvers`` entry-point group.

    Packages above this one (the course tracks) declare their resolvers there, as ROS packages export
    their plugins in their manifest, so this module never imports them.
    """
    global _resolvers_installed
    if not _resolvers_installed:
        _resolvers_installed = True
        for entry in metadata.entry_points(group=_RESOLVER_GROUP):
            entry.load()()


def _entry_points(kind: str) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for ep in metadata.entry_points(group=_ENTRY_POINT_GROUP):
        k, _, name = ep.name.partition(":")
        if k == kind and name:
            out[name] = ep
    return out


def available(kind: str) -> list[str]:
    """Every type string of ``kind`` that :func:`resolve` would accept, sorted."""
    _check_kind(kind)
    _install_resolvers()
    names = set(_BUILTIN[kind]) | set(_registered[kind]) | set(_resolvers[kind]) | set(_entry_points(kind))
    return sorted(names)


def _import(target: str) -> Any:
    module, _, attr = target.partition(":")
    return getattr(importlib.import_module(module), attr)


def resolve(kind: str, type_name: str) -> Any:
    """The class registered for ``type_name``.

    Raises:
        PluginNotFound: If nothing provides ``type_name``; the message lists what exists.
        UnfinishedExercise: (a ``PluginNotFound``) If ``type_name`` is one of the original workshop's names and the
            learner's class it stands for is not finished yet; the message says which file, line and what to do.
    """
    _check_kind(kind)
    _install_resolvers()
    if type_name in _registered[kind]:
        return _registered[kind][type_name]
    if type_name in _resolvers[kind]:
        return _resolvers[kind][type_name]()
    if type_name in _BUILTIN[kind]:
        return _import(_BUILTIN[kind][type_name])
    eps = _entry_points(kind)
    if type_name in eps:
        return eps[type_name].load()
    raise PluginNotFound(type_name, kind, available(kind))


def describe_unfinished(type_name: str, kind: str | None = None) -> str | None:
    """Why ``type_name`` cannot be loaded yet, if it names a learner's unfinished class; else ``None``.

    For tools that report rather than raise (lint): one sentence naming the task, the learner's file and line,
    and what to do instead. ``None`` for a type that loads, and for one that is simply unknown (that is
    :class:`PluginNotFound`'s message, with the names that exist).

    Args:
        type_name: A plugin type string, e.g. ``"controlko_controllers/DisplacementController"``.
        kind: ``"hardware"`` or ``"controller"``; default both.
    """
    for k in KINDS if kind is None else (kind,):
        _check_kind(k)
        try:
            resolve(k, type_name)
        except UnfinishedExercise as exc:
            return str(exc)
        except PluginNotFound:
            continue
        return None
    return None
