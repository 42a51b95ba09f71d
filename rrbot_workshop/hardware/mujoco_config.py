"""What a ``<ros2_control>`` tag asks of ``rrbot_workshop/MujocoSystem``, checked and converted.

:func:`simulation_request` turns a :class:`~rrbot_workshop.description.HardwareInfo` into the arguments of
:func:`~.mujoco_model.build_model`: the URDF text, the actuated joints and their interfaces, the force-torque
sensors and their frames, and the numeric parameters (time step, servo gains, joint damping and friction,
gravity). Everything that cannot be simulated is rejected here, once, with the element at fault named.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo
from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware.mujoco_model import COMMAND_MODES, ServoGains

__all__ = ["JOINT_STATE_INTERFACES", "FORCE_TORQUE_INTERFACES", "SimulationRequest", "simulation_request"]

#: Joint state interfaces MujocoSystem can fill.
JOINT_STATE_INTERFACES: tuple[str, ...] = ("position", "velocity", "acceleration", "effort")
#: State interfaces of a force-torque sensor, in the order of MuJoCo's force then torque readings.
FORCE_TORQUE_INTERFACES: tuple[str, ...] = ("fx", "fy", "fz", "tx", "ty", "tz")

_DEFAULTS = ServoGains()


@dataclass
class SimulationRequest:
    """Arguments of :func:`~.mujoco_model.build_model` for one hardware component.

    Attributes:
        urdf: The whole URDF text.
        timestep: Physics time step in [s].
        command_interfaces: Joint name -> command interface names.
        force_torque_sensors: Sensor name -> frame (URDF link) name.
        gains: Joint name -> servo gains.
        joint_dynamics: Joint name -> damping [N m s/rad], friction [N m], armature [kg m^2] overrides.
        gravity: Gravity vector in [m/s^2].
        add_floor: Whether to add a ground plane.
    """

    urdf: str
    timestep: float = 0.001
    command_interfaces: dict[str, list[str]] = field(default_factory=dict)
    force_torque_sensors: dict[str, str] = field(default_factory=dict)
    gains: dict[str, ServoGains] = field(default_factory=dict)
    joint_dynamics: dict[str, dict[str, float]] = field(default_factory=dict)
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    add_floor: bool = True


def simulation_request(info: HardwareInfo) -> SimulationRequest:
    """Read and check everything MujocoSystem needs from its ``<ros2_control>`` tag.

    Args:
        info: The parsed tag; ``info.robot_description`` (or a whole ``<robot>`` in ``info.original_xml``)
            must hold the URDF.

    Raises:
        DescriptionError: If there is no URDF, a parameter is not a valid number or boolean, a joint has an
            interface that cannot be simulated, or a sensor is not a force-torque sensor with a ``frame_id``.
    """
    urdf = info.robot_description
    if not urdf and _is_urdf(info.original_xml):
        urdf = info.original_xml
    if not urdf:
        raise DescriptionError(
            "the whole URDF is needed to build the simulation, but HardwareInfo.robot_description is empty"
        )
    hw = info.hardware_parameters
    timestep = _float(hw, "timestep", 0.001, info.name)
    if timestep <= 0.0:
        raise DescriptionError(f"parameter 'timestep' of '{info.name}' must be > 0 [s]", attribute="timestep")
    default_gains = ServoGains(
        _float(hw, "position_kp", _DEFAULTS.position_kp, info.name),
        _float(hw, "position_kv", _DEFAULTS.position_kv, info.name),
        _float(hw, "velocity_kv", _DEFAULTS.velocity_kv, info.name),
    )
    request = SimulationRequest(
        urdf=urdf,
        timestep=timestep,
        gravity=_gravity(hw, info.name),
        add_floor=_bool(hw, "add_floor", True, info.name),
    )
    for joint in info.joints:
        _check_joint(joint)
        request.command_interfaces[joint.name] = [itf.name for itf in joint.command_interfaces]
        p = joint.parameters
        request.gains[joint.name] = ServoGains(
            _float(p, "position_kp", default_gains.position_kp, joint.name),
            _float(p, "position_kv", default_gains.position_kv, joint.name),
            _float(p, "velocity_kv", default_gains.velocity_kv, joint.name),
        )
        request.joint_dynamics[joint.name] = {
            key: _float(p, key, 0.0, joint.name) for key in ("damping", "friction", "armature") if key in p
        }
    request.force_torque_sensors = {sensor.name: _check_sensor(sensor) for sensor in info.sensors}
    return request


def _check_joint(joint: ComponentInfo) -> None:
    for itf in joint.state_interfaces:
        if itf.name not in JOINT_STATE_INTERFACES:
            raise DescriptionError(
                f"state interface '{joint.name}/{itf.name}' cannot be simulated "
                f"(valid: {', '.join(JOINT_STATE_INTERFACES)})",
                element=f"<joint name='{joint.name}'>",
                attribute=itf.name,
            )
    for itf in joint.command_interfaces:
        if itf.name not in COMMAND_MODES:
            raise DescriptionError(
                f"command interface '{joint.name}/{itf.name}' cannot be simulated "
                f"(valid: {', '.join(COMMAND_MODES)})",
                element=f"<joint name='{joint.name}'>",
                attribute=itf.name,
            )


def _check_sensor(sensor: ComponentInfo) -> str:
    """The ``frame_id`` of a force-torque sensor."""
    names = [itf.name for itf in sensor.state_interfaces]
    unknown = [n for n in names if n not in FORCE_TORQUE_INTERFACES]
    frame = sensor.parameters.get("frame_id", "").strip()
    if unknown or not frame:
        what = f"state interfaces {unknown}" if unknown else "no 'frame_id' parameter"
        raise DescriptionError(
            f"sensor '{sensor.name}' has {what}; only force-torque sensors can be simulated "
            f"(state interfaces among {', '.join(FORCE_TORQUE_INTERFACES)} and <param name=\"frame_id\">)",
            element=f"<sensor name='{sensor.name}'>",
        )
    return frame


def _float(params: Mapping[str, str], name: str, default: float, owner: str, minimum: float = 0.0) -> float:
    text = params.get(name, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < minimum:
        raise DescriptionError(
            f"parameter '{name}' of '{owner}' is '{text}'; expected a finite number >= {minimum}", attribute=name
        )
    return value


def _bool(params: Mapping[str, str], name: str, default: bool, owner: str) -> bool:
    text = params.get(name, "").strip().lower()
    if not text:
        return default
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    raise DescriptionError(f"parameter '{name}' of '{owner}' is '{text}'; expected true or false", attribute=name)


def _gravity(params: Mapping[str, str], owner: str) -> tuple[float, float, float]:
    text = params.get("gravity", "").strip()
    if not text or text.lower() in ("true", "1"):
        return (0.0, 0.0, -9.81)
    if text.lower() in ("false", "0"):
        return (0.0, 0.0, 0.0)
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != 3:
        raise DescriptionError(
            f"parameter 'gravity' of '{owner}' is '{text}'; expected true, false or three numbers in [m/s^2]",
            attribute="gravity",
        )
    return values[0], values[1], values[2]


def _is_urdf(text: str) -> bool:
    """True if ``text`` is an XML document whose root is ``<robot>``."""
    try:
        return ET.fromstring(text.lstrip()).tag == "robot"
    except ET.ParseError:
        return False
