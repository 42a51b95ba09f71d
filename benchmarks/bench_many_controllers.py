"""Cost in the number of controllers: lint of a controllers YAML with N controllers, and loading N controllers.

Issue 23 measured both as quadratic (lint of 50 000 controllers past 120 s; loading 1 000 hung). Prints seconds and
microseconds per controller for a few sizes, so a growth that is not linear shows as a rising per-controller figure.

    .venv/bin/python benchmarks/bench_many_controllers.py [--lint 5000 20000 50000] [--load 250 500 1000]
"""

from __future__ import annotations

import argparse
import logging
import tempfile
import time
from pathlib import Path

from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.params import load_controllers_yaml
from rrbot_workshop.tools.lint import lint_controllers

FORWARD = "forward_command_controller/ForwardCommandController"


def controllers_yaml(n: int) -> str:
    """A controllers file with ``n`` forward command controllers over joint1/position (the same joint: lint and load
    do not claim; only activation would)."""
    lines = ["controller_manager:", "  ros__parameters:", "    update_rate: 100"]
    lines += [f"    fwd_{k}:\n      type: {FORWARD}" for k in range(n)]
    for k in range(n):
        lines += [f"fwd_{k}:", "  ros__parameters:", "    joints: [joint1]", "    interface_name: position"]
    return "\n".join(lines) + "\n"


def bench_lint(n: int) -> float:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "many.yaml"
        path.write_text(controllers_yaml(n))
        start = time.perf_counter()
        findings = lint_controllers(path)
        elapsed = time.perf_counter() - start
    assert not [f for f in findings if f.level == "error"], findings[:3]
    return elapsed


def _hardware() -> ResourceManager:
    rm = ResourceManager(update_rate=100)
    info = HardwareInfo(name="arm", type="system", hardware_plugin_name="mock_components/GenericSystem")
    info.joints.append(ComponentInfo(name="joint1", type="joint",
                                     command_interfaces=[InterfaceInfo("position", initial_value="0.0")],
                                     state_interfaces=[InterfaceInfo("position", initial_value="0.0")]))
    rm.load_hardware_infos([info])
    return rm


def bench_load(n: int) -> tuple[float, float]:
    """Seconds to load all ``n``, and to configure all ``n``, on one manager."""
    cm = ControllerManager(_hardware(), params=load_controllers_yaml(controllers_yaml(n)), update_rate=100)
    names = [f"fwd_{k}" for k in range(n)]
    start = time.perf_counter()
    for name in names:
        cm.load_controller(name)
    loaded = time.perf_counter() - start
    start = time.perf_counter()
    for name in names:
        cm.configure_controller(name)
    configured = time.perf_counter() - start
    return loaded, configured


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lint", type=int, nargs="*", default=[5000, 20000, 50000])
    parser.add_argument("--load", type=int, nargs="*", default=[250, 500, 1000])
    args = parser.parse_args()
    logging.disable(logging.INFO)
    print("lint of a controllers YAML with N controllers")
    print(f"{'N':>8} {'seconds':>9} {'us/controller':>14}")
    for n in args.lint:
        t = bench_lint(n)
        print(f"{n:>8} {t:>9.2f} {t / n * 1e6:>14.0f}")
    print("loading and configuring N controllers on one manager")
    print(f"{'N':>8} {'load [s]':>9} {'us/controller':>14} {'configure [s]':>14} {'us/controller':>14}")
    for n in args.load:
        loaded, configured = bench_load(n)
        print(f"{n:>8} {loaded:>9.2f} {loaded / n * 1e6:>14.0f} {configured:>14.2f} {configured / n * 1e6:>14.0f}")


if __name__ == "__main__":
    main()
