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

PREDICTIONS: dict[str, dict[str, Any]] = {
    # the hardware's read() returns ERROR once
    "read_error": {
        "controllers": {"joint_state_broadcaster": "inactive", "forward_position_controller": "inactive",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "unconfigured"},
        "joints": [0.2, 0.2],
    },
    # the forward controller's update() raises once
    "update_exception": {
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "inactive",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
        "joints": [0.2, 0.2],
    },
    # one number for two joints on ~/commands
    "wrong_size_command": {
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "inactive",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
        "joints": [0.2, 0.2],
    },
    # [0.5, 10.0] commanded; joint2's upper limit is 4.19 rad; enforce_command_limits: false
    "beyond_limits": {
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
        "joints": [0.5, 10.0],
    },
    # the same with enforce_command_limits: true
    "beyond_limits_enforced": {
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
        "joints": [0.5, 4.19],
    },
    # [nan, 0.5] commanded
    "nan_command": {
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
        "joints": [0.2, 0.2],
    },
    # the hardware set inactive by hand, then [0.6, 0.6] commanded
    "hardware_inactive": {
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "inactive"},
        "joints": [0.6, 0.6],
    },
    # a strict switch activating the trajectory controller while the forward controller runs
    "double_claim": {
        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                        "joint_trajectory_controller": "inactive"},
        "hardware": {"rrbot": "active"},
        "joints": [0.2, 0.2],
    },
}
