"""The fault lab of task 14: break a running RRBot on purpose and record what ros2_control does.

Each fault starts a fresh mock RRBot (``descriptions/rrbot``, broadcaster and forward position controller active,
trajectory controller loaded and inactive), commands ``[0.2, 0.2]``, injects the fault and lets the system run. The
outcome is what a learner predicts in task 14: the state of every controller and hardware component afterwards and
the joints' positions (to 2 decimals). A timeline goes with it for the plots: the lifecycle states and the joints'
commanded and measured positions, cycle by cycle.

:func:`reveal` is what notebook 14 calls: it shows a fault's outcome, its timeline and why it happens only once the
learner has written a complete prediction for it, and grades that prediction first. So the notebook stores no outcome
before the learner has predicted; and the prediction is sealed before the outcome is shown, so copying the outcome
into ``predictions.py`` afterwards earns nothing.

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

__all__ = ["FAULTS", "EXPLANATIONS", "Outcome", "run_fault", "compare", "missing", "plot_timeline", "reveal"]

FAULTS = (
    "read_error", "update_exception", "wrong_size_command", "beyond_limits", "beyond_limits_enforced",
    "nan_command", "hardware_inactive", "double_claim",
)
#: Seconds of simulated time the system runs after the fault.
AFTER = 2.0
#: Positions are predicted to 2 decimals: closer than this [rad] counts as equal (4.19 for 4.1888 is right).
POSITION_TOLERANCE = 0.005
#: The joints of the fault lab's RRBot, in the order of a prediction's ``joints``.
JOINTS = ("joint1", "joint2")

#: Why each fault ends as it does, shown by :func:`reveal` once the learner has predicted it.
EXPLANATIONS = {
    "read_error": (
        "The component's on_error runs. Its default (rclcpp_lifecycle's) returns SUCCESS, so the component ends "
        "unconfigured, ready to be configured and activated again; an on_error returning FAILURE or ERROR would "
        "finalize it (Humble's documentation says the same). Its interfaces are no longer available, so every "
        "controller that used them is deactivated, the broadcaster too: there is nothing left to read. The trajectory "
        "controller was inactive and stays so. /joint_states is no longer published: its last message shows where the "
        "joints were."),
    "update_exception": (
        "The controller manager catches the exception, treats it as update() returning ERROR and deactivates that "
        "controller (and would activate its fallback_controllers, if it had any). The broadcaster and the hardware go "
        "on. Mock hardware keeps the last command it was written, so the joints stay at [0.2, 0.2]."),
    "wrong_size_command": (
        "The forward controller's update() sees a message whose size is not its number of joints and returns ERROR; the "
        "controller manager deactivates it, as for an exception. Nothing was written, so the joints stay at their last "
        "command."),
    "beyond_limits": (
        "With enforce_command_limits at Jazzy's default, false, commands are written as they are: the mock joint goes "
        "to 10 rad, far past its URDF limit, within one cycle. A real driver (or the real joint) would refuse or break. "
        "Limits in the URDF describe the robot; they guard nothing until something applies them."),
    "beyond_limits_enforced": (
        "With enforce_command_limits: true, the controller manager limits every position command before write(): each "
        "cycle it moves at most max_velocity x period (pi/100 rad at 100 Hz) towards the target, and never past the "
        "URDF range. joint2 ramps up and stops at its upper limit, 240 degrees (4.19 rad), well within the 2 s."),
    "nan_command": (
        "The forward controller drops a message holding a non-finite number and keeps its last command; the controller "
        "stays active. ros2_controllers does this since its July 2025 releases (4.29.0 for Jazzy); before, it wrote the "
        "finite numbers and left NaN to the hardware."),
    "hardware_inactive": (
        "The controllers stay active: Jazzy does not deactivate them when a component is set inactive by hand "
        "(ros2_control issue #3444). An inactive component is still read but no longer written. Mock hardware copies "
        "commands into states when it reads, so here the joints still follow [0.6, 0.6]; on a real driver they would "
        "not move while the controller believes it commands them. Deactivate the controllers before taking hardware "
        "out."),
    "double_claim": (
        "The forward controller holds the joints' position command interfaces; a strict switch that would claim them "
        "twice is rejected as a whole: nothing changes state, and the error names the interfaces and the controllers "
        "involved."),
}


@dataclass
class Outcome:
    """What ros2_control did after a fault.

    Attributes:
        controllers: Controller name -> lifecycle state label, after the fault.
        hardware: Hardware component name -> lifecycle state label, after the fault.
        joints: Joint positions [rad] reported on ``/joint_states`` at the end (the last message published).
        error: The message of an exception the request raised (``SwitchError`` ...), or ``""``.
        timeline: ``(time [s], {name: state})`` once per cycle, controllers and hardware (prefixed ``hw:``).
        positions: ``(time [s], measured [rad], commanded [rad])`` once per cycle, one value per joint of
            :data:`JOINTS` (NaN where an interface is unavailable).
        sent: The command published on ``~/commands`` at the fault, if the fault is one.
        entries: ``list_controllers()`` and ``list_hardware_components()`` at the end (for the lifecycle diagram).
    """

    controllers: dict[str, str]
    hardware: dict[str, str]
    joints: list[float]
    error: str = ""
    timeline: list[tuple[float, dict[str, str]]] = field(default_factory=list)
    positions: list[tuple[float, list[float], list[float]]] = field(default_factory=list)
    entries: tuple[list[Any], list[Any]] = field(default_factory=lambda: ([], []))
    sent: list[float] | None = None

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

    positions: list[tuple[float, list[float], list[float]]] = []
    rm = system.controller_manager.resource_manager

    def value(name: str, kind: str) -> float:
        try:
            found = rm.get_interface_value(name, kind)
            return float(found) if found is not None else math.nan
        except Exception:  # noqa: BLE001 - an interface removed after an error reads as "no value"
            return math.nan

    def record(time: float, period: float) -> None:
        controllers, hardware = _states(system)
        timeline.append((time, {**controllers, **{f"hw:{k}": v for k, v in hardware.items()}}))
        positions.append((time, [value(f"{j}/position", "state") for j in JOINTS],
                          [value(f"{j}/position", "command") for j in JOINTS]))

    cm = system.controller_manager
    cm.add_cycle_hook(record)
    error = ""
    sent = {"wrong_size_command": [0.7], "beyond_limits": [0.5, 10.0], "beyond_limits_enforced": [0.5, 10.0],
            "nan_command": [math.nan, 0.5], "hardware_inactive": [0.6, 0.6]}.get(name)
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
        elif name == "hardware_inactive":
            cm.set_hardware_component_state("rrbot", "inactive")
            system.publish(command, Float64MultiArray(data=list(sent or [])))
        elif sent is not None:
            system.publish(command, Float64MultiArray(data=list(sent)))
        elif name == "double_claim":
            try:
                cm.switch_controllers(activate=["joint_trajectory_controller"], strictness="strict")
            except RRBotWorkshopError as exc:
                error = str(exc)
        system.spin(AFTER)
        controllers, hardware = _states(system)
        msg = system.latest("/joint_states")
        joints = [float(p) for p in msg.position] if msg is not None else []
        entries = (cm.list_controllers(), cm.list_hardware_components())
    finally:
        system.shutdown()
    return Outcome(controllers, hardware, joints, error, timeline, positions, entries, sent)


def _same_state(predicted: Any, real: str) -> bool:
    return isinstance(predicted, str) and predicted.strip().lower() == real


def compare(prediction: Any, outcome: Outcome, reveal: bool = True, part: str = "all") -> list[str]:
    """Where ``prediction`` (``{"controllers": {...}, "hardware": {...}, "joints": [...]}``) differs from ``outcome``.

    States are compared as labels in any letter case; positions to 2 decimals (:data:`POSITION_TOLERANCE`).

    Args:
        prediction: The learner's prediction for one fault.
        outcome: What happened.
        reveal: Say what really happened (after the learner ran the fault); False names only what is wrong (the
            self-check must not give the answers away).
        part: ``"states"`` (controllers and hardware), ``"joints"`` (positions) or ``"all"``.

    Returns:
        One line per difference; empty when the prediction is right. A missing or ``None`` entry is a difference.
    """
    if not isinstance(prediction, dict):
        return [f"a prediction is a dict with 'controllers', 'hardware' and 'joints', got {type(prediction).__name__}"]
    problems = []
    if part in ("all", "states"):
        for key in ("controllers", "hardware"):
            mine = prediction.get(key)
            if not isinstance(mine, dict):
                problems.append(f"'{key}' is not predicted (a dict of name -> state)")
                continue
            for entry, state in getattr(outcome, key).items():
                if not _same_state(mine.get(entry), state):
                    what = f"{'controller' if key == 'controllers' else 'hardware'} '{entry}'"
                    said = "not predicted yet" if mine.get(entry) is None else f"predicted {mine.get(entry)!r}"
                    problems.append(f"{what}: {said}" + (f", but it is {state!r}" if reveal else ""))
    if part in ("all", "joints"):
        joints = prediction.get("joints")
        if not isinstance(joints, list | tuple) or len(joints) != len(outcome.joints):
            problems.append(f"'joints' must list {len(outcome.joints)} positions, got {joints!r}")
        else:
            for i, (mine, real) in enumerate(zip(joints, outcome.joints, strict=True)):
                number = isinstance(mine, int | float) and not isinstance(mine, bool) and math.isfinite(mine)
                if not number or abs(float(mine) - real) > POSITION_TOLERANCE:
                    said = "not predicted yet" if mine is None else f"predicted {mine!r} rad"
                    problems.append(f"joint{i + 1}: {said}" + (f", it ends at {real:.2f} rad" if reveal
                                                                else "" if mine is None else " (to 2 decimals)"))
    return problems


def missing(prediction: Any) -> list[str]:
    """The entries of one fault's prediction that are not written yet (``None`` or absent); empty when complete."""
    if not isinstance(prediction, dict):
        return ["the whole prediction"]
    gaps = []
    for key, names in (("controllers", ("joint_state_broadcaster", "forward_position_controller",
                                        "joint_trajectory_controller")), ("hardware", ("rrbot",))):
        mine = prediction.get(key)
        gaps += [f"{key}[{name!r}]" for name in names if not isinstance(mine, dict) or mine.get(name) is None]
    joints = prediction.get("joints")
    if not isinstance(joints, list | tuple) or len(joints) != len(JOINTS) or any(j is None for j in joints):
        gaps.append("joints")
    return gaps


_LEVELS = {"finalized": 0, "unconfigured": 1, "inactive": 2, "active": 3}


def plot_timeline(outcome: Outcome, title: str = "") -> Any:
    """A figure of the run: lifecycle states (top) and joint positions (bottom), the fault at 0.5 s.

    Top: one stepped line per controller and component; the y axis reads finalized, unconfigured, inactive, active.
    Names are offset a little so lines that share a state stay visible. Bottom: each joint's measured position (solid)
    and command (dotted), with joint2's URDF range shaded, and the command sent at the fault (crosses, and as text).

    Returns:
        The matplotlib figure.
    """
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 4.6), sharex=True, height_ratios=[1, 1.2])
    if outcome.timeline:
        names = list(outcome.timeline[0][1])
        t0 = outcome.timeline[0][0]
        times = [t - t0 for t, _ in outcome.timeline]
        for i, name in enumerate(names):
            offset = (i - (len(names) - 1) / 2) * 0.06
            levels = [_LEVELS.get(states.get(name, ""), math.nan) + offset for _, states in outcome.timeline]
            top.step(times, levels, where="post", label=name.replace("hw:", "[hw] "))
        top.set_yticks(list(_LEVELS.values()), list(_LEVELS))
        top.set_ylim(-0.5, 3.5)
        top.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    if outcome.positions:
        t0 = outcome.positions[0][0]
        times = [t - t0 for t, _, _ in outcome.positions]
        for j, joint in enumerate(JOINTS):
            line = bottom.plot(times, [m[j] for _, m, _ in outcome.positions], label=f"{joint} measured")[0]
            bottom.plot(times, [c[j] for _, _, c in outcome.positions], ls=":", lw=2, color=line.get_color(),
                        label=f"{joint} command")
        bottom.axhspan(math.radians(-60), math.radians(240), color="grey", alpha=0.12, label="joint2's URDF range")
        if outcome.sent is not None:
            finite = [v for v in outcome.sent if math.isfinite(v)]
            bottom.plot([0.5] * len(finite), finite, "kx", ms=9, mew=2, label="sent on ~/commands")
            text = "[" + ", ".join("nan" if math.isnan(v) else f"{v:g}" for v in outcome.sent) + "]"
            bottom.annotate(f"sent at 0.5 s: {text}", (0.99, 0.04), xycoords="axes fraction", ha="right", fontsize=8)
        bottom.set_ylabel("position [rad]")
        bottom.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    bottom.axvline(0.5, color="red", lw=0.8, ls="--")
    top.axvline(0.5, color="red", lw=0.8, ls="--")
    bottom.set_xlabel("time [s] (the fault at 0.5 s, red)")
    if title:
        top.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def _file_predictions() -> Any:
    """``PREDICTIONS`` of task 14's ``predictions.py`` on the current track, read afresh (None if it does not load)."""
    from rrbot_workshop.course.learner import load_module

    module = load_module(14, "predictions.py", quiet=True)
    return getattr(module, "PREDICTIONS", None) if module is not None else None


def reveal(name: str, predictions: dict[str, Any] | None = None) -> Any:
    """Run fault ``name`` and show what happened and why, once the learner has predicted it.

    The learner's prediction (``predictions``, or ``PREDICTIONS`` read afresh from task 14's ``predictions.py``) is
    graded first: right or wrong, part by part, with what really happened. Then come the timeline, the explanation
    and the lifecycle diagram. An incomplete prediction shows nothing of the outcome: it says what is still to write.
    Before anything of the outcome is shown, the prediction of ``name`` in ``predictions.py`` is sealed as it is
    (:func:`rrbot_workshop.course.grading.sealed.seal`): the self-check grades that one, and a change made after it
    earns nothing.

    Returns:
        The lifecycle diagram after the fault (the notebook displays it), or ``None`` when nothing was run.

    Raises:
        ValueError: If ``name`` is not one of :data:`FAULTS`.
    """
    import matplotlib.pyplot as plt

    from rrbot_workshop.course.grading import sealed

    if name not in FAULTS:
        raise ValueError(f"unknown fault {name!r}; the faults are {list(FAULTS)}")
    in_file = _file_predictions()
    if predictions is None:
        if not isinstance(in_file, dict):
            print("predictions.py does not define PREDICTIONS yet: write your predictions there first.")
            return None
        predictions = in_file
    gaps = missing(predictions.get(name))
    if gaps:
        what = "is not written yet" if len(gaps) == 5 else f"still lacks {', '.join(gaps)}"
        print(f"Predict '{name}' first: PREDICTIONS['{name}'] in predictions.py {what}. Save the file and run this cell "
              "again: the outcome, and why it happens, are shown once you have predicted it.")
        return None
    if sealed.seal(14, in_file if isinstance(in_file, dict) else None, [name]):
        print(f"Your prediction of '{name}' is sealed as it is now: the self-check grades this one, and a change made "
              "after the outcome below earns nothing.")
    else:
        changed = sealed.changed_since_sealed(14, name, predictions.get(name), notebook="this notebook")
        if changed:
            print(changed + ".")
    outcome = run_fault(name)
    states = compare(predictions[name], outcome, part="states")
    joints = compare(predictions[name], outcome, part="joints")
    for part, problems in (("states", states), ("joint positions", joints)):
        print(f"Your {part}: right." if not problems else f"Your {part}: not what happens:\n  " + "\n  ".join(problems))
    if outcome.error:
        print("The request was refused:", outcome.error)
    print()
    print("Why:", EXPLANATIONS[name])
    plot_timeline(outcome, title=name)
    plt.show()
    from rrbot_workshop import viz

    return viz.lifecycle_states(controllers=outcome.entries[0], components=outcome.entries[1])
