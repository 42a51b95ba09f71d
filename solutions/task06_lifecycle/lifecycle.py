"""Task 6: the lifecycle of controllers and hardware, driven through the controller manager.

Each function gets the running system's controller manager (``system.controller_manager``) and uses its services as
``ros2 control`` would: ``load_controller``, ``configure_controller`` (or ``set_controller_state``),
``switch_controllers``, ``cleanup_controller``, ``unload_controller``, ``set_hardware_component_state`` and the
``list_controllers`` / ``list_hardware_components`` introspection.

``PREDICTIONS`` (first in this file: make them before anything else) holds what you expect of requests made on a fresh
RRBot; the self-check runs each one and tells you which parts of each prediction are wrong, not what the right answer
is. Notebook 06 shows the outcomes and why only once every prediction is made, and keeps your predictions as they are
then: a prediction changed after the outcomes were shown earns nothing.
"""

from __future__ import annotations

from typing import Any

__all__ = ["switch_to_trajectory_controller", "recover", "remove_controller", "PREDICTIONS"]


# --------------------------------------------------------------------------------------------- 6.4 (first)

# Predict these first, before you read on here or run anything in notebook 06: the notebook's cells that show some of
# the outcomes run only once every prediction is made. Notebook 06's prediction cell then keeps your predictions as
# they are (a change after it earns nothing), grades them and shows what happened.

# Each request is made on a fresh mock RRBot: joint_state_broadcaster and forward_position_controller active,
# joint_trajectory_controller loaded and inactive, hardware component 'rrbot' active.
#   accepted: does the request succeed (no error)?
#   controllers / hardware: the states right after it.
PREDICTIONS: dict[str, dict[str, Any]] = {
    # switch_controllers(activate=[joint_trajectory_controller], strictness="strict")
    "activate_next_to_forward": {
        "accepted": False,
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
    },
    # the same with strictness="best_effort"
    "activate_next_to_forward_best_effort": {
        "accepted": False,
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
    },
    # configure_controller("forward_position_controller")
    "configure_an_active_controller": {
        "accepted": False,
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
    },
    # unload_controller("forward_position_controller")
    "unload_an_active_controller": {
        "accepted": False,
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
    },
    # set_hardware_component_state("rrbot", "inactive")
    "deactivate_the_hardware": {
        "accepted": True,
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "inactive"},
    },
    # set_hardware_component_state("rrbot", "unconfigured"), then
    # switch_controllers(activate=[joint_trajectory_controller], deactivate=[forward_position_controller], "strict")
    "switch_on_unconfigured_hardware": {
        "accepted": False,
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "unconfigured"},
    },
    # cleanup_controller("joint_trajectory_controller")
    "cleanup_an_inactive_controller": {
        "accepted": True,
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "unconfigured"},
        "hardware": {"rrbot": "active"},
    },
}


# --------------------------------------------------------------------------------------------- 6.1


def switch_to_trajectory_controller(cm: Any) -> None:
    """The original workshop's sequence: load the joint trajectory controller, configure it, then in one strict switch
    deactivate the forward position controller and activate it (no cycle may run with neither active; the forward
    controller ends inactive, still loaded)."""
    cm.load_controller("joint_trajectory_controller")
    cm.set_controller_state("joint_trajectory_controller", "inactive")
    cm.switch_controllers(activate=["joint_trajectory_controller"], deactivate=["forward_position_controller"],
                          strictness="strict")


# --------------------------------------------------------------------------------------------- 6.2


def recover(cm: Any, component: str, controllers: list[str]) -> None:
    """After ``component`` failed (its read returned ERROR: it is unconfigured, the controllers using it inactive), bring
    it back to active and reactivate exactly ``controllers`` in one switch; other components and controllers
    stay as they are."""
    cm.set_hardware_component_state(component, "active")
    cm.switch_controllers(activate=controllers, strictness="strict")


# --------------------------------------------------------------------------------------------- 6.3


def remove_controller(cm: Any, name: str) -> None:
    """Take controller ``name`` out of the manager from whatever state it is in."""
    state = next(c.state for c in cm.list_controllers() if c.name == name)
    if state == "active":
        cm.switch_controllers(deactivate=[name], strictness="strict")
    if state in ("active", "inactive"):
        cm.cleanup_controller(name)
    cm.unload_controller(name)
