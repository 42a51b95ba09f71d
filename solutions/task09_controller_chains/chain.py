"""Task 9.2: bring a controller chain up and down in an order the controller manager accepts.

A controller can only claim a reference interface that an *active* controller exports: the PIDs must be active
before (or in the same switch as) the trajectory controller that chains to them, and they can only stop once
nothing claims their references any more.
"""

from __future__ import annotations

from rrbot_workshop.controller_manager.manager import ControllerManager

__all__ = ["CHAIN", "activate_chain", "deactivate_chain"]

#: The chain, head first.
CHAIN = ["joint_trajectory_controller", "pid_controller_joint1", "pid_controller_joint2"]


def activate_chain(cm: ControllerManager) -> None:
    """Load and configure the chain's controllers that are not yet, then activate the whole chain.

    It must work from whatever state the chain is in (nothing loaded, some controllers only loaded or configured,
    a PID already active, the head deactivated while the PIDs run), and it switches with strictness ``"strict"``.

    Args:
        cm: The controller manager; the controllers are declared in its controllers YAML.
    """
    loaded = {c.name: c.state for c in cm.list_controllers()}
    for name in CHAIN:
        if name not in loaded:
            cm.load_controller(name)
            loaded[name] = "unconfigured"
        if loaded[name] == "unconfigured":
            cm.configure_controller(name)
    followers = [name for name in CHAIN[1:] if loaded[name] != "active"]
    if followers:
        cm.switch_controllers(activate=followers, strictness="strict")
    if loaded[CHAIN[0]] != "active":
        cm.switch_controllers(activate=[CHAIN[0]], strictness="strict")


def deactivate_chain(cm: ControllerManager) -> None:
    """Deactivate the chain: the head first, then the PIDs it was feeding.

    Only the active controllers are deactivated, with strictness ``"strict"``; every controller stays loaded and
    configured, and the ones that were not active stay as they were.

    Args:
        cm: The controller manager.
    """
    active = {c.name for c in cm.list_controllers() if c.state == "active"}
    if CHAIN[0] in active:
        cm.switch_controllers(deactivate=[CHAIN[0]], strictness="strict")
    followers = [name for name in CHAIN[1:] if name in active]
    if followers:
        cm.switch_controllers(deactivate=followers, strictness="strict")
