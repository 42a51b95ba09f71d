"""How the cycle scales with the number of joints: microseconds per joint and cycle, stage by stage.

A chain of N revolute joints on ``mock_components/GenericSystem`` (position command; position and velocity states),
with the joint state broadcaster and either a forward command controller or the joint trajectory controller
(interpolating a long trajectory through all joints while it is measured). Each cycle is timed in its three stages
(hardware read, controller updates, hardware write), the way ``ControllerManager.update`` runs them, with the garbage
collector paused as ``System.spin_cycles`` pauses it (and the heap collected before each measurement).

Run: ``.venv/bin/python benchmarks/bench_scaling.py [--joints 2 6 24 96 192] [--cycles 2000]``. Figures depend on
the machine; they are printed, never asserted.
"""

from __future__ import annotations

import argparse
import gc
import logging
import time
from collections.abc import Sequence

import rrbot_workshop as rw
from rrbot_workshop.msgs import Float64MultiArray, JointTrajectory, JointTrajectoryPoint


def chain_urdf(n: int) -> str:
    """A chain of ``n`` revolute joints with a mock ``<ros2_control>`` block."""
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>'
        for i in range(n)
    )
    control = "".join(
        f'<joint name="j{i}"><command_interface name="position"/><state_interface name="position"/>'
        f'<state_interface name="velocity"/></joint>'
        for i in range(n)
    )
    return (f'<robot name="chain{n}">{links}{joints}<ros2_control name="chain" type="system"><hardware>'
            f"<plugin>mock_components/GenericSystem</plugin></hardware>{control}</ros2_control></robot>")


def controllers(n: int) -> dict:
    names = [f"j{i}" for i in range(n)]
    return {
        "controller_manager": {"ros__parameters": {
            "update_rate": 100,
            "joint_state_broadcaster": {"type": "joint_state_broadcaster/JointStateBroadcaster"},
            "forward": {"type": "forward_command_controller/ForwardCommandController"},
            "jtc": {"type": "joint_trajectory_controller/JointTrajectoryController"},
        }},
        "forward": {"ros__parameters": {"joints": names, "interface_name": "position"}},
        "jtc": {"ros__parameters": {"joints": names, "command_interfaces": ["position"],
                                    "state_interfaces": ["position", "velocity"]}},
    }


def measure(n: int, robot_controller: str, cycles: int) -> dict[str, float]:
    """Microseconds per joint-cycle: total and per stage."""
    system = rw.bringup(chain_urdf(n), controllers(n), spawn=["joint_state_broadcaster", robot_controller],
                        name=f"scaling_{n}_{robot_controller}")
    try:
        if robot_controller == "forward":
            system.publish("/forward/commands", Float64MultiArray(data=[0.1] * n))
        else:
            names = [f"j{i}" for i in range(n)]
            points = [JointTrajectoryPoint(positions=[0.5] * n, time_from_start=500.0),
                      JointTrajectoryPoint(positions=[-0.5] * n, time_from_start=1000.0)]
            system.publish("/jtc/joint_trajectory", JointTrajectory(joint_names=names, points=points))
        system.spin_cycles(20)  # warm-up: the first messages delivered, plans prepared
        cm, clock = system.controller_manager, system.clock
        period = clock.period
        stages = [0.0, 0.0, 0.0]
        gc.collect()  # the systems measured before are garbage now: none of them is walked during this measurement
        gc.disable()  # as System.spin_cycles runs its cycles (controller_manager/node_loop.py)
        for _ in range(cycles):
            now = clock.tick()
            cm.bus.deliver()
            t0 = time.perf_counter()
            cm.read(now, period)
            t1 = time.perf_counter()
            cm.update_controllers(now, period)
            t2 = time.perf_counter()
            cm.write(now, period)
            t3 = time.perf_counter()
            stages[0] += t1 - t0
            stages[1] += t2 - t1
            stages[2] += t3 - t2
        gc.enable()
        assert all(c.state == "active" for c in cm.list_controllers() if c.name != ("jtc" if robot_controller ==
                                                                                      "forward" else "forward"))
    finally:
        system.shutdown()
    scale = 1e6 / (cycles * n)
    read, update, write = (s * scale for s in stages)
    return {"total": read + update + write, "read": read, "update": update, "write": write}


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, nargs="+", default=[2, 6, 24, 96, 192])
    parser.add_argument("--cycles", type=int, default=2000)
    args = parser.parse_args(argv)
    logging.disable(logging.WARNING)
    print(f"microseconds per joint and cycle, {args.cycles} cycles, JSB + the robot controller, mock hardware")
    print(f"{'joints':>6}  {'controller':<8} {'total':>7} {'read':>7} {'update':>7} {'write':>7}  {'cycles/s':>9}")
    for n in args.joints:
        for ctrl in ("forward", "jtc"):
            f = measure(n, ctrl, args.cycles)
            rate = 1e6 / (f["total"] * n)
            print(f"{n:>6}  {ctrl:<8} {f['total']:7.2f} {f['read']:7.2f} {f['update']:7.2f} {f['write']:7.2f}  "
                  f"{rate:9.0f}")


if __name__ == "__main__":
    main()
