"""Task 3 - the roles of ros2_control's components, answered as code over a running system.

Each function takes a running :class:`rrbot_workshop.System` (what ``rw.bringup(...)`` returns) and answers one
question about who does what:

* the **controller manager** (``system.controller_manager``) runs the loop and decides which controllers run,
  in which order and how often (tasks 3.1-3.3);
* **controllers** claim command interfaces and read state interfaces; chainable ones export interfaces of their
  own (tasks 3.4-3.6);
* the **resource manager** (``system.resource_manager``) stores every interface, knows which are available and
  who holds each claim (tasks 3.7-3.9);
* **hardware components** own the interfaces and have a lifecycle of their own (task 3.10).

The grader brings up several different systems and compares your answers with what it finds itself, so an answer
must be *computed* from the system it is given: a list copied from one notebook cell will not do.

Where to look (the same questions ``ros2 control ...`` answers on a real robot):

* ``system.controller_manager.list_controllers()`` - one entry per loaded controller, **in update order**, with
  ``name``, ``state`` (``"active"``, ``"inactive"``, ...), ``type``, ``update_rate``, ``claimed_interfaces``,
  ``required_command_interfaces``, ``required_state_interfaces``, ``reference_interfaces`` ...
  (``ros2 control list_controllers -v``);
* ``system.controller_manager.list_hardware_components()`` - one entry per ``<ros2_control>`` tag, with ``name``,
  ``state`` (a lifecycle ``State``; ``.label`` is its text), ``command_interfaces`` and ``state_interfaces``
  (each with ``name``, ``is_available``, ``is_claimed``) (``ros2 control list_hardware_components -v``);
* ``system.controller_manager.list_hardware_interfaces()`` - every interface with ``is_available`` and
  ``is_claimed`` (``ros2 control list_hardware_interfaces``);
* ``system.resource_manager`` - the storage itself; ``help(system.resource_manager)`` lists its questions.

This is the finished version (the ``solutions`` track); the learner's copy is in ``exercises/``.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "loop_rate",
    "controller_update_rates",
    "update_order",
    "claimant_of",
    "state_interfaces_read_by",
    "reference_interfaces_of",
    "owner_of_interface",
    "available_interfaces",
    "claimable_command_interfaces",
    "hardware_states",
]


# ============================================================================ the controller manager


def loop_rate(system: Any) -> int:
    """Rate of the control loop (read -> update -> write) in [Hz].

    The controller manager runs one loop: read every hardware component, update the active controllers, write
    every hardware component - ``update_rate`` times per second, as set in the controllers YAML
    (``controller_manager: ros__parameters: update_rate: 100``). RRBot's YAML asks for 100 Hz, but the grader
    also brings up systems with other rates.
    """
    return system.controller_manager.get_update_rate()


def controller_update_rates(system: Any) -> dict[str, int]:
    """Rate at which each loaded controller is updated, in [Hz], by controller name.

    A controller may run slower than the loop: its own ``update_rate`` parameter. The manager settles it when
    the controller is configured: no rate (or 0) means the loop rate; a rate above the loop rate is cut to the
    loop rate; a rate that does not divide the loop rate is rounded to one the loop can keep (30 Hz on a 100 Hz
    loop runs every third cycle: 33 Hz). Example on RRBot with RRBot's YAML: ``{"joint_state_broadcaster": 100,
    "forward_position_controller": 100, ...}``.
    """
    return {c.name: c.update_rate for c in system.controller_manager.list_controllers()}


def update_order(system: Any) -> list[str]:
    """Names of the controllers the controller manager updates in each cycle, in the order it updates them.

    Only **active** controllers are updated: a loaded or configured (inactive) controller waits. The order puts
    preceding controllers first: a controller that writes into another controller's reference interfaces runs
    before it, so the follower uses this cycle's reference (``joint_trajectory_controller`` before the
    ``pid_controller`` it feeds). Example: with ``joint_state_broadcaster`` and ``forward_position_controller``
    active and ``joint_trajectory_controller`` inactive, the answer is
    ``["joint_state_broadcaster", "forward_position_controller"]``.
    """
    return [c.name for c in system.controller_manager.list_controllers() if c.state == "active"]


# ============================================================================ controllers


def claimant_of(system: Any, interface: str) -> str | None:
    """Name of the controller that holds the claim on command interface ``interface``, or None if it is free.

    A command interface is written by at most one controller at a time: activating a controller claims its
    command interfaces, and the resource manager refuses a second claim (``InterfaceAlreadyClaimed``). A
    chainable controller's reference interface (``"pid_controller_joint1/joint1/position"``) is a command
    interface too, claimed by the preceding controller. Example: with ``forward_position_controller`` active,
    ``claimant_of(system, "joint1/position") == "forward_position_controller"`` and
    ``claimant_of(system, "joint1/velocity") is None``.
    """
    return system.resource_manager.command_interface_holder(interface)


def state_interfaces_read_by(system: Any, controller: str) -> list[str]:
    """Sorted full names of the state interfaces ``controller`` reads; [] unless it is active.

    State interfaces are not claimed exclusively: any number of controllers may read ``joint1/position``. A
    controller gets (loans) its state interfaces when it is activated and gives them back when it is deactivated,
    so an inactive controller reads nothing. ``joint_state_broadcaster`` reads every available state interface
    unless its ``joints`` and ``interfaces`` parameters are both given; ``joint_trajectory_controller`` reads its
    ``state_interfaces`` of each of its ``joints``.
    """
    loans = system.controller_manager.get_controller(controller).state_interfaces  # empty unless active
    return sorted(loan.name for loan in loans)


def reference_interfaces_of(system: Any, controller: str) -> list[str]:
    """Sorted full names of the reference interfaces ``controller`` exported; [] for a controller that exports none.

    A chainable controller (``pid_controller/PidController``) exports *reference interfaces* when it is
    configured: inputs named ``"<controller name>/<joint>/<interface>"`` that a preceding controller can claim
    like command interfaces, which chains the two. They stay in the resource manager until the controller is
    cleaned up; they are available only while it is active. Example: ``pid_controller_joint1`` with
    ``dof_names: [joint1]`` and ``reference_and_state_interfaces: [position]`` exports
    ``["pid_controller_joint1/joint1/position"]``.
    """
    return sorted(system.resource_manager.get_controller_reference_interface_names(controller))


# ============================================================================ the resource manager


def owner_of_interface(system: Any, interface: str) -> str | None:
    """Name of the hardware component that exports ``interface``, or None if no component does.

    Each ``<ros2_control>`` tag of the URDF becomes one hardware component, and every interface it declares
    belongs to that component alone. A robot made of parts has several (two RRBots with prefixes ``left_`` and
    ``right_`` have ``left_rrbot`` and ``right_rrbot``). An interface exported by a controller belongs to no
    hardware component: answer None for it.
    """
    return system.resource_manager.hardware_of_interface(interface)


def available_interfaces(system: Any) -> dict[str, list[str]]:
    """Interfaces available now: ``{"state": [...], "command": [...]}``, each list sorted.

    The resource manager stores every interface from the moment a component is loaded, but makes a component's
    state *and* command interfaces available only while it is **inactive or active** (configuring makes them
    available; cleanup, shutdown or an error take them away). A chainable controller's exported interfaces are
    available while it is active. An unconfigured RRBot offers nothing at all.
    """
    rm = system.resource_manager
    return {"state": rm.available_state_interfaces(), "command": rm.available_command_interfaces()}


def claimable_command_interfaces(system: Any) -> list[str]:
    """Sorted command interfaces that a controller being activated now could claim.

    Available is not enough. A command interface can be claimed if it is available, nobody holds it yet, and -
    for a hardware interface - its component is **active**: an inactive component still shows its interfaces,
    but refuses to start commanding them, so activating a controller that needs them is rejected (ros2_control's
    ``allow_controller_activation_with_inactive_hardware``, false by default). A chainable controller's reference
    interface can be claimed while it is available and free.
    """
    rm = system.resource_manager
    states = hardware_states(system)
    claimable = []
    for name in available_interfaces(system)["command"]:
        if rm.command_interface_is_claimed(name):
            continue
        owner = owner_of_interface(system, name)
        if owner is not None and states[owner] != "active":
            continue
        claimable.append(name)
    return claimable


# ============================================================================ hardware components


def hardware_states(system: Any) -> dict[str, str]:
    """Lifecycle state label (``"unconfigured"``, ``"inactive"``, ``"active"``, ...) of each hardware component.

    Hardware components have the same lifecycle as controllers, driven by the resource manager: unconfigured
    after loading, inactive after configure (interfaces available, commands not written), active after activate.
    By default every component is activated at start-up; ``hardware_components_initial_state`` in the YAML, or
    ``set_hardware_component_state``, chooses otherwise. Example: ``{"rrbot": "active"}``.
    """
    return {comp.name: comp.state.label for comp in system.controller_manager.list_hardware_components()}
