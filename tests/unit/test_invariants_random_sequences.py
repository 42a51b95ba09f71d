"""Seeded random sequences of load / configure / switch / hardware state changes / spin / unload on RRBot.

Every controller the chained RRBot configuration has (broadcaster, two chainable PIDs, trajectory controller, forward
controller) goes through random requests, valid or not, and after every step these hold:

* no command interface is claimed twice, and only active controllers hold claims;
* a controller activated by a switch runs on active hardware only (hardware set inactive by hand later leaves its
  controllers active, as Jazzy does: ros2_control issue #3444, so this is checked right after the switch);
* a chainable controller is in chained mode exactly when an active controller claims its reference interfaces;
* a rejected request changes nothing (same states, claims and chained modes before and after);
* only the library's own exceptions escape.

``SEQUENCES * STEPS`` operations run in CI (10,000); ``benchmarks/fuzz_switches.py`` runs as many more as asked.
"""

from __future__ import annotations

import logging
import random
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.exceptions import RRBotWorkshopError

SEQUENCES, STEPS = 20, 500
CONTROLLERS = ["joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2",
               "joint_trajectory_controller", "forward_position_controller"]
HARDWARE = "rrbot"


def _start() -> System:
    return bringup("rrbot", "rrbot_chained_controllers.yaml",
                   xacro_args={"use_mock_hardware": True, "calculate_dynamics": True}, name="invariants")


def snapshot(system: System) -> dict[str, Any]:
    """Everything a rejected request must leave as it was."""
    cm = system.controller_manager
    return {
        "controllers": {c.name: (c.state, c.is_chained, tuple(sorted(c.claimed_interfaces))) for c in cm.list_controllers()},
        "hardware": {c.name: getattr(c.state, "label", str(c.state)) for c in cm.list_hardware_components()},
    }


def check_invariants(system: System, activated: list[str]) -> None:
    cm = system.controller_manager
    entries = cm.list_controllers()
    claimed: dict[str, str] = {}
    for entry in entries:
        for itf in entry.claimed_interfaces:
            assert itf not in claimed, f"'{itf}' claimed by '{claimed[itf]}' and '{entry.name}'"
            claimed[itf] = entry.name
        if entry.claimed_interfaces:
            assert entry.state == "active", f"'{entry.name}' is {entry.state} but holds {entry.claimed_interfaces}"
    hardware = {c.name: getattr(c.state, "label", str(c.state)) for c in cm.list_hardware_components()}
    for name in activated:
        entry = next(e for e in entries if e.name == name)
        if entry.state == "active" and entry.claimed_interfaces and any(
            not itf.startswith("pid_controller") for itf in entry.claimed_interfaces
        ):
            assert hardware[HARDWARE] == "active", f"'{name}' was activated on '{HARDWARE}' in state {hardware[HARDWARE]}"
    for entry in entries:
        refs = {r if r.startswith(f"{entry.name}/") else f"{entry.name}/{r}" for r in entry.reference_interfaces}
        if not refs:
            continue
        used = any(itf in refs for itf in claimed)
        assert entry.is_chained == used, (
            f"'{entry.name}' chained={entry.is_chained} while its references are {'claimed' if used else 'free'}"
        )


def _step(system: System, rng: random.Random) -> None:
    cm = system.controller_manager
    op = rng.choice(["load", "configure", "switch", "switch", "switch", "restart", "restart", "chain_up", "hardware",
                     "spin", "spin", "unload", "cleanup"])
    name = rng.choice(CONTROLLERS + ["no_such_controller"])
    before = snapshot(system)
    activated: list[str] = []
    try:
        if op == "load":
            cm.load_controller(name)
        elif op == "configure":
            cm.configure_controller(name)
        elif op == "switch":
            activate = rng.sample(CONTROLLERS, rng.randint(0, 3))
            deactivate = rng.sample(CONTROLLERS, rng.randint(0, 2))
            if rng.random() < 0.1:
                activate.append("no_such_controller")
            strictness = rng.choice(["strict", "best_effort"])
            was_active = {c.name for c in cm.list_controllers() if c.state == "active"}
            cm.switch_controllers(activate=activate, deactivate=deactivate, strictness=strictness)
            activated = [c.name for c in cm.list_controllers() if c.state == "active" and c.name not in was_active]
        elif op == "chain_up":  # the valid path to the interesting states: the whole chain, as the spawner does it
            if snapshot(system)["hardware"][HARDWARE] != "active":
                cm.set_hardware_component_state(HARDWARE, "active")
            states = {c.name: c.state for c in cm.list_controllers()}
            chain = ["pid_controller_joint1", "pid_controller_joint2", "joint_trajectory_controller"]
            to_spawn = [n for n in chain if states.get(n) != "active"]
            if to_spawn:
                try:  # loading and configuring are steps of their own: a refused activation does not undo them
                    system.spawn(to_spawn, activate_as_group=True)
                except RRBotWorkshopError:
                    pass
                activated = [c.name for c in cm.list_controllers() if c.state == "active" and states.get(c.name) != "active"]
        elif op == "restart":  # deactivate and activate the same active controllers in one switch
            active = [c.name for c in cm.list_controllers() if c.state == "active"]
            chosen = rng.sample(active, min(len(active), rng.randint(1, 2)))
            cm.switch_controllers(activate=chosen, deactivate=chosen, strictness=rng.choice(["strict", "best_effort"]))
        elif op == "hardware":
            cm.set_hardware_component_state(HARDWARE, rng.choice(["unconfigured", "inactive", "active", "active", "active"]))
        elif op == "spin":
            system.spin_cycles(rng.randint(1, 3))
        elif op == "unload":
            cm.unload_controller(name)
        elif op == "cleanup":
            cm.cleanup_controller(name)
    except rw.SwitchError as exc:
        if not exc.partial:
            assert snapshot(system) == before, f"a rejected switch changed the system: {exc}"
    except RRBotWorkshopError:
        if op in ("load", "configure", "unload", "cleanup"):
            after = snapshot(system)
            changed = {n for n in set(before["controllers"]) | set(after["controllers"])
                       if before["controllers"].get(n) != after["controllers"].get(n)}
            assert changed <= {name}, f"a rejected {op} of '{name}' changed {changed}"
    check_invariants(system, activated)


@pytest.mark.parametrize("seed", range(SEQUENCES))
def test_random_sequence_keeps_the_invariants(seed: int) -> None:
    logging.disable(logging.CRITICAL)  # the sequences provoke thousands of logged refusals on purpose
    try:
        rng = random.Random(seed)
        system = _start()
        try:
            for _ in range(STEPS):
                _step(system, rng)
        finally:
            system.shutdown()
    finally:
        logging.disable(logging.NOTSET)
