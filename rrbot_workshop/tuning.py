"""Tuning a joint's PID from the robot description, with python-control.

A PID controller in a chain (``joint_trajectory_controller -> pid_controller -> effort``) closes a loop around a
joint whose dynamics the URDF already describes: the inertias of the links it carries, the ``<dynamics>``
damping, and gravity. This module turns that into a linear model, predicts the closed loop's step response at
the controller's update rate, and measures the same figures on a simulated run, so a notebook can overlay
prediction and simulation::

    plant = rw.tuning.joint_plant(urdf, "joint1", {"joint1": 0.0, "joint2": 0.0})
    gains = rw.tuning.PidGains(p=100.0, i=50.0, d=10.0)
    prediction = rw.tuning.predict_step(plant, gains, period=0.01, step=0.5)
    prediction.overshoot, prediction.settling_time

The model is the joint alone: the other joints are held where they are (their own PIDs do that), and gravity is
linearized around the given pose. The controller is control_toolbox's ``Pid`` in its Jazzy default (``legacy``:
the integral is accumulated first, then used in the same cycle) with the derivative acting on the measured
velocity, as ``pid_controller`` computes it when its references are ``[position, velocity]`` and the velocity
reference is zero.
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from rrbot_workshop.exceptions import DescriptionError

if TYPE_CHECKING:
    import control
    import yourdfpy

__all__ = [
    "JointPlant", "PidGains", "StepResponse", "joint_plant", "closed_loop", "predict_step", "step_metrics", "measure_step",
]

def _control() -> Any:
    """python-control, imported when a model is first built (it takes seconds to import; measuring a step does not
    need it, and the graders measure steps)."""
    import control

    return control


#: Gravity used by the model [m/s^2], as in the simulation.
GRAVITY = np.array([0.0, 0.0, -9.81])
#: Band around the final value used for the settling time, as a fraction of the step (2 %).
SETTLING_BAND = 0.02


@dataclass(frozen=True)
class JointPlant:
    """Linear model of one joint, effort in, position out: ``J q'' + b q' + k q = tau``.

    Attributes:
        joint: Joint name.
        inertia: Inertia of everything the joint moves, about its axis, in [kg m^2].
        damping: Viscous damping of the joint in [N m s/rad] (URDF ``<dynamics damping>``).
        gravity_stiffness: Change of the gravity torque with the joint angle around the pose, in [N m/rad]; positive
            when gravity pulls the joint back towards the pose (hanging), negative when it pulls it away.
        gravity_torque: Torque the joint must hold against gravity at the pose, in [N m].
    """

    joint: str
    inertia: float
    damping: float
    gravity_stiffness: float
    gravity_torque: float

    def transfer_function(self) -> control.TransferFunction:
        """``P(s) = 1 / (J s^2 + b s + k)``: effort [N m] to position [rad]."""
        control = _control()
        return control.tf([1.0], [self.inertia, self.damping, self.gravity_stiffness])

    def state_space(self) -> control.StateSpace:
        """The plant with two outputs, position [rad] and velocity [rad/s] (what the PID reads)."""
        a = [[0.0, 1.0], [-self.gravity_stiffness / self.inertia, -self.damping / self.inertia]]
        control = _control()
        return control.ss(a, [[0.0], [1.0 / self.inertia]], [[1.0, 0.0], [0.0, 1.0]], [[0.0], [0.0]])


@dataclass(frozen=True)
class PidGains:
    """Gains of one ``pid_controller`` joint, with the names of its YAML (``gains.<joint>.p`` ...).

    Attributes:
        p: Proportional gain in [N m/rad].
        i: Integral gain in [N m/(rad s)].
        d: Derivative gain in [N m s/rad].
    """

    p: float
    i: float = 0.0
    d: float = 0.0


@dataclass(frozen=True)
class StepResponse:
    """A step response and its figures.

    Attributes:
        time: Sample times in [s], starting at 0.
        position: Joint position at those times in [rad].
        start: Position before the step in [rad].
        target: Commanded position in [rad].
        overshoot: Largest excursion past the target, in percent of the step.
        settling_time: Time after which the position stays within 2 % of the step around the target, in [s]
            (``inf`` if it never does within the run).
        steady_state_error: ``target - position`` at the end of the run, in [rad].
    """

    time: np.ndarray
    position: np.ndarray
    start: float
    target: float
    overshoot: float
    settling_time: float
    steady_state_error: float


def _urdf_model(urdf: str) -> yourdfpy.URDF:
    import yourdfpy  # about 1 s with trimesh: only the plant model needs it, not measure_step (a grader's import)

    try:
        return yourdfpy.URDF.load(io.StringIO(urdf), build_scene_graph=True, load_meshes=False,
                                  build_collision_scene_graph=False, load_collision_meshes=False)
    except Exception as exc:  # noqa: BLE001 - yourdfpy raises many kinds for bad text
        raise DescriptionError(f"the URDF cannot be read for tuning: {exc}", element="<robot>") from exc


def _descendants(model: yourdfpy.URDF, link: str) -> list[str]:
    out = [link]
    for joint in model.robot.joints:
        if joint.parent == link:
            out += _descendants(model, joint.child)
    return out


def _gravity_torque(model: yourdfpy.URDF, joint: str, links: Sequence[str]) -> float:
    """Torque of gravity about the joint's axis at the model's current configuration [N m]."""
    spec = model.joint_map[joint]
    frame = model.get_transform(spec.child)  # the joint frame moves with the child link
    axis = frame[:3, :3] @ np.asarray(spec.axis, dtype=float)
    pivot = frame[:3, 3]
    torque = 0.0
    for name in links:
        inertial = model.link_map[name].inertial
        if inertial is None or not inertial.mass:
            continue
        com = (model.get_transform(name) @ inertial.origin)[:3, 3]
        torque += float(axis @ np.cross(com - pivot, inertial.mass * GRAVITY))
    return torque


def joint_plant(urdf: str, joint: str, positions: Mapping[str, float] | None = None) -> JointPlant:
    """Linear model of ``joint`` at the pose ``positions``, from the URDF's inertias, damping and gravity.

    Args:
        urdf: URDF text (xacro already processed).
        joint: A revolute or continuous joint of the URDF.
        positions: Joint name -> position in [rad]; joints not listed are at 0.

    Returns:
        The joint's plant.

    Raises:
        DescriptionError: If the URDF cannot be read, the joint is unknown or not revolute/continuous, or a
            position names an unknown joint.
    """
    model = _urdf_model(urdf)
    if joint not in model.joint_map:
        raise DescriptionError(
            f"no joint '{joint}' in the URDF (joints: {sorted(model.joint_map)})", element=f"<joint name='{joint}'>"
        )
    spec = model.joint_map[joint]
    if spec.type not in ("revolute", "continuous"):
        raise DescriptionError(
            f"joint '{joint}' is {spec.type}; the tuning model handles revolute and continuous joints",
            element=f"<joint name='{joint}'>",
        )
    pose = dict(positions or {})
    unknown = sorted(set(pose) - set(model.actuated_joint_names))
    if unknown:
        raise DescriptionError(f"positions for unknown joints {unknown} (joints: {model.actuated_joint_names})")
    names = model.actuated_joint_names
    q = np.array([pose.get(n, 0.0) for n in names])
    model.update_cfg(q)
    links = _descendants(model, spec.child)
    frame = model.get_transform(spec.child)
    axis = frame[:3, :3] @ np.asarray(spec.axis, dtype=float)
    pivot = frame[:3, 3]
    inertia = 0.0
    for name in links:
        inertial = model.link_map[name].inertial
        if inertial is None or not inertial.mass:
            continue
        pose_w = model.get_transform(name) @ inertial.origin
        rot, com = pose_w[:3, :3], pose_w[:3, 3]
        about_com = float(axis @ rot @ np.asarray(inertial.inertia) @ rot.T @ axis)
        lever = np.cross(axis, com - pivot)
        inertia += about_com + inertial.mass * float(lever @ lever)
    torque = _gravity_torque(model, joint, links)
    step = 1e-5
    index = names.index(joint)
    q_plus = q.copy()
    q_plus[index] += step
    model.update_cfg(q_plus)
    stiffness = -(_gravity_torque(model, joint, links) - torque) / step
    damping = float(spec.dynamics.damping) if spec.dynamics is not None and spec.dynamics.damping else 0.0
    return JointPlant(joint=joint, inertia=inertia, damping=damping,
                      gravity_stiffness=round(stiffness, 9) + 0.0, gravity_torque=-torque + 0.0)


def closed_loop(plant: JointPlant, gains: PidGains, period: float) -> control.StateSpace:
    """The discrete closed loop, position reference [rad] to position [rad], at the controller's period.

    The plant is sampled with a zero-order hold (the effort command is held for one period); the controller is
    ``u = p e + I + d (0 - v)`` with ``I += i e period`` accumulated before it is used (``legacy``).

    Args:
        plant: The joint's model.
        gains: PID gains.
        period: Controller update period in [s] (``1 / update_rate``).

    Raises:
        ValueError: If the period is not positive.
    """
    if not period > 0.0:
        raise ValueError(f"period must be a positive number of seconds, got {period}")
    control = _control()
    sampled = control.c2d(plant.state_space(), period, method="zoh")
    a, b, c = (np.asarray(m) for m in (sampled.A, sampled.B, sampled.C))
    # State: [q, v, I], input: r. With e = r - q:  I' = I + i T (r - q);  u = p (r - q) + I' - d v.
    ki = gains.i * period
    u_row = np.array([-(gains.p + ki), -gains.d, 1.0])
    u_ref = gains.p + ki
    a_cl = np.zeros((3, 3))
    a_cl[:2, :] = np.hstack([a, np.zeros((2, 1))]) + b @ u_row[None, :]
    a_cl[2, :] = [-ki, 0.0, 1.0]
    b_cl = np.vstack([b * u_ref, [[ki]]])
    c_cl = np.array([[c[0, 0], c[0, 1], 0.0]])
    return control.ss(a_cl, b_cl, c_cl, [[0.0]], period)


def step_metrics(
    time: Sequence[float] | np.ndarray, position: Sequence[float] | np.ndarray, start: float, target: float
) -> StepResponse:
    """Overshoot, settling time and steady-state error of a response to a step from ``start`` to ``target``.

    Works the same on a prediction and on a recorded simulation, so the two compare like with like.

    Args:
        time: Sample times in [s], the step at ``time[0]``.
        position: Positions in [rad].
        start: Position before the step in [rad].
        target: Commanded position in [rad].

    Raises:
        ValueError: If the series are empty, of different lengths, or the step is zero.
    """
    t = np.asarray(time, dtype=float)
    y = np.asarray(position, dtype=float)
    if t.size == 0 or t.size != y.size:
        raise ValueError(f"time and position must be non-empty and of the same length ({t.size} != {y.size})")
    size = target - start
    if size == 0.0:
        raise ValueError("the step is zero: start and target are equal")
    progress = (y - start) / size  # 0 at the start, 1 at the target
    overshoot = max(0.0, float(progress.max()) - 1.0) * 100.0
    outside = np.nonzero(np.abs(progress - 1.0) > SETTLING_BAND)[0]
    if outside.size == 0:
        settling = 0.0
    elif outside[-1] == t.size - 1:
        settling = math.inf
    else:
        settling = float(t[outside[-1] + 1] - t[0])
    return StepResponse(time=t - t[0], position=y, start=start, target=target, overshoot=overshoot,
                        settling_time=settling, steady_state_error=float(target - y[-1]))


def predict_step(plant: JointPlant, gains: PidGains, period: float, step: float, *, start: float = 0.0,
                 duration: float = 3.0) -> StepResponse:
    """Predicted response of the joint to a position step ``start -> start + step`` under the PID.

    Args:
        plant: The joint's model (linearized at ``start``).
        gains: PID gains.
        period: Controller update period in [s].
        step: Size of the step in [rad].
        start: Position before the step in [rad].
        duration: Length of the prediction in [s].
    """
    loop = closed_loop(plant, gains, period)
    steps = int(round(duration / period))
    t = np.arange(steps + 1) * period
    response = _control().forced_response(loop, T=t, U=np.full_like(t, step))
    y = start + np.asarray(response.outputs).reshape(-1)
    return step_metrics(t, y, start, start + step)


def measure_step(system: Any, controller: str, target: float, duration: float = 3.0) -> StepResponse:
    """Step a running ``pid_controller`` (not chained) to ``target`` and measure the response in simulation.

    The step is sent on the controller's ``~/reference`` topic (value ``target``, velocity reference 0 when the
    controller has a velocity reference) and the joint is sampled from ``/joint_states`` once per cycle; sample
    ``k`` is the position read in the ``k``-th cycle after the step, the same instants as :func:`predict_step`.

    Args:
        system: A running :class:`~rrbot_workshop.bringup.System` with ``controller`` active and not chained, and the
            joint state broadcaster active.
        controller: Name of an active PidController with one DOF (a joint).
        target: Position reference in [rad].
        duration: Length of the measurement in [s] (simulated time).

    Raises:
        ControllerError: If the controller is not an active, unchained PidController with one DOF.
    """
    from rrbot_workshop.exceptions import ControllerError
    from rrbot_workshop.msgs import MultiDOFCommand

    cm = system.controller_manager
    entry = next((c for c in cm.list_controllers() if c.name == controller), None)
    if entry is None or entry.state != "active" or entry.is_chained:
        raise ControllerError(
            f"measure_step needs '{controller}' loaded, active and not chained "
            f"(it is {'not loaded' if entry is None else entry.state + (', chained' if entry.is_chained else '')})"
        )
    pid = cm.get_controller(controller)
    dofs = list(getattr(pid, "reference_and_state_dof_names", []))
    if len(dofs) != 1:
        raise ControllerError(f"measure_step needs a PidController with one DOF; '{controller}' has {dofs}")
    joint = dofs[0]
    period = 1.0 / cm.get_update_rate()

    def position() -> float:
        msg = system.latest("/joint_states")
        return float(msg.position[msg.name.index(joint)])

    start = position()
    system.publish(f"/{controller}/reference", MultiDOFCommand(dof_names=[joint], values=[target], values_dot=[0.0]))
    steps = int(round(duration / period))
    samples = []
    for _ in range(steps + 1):
        system.spin(seconds=period)
        samples.append(position())
    return step_metrics(np.arange(steps + 1) * period, samples, start, target)
