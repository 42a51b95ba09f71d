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
    # TODO(task 6.4): predict each request before you run it in notebook 06: replace every None. States are
    #   "unconfigured", "inactive", "active" or "finalized" ("unloaded" for a controller no longer loaded); accepted is
    #   True or False. Each request is one check (1 point): all its parts must be right.
    # switch_controllers(activate=[joint_trajectory_controller], strictness="strict")
    "activate_next_to_forward": {
        "accepted": None,
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
    },
    # the same with strictness="best_effort"
    "activate_next_to_forward_best_effort": {
        "accepted": None,
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
    },
    # configure_controller("forward_position_controller")
    "configure_an_active_controller": {
        "accepted": None,
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
    },
    # unload_controller("forward_position_controller")
    "unload_an_active_controller": {
        "accepted": None,
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
    },
    # set_hardware_component_state("rrbot", "inactive")
    "deactivate_the_hardware": {
        "accepted": None,
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
    },
    # set_hardware_component_state("rrbot", "unconfigured"), then
    # switch_controllers(activate=[joint_trajectory_controller], deactivate=[forward_position_controller], "strict")
    "switch_on_unconfigured_hardware": {
        "accepted": None,
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
    },
    # cleanup_controller("joint_trajectory_controller")
    "cleanup_an_inactive_controller": {
        "accepted": None,
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
    },
}


# --------------------------------------------------------------------------------------------- 6.1


def switch_to_trajectory_controller(cm: Any) -> None:
    """The original workshop's sequence: load the joint trajectory controller, configure it, then in one strict switch
    deactivate the forward position controller and activate it (no cycle may run with neither active; the forward
    controller ends inactive, still loaded)."""
    # TODO(task 6.1): three requests, as `ros2 control` would make them: load, configure, switch. Which controllers go
    #   into the switch, and which strictness makes it all or nothing?
    raise NotImplementedError("TODO(task 6.1): switch_to_trajectory_controller")


# --------------------------------------------------------------------------------------------- 6.2


def recover(cm: Any, component: str, controllers: list[str]) -> None:
    """After ``component`` failed (its read returned ERROR: it is unconfigured, the controllers using it inactive), bring
    it back to active and reactivate exactly ``controllers`` in one switch; other components and controllers
    stay as they are."""
    # TODO(task 6.2): which state is the component in after a read error (notebook 06 shows it), and which requests take
    #   it back to active? Only then can its controllers claim its interfaces again.
    raise NotImplementedError("TODO(task 6.2): recover")


# --------------------------------------------------------------------------------------------- 6.3


def remove_controller(cm: Any, name: str) -> None:
    """Take controller ``name`` out of the manager from whatever state it is in."""
    # TODO(task 6.3): look the controller's state up, and walk it down the lifecycle as far as unloading needs (notebook
    #   06 shows cleanup and unload). Any controller may be named, and the others stay as they were.
    raise NotImplementedError("TODO(task 6.3): remove_controller")
