"""Task 9.2: bring a controller chain up and down in an order the controller manager accepts.

The chain is ``joint_trajectory_controller -> pid_controller_joint1, pid_controller_joint2 -> hardware``.
Notebook 09 shows what the controller manager answers when the order is wrong; read its error before writing
these two functions.
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
    # TODO(task 9.2): load and configure what is missing (cm.list_controllers() tells each state), then
    #   activate with strict switches. A preceding controller claims interfaces that its followers export:
    #   when do those interfaces exist and become available?
    raise NotImplementedError("TODO(task 9.2): activate the chain")


def deactivate_chain(cm: ControllerManager) -> None:
    """Deactivate the chain's active controllers, leaving them loaded and configured.

    Only the active controllers are deactivated, with strictness ``"strict"``; every controller stays loaded and
    configured, and the ones that were not active stay as they were.

    Args:
        cm: The controller manager.
    """
    # TODO(task 9.2): the reverse question: which controller may stop first while the others still run?
    raise NotImplementedError("TODO(task 9.2): deactivate the chain")
