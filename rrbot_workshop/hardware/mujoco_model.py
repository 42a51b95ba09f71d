"""Build a MuJoCo model straight from URDF text, with one actuator per declared command interface.

Simulator plugins for ros2_control usually ask for a hand-written MJCF file next to the URDF, and the two drift
apart. Here the URDF is the only source: MuJoCo's own URDF importer reads the links, joints, limits, inertias and
geometry, and :func:`build_model` adds what a ``<ros2_control>`` tag implies:

* one actuator per joint and per command interface: ``position`` -> a position servo (gains ``kp``, ``kv``),
  ``velocity`` -> a velocity servo (gain ``kv``), ``effort`` -> a motor. Each actuator's force is limited by the
  URDF ``<limit effort>`` when that is positive. All actuators start *disabled* (zero gains), so a joint is passive
  until :class:`MujocoModel.enable` gives it a mode;
* a site and a force/torque sensor pair at the frame named by a force-torque sensor's ``frame_id``;
* a floor and a light, the time step, gravity and the implicit-fast integrator (stable with stiff servos).

The URDF is first made loadable by :func:`~.mujoco_urdf.prepare_urdf` (mesh paths, kept frames).

Actuators are found again through the compiled ``actuator_trnid`` table and classified by their gain/bias
parameters, never by name, so the mapping holds for any naming scheme.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware.mujoco_urdf import effort_limits, frame_in_body, prepare_urdf

__all__ = [
    "COMMAND_MODES",
    "ServoGains",
    "JointBinding",
    "ForceTorqueBinding",
    "MujocoModel",
    "classify_actuator",
    "build_model",
]

#: Command interfaces a joint can be driven through, each mapped to one MuJoCo actuator.
COMMAND_MODES: tuple[str, ...] = ("position", "velocity", "effort")


@dataclass(frozen=True)
class ServoGains:
    """Gains of the actuators of one joint.

    Attributes:
        position_kp: Stiffness of the position servo in [N m/rad] (or [N/m] for prismatic joints).
        position_kv: Damping of the position servo in [N m s/rad].
        velocity_kv: Gain of the velocity servo in [N m s/rad].
    """

    position_kp: float = 1000.0
    position_kv: float = 20.0
    velocity_kv: float = 100.0


@dataclass
class JointBinding:
    """Where one joint lives in the compiled model.

    Attributes:
        name: Joint name.
        joint_id: Index in ``model.jnt_*``.
        qpos_adr: Index of its position in ``data.qpos``.
        dof_adr: Index of its velocity in ``data.qvel`` (and ``qacc``, ``qfrc_*``).
        actuators: Command interface name -> actuator index.
    """

    name: str
    joint_id: int
    qpos_adr: int
    dof_adr: int
    actuators: dict[str, int] = field(default_factory=dict)


@dataclass
class ForceTorqueBinding:
    """A force-torque sensor: a site at ``frame_id`` and the ``sensordata`` slots of its force and torque.

    Attributes:
        name: Sensor name (the ``<sensor name>`` of the ``<ros2_control>`` tag).
        frame_id: Frame (URDF link) the wrench is measured in.
        site_id: Index of the site in ``model.site_*``.
        force_adr: First index of the 3 force values in ``data.sensordata``.
        torque_adr: First index of the 3 torque values in ``data.sensordata``.
    """

    name: str
    frame_id: str
    site_id: int
    force_adr: int
    torque_adr: int


@dataclass
class MujocoModel:
    """A compiled model with the tables the hardware component needs.

    Attributes:
        model: The compiled ``mujoco.MjModel``.
        joints: Joint name -> :class:`JointBinding`, for the joints asked for in :func:`build_model`.
        force_torque_sensors: Sensor name -> :class:`ForceTorqueBinding`.
        nominal_gainprm: Copy of ``model.actuator_gainprm`` with every actuator enabled.
        nominal_biasprm: Copy of ``model.actuator_biasprm`` with every actuator enabled.
    """

    model: mujoco.MjModel
    joints: dict[str, JointBinding]
    force_torque_sensors: dict[str, ForceTorqueBinding]
    nominal_gainprm: np.ndarray
    nominal_biasprm: np.ndarray

    def disable(self, actuator_id: int) -> None:
        """Zero the gains of one actuator: it applies no force whatever its control."""
        self.model.actuator_gainprm[actuator_id, :] = 0.0
        self.model.actuator_biasprm[actuator_id, :] = 0.0

    def enable(self, actuator_id: int) -> None:
        """Give one actuator back its nominal gains."""
        self.model.actuator_gainprm[actuator_id, :] = self.nominal_gainprm[actuator_id]
        self.model.actuator_biasprm[actuator_id, :] = self.nominal_biasprm[actuator_id]

    def disable_all(self) -> None:
        """Disable every actuator: all joints become passive."""
        for actuator_id in range(self.model.nu):
            self.disable(actuator_id)


# --------------------------------------------------------------------------- actuators
def classify_actuator(model: mujoco.MjModel, actuator_id: int) -> str:
    """What a compiled actuator does, read from its parameters (not its name).

    Returns:
        ``"effort"`` (no bias: a motor), ``"position"`` (affine bias on the joint position), ``"velocity"``
        (affine bias on the velocity only) or ``"custom"``. A disabled actuator (all zero) reads ``"effort"``;
        classify with the nominal parameters of :class:`MujocoModel` instead.
    """
    bias_type = model.actuator_biastype[actuator_id]
    bias = model.actuator_biasprm[actuator_id]
    if bias_type == mujoco.mjtBias.mjBIAS_NONE:
        return "effort"
    if bias_type == mujoco.mjtBias.mjBIAS_AFFINE and bias[1] != 0.0:
        return "position"
    if bias_type == mujoco.mjtBias.mjBIAS_AFFINE and bias[1] == 0.0 and bias[2] != 0.0:
        return "velocity"
    return "custom"


def build_model(
    urdf: str,
    command_interfaces: Mapping[str, Sequence[str]],
    force_torque_sensors: Mapping[str, str] | None = None,
    *,
    timestep: float = 0.001,
    gains: Mapping[str, ServoGains] | None = None,
    joint_dynamics: Mapping[str, Mapping[str, float]] | None = None,
    gravity: Sequence[float] = (0.0, 0.0, -9.81),
    add_floor: bool = True,
    base_dir: str | Path | None = None,
) -> MujocoModel:
    """Compile a MuJoCo model from URDF text.

    Args:
        urdf: URDF text (xacro already processed).
        command_interfaces: Joint name -> command interfaces to actuate (``"position"``, ``"velocity"``,
            ``"effort"``). Joints listed with no interface are tracked but passive.
        force_torque_sensors: Sensor name -> URDF link whose frame the wrench is measured in.
        timestep: Physics time step in [s].
        gains: Joint name -> servo gains; joints not listed get :class:`ServoGains` defaults.
        joint_dynamics: Joint name -> ``{"damping": [N m s/rad], "friction": [N m], "armature": [kg m^2]}``;
            values override the URDF ``<dynamics>``.
        gravity: Gravity vector in [m/s^2].
        add_floor: Add a ground plane at z = 0 and a light.
        base_dir: Folder for relative mesh paths.

    Returns:
        The compiled model and its joint, actuator and sensor tables. Every actuator starts disabled.

    Raises:
        DescriptionError: If the URDF cannot be compiled (the message carries MuJoCo's reason), a joint is missing
            or not a hinge/slide, a command interface is not one of :data:`COMMAND_MODES`, the time step is not
            positive, or a sensor frame is unknown.
    """
    if not timestep > 0.0:
        raise DescriptionError(f"timestep must be a positive number of seconds, got {timestep}", attribute="timestep")
    text, urdf_root = prepare_urdf(urdf, base_dir)
    try:
        spec = mujoco.MjSpec.from_string(text)
    except Exception as exc:  # noqa: BLE001 - MuJoCo raises plain ValueError/Exception with its own message
        raise DescriptionError(f"MuJoCo cannot read the URDF: {exc}", element="<robot>") from exc
    spec.compiler.degree = False  # radians everywhere, as in URDF (MjSpec's own default is degrees)
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = list(gravity)
    if add_floor:
        spec.worldbody.add_geom(
            name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5.0, 5.0, 0.05], rgba=[0.8, 0.8, 0.8, 1.0]
        )
        spec.worldbody.add_light(name="light", pos=[0.0, 0.0, 4.0], dir=[0.0, 0.0, -1.0])

    spec_joints = {j.name: j for j in spec.joints}
    hinge_or_slide = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    efforts = effort_limits(urdf_root)
    gains = gains or {}
    for joint_name, dynamics in (joint_dynamics or {}).items():
        if joint_name not in spec_joints:
            continue  # reported below if the joint is also asked for
        if "damping" in dynamics:
            spec_joints[joint_name].damping[0] = dynamics["damping"]
        if "friction" in dynamics:
            spec_joints[joint_name].frictionloss = dynamics["friction"]
        if "armature" in dynamics:
            spec_joints[joint_name].armature = dynamics["armature"]

    for joint_name, interfaces in command_interfaces.items():
        joint = spec_joints.get(joint_name)
        if joint is None or joint.type not in hinge_or_slide:
            valid = sorted(n for n, j in spec_joints.items() if j.type in hinge_or_slide)
            raise DescriptionError(
                f"joint '{joint_name}' is not a revolute, continuous or prismatic joint of the URDF "
                f"(valid: {', '.join(valid) or 'none'})",
                element=f"<joint name='{joint_name}'>",
            )
        joint_gains = gains.get(joint_name, ServoGains())
        effort = efforts.get(joint_name, 0.0)
        for interface in interfaces:
            if interface not in COMMAND_MODES:
                raise DescriptionError(
                    f"command interface '{joint_name}/{interface}' cannot be simulated "
                    f"(valid: {', '.join(COMMAND_MODES)})",
                    element=f"<joint name='{joint_name}'>",
                    attribute=interface,
                )
            actuator = spec.add_actuator(
                name=f"{joint_name}/{interface}", target=joint_name, trntype=mujoco.mjtTrn.mjTRN_JOINT
            )
            if interface == "position":
                actuator.set_to_position(kp=joint_gains.position_kp, kv=joint_gains.position_kv)
            elif interface == "velocity":
                actuator.set_to_velocity(kv=joint_gains.velocity_kv)
            else:
                actuator.set_to_motor()
            if effort > 0.0:  # a URDF effort of 0 means "not given" here, not "cannot move"
                actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
                actuator.forcerange = [-effort, effort]

    body_names = {b.name for b in spec.bodies}
    for sensor_name, frame in (force_torque_sensors or {}).items():
        body, pos, rot = frame_in_body(frame, urdf_root, body_names)
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, rot.flatten())
        spec.body(body).add_site(name=f"{sensor_name}_site", pos=list(pos), quat=list(quat))
        for suffix, kind in (("force", mujoco.mjtSensor.mjSENS_FORCE), ("torque", mujoco.mjtSensor.mjSENS_TORQUE)):
            spec.add_sensor(
                name=f"{sensor_name}_{suffix}", type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f"{sensor_name}_site"
            )

    try:
        model = spec.compile()
    except Exception as exc:  # noqa: BLE001
        raise DescriptionError(
            f"MuJoCo cannot compile the URDF: {exc} (every link moved by a joint needs an <inertial> with positive "
            "mass and inertia)",
            element="<robot>",
        ) from exc
    return _bind(model, command_interfaces, force_torque_sensors or {})


def _bind(
    model: mujoco.MjModel, command_interfaces: Mapping[str, Sequence[str]], force_torque_sensors: Mapping[str, str]
) -> MujocoModel:
    """Build the joint/actuator/sensor tables from the compiled arrays, then disable every actuator."""
    joints: dict[str, JointBinding] = {}
    for joint_name in command_interfaces:
        joint_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint_name)
        joints[joint_name] = JointBinding(
            joint_name, joint_id, int(model.jnt_qposadr[joint_id]), int(model.jnt_dofadr[joint_id])
        )
    by_id = {b.joint_id: b for b in joints.values()}
    for actuator_id in range(model.nu):
        if model.actuator_trntype[actuator_id] != mujoco.mjtTrn.mjTRN_JOINT:
            continue
        binding = by_id.get(int(model.actuator_trnid[actuator_id, 0]))
        if binding is not None:
            binding.actuators[classify_actuator(model, actuator_id)] = actuator_id
    sensors: dict[str, ForceTorqueBinding] = {}
    for sensor_name, frame in force_torque_sensors.items():
        force_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, f"{sensor_name}_force")
        torque_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, f"{sensor_name}_torque")
        sensors[sensor_name] = ForceTorqueBinding(
            sensor_name,
            frame,
            int(model.sensor_objid[force_id]),
            int(model.sensor_adr[force_id]),
            int(model.sensor_adr[torque_id]),
        )
    result = MujocoModel(model, joints, sensors, model.actuator_gainprm.copy(), model.actuator_biasprm.copy())
    result.disable_all()
    return result
