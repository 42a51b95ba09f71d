"""Grader of task 9: a controller chain on RRBot in MuJoCo, and PID gains tuned to a specification.

The specification:

* ``rrbot_bringup/config/rrbot_chained_controllers.yaml`` declares ``joint_state_broadcaster``,
  ``pid_controller_joint1``/``pid_controller_joint2`` (``pid_controller/PidController``, one DOF each, commanding the
  joint's ``effort``, with references and states ``[position, velocity]``) and ``joint_trajectory_controller``
  (joints ``[joint1, joint2]``, commanding the PIDs' reference interfaces ``pid_controller_jointN/jointN`` with
  ``[position, velocity]``); every parameter is one that Jazzy's controllers declare;
* ``chain.py``: ``activate_chain(cm)`` brings the chain up with strict switches that the controller manager accepts
  (the PIDs active before or with the trajectory controller); ``deactivate_chain(cm)`` takes it down, head first;
* running, the trajectory controller is updated before the PIDs (Jazzy's chain order), the PIDs are in chained
  mode, and a trajectory is tracked within :data:`TRACKING_TOLERANCE`;
* the gains meet the step specification on joint1 (:data:`SPEC`), measured in simulation with the PID alone: the
  specification is here, not in the learner's files.

The system is the library's RRBot description with ``sim_mujoco:=true`` (MuJoCo, effort-controlled joints).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop import tuning
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.lint import lint_controllers
from rrbot_workshop.description.xacro import descriptions_root
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint, MultiDOFCommand

TASK = 9
CONTROLLERS = "rrbot_bringup/config/rrbot_chained_controllers.yaml"
CHAIN_FILE = "chain.py"
JSB, JTC = "joint_state_broadcaster", "joint_trajectory_controller"
PIDS = ["pid_controller_joint1", "pid_controller_joint2"]
JOINTS = ["joint1", "joint2"]
TYPES = {
    JSB: "joint_state_broadcaster/JointStateBroadcaster",
    PIDS[0]: "pid_controller/PidController",
    PIDS[1]: "pid_controller/PidController",
    JTC: "joint_trajectory_controller/JointTrajectoryController",
}
#: Step specification on joint1 (0 -> 0.5 rad at 100 Hz, PID alone): the learner tunes gains to meet it.
SPEC = {"step": 0.5, "overshoot": 5.0, "settling_time": 0.5, "steady_state_error": 0.005}  # [rad], [%], [s], [rad]
#: Largest allowed distance between the trajectory controller's reference and the joints during a trajectory [rad].
TRACKING_TOLERANCE = 0.03
#: Final position error allowed at the end of the trajectory [rad].
GOAL_TOLERANCE = 0.005


# --------------------------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


@pytest.fixture(scope="module")
def controllers_yaml(controllers_file: Path) -> dict[str, Any]:
    try:
        data = yaml.safe_load(controllers_file.read_text())
    except yaml.YAMLError as exc:
        pytest.fail(f"{controllers_file.name} is not valid YAML: {exc}", pytrace=False)
    if not isinstance(data, dict):
        pytest.fail(f"{controllers_file.name} must be a mapping of controller names to their parameters", pytrace=False)
    return data


@pytest.fixture(scope="module")
def chain(task_file: Callable[[int, str], Path]) -> ModuleType:
    path = task_file(TASK, CHAIN_FILE)
    module = rw.course.load_module(TASK, CHAIN_FILE, quiet=True)
    if module is None:
        pytest.fail(f"{path} does not import; open it in JupyterLab and run notebook 09's cell that loads it",
                    pytrace=False)
    return module


def _params(data: dict[str, Any], name: str) -> dict[str, Any]:
    params = (data.get(name) or {}).get("ros__parameters")
    if not isinstance(params, dict):
        pytest.fail(f"no '{name}: ros__parameters:' section in the controllers YAML", pytrace=False)
    return params


@contextmanager
def _system(controllers: Path | dict[str, Any], spawn: list[str]) -> Iterator[System]:
    try:
        system = bringup(descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro", controllers,
                         xacro_args={"sim_mujoco": True}, spawn=spawn)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"the system does not start with your controllers YAML: {exc}", pytrace=False)
    try:
        yield system
    finally:
        system.shutdown()


def _call(chain: ModuleType, function: str, *args: Any) -> None:
    fn = getattr(chain, function, None)
    if not callable(fn):
        pytest.fail(f"chain.py has no function {function}()", pytrace=False)
    try:
        fn(*args)
    except NotImplementedError:
        pytest.fail(f"{function}() is not written yet", pytrace=False)
    except rw.SwitchError as exc:
        pytest.fail(f"{function}() made a switch the controller manager rejected: {exc}", pytrace=False)
    except Exception as exc:  # noqa: BLE001 - the learner's error is the check's failure
        pytest.fail(f"{function}() raised {type(exc).__name__}: {exc}", pytrace=False)


def _states(system: System) -> dict[str, str]:
    return {c.name: c.state for c in system.controller_manager.list_controllers()}


# --------------------------------------------------------------------------------------------- 9.1 the YAML


@graded(points=1, hint="Task 9.1: the controller manager must declare the four controllers with the Jazzy type names, "
        "and every parameter must be one the controller declares (`rrbot-workshop lint` on your YAML says which is not).")
def test_yaml_is_valid_for_jazzy(controllers_file: Path, controllers_yaml: dict[str, Any]) -> None:
    manager = _params(controllers_yaml, "controller_manager")
    types = {name: (manager.get(name) or {}).get("type") for name in TYPES}
    assert types == TYPES, f"controller types {types}, expected {TYPES}"
    errors = [f for f in lint_controllers(controllers_file) if f.level == "error"]
    assert not errors, "the YAML would not load on a Jazzy robot: " + "; ".join(f.message for f in errors)


@graded(points=2, hint="Task 9.1: a PID that drives a joint's effort and is fed by a trajectory controller needs a "
        "reference for position AND velocity; each PidController has one DOF, its joint.")
def test_pids_command_effort_with_position_and_velocity_references(controllers_yaml: dict[str, Any]) -> None:
    for pid, joint in zip(PIDS, JOINTS, strict=True):
        params = _params(controllers_yaml, pid)
        assert params.get("dof_names") == [joint], f"{pid}: dof_names {params.get('dof_names')}, expected [{joint}]"
        assert params.get("command_interface") == "effort", f"{pid}: command_interface {params.get('command_interface')!r}"
        refs = params.get("reference_and_state_interfaces")
        assert refs == ["position", "velocity"], f"{pid}: reference_and_state_interfaces {refs}"


@graded(points=2, hint="Task 9.1: the trajectory controller reads the joints' states, but its commands go to the "
        "interfaces the PIDs export, named <controller>/<dof>/<interface>. Which JTC parameter names command joints?")
def test_trajectory_controller_commands_the_pids(controllers_yaml: dict[str, Any]) -> None:
    params = _params(controllers_yaml, JTC)
    assert params.get("joints") == JOINTS, f"{JTC}: joints {params.get('joints')}, expected {JOINTS}"
    expected = [f"{pid}/{joint}" for pid, joint in zip(PIDS, JOINTS, strict=True)]
    assert params.get("command_joints") == expected, f"{JTC}: command_joints {params.get('command_joints')}"
    assert params.get("command_interfaces") == ["position", "velocity"], (
        f"{JTC}: command_interfaces {params.get('command_interfaces')}, the PIDs take position and velocity references"
    )
    assert params.get("state_interfaces") == ["position", "velocity"], f"{JTC}: state_interfaces"


# --------------------------------------------------------------------------------------------- 9.2 the order


@graded(points=3, hint="Task 9.2: a controller can only claim reference interfaces that an ACTIVE controller exports. "
        "Activate the PIDs first (or in the same switch as the trajectory controller).")
def test_activate_chain_connects(controllers_file: Path, chain: ModuleType) -> None:
    with _system(controllers_file, [JSB]) as system:
        cm = system.controller_manager
        requests: list[tuple[list[str], list[str]]] = []
        original = cm.switch_controllers

        def recording(activate: Any = (), deactivate: Any = (), *args: Any, **kwargs: Any) -> Any:
            requests.append((list(activate or []), list(deactivate or [])))
            return original(activate, deactivate, *args, **kwargs)

        cm.switch_controllers = recording  # type: ignore[method-assign]
        try:
            _call(chain, "activate_chain", cm)
        finally:
            del cm.switch_controllers
        states = _states(system)
        assert all(states.get(n) == "active" for n in [JTC, *PIDS]), f"after activate_chain(): {states}"
        assert requests, "activate_chain() made no switch"
        chained = {c.name: c.is_chained for c in cm.list_controllers()}
        assert chained[PIDS[0]] and chained[PIDS[1]], f"the PIDs are not in chained mode: {chained}"
        claimed = {c.name: sorted(c.claimed_interfaces) for c in cm.list_controllers()}
        assert claimed[JTC] == sorted(f"{p}/{j}/{i}" for p, j in zip(PIDS, JOINTS, strict=True)
                                      for i in ("position", "velocity")), f"{JTC} claims {claimed[JTC]}"


@graded(points=2, hint="Task 9.2: Jazzy updates a preceding controller before its followers, whatever the load order: "
        "the trajectory controller first, then the PIDs. Your chain must produce that order.")
def test_update_order_is_jazzy(controllers_file: Path, chain: ModuleType) -> None:
    with _system(controllers_file, [JSB]) as system:
        _call(chain, "activate_chain", system.controller_manager)
        order = [c.name for c in system.controller_manager.list_controllers() if c.state == "active"]
        assert order.index(JTC) < order.index(PIDS[0]) and order.index(JTC) < order.index(PIDS[1]), (
            f"update order {order}: the trajectory controller must come before the PIDs"
        )


@graded(points=2, hint="Task 9.2: the PIDs cannot stop while the trajectory controller still claims their references; "
        "deactivate the head of the chain first. Everything stays loaded and configured (inactive).")
def test_deactivate_chain(controllers_file: Path, chain: ModuleType) -> None:
    with _system(controllers_file, [JSB]) as system:
        cm = system.controller_manager
        _call(chain, "activate_chain", cm)
        _call(chain, "deactivate_chain", cm)
        states = _states(system)
        assert all(states.get(n) == "inactive" for n in [JTC, *PIDS]), f"after deactivate_chain(): {states}"
        assert states.get(JSB) == "active", "deactivate_chain() must leave the joint state broadcaster running"
        _call(chain, "activate_chain", cm)
        assert all(_states(system).get(n) == "active" for n in [JTC, *PIDS]), "the chain does not come back up"


# --------------------------------------------------------------------------------------------- running the chain


def _trajectory() -> JointTrajectory:
    points = [([0.6, -0.4], 1.5), ([0.0, 0.5], 3.0), ([-0.3, 0.0], 4.5)]
    return JointTrajectory(
        joint_names=list(JOINTS),
        points=[JointTrajectoryPoint(positions=list(p), velocities=[0.0, 0.0], time_from_start=t) for p, t in points],
    )


@graded(points=3, hint="Task 9: with the chain connected, the PIDs follow the trajectory controller's position and "
        "velocity references. Large tracking errors come from slow gains (see the step specification).")
def test_trajectory_is_tracked_through_the_chain(controllers_file: Path, chain: ModuleType) -> None:
    with _system(controllers_file, [JSB]) as system:
        cm = system.controller_manager
        _call(chain, "activate_chain", cm)
        system.spin(seconds=1.0)
        system.publish(f"/{JTC}/joint_trajectory", _trajectory())
        jtc = cm.get_controller(JTC)
        worst = 0.0
        for _ in range(600):
            system.spin(seconds=0.01)
            state = system.latest(f"/{JTC}/controller_state")
            if state is not None and state.error.positions:
                worst = max(worst, max(abs(e) for e in state.error.positions))
        msg = system.latest("/joint_states")
        final = [msg.position[msg.name.index(j)] for j in JOINTS]
        assert worst <= TRACKING_TOLERANCE, f"largest tracking error {worst:.3f} rad > {TRACKING_TOLERANCE} rad"
        assert all(math.isclose(a, b, abs_tol=GOAL_TOLERANCE) for a, b in zip(final, [-0.3, 0.0], strict=True)), (
            f"the joints end at {final}, goal [-0.3, 0.0] (tolerance {GOAL_TOLERANCE} rad); {type(jtc).__name__} active"
        )


# --------------------------------------------------------------------------------------------- 9.3 tuning


@graded(points=4, hint=f"Task 9.3: a 0.5 rad step of joint1 must overshoot at most {SPEC['overshoot']:g} %, settle "
        f"within 2 % in {SPEC['settling_time']:g} s and end within {SPEC['steady_state_error']:g} rad. Predict with "
        "rw.tuning.predict_step before you simulate: stiffer p, damping from d, and little i.")
def test_gains_meet_the_step_specification(controllers_file: Path) -> None:
    with _system(controllers_file, [JSB, *PIDS]) as system:
        for pid, joint in zip(PIDS, JOINTS, strict=True):
            system.publish(f"/{pid}/reference", MultiDOFCommand(dof_names=[joint], values=[0.0], values_dot=[0.0]))
        system.spin(seconds=2.0)
        response = tuning.measure_step(system, PIDS[0], SPEC["step"])
    problems = []
    if response.overshoot > SPEC["overshoot"]:
        problems.append(f"overshoot {response.overshoot:.1f} % > {SPEC['overshoot']:g} %")
    if response.settling_time > SPEC["settling_time"]:
        problems.append(f"settling time {response.settling_time:.2f} s > {SPEC['settling_time']:g} s")
    if abs(response.steady_state_error) > SPEC["steady_state_error"]:
        problems.append(f"final error {response.steady_state_error:.4f} rad")
    assert not problems, "step of joint1: " + ", ".join(problems)
