"""The fault lab of task 14: break a running RRBot on purpose and record what ros2_control does.

Each fault starts a fresh mock RRBot (``descriptions/rrbot``, broadcaster and forward position controller active,
trajectory controller loaded and inactive), commands ``[0.2, 0.2]``, injects the fault and lets the system run. The
outcome is what a learner predicts in task 14: the state of every controller and hardware component afterwards and
the joints' positions. A timeline of the states, cycle by cycle, goes with it for the plots.

The faults (:data:`FAULTS`):

``read_error``
    The hardware's ``read`` returns ERROR once.
``update_exception``
    The forward controller's ``update`` raises an exception once.
``wrong_size_command``
    One number is sent to the forward controller, which commands two joints.
``beyond_limits``
    ``[0.5, 10.0]`` is commanded; joint2's URDF limit is 240 degrees (4.19 rad); ``enforce_command_limits`` is false
    (Jazzy's default).
``beyond_limits_enforced``
    The same with ``enforce_command_limits: true``.
``nan_command``
    ``[nan, 0.5]`` is commanded.
``hardware_inactive``
    The hardware component is set inactive by hand, then ``[0.6, 0.6]`` is commanded.
``double_claim``
    A strict switch asks to activate the trajectory controller while the forward controller runs.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import yaml

from rrbot_workshop.exceptions import RRBotWorkshopError

__all__ = ["FAULTS", "Outcome", "run_fault", "compare", "plot_timeline"]

FAULTS = (
    "read_error", "update_exception", "wrong_size_command", "beyond_limits", "beyond_limits_enforced",
    "nan_command", "hardware_inactive", "double_claim",
)
#: Seconds of simulated time the system runs after the fault.
AFTER = 2.0
#: Positions closer than this [rad] count as equal when predictions are compared.
POSITION_TOLERANCE = 1e-3


@dataclass
class Outcome:
    """What ros2_control did after a fault.

    Attributes:
        controllers: Controller name -> lifecycle state label, after the fault.
        hardware: Hardware component name -> lifecycle state label, after the fault.
        joints: Joint positions [rad] reported on ``/joint_states`` at the end (the last message published).
        error: The message of an exception the request raised (``SwitchError`` ...), or ``""``.
        timeline: ``(time [s], {name: state})`` once per cycle, controllers and hardware (prefixed ``hw:``).
        entries: ``list_controllers()`` and ``list_hardware_components()`` at the end (for the lifecycle diagram).
    """

    controllers: dict[str, str]
    hardware: dict[str, str]
    joints: list[float]
    error: str = ""
    timeline: list[tuple[float, dict[str, str]]] = field(default_factory=list)
    entries: tuple[list[Any], list[Any]] = field(default_factory=lambda: ([], []))

    def prediction_view(self) -> dict[str, Any]:
        """The outcome in the shape a prediction has (what task 14 compares)."""
        return {"controllers": dict(self.controllers), "hardware": dict(self.hardware),
                "joints": [round(p, 4) for p in self.joints]}


def _states(system: Any) -> tuple[dict[str, str], dict[str, str]]:
    cm = system.controller_manager
    controllers = {c.name: c.state for c in cm.list_controllers()}
    hardware = {c.name: getattr(c.state, "label", str(c.state)) for c in cm.list_hardware_components()}
    return controllers, hardware


def _start(enforce: bool = False) -> Any:
    from rrbot_workshop.bringup import bringup
    from rrbot_workshop.description.xacro import descriptions_root

    config = yaml.safe_load((descriptions_root() / "rrbot" / "config" / "rrbot_controllers.yaml").read_text())
    config["controller_manager"]["ros__parameters"]["enforce_command_limits"] = enforce
    return bringup("rrbot", config, xacro_args={"use_mock_hardware": True},
                   spawn=["joint_state_broadcaster", "forward_position_controller"],
                   inactive=["joint_trajectory_controller"], name="fault_lab")


def _once(replacement: Callable[..., Any], original: Callable[..., Any]) -> Callable[..., Any]:
    calls = {"n": 0}

    def wrapper(*args: Any) -> Any:
        calls["n"] += 1
        return replacement(*args) if calls["n"] == 1 else original(*args)

    return wrapper


def run_fault(name: str) -> Outcome:
    """Run fault ``name`` on a fresh RRBot and return what happened.

    Raises:
        ValueError: If ``name`` is not one of :data:`FAULTS`.
    """
    from rrbot_workshop.middleware.lifecycle import ReturnType
    from rrbot_workshop.msgs import Float64MultiArray

    if name not in FAULTS:
        raise ValueError(f"unknown fault {name!r}; the faults are {list(FAULTS)}")
    system = _start(enforce=name == "beyond_limits_enforced")
    timeline: list[tuple[float, dict[str, str]]] = []

    def record(time: float, period: float) -> None:
        controllers, hardware = _states(system)
        timeline.append((time, {**controllers, **{f"hw:{k}": v for k, v in hardware.items()}}))

    cm = system.controller_manager
    cm.add_cycle_hook(record)
    error = ""
    try:
        command = "/forward_position_controller/commands"
        system.publish(command, Float64MultiArray(data=[0.2, 0.2]))
        system.spin(0.5)
        if name == "read_error":
            component = cm.resource_manager.get_component("rrbot")
            component.impl.read = _once(lambda t, p: ReturnType.ERROR, component.impl.read)  # type: ignore[method-assign]
        elif name == "update_exception":
            controller = cm.get_controller("forward_position_controller")

            def boom(time: float, period: float) -> ReturnType:
                raise RuntimeError("a bug in update()")

            controller.update = _once(boom, controller.update)  # type: ignore[method-assign]
        elif name == "wrong_size_command":
            system.publish(command, Float64MultiArray(data=[0.7]))
        elif name in ("beyond_limits", "beyond_limits_enforced"):
            system.publish(command, Float64MultiArray(data=[0.5, 10.0]))
        elif name == "nan_command":
            system.publish(command, Float64MultiArray(data=[math.nan, 0.5]))
        elif name == "hardware_inactive":
            cm.set_hardware_component_state("rrbot", "inactive")
            system.publish(command, Float64MultiArray(data=[0.6, 0.6]))
        elif name == "double_claim":
            try:
                cm.switch_controllers(activate=["joint_trajectory_controller"], strictness="strict")
            except RRBotWorkshopError as exc:
                error = str(exc).splitlines()[0]
        system.spin(AFTER)
        controllers, hardware = _states(system)
        msg = system.latest("/joint_states")
        joints = [float(p) for p in msg.position] if msg is not None else []
        entries = (cm.list_controllers(), cm.list_hardware_components())
    finally:
        system.shutdown()
    return Outcome(controllers, hardware, joints, error, timeline, entries)


def compare(prediction: Any, outcome: Outcome, reveal: bool = True) -> list[str]:
    """Where ``prediction`` (``{"controllers": {...}, "hardware": {...}, "joints": [...]}``) differs from ``outcome``.

    Args:
        prediction: The learner's prediction for one fault.
        outcome: What happened.
        reveal: Say what really happened (after the learner ran the fault); False names only what is wrong (the
            self-check must not give the answers away).

    Returns:
        One line per difference; empty when the prediction is right. A missing or ``None`` entry is a difference.
    """
    if not isinstance(prediction, dict):
        return [f"a prediction is a dict with 'controllers', 'hardware' and 'joints', got {type(prediction).__name__}"]
    problems = []
    for key in ("controllers", "hardware"):
        mine = prediction.get(key)
        if not isinstance(mine, dict):
            problems.append(f"'{key}' is not predicted (a dict of name -> state)")
            continue
        for entry, state in getattr(outcome, key).items():
            if mine.get(entry) != state:
                what = f"{key[:-1] if key == 'controllers' else 'hardware'} '{entry}'"
                problems.append(f"{what}: predicted {mine.get(entry)!r}" + (f", but it is {state!r}" if reveal else ""))
    joints = prediction.get("joints")
    if not isinstance(joints, list | tuple) or len(joints) != len(outcome.joints):
        problems.append(f"'joints' must list {len(outcome.joints)} positions, got {joints!r}")
    else:
        for i, (mine, real) in enumerate(zip(joints, outcome.joints, strict=True)):
            if not isinstance(mine, int | float) or abs(float(mine) - real) > POSITION_TOLERANCE:
                problems.append(f"joint{i + 1}: predicted {mine!r} rad" + (f", it ends at {real:.4f} rad" if reveal else ""))
    return problems


_LEVELS = {"finalized": 0, "unconfigured": 1, "inactive": 2, "active": 3}


def plot_timeline(outcome: Outcome, ax: Any, title: str = "") -> None:
    """Draw each controller's and component's lifecycle state over the run on a matplotlib ``ax``.

    One line per name, stepped at the cycles where the state changes; the y axis reads finalized, unconfigured,
    inactive, active. Names are offset a little so lines that share a state stay visible.
    """
    if not outcome.timeline:
        return
    names = list(outcome.timeline[0][1])
    t0 = outcome.timeline[0][0]
    for i, name in enumerate(names):
        offset = (i - (len(names) - 1) / 2) * 0.06
        times = [t - t0 for t, _ in outcome.timeline]
        levels = [_LEVELS.get(states.get(name, ""), math.nan) + offset for _, states in outcome.timeline]
        ax.step(times, levels, where="post", label=name.replace("hw:", "[hw] "))
    ax.set_yticks(list(_LEVELS.values()), list(_LEVELS))
    ax.set_ylim(-0.5, 3.5)
    ax.set_xlabel("time [s] (the fault at 0.5 s)")
    if title:
        ax.set_title(title, fontsize=10)
