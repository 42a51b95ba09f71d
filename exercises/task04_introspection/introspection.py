"""Task 4: introspection of a running ros2_control system, answered with the controller manager's API.

YOUR TASK: replace each ``raise NotImplementedError("TODO(task 4.k) ...")`` with a few lines that answer
question 4.k with the API. Notebook ``04_introspection.ipynb`` shows every answer with the ``%control`` magic
first; check your work with ``check(4)`` in the notebook or ``rrbot-workshop grade 4`` in a terminal. The
grader calls your functions on freshly brought-up systems (other robots, other controller names), so compute
the answers from the system, never type them in.

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
from rrbot_workshop.exceptions import SwitchError  # noqa: F401 - for task 4.6

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
    # TODO(task 4.1): ask the controller manager for its controllers, as `ros2 control list_controllers` does.
    #   cm = controller_manager_of(target) gives the manager; cm.list_controllers() returns one ControllerState
    #   per loaded controller (fields as in controller_manager_msgs/ControllerState: .name, .state, .type,
    #   .claimed_interfaces, .required_command_interfaces, ...). Return the names, in that order.
    #   "Loaded" includes controllers that are only loaded (unconfigured) or configured (inactive).
    raise NotImplementedError("TODO(task 4.1): return the names of the loaded controllers from cm.list_controllers()")


def controller_states(target: Any) -> dict[str, str]:
    """Question 4.2: in which lifecycle state is each controller? (``ros2 control list_controllers``)

    Args:
        target: A running system or its controller manager.

    Returns:
        Controller name -> state label (``"unconfigured"``, ``"inactive"``, ``"active"`` or ``"finalized"``).
    """
    # TODO(task 4.2): the same list, now with each entry's .state: a lifecycle label such as "active" or
    #   "inactive". On the mock RRBot brought up with spawn=[joint_state_broadcaster, forward_position_controller]
    #   and inactive=[joint_trajectory_controller], the answer is
    #   {"joint_state_broadcaster": "active", "forward_position_controller": "active",
    #    "joint_trajectory_controller": "inactive"}.
    raise NotImplementedError("TODO(task 4.2): map each controller's name to its .state from cm.list_controllers()")


def hardware_component_states(target: Any) -> dict[str, str]:
    """Question 4.3: in which lifecycle state is each hardware component? (``ros2 control list_hardware_components``)

    Args:
        target: A running system or its controller manager.

    Returns:
        Hardware component name -> state label (``"unconfigured"``, ``"inactive"``, ``"active"``...).
    """
    # TODO(task 4.3): cm.list_hardware_components() returns one HardwareComponentState per <ros2_control> tag
    #   of the URDF (.name, .type, .plugin_name, .state, .command_interfaces, .state_interfaces). Its .state is a
    #   lifecycle State object, not a string: use .state.label ("active", "inactive", "unconfigured").
    #   In the original workshop this was the service call
    #   `ros2 service call /controller_manager/list_hardware_components ...`.
    raise NotImplementedError("TODO(task 4.3): map each hardware component's name to its state label")


def available_interfaces(target: Any) -> dict[str, list[str]]:
    """Question 4.4: which interfaces are available, and which are claimed? (``ros2 control list_hardware_interfaces``)

    Args:
        target: A running system or its controller manager.

    Returns:
        ``{"command": [...], "state": [...], "claimed": [...]}``: the available command interfaces, the
        available state interfaces and the claimed command interfaces, each list sorted by name.
    """
    # TODO(task 4.4): cm.list_hardware_interfaces() has two lists, .command_interfaces and .state_interfaces,
    #   of HardwareInterface entries (.name, .is_available, .is_claimed). An interface exists as soon as its
    #   component is loaded, but it is available only once the component is configured (inactive or active),
    #   and a command interface is claimed while an active controller holds it. Build the three sorted lists:
    #   available command interfaces, available state interfaces, claimed command interfaces
    #   (the "[available] [claimed]" marks that `ros2 control list_hardware_interfaces` prints).
    raise NotImplementedError("TODO(task 4.4): build {'command': ..., 'state': ..., 'claimed': ...}")


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
    # TODO(task 4.5): two steps, as in the workshop:
    #   1. `spawner <activate> --inactive`: if `activate` is not in cm.controllers yet, cm.load_controller(activate);
    #      if it is then "unconfigured", cm.configure_controller(activate). It is now inactive: ready, not running.
    #   2. `switch_controllers --deactivate <deactivate> --activate <activate> --strict`: ONE call to
    #      cm.switch_controllers(activate=[...], deactivate=[...], strictness="strict"). Both controllers claim
    #      joint1/position and joint2/position, so they must change places in the same switch: activating first
    #      would be rejected (the interfaces are claimed), deactivating first would leave the robot uncommanded.
    #   Then return controller_states(cm).
    raise NotImplementedError("TODO(task 4.5): load/configure `activate` if needed, then one strict switch")


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
    # TODO(task 4.6): ask for every "inactive" controller in ONE strict switch and catch the SwitchError
    #   (rw.SwitchError). A rejection is data, not just text: look at what the exception object carries
    #   (help(SwitchError)) rather than parsing its message. If nothing is raised, both lists are empty.
    raise NotImplementedError("TODO(task 4.6): try the switch, catch SwitchError, return the names it quotes")


def interfaces_in_use(target: Any) -> dict[str, dict[str, list[str]]]:
    """Question 4.7: which interfaces does each controller use? (``ros2 control list_controllers -v``)

    An active controller uses the command interfaces it has claimed and the state interfaces it
    requires; a controller that is not active uses none.

    Args:
        target: A running system or its controller manager.

    Returns:
        Controller name -> ``{"command": [...], "state": [...]}``, each list sorted, for every loaded controller.
    """
    # TODO(task 4.7): `ros2 control list_controllers -v` prints, per controller, its "claimed interfaces" and its
    #   "required state interfaces". From cm.list_controllers(): "command" is the entry's .claimed_interfaces
    #   (empty unless it is active), "state" is its .required_state_interfaces if it is active and [] otherwise.
    #   Sort both lists. Expect joint_state_broadcaster to read every state interface and claim no command
    #   interface, and the active joint controller to claim joint1/position and joint2/position.
    raise NotImplementedError("TODO(task 4.7): map each controller to {'command': [...], 'state': [...]}")
