"""Control-loop rate: the full stack against a plain Python loop doing the same work.

Brings up RRBot on mock hardware (``mock_components/GenericSystem``) with ``joint_state_broadcaster``
and ``forward_position_controller`` through :func:`rrbot_workshop.bringup`, and counts control cycles
per second of wall time on the simulated clock (no sleeping). The baseline does the same work per
cycle in plain Python: read the mock (state follows command), read all 18 interfaces the broadcaster reads,
publish both broadcaster messages, forward the latest command. It runs twice: building both messages in every cycle
(the loop one writes by hand) and building them only when someone reads them, as the framework does (the same work
as the framework, to the message). Against the second, the ratio is the price of the framework's structure
(lifecycle checks, loans, chain order, rate rule, statistics, a call per controller and component).

Run: ``.venv/bin/python benchmarks/bench_loop.py [cycles]``. Not part of the test suite.
"""

from __future__ import annotations

import gc
import sys
import time

import rrbot_workshop as rw
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import DynamicJointState, Float64MultiArray, Header, InterfaceValue, JointState


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


def bench_plain(cycles: int, lazy: bool = True) -> float:
    """Cycles per second of a hand-written loop doing the framework's work, no less.

    Per cycle, as the framework does on RRBot: deliver the topic messages; read the mock (each position state follows
    its command, each GPIO output's state its command); read every one of the 18 state interfaces the broadcaster
    reads (joints, force-torque sensor, GPIO); publish ``/joint_states`` and ``/dynamic_joint_states``, built only when
    read if ``lazy`` (as the framework's lazy publishing does), else in every cycle; copy the latest forward command
    into the two position commands.
    """
    bus = TopicBus()
    names = ["flange_gpios/digital_in_1", "flange_gpios/digital_in_2", "flange_gpios/digital_out_1",
             "flange_gpios/digital_out_2", "joint1/acceleration", "joint1/effort", "joint1/position",
             "joint1/velocity", "joint2/acceleration", "joint2/effort", "joint2/position", "joint2/velocity",
             "tcp_fts_sensor/fx", "tcp_fts_sensor/fy", "tcp_fts_sensor/fz", "tcp_fts_sensor/tx", "tcp_fts_sensor/ty",
             "tcp_fts_sensor/tz"]
    states = [0.0] * len(names)
    commands = {"joint1/position": 0.0, "joint2/position": 0.0, "flange_gpios/digital_out_1": 0.0,
                "flange_gpios/digital_out_2": 0.0}
    mirror = [(names.index(n), n) for n in commands]  # state index <- command name
    forward = ["joint1/position", "joint2/position"]
    joints = ["joint1", "joint2"]
    # what a hand-written loop works out once: where each joint's fields are, which values make up each group
    first = {j: 4 + 4 * k for k, j in enumerate(joints)}
    js_index = [[first[j] + offset for j in joints] for offset in (2, 3, 1)]  # position, velocity, effort
    groups = sorted({n.rsplit("/", 1)[0] for n in names})
    group_plan = [(g, [n.rsplit("/", 1)[1] for n in names if n.startswith(g + "/")],
                   [i for i, n in enumerate(names) if n.startswith(g + "/")]) for g in groups]
    latest: list[Float64MultiArray | None] = [None]
    bus.create_subscription(Float64MultiArray, "/commands", lambda m: latest.__setitem__(0, m))
    bus.publish("/commands", Float64MultiArray(data=[0.7, 0.7]))
    joint_pub = bus.create_publisher(JointState, "/joint_states")
    dynamic_pub = bus.create_publisher(DynamicJointState, "/dynamic_joint_states")
    period = 0.01

    def cycle(t: float) -> None:
        bus.deliver()
        for index, name in mirror:  # read: the mock mirrors commands
            states[index] = commands[name]
        values = list(states)  # the broadcaster reads every interface

        def joint_state() -> JointState:
            position, velocity, effort = ([values[i] for i in index] for index in js_index)
            return JointState(header=Header(stamp=t), name=list(joints), position=position, velocity=velocity,
                              effort=effort)

        def dynamic_state() -> DynamicJointState:
            out = DynamicJointState(header=Header(stamp=t), joint_names=list(groups))
            for _, itfs, indices in group_plan:
                out.interface_values.append(InterfaceValue(list(itfs), [values[i] for i in indices]))
            return out

        if lazy:
            joint_pub.publish_lazy(joint_state)
            dynamic_pub.publish_lazy(dynamic_state)
        else:
            joint_pub.publish(joint_state())
            dynamic_pub.publish(dynamic_state())
        msg = latest[0]  # forward
        if msg is not None and len(msg.data) == len(forward):
            for name, v in zip(forward, msg.data, strict=True):
                commands[name] = v
        # write: nothing to send for the mock

    for k in range(10):
        cycle(k * period)
    gc.disable()  # as System.spin_cycles runs the framework's cycles (node_loop.run_cycles): the same conditions
    try:
        start = time.perf_counter()
        for k in range(cycles):
            cycle((k + 1) * period)
        elapsed = time.perf_counter() - start
    finally:
        gc.enable()
    assert bus.latest("/joint_states").position == [0.7, 0.7]
    return cycles / elapsed


def main(argv: list[str]) -> None:
    cycles = int(argv[1]) if len(argv) > 1 else 20000
    framework = bench_framework(cycles)
    plain = bench_plain(cycles)
    eager = bench_plain(cycles, lazy=False)
    print(f"cycles: {cycles}")
    print(f"rrbot_workshop (bringup, JSB + forward controller, mock hardware): {framework:10.0f} cycles/s")
    print(f"plain Python loop, the same work (messages built when read):       {plain:10.0f} cycles/s")
    print(f"plain Python loop, both messages built in every cycle:             {eager:10.0f} cycles/s")
    print(f"framework / same-work plain loop: {plain / framework:.2f}x the time per cycle; "
          f"/ eager plain loop: {eager / framework:.2f}x; real-time margin at 100 Hz: {framework / 100:.0f}x")


if __name__ == "__main__":
    main(sys.argv)
