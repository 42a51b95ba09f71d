"""Task 14: what ros2_control does when things go wrong, predicted before running it.

Every fault starts from the same mock RRBot: broadcaster and forward position controller active, trajectory
controller inactive, the joints commanded to [0.2, 0.2]. Then the fault, then 2 s of simulated time.
Predict, for each fault, the state of every controller and of the hardware component afterwards, and the joint
positions the last /joint_states message reports, in rad, to 2 decimals (a position within 0.005 rad of what happens
counts as right). Each fault's states earn a point, and its positions another.
"""

from __future__ import annotations

from typing import Any

__all__ = ["PREDICTIONS"]

# TODO(task 14): replace every None: a state ("unconfigured", "inactive", "active", "finalized") or a position in
#   rad, to 2 decimals. Reason from what you know of the controller manager and the lifecycle and write your
#   prediction; notebook 14 runs a fault and explains it only once you have predicted it, and keeps your prediction
#   as it was then: a prediction changed after its outcome was shown earns nothing. The self-check only says which
#   parts of your predictions are wrong, never the answer, and gives no hint for a part not predicted yet.
PREDICTIONS: dict[str, dict[str, Any]] = {
    # the hardware's read() returns ERROR once
    "read_error": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
    # the forward controller's update() raises once
    "update_exception": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
    # one number for two joints on ~/commands
    "wrong_size_command": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
    # [0.5, 10.0] commanded; joint2's upper limit is 4.19 rad; enforce_command_limits: false
    "beyond_limits": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
    # the same with enforce_command_limits: true
    "beyond_limits_enforced": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
    # [nan, 0.5] commanded
    "nan_command": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
    # the hardware set inactive by hand, then [0.6, 0.6] commanded
    "hardware_inactive": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
    # a strict switch activating the trajectory controller while the forward controller runs
    "double_claim": {
        "controllers": {"joint_state_broadcaster": None, "forward_position_controller": None,
                        "joint_trajectory_controller": None},
        "hardware": {"rrbot": None},
        "joints": [None, None],
    },
}
