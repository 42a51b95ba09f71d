"""How fast RRBot runs in MuJoCo: simulated seconds per wall-clock second.

Four figures per control rate, each the best of a few repeats:

* ``physics``: ``mj_step`` alone, the 1 ms physics steps of the same model (the ceiling);
* ``hardware``: ``MujocoSystem.read``/``write`` with no controller (the component's own overhead);
* ``JSB + JTC``: ``System.spin`` (controller manager loop) with the joint state broadcaster and the trajectory controller on the
  position interfaces, moving through the four workshop goals;
* ``JSB + JTC -> PID``: the same goals through the chain JTC -> two PID controllers -> effort interfaces.

Run: ``.venv/bin/python benchmarks/bench_mujoco.py [--seconds 8] [--rates 1000 100]``. Figures depend on the
machine; they are printed, never asserted.
"""

from __future__ import annotations

import argparse
import logging
import time
from collections.abc import Callable, Sequence

import mujoco
import yaml

import rrbot_workshop as rw
from rrbot_workshop import msgs
from rrbot_workshop.hardware.mujoco_system import MujocoSystem
from rrbot_workshop.middleware.lifecycle import State

_ROOT = rw.description.descriptions_root() / "rrbot"
_GOALS = ([0.785, 0.785], [0.0, 0.0], [-0.785, -0.785], [0.0, 0.0])


def _urdf() -> str:
    return rw.description.process_xacro(_ROOT / "urdf/rrbot.urdf.xacro", sim_mujoco="true")


def _infos(urdf: str) -> list[rw.description.HardwareInfo]:
    return rw.description.parse_ros2_control(urdf)


def _best_rate(run: Callable[[float], None], seconds: float, repeats: int) -> float:
    """Simulated seconds per wall second of ``run(seconds)``, best of ``repeats``."""
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        run(seconds)
        best = min(best, time.perf_counter() - start)
    return seconds / best


def bench_physics(rate: int, seconds: float, repeats: int) -> float:
    """Bare ``mj_step`` on the RRBot model."""
    system = MujocoSystem()
    system.on_init(_infos(_urdf())[0])
    model, data = system.get_model(), system.get_data()
    steps_per_cycle = round(1.0 / rate / model.opt.timestep)

    def run(sim_seconds: float) -> None:
        for _ in range(round(sim_seconds * rate)):
            mujoco.mj_step(model, data, nstep=steps_per_cycle)

    return _best_rate(run, seconds, repeats)


def bench_hardware(rate: int, seconds: float, repeats: int) -> float:
    """``read`` + ``write`` of the component, joints in position mode, no controller."""
    system = MujocoSystem()
    system.on_init(_infos(_urdf())[0])
    system._register_handles(system.export_state_interfaces(), system.export_command_interfaces())
    system.on_configure(State.UNCONFIGURED)
    system.on_activate(State.INACTIVE)
    system.perform_command_mode_switch(["joint1/position", "joint2/position"], [])
    period = 1.0 / rate

    def run(sim_seconds: float) -> None:
        for _ in range(round(sim_seconds * rate)):
            system.read(0.0, period)
            system.write(0.0, period)

    return _best_rate(run, seconds, repeats)


def bench_controllers(rate: int, seconds: float, repeats: int, yaml_name: str, controllers: Sequence[str]) -> float:
    """``System.spin`` with ``controllers`` active, sending the four goals in turn."""
    config = yaml.safe_load((_ROOT / "config" / yaml_name).read_text())
    config["controller_manager"]["ros__parameters"]["update_rate"] = rate
    system = rw.bringup(
        description=_ROOT / "urdf/rrbot.urdf.xacro", controllers=config, xacro_args={"sim_mujoco": "true"},
        spawn=list(controllers),
    )
    segment = seconds / len(_GOALS)

    def run(sim_seconds: float) -> None:
        for goal in _GOALS:
            point = msgs.JointTrajectoryPoint(positions=list(goal), time_from_start=0.75 * segment)
            system.publish(
                "/joint_trajectory_controller/joint_trajectory",
                msgs.JointTrajectory(joint_names=["joint1", "joint2"], points=[point]),
            )
            system.spin(seconds=sim_seconds / len(_GOALS))

    try:
        return _best_rate(run, seconds, repeats)
    finally:
        system.shutdown()


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=8.0, help="simulated seconds per run [s]")
    parser.add_argument("--repeats", type=int, default=3, help="runs per figure (the best is kept)")
    parser.add_argument("--rates", type=int, nargs="+", default=[1000, 100], help="control rates [Hz]")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    position = ("joint_state_broadcaster", "joint_trajectory_controller")
    chain = ("joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2", "joint_trajectory_controller")
    print(f"RRBot in MuJoCo, 1 ms physics step, {args.seconds:g} simulated s per run, best of {args.repeats}")
    print(f"{'control rate':>12}  {'physics':>9}  {'hardware':>9}  {'JSB + JTC':>9}  {'JTC -> PID':>10}   (simulated s / wall s)")
    for rate in args.rates:
        figures = (
            bench_physics(rate, args.seconds, args.repeats),
            bench_hardware(rate, args.seconds, args.repeats),
            bench_controllers(rate, args.seconds, args.repeats, "rrbot_sim_position_controllers.yaml", position),
            bench_controllers(rate, args.seconds, args.repeats, "rrbot_sim_effort_controllers.yaml", chain),
        )
        print(f"{rate:>9} Hz  {figures[0]:>9.1f}  {figures[1]:>9.1f}  {figures[2]:>9.1f}  {figures[3]:>10.1f}")


if __name__ == "__main__":
    main()
