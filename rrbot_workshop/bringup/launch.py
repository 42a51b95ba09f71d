"""Bring-up: the launch file of this library. Description + controllers YAML -> a running :class:`System`.

A ros2_control launch file runs xacro, starts ``ros2_control_node`` with the URDF and the controllers
YAML, and calls spawners. :func:`bringup` does the same in one call:

1. the description (a ``.xacro``/``.urdf`` path, URDF text, or a package name under ``descriptions/``)
   becomes URDF text, and its ``<ros2_control>`` tags become :class:`~rrbot_workshop.description.HardwareInfo`;
2. the resource manager loads the hardware and brings each component to its initial state
   (``hardware_components_initial_state`` of the controller manager, or ``hardware_initial_state``);
3. the controller manager is created with the YAML's parameters;
4. spawner semantics: controllers in ``spawn`` are loaded, configured and activated together in one
   strict switch; those in ``inactive`` are loaded and configured only.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from rrbot_workshop.bringup.inputs import controllers_config, description_to_urdf, hardware_initial_states
from rrbot_workshop.bringup.system import System, namespaced, register, shared_graph, unique_name
from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.description.packages import use_package_path
from rrbot_workshop.exceptions import ArgumentError, ControllerNotFound, ParameterError
from rrbot_workshop.hardware_interface.resource_loading import mock_hardware_infos
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.arguments import mapping, name_list
from rrbot_workshop.middleware.clock import Clock, make_clock
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.topics import TopicBus

__all__ = ["bringup"]

_log = logging.getLogger(__name__)


def bringup(
    description: str | Path,
    controllers: str | Path | Mapping[str, Any] | ControllersConfig | None = None,
    xacro_args: Mapping[str, Any] | None = None,
    spawn: Iterable[str] = (),
    inactive: Iterable[str] = (),
    clock: str | Clock = "sim",
    hardware_initial_state: Mapping[str, str | State] | None = None,
    name: str | None = None,
    package_path: Iterable[str | Path] | None = None,
    mock_hardware: str | None = None,
    namespace: str | None = None,
    launch_args: Mapping[str, Any] | None = None,
    controller_types: Mapping[str, str] | None = None,
) -> System:
    """Build and start a system from a description and a controllers YAML.

    Args:
        description: ``.xacro``/``.urdf`` path, URDF text, or a package name under ``descriptions/``
            (then ``urdf/<name>.urdf.xacro`` is used).
        controllers: Controllers YAML: a path, a file name under ``descriptions/<package>/config/``,
            YAML text, a mapping, or a :class:`ControllersConfig`. None: no controllers declared.
        xacro_args: Xacro arguments (``{"use_mock_hardware": True}``).
        spawn: Controllers to load, configure and activate (one strict switch for all).
        inactive: Controllers to load and configure only.
        clock: ``"sim"`` (deterministic, default), ``"wall"`` (paced to real time) or a clock object.
        hardware_initial_state: Component name -> ``"unconfigured"``/``"inactive"``/``"active"``;
            overrides ``hardware_components_initial_state`` from the YAML. Unlisted components become active.
        name: System name for ``%control --system``; the robot name (plus a number if taken) by default.
        package_path: Folders searched first for packages (``$(find pkg)``, ``package://pkg/...``), before
            ``$RRBOT_WORKSHOP_PACKAGE_PATH`` and ``descriptions/``: source trees (a clone, a workspace's ``src/``)
            or installed trees (see :mod:`rrbot_workshop.description.packages`).
        mock_hardware: None: load the plugins as written. ``"unknown"``: every ``<hardware><plugin>`` the library
            does not have becomes the mock of its component's type. ``"all"``: every component does. The
            replaced plugins are logged and kept in ``system.mocked_hardware``.
        namespace: The node namespace of the controller manager and its controllers (``"/rrbot_1"``), as a launch
            file's ``Node(..., namespace=...)``: the manager is ``/rrbot_1/controller_manager`` (its services too),
            controllers' topics resolve in it (``/rrbot_1/forward_position_controller/commands``,
            ``/rrbot_1/joint_states``), and each node takes the YAML sections whose keys match its fully qualified
            name as ROS 2 matches them (``/**/controller_manager``, ``/rrbot_1/...``). Systems with a namespace
            share one topic graph, as nodes of one ROS graph do. None: the root namespace, a graph of its own.
        launch_args: Launch arguments for ``$(var name)`` in the controllers YAML (and in parameter files given to
            :meth:`System.spawn`), as ``ParameterFile(..., allow_substs=True)`` fills them.
        controller_types: Controller name or plugin type -> a library controller type to load in its place, with
            the same parameters (``{"r6bot_controller": "joint_trajectory_controller/JointTrajectoryController"}``
            lets example 7 run with the JTC standing in for its own controller); a log line says so.

    Returns:
        The running :class:`System` (it becomes the "current" one for the magics).

    Raises:
        DescriptionError: If the description cannot be found or parsed.
        ParameterError: If the controllers YAML cannot be found or is malformed.
        HardwareError: If hardware cannot be loaded, or an initial state names an unknown component.
        ControllerNotFound: If a controller in ``spawn``/``inactive`` is not declared in the YAML.
        ControllerError: If a controller fails to load, configure or activate.
        SwitchError: If activating ``spawn`` is rejected.
        ArgumentError: If an argument is of the wrong type (``spawn=3``, ``xacro_args=[...]``, ``name=""``, ...).
    """
    from rrbot_workshop.description import parse_ros2_control

    _check_arguments(description, xacro_args, hardware_initial_state, name, package_path, controller_types)
    for label, given in (("launch_args", launch_args), ("controller_types", controller_types)):
        if given is not None and not isinstance(given, Mapping):
            raise ParameterError("bringup", label, f"must be a mapping of names to values, got {given!r}")
    package_path = [package_path] if isinstance(package_path, str | Path) else list(package_path or [])
    urdf, package, source = description_to_urdf(description, xacro_args or {}, package_path)
    args = {str(k): v for k, v in (launch_args or {}).items()}
    cfg = namespaced(controllers_config(controllers, package, package_path, args), namespace)
    infos = parse_ros2_control(urdf, source=source)
    infos, mocked = mock_hardware_infos(infos, mock_hardware)
    for component, original in mocked.items():
        _log.info("hardware component '%s': plugin '%s' replaced by its mock '%s' (mock_hardware=%r)", component,
                  original or "(none)", next(i.hardware_plugin_name for i in infos if i.name == component), mock_hardware)
    spawn = name_list("bringup", "spawn", spawn) if spawn != () else []
    inactive = name_list("bringup", "inactive", inactive) if inactive != () else []
    both = sorted(set(spawn) & set(inactive))
    if both:
        raise ParameterError("bringup", "spawn/inactive", f"{both} appear in both lists; choose one")
    for ctrl in [*spawn, *inactive]:
        if ctrl not in cfg.controller_types and "type" not in cfg.parameters_for(ctrl):  # '/**' may give the type
            raise ControllerNotFound(ctrl, cfg.controller_types, what=f"declared in the controllers config ({cfg.source})")

    the_clock = make_clock(clock, cfg.update_rate)
    rm = ResourceManager(update_rate=cfg.update_rate, initial_states=hardware_initial_states(cfg, hardware_initial_state))
    with use_package_path(package_path):  # simulated hardware resolves package:// meshes while it loads
        rm.load_hardware_infos(infos)
    bus = shared_graph(cfg.manager_name) if cfg.namespace != "/" else TopicBus()
    cm = ControllerManager(rm, bus, cfg.update_rate, urdf, cfg, the_clock)
    cm.launch_args = args
    cm.controller_type_stand_ins.update(controller_types or {})
    name = unique_name(urdf, name)
    system = System(name, urdf, infos, cm, the_clock)
    system.mocked_hardware = mocked
    try:
        for ctrl in [*spawn, *inactive]:
            cm.load_controller(ctrl)
            cm.configure_controller(ctrl)
        if spawn:
            cm.switch_controllers(activate=spawn, strictness="strict")
    except Exception:
        system._running = True
        system.shutdown()
        raise
    register(system)
    _log.info("brought up '%s': hardware %s, active %s", name, rm.component_names(), spawn)
    return system


def _check_arguments(description: Any, xacro_args: Any, hardware_initial_state: Any, name: Any, package_path: Any,
                     controller_types: Any) -> None:
    """Refuse arguments of :func:`bringup` of the wrong type before anything is read or built.

    Raises:
        ArgumentError: Naming the argument and what it takes.
    """
    if not isinstance(description, str | Path):
        raise ArgumentError("bringup", "description", description,
                            "a .xacro/.urdf path, URDF text or a package name under descriptions/")
    mapping("bringup", "xacro_args", xacro_args, "a mapping of xacro argument names to values")
    states = mapping("bringup", "hardware_initial_state", hardware_initial_state,
                     "a mapping of component names to 'unconfigured', 'inactive' or 'active'")
    for component, state in states.items():
        if not isinstance(state, str | State):
            raise ArgumentError("bringup", f"hardware_initial_state[{component!r}]", state,
                                "'unconfigured', 'inactive' or 'active'")
    if name is not None and (not isinstance(name, str) or not name.strip()):
        raise ArgumentError("bringup", "name", name, "None or a non-empty string")
    if package_path is not None and not isinstance(package_path, str | Path):
        if isinstance(package_path, bytes | Mapping) or not isinstance(package_path, Iterable):
            raise ArgumentError("bringup", "package_path", package_path, "a folder or a list of folders")
        for index, folder in enumerate(package_path if isinstance(package_path, list | tuple) else ()):
            if not isinstance(folder, str | Path):
                raise ArgumentError("bringup", f"package_path[{index}]", folder, "a folder (a str or Path)")
    if isinstance(controller_types, Mapping):
        for key, value in controller_types.items():
            if not isinstance(key, str) or not isinstance(value, str) or not value:
                raise ArgumentError("bringup", f"controller_types[{key!r}]", value,
                                    "a controller type name such as 'joint_trajectory_controller/JointTrajectoryController'")
