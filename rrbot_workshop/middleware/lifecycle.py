"""Lifecycle states and return codes shared by hardware components and controllers.

ros2_control builds both hardware components and controllers on the ROS 2 managed-node state machine:
``unconfigured -> inactive -> active``, with ``finalized`` as the end. The primary states and the result
codes of every transition callback live here so that hardware and controllers speak the same words.
"""

from __future__ import annotations

import enum

__all__ = ["State", "CallbackReturn", "ReturnType", "TRANSITION_SOURCES", "TRANSITIONS", "TransitionCounter"]


class State(enum.Enum):
    """Primary lifecycle states (``lifecycle_msgs/msg/State``). The value is the ROS label."""

    UNKNOWN = "unknown"
    UNCONFIGURED = "unconfigured"
    INACTIVE = "inactive"
    ACTIVE = "active"
    FINALIZED = "finalized"

    @property
    def label(self) -> str:
        """The ROS label, e.g. ``"inactive"``."""
        return self.value

    @property
    def id(self) -> int:
        """The numeric id of ``lifecycle_msgs/msg/State`` (0 unknown, 1 unconfigured, 2 inactive, 3 active, 4 finalized)."""
        return _STATE_IDS[self]

    @classmethod
    def from_label(cls, label: str) -> State:
        """Parse a label such as ``"active"`` (any letter case).

        Raises:
            ValueError: If the label is not one of the five primary states (or not a string).
        """
        try:
            if not isinstance(label, str):
                raise ValueError(label)
            return cls(label.strip().lower())
        except ValueError:
            valid = ", ".join(s.value for s in cls)
            raise ValueError(f"unknown lifecycle state '{label}' (valid: {valid})") from None

    def __str__(self) -> str:
        return self.value


#: ``lifecycle_msgs/msg/State`` id of each primary state (looked up, not searched: activity messages list many).
_STATE_IDS: dict[State, int] = {state: k for k, state in enumerate(State)}


class CallbackReturn(enum.Enum):
    """Result of a lifecycle callback (``on_configure``, ``on_activate``, ...)."""

    SUCCESS = "success"
    FAILURE = "failure"
    ERROR = "error"


class ReturnType(enum.Enum):
    """Result of ``read``/``write``/``update`` and mode-switch hooks (``hardware_interface::return_type``)."""

    OK = "ok"
    ERROR = "error"
    DEACTIVATE = "deactivate"


#: For each transition, the states it may start from (a call from any other state is a no-op).
TRANSITION_SOURCES: dict[str, tuple[State, ...]] = {
    "configure": (State.UNCONFIGURED,),
    "cleanup": (State.INACTIVE,),
    "activate": (State.INACTIVE,),
    "deactivate": (State.ACTIVE,),
    "shutdown": (State.UNCONFIGURED, State.INACTIVE, State.ACTIVE),
}


class TransitionCounter:
    """Counts lifecycle state changes of every controller and hardware component in the process.

    The control cycle is compiled: the controller manager and the resource manager prepare, once, the list of what
    each cycle calls (the active controllers in chain order, the components that read and write). A plan is kept
    while :attr:`value` is the one it was built at; every state change calls :meth:`bump`, and the next cycle
    rebuilds. The cycle itself still checks each state it relies on, so a stale plan can skip work, never run work
    that the states forbid.
    """

    __slots__ = ("value",)

    def __init__(self) -> None:
        self.value = 0

    def bump(self) -> None:
        """Record a state change."""
        self.value += 1


#: The process-wide counter the controller and hardware lifecycles bump.
TRANSITIONS = TransitionCounter()
