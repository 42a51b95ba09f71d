"""control_toolbox: the PID of ros2_control's control_toolbox package (Jazzy semantics)."""

from rrbot_workshop.control_toolbox.pid import ANTIWINDUP_STRATEGIES, Gains, Pid

__all__ = ["ANTIWINDUP_STRATEGIES", "Gains", "Pid"]
