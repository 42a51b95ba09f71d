"""Control-loop rate: the full stack against a plain Python loop doing the same work.

Brings up RRBot on mock hardware (``mock_components/GenericSystem``) with ``joint_state_broadcaster``
and ``forward_position_controller`` through :func:`rrbot_workshop.bringup`, and counts control cycles
per second of wall time on the simulated clock (no sleeping). The baseline does the same work per
cycle in a few lines of plain Python: read the mock (state follows command), broadcast a JointState,
forward the latest command, write. The ratio is the price of the framework's structure (lifecycle
checks, loans, chain order, rate rule, topic bus).

Run: ``.venv/bin/python benchmarks/bench_loop.py [cycles]``. Not part of the test suite.
"""

from __future__ import annotations

import sys
import time

import rrbot_workshop as rw
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import Float64MultiArray, Header, JointState


def bench_framework(cycles: int) -> float:
    """Cycles per second of the full stack."""
    with rw.bringup(
        "rrbot", "rrbot_controllers.yaml", spawn=["joint_state_broadcaster", "forward_position_controller"]
    ) as system:
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.7, 0.7]))
        system.spin_cycles(10)  # warm-up
        start = time.perf_counter()
        system.spin_cycles(cycles)
        elapsed = time.perf_counter() - start
        assert system.latest("/joint_states").position == [0.7, 0.7]
    return cycles / elapsed


def bench_plain(cycles: int) -> float:
    """Cycles per second of a hand-written loop doing the same work."""
    bus = TopicBus()
    joints = ["joint1", "joint2"]
    command = {j: 0.0 for j in joints}
    state = {j: {"position": 0.0, "velocity": 0.0, "effort": 0.0} for j in joints}
    latest: list[Float64MultiArray | None] = [None]
    bus.create_subscription(Float64MultiArray, "/commands", lambda m: latest.__setitem__(0, m))
    bus.publish("/commands", Float64MultiArray(data=[0.7, 0.7]))
    period = 0.01
    t = 0.0

    def cycle(t: float) -> None:
        bus.deliver()
        for j in joints:  # read: the mock mirrors commands
            state[j]["position"] = command[j]
        bus.publish("/joint_states", JointState(  # broadcast
            header=Header(stamp=t), name=list(joints),
            position=[state[j]["position"] for j in joints],
            velocity=[state[j]["velocity"] for j in joints],
            effort=[state[j]["effort"] for j in joints],
        ))
        msg = latest[0]  # forward
        if msg is not None and len(msg.data) == len(joints):
            for j, v in zip(joints, msg.data, strict=True):
                command[j] = v
        # write: nothing to send for the mock

    for k in range(10):
        cycle(k * period)
    start = time.perf_counter()
    for k in range(cycles):
        t = (k + 1) * period
        cycle(t)
    elapsed = time.perf_counter() - start
    assert bus.latest("/joint_states").position == [0.7, 0.7]
    return cycles / elapsed


def main(argv: list[str]) -> None:
    cycles = int(argv[1]) if len(argv) > 1 else 20000
    framework = bench_framework(cycles)
    plain = bench_plain(cycles)
    print(f"cycles: {cycles}")
    print(f"rrbot_workshop (bringup, JSB + forward controller, mock hardware): {framework:10.0f} cycles/s")
    print(f"plain Python loop doing the same work:                             {plain:10.0f} cycles/s")
    print(f"framework overhead: {plain / framework:.1f}x; real-time margin at 100 Hz: {framework / 100:.0f}x")


if __name__ == "__main__":
    main(sys.argv)
