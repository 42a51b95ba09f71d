"""Task 4: introspection of a running ros2_control system, answered with the controller manager's API.

On a ROS 2 robot you ask these questions with ``ros2 control <verb>`` (package ros2controlcli) or by
calling the controller manager's services (``/controller_manager/list_controllers``...). Here the same
services are methods of the controller manager:

=====================================  ==========================================  ===============================
question                               ROS 2 command                               API used here
=====================================  ==========================================  ===============================
4.1 which controllers are loaded?      ``ros2 control list_controllers``           ``cm.list_controllers()``
4.2 in which state is each one?        ``ros2 control list_controllers``           ``cm.list_controllers()``
4.3 in which state is the hardware?    ``ros2 control list_hardware_components``   ``cm.list_hardware_components()``
4.4 which interfaces are available?    ``ros2 control list_hardware_interfaces``   ``cm.list_hardware_interfaces()``
4.5 switch between two controllers     spawner ``--inactive``, then                ``cm.load_controller``,
                                       ``ros2 control switch_controllers``         ``configure_controller``,
                                                                                   ``switch_controllers``
4.6 all controllers at once?           ``switch_controllers --activate a b``       ``cm.switch_controllers`` and
                                                                                   its ``SwitchError``
4.7 which interfaces does each use?    ``ros2 control list_controllers -v``        ``cm.list_controllers()``
=====================================  ==========================================  ===============================

Every function takes a running :class:`~rrbot_workshop.System` (what ``rw.bringup`` returns) or its
controller manager, and returns plain Python values (names and state labels), so the answers can be
printed, compared and graded.
"""

from __future__ import annotations

from typing import Any

from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.exceptions import SwitchError

__all__ = [
    "controller_manager_of",
    "loaded_controllers",
    "controller_states",
    "hardware_component_states",
    "available_interfaces",
    "switch_between",
    "activate_all_at_once",
    "interfaces_in_use",
]


def controller_manager_of(target: Any) -> ControllerManager:
    """The controller manager of ``target``: a running ``System``, or a ``ControllerManager`` itself.

    Args:
        target: What ``rw.bringup(...)`` returned, or its ``controller_manager``.

    Returns:
        The controller manager.
    """
    return getattr(target, "controller_manager", target)


def loaded_controllers(target: Any) -> list[str]:
    """Question 4.1: which controllers are loaded? (``ros2 control list_controllers``)

    Args:
        target: A running system or its controller manager.

    Returns:
        The names of all loaded controllers, whatever their state, in the order ``list_controllers`` gives.
    """
    cm = controller_manager_of(target)
    return [entry.name for entry in cm.list_controllers()]


def controller_states(target: Any) -> dict[str, str]:
    """Question 4.2: in which lifecycle state is each controller? (``ros2 control list_controllers``)

    Args:
        target: A running system or its controller manager.

    Returns:
        Controller name -> state label (``"unconfigured"``, ``"inactive"``, ``"active"`` or ``"finalized"``).
    """
    cm = controller_manager_of(target)
    return {entry.name: entry.state for entry in cm.list_controllers()}


def hardware_component_states(target: Any) -> dict[str, str]:
    """Question 4.3: in which lifecycle state is each hardware component? (``ros2 control list_hardware_components``)

    Args:
        target: A running system or its controller manager.

    Returns:
        Hardware component name -> state label (``"unconfigured"``, ``"inactive"``, ``"active"``...).
    """
    cm = controller_manager_of(target)
    return {component.name: component.state.label for component in cm.list_hardware_components()}


def available_interfaces(target: Any) -> dict[str, list[str]]:
    """Question 4.4: which interfaces are available, and which are claimed? (``ros2 control list_hardware_interfaces``)

    Args:
        target: A running system or its controller manager.

    Returns:
        ``{"command": [...], "state": [...], "claimed": [...]}``: the available command interfaces, the
        available state interfaces and the claimed command interfaces, each list sorted by name.
    """
    cm = controller_manager_of(target)
    interfaces = cm.list_hardware_interfaces()
    return {
        "command": sorted(i.name for i in interfaces.command_interfaces if i.is_available),
        "state": sorted(i.name for i in interfaces.state_interfaces if i.is_available),
        "claimed": sorted(i.name for i in interfaces.command_interfaces if i.is_claimed),
    }


def switch_between(target: Any, deactivate: str, activate: str) -> dict[str, str]:
    """Question 4.5: hand the robot from the active controller ``deactivate`` to ``activate``.

    ``activate`` may not be loaded yet: then it is loaded and configured first, as
    ``ros2 run controller_manager spawner <name> --inactive`` does. The swap itself is one strict switch,
    ``ros2 control switch_controllers --deactivate <old> --activate <new> --strict``, so the robot is
    never left without a controller between the two.

    Args:
        target: A running system or its controller manager.
        deactivate: Name of the controller that is active now.
        activate: Name of the controller to activate (declared in the controllers YAML).

    Returns:
        Controller name -> state label after the switch (the answer of question 4.2).

    Raises:
        SwitchError: If the switch is rejected (nothing changes then).
    """
    cm = controller_manager_of(target)
    if activate not in cm.controllers:
        cm.load_controller(activate)
    if controller_states(cm)[activate] == "unconfigured":
        cm.configure_controller(activate)
    cm.switch_controllers(activate=[activate], deactivate=[deactivate], strictness="strict")
    return controller_states(cm)


def activate_all_at_once(target: Any) -> dict[str, list[str]]:
    """Question 4.6: what happens when every controller is activated at the same time?

    Asks, in one strict switch, to activate every controller that is inactive (loaded and configured
    but not running). Two controllers that command the same joint interface cannot both run: the
    controller manager rejects the whole switch, names the interface and the two controllers, and
    changes nothing.

    Args:
        target: A running system or its controller manager.

    Returns:
        ``{"interfaces": [...], "controllers": [...]}``: the command interfaces and the controllers that
        the rejection names, each sorted. Both lists are empty if the switch went through.
    """
    cm = controller_manager_of(target)
    inactive = [name for name, state in controller_states(cm).items() if state == "inactive"]
    try:
        cm.switch_controllers(activate=inactive, strictness="strict")
    except SwitchError as error:
        # The rejection carries its data: no need to parse the English of error.reasons.
        return {"interfaces": sorted(error.interfaces), "controllers": sorted(error.controllers)}
    return {"interfaces": [], "controllers": []}


def interfaces_in_use(target: Any) -> dict[str, dict[str, list[str]]]:
    """Question 4.7: which interfaces does each controller use? (``ros2 control list_controllers -v``)

    An active controller uses the command interfaces it has claimed and the state interfaces it
    requires; a controller that is not active uses none.

    Args:
        target: A running system or its controller manager.

    Returns:
        Controller name -> ``{"command": [...], "state": [...]}``, each list sorted, for every loaded controller.
    """
    cm = controller_manager_of(target)
    out: dict[str, dict[str, list[str]]] = {}
    for entry in cm.list_controllers():
        active = entry.state == "active"
        out[entry.name] = {
            "command": sorted(entry.claimed_interfaces),
            "state": sorted(entry.required_state_interfaces) if active else [],
        }
    return out
