"""Control cycles per second of mock RRBot with the trajectory controller, alone and chained to PIDs.

Run: ``.venv/bin/python benchmarks/bench_controllers.py [--seconds 20]``. Each case brings RRBot up on
mock hardware with ``calculate_dynamics``, lets the task-2 goal publisher send its goals, and times
``spin`` over the given simulated duration. The figures are printed; nothing is asserted.
"""

from __future__ import annotations

import argparse
import time

import rrbot_workshop as rw
from rrbot_workshop.controllers.goal_publishers import JointTrajectoryGoalPublisher

CASES = {
    "JSB + JTC": ("rrbot_controllers.yaml", ["joint_state_broadcaster", "joint_trajectory_controller"]),
    "JSB + JTC -> 2 PIDs": ("rrbot_chained_controllers.yaml",
                            ["joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2",
                             "joint_trajectory_controller"]),
}


def run(controllers: str, spawn: list[str], seconds: float) -> float:
    """Cycles per second of wall time over ``seconds`` of simulated time."""
    system = rw.bringup("rrbot", controllers, xacro_args={"calculate_dynamics": True}, spawn=spawn)
    try:
        system.controller_manager.add_cycle_hook(JointTrajectoryGoalPublisher(system.bus))
        system.spin(0.5)  # warm-up
        cycles = round(seconds / system.period)
        start = time.perf_counter()
        system.spin_cycles(cycles)
        return cycles / (time.perf_counter() - start)
    finally:
        system.shutdown()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated time per case in [s]")
    args = parser.parse_args()
    for name, (controllers, spawn) in CASES.items():
        rate = run(controllers, spawn, args.seconds)
        print(f"{name:24s} {rate:10.0f} cycles/s  ({rate / 100:.0f}x real time at 100 Hz)")


if __name__ == "__main__":
    main()
