"""Where the interfaces of ``rrbot_workshop/MujocoSystem`` meet MuJoCo's arrays, worked out once.

``read`` and ``write`` run every control cycle, so the component does not look names up there: at
configure time :func:`plan_state_reads` lists, for every ``MjData`` array read, the state interfaces it fills, each
with its index and sign (the array is turned into Python floats once per cycle); :func:`plan_gpio_mirrors` pairs each
GPIO command with the same-named GPIO state; and whenever the command modes change :func:`plan_command_writes` lists which
command feeds which actuator control (:func:`command_write_steps` gives the flat list and index of each command's
value). The cyclic code is then a flat loop over these lists.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import mujoco
import numpy as np

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware.mujoco_config import FORCE_TORQUE_INTERFACES
from rrbot_workshop.hardware.mujoco_model import MujocoModel
from rrbot_workshop.hardware_interface.handles import CommandInterface, StateInterface

__all__ = [
    "StateRead",
    "GpioMirror",
    "CommandWrite",
    "plan_state_reads",
    "plan_gpio_mirrors",
    "plan_command_writes",
    "command_write_steps",
]

#: ``(array, [(store, slot, index, sign), ...])``: each state (the value in ``store[slot]``, its handle's flat list
#: and index) becomes ``sign * array[index]``.
StateRead = tuple[np.ndarray, list[tuple[list[Any], int, int, float]]]
#: ``(get_command, set_state)``: the state repeats the command.
GpioMirror = tuple[Callable[[], Any], Callable[[Any], None]]
#: ``(command, actuator)``: the command's value becomes ``data.ctrl[actuator]``.
CommandWrite = tuple[CommandInterface, int]


def plan_state_reads(
    info: HardwareInfo, sim: MujocoModel, data: mujoco.MjData, state_handles: Mapping[str, StateInterface]
) -> list[StateRead]:
    """Where each joint and force-torque state interface is read from.

    Joint ``position`` comes from ``qpos``, ``velocity`` from ``qvel``, ``acceleration`` from ``qacc`` and
    ``effort`` from ``qfrc_actuator``; a force-torque sensor's ``fx`` ... ``tz`` from ``sensordata``, negated
    (MuJoCo reports the force the parent side applies to the child side; the component reports the load's).

    Args:
        info: The component's ``<ros2_control>`` tag.
        sim: The compiled model with its joint and sensor tables.
        data: The live data whose arrays are read.
        state_handles: Full name -> exported state interface; interfaces missing here are left out.
    """
    reads: dict[int, StateRead] = {}

    def add(array: np.ndarray, handle: StateInterface, index: int, sign: float) -> None:
        reads.setdefault(id(array), (array, []))[1].append((handle._store, handle._index, index, sign))  # noqa: SLF001

    sources = {"position": (data.qpos, "q"), "velocity": (data.qvel, "v"), "acceleration": (data.qacc, "v"),
               "effort": (data.qfrc_actuator, "v")}
    for joint in info.joints:
        binding = sim.joints[joint.name]
        for itf in joint.state_interfaces:
            handle = state_handles.get(f"{joint.name}/{itf.name}")
            if handle is not None:
                array, kind = sources[itf.name]
                add(array, handle, binding.qpos_adr if kind == "q" else binding.dof_adr, 1.0)
    sensordata = data.sensordata  # one view (each attribute access makes a new one)
    for sensor in info.sensors:
        ft = sim.force_torque_sensors[sensor.name]
        for itf in sensor.state_interfaces:
            handle = state_handles.get(f"{sensor.name}/{itf.name}")
            if handle is not None:
                k = FORCE_TORQUE_INTERFACES.index(itf.name)
                adr = ft.force_adr + k if k < 3 else ft.torque_adr + k - 3
                add(sensordata, handle, adr, -1.0)
    return list(reads.values())


def plan_gpio_mirrors(
    info: HardwareInfo, state_handles: Mapping[str, StateInterface], command_handles: Mapping[str, CommandInterface]
) -> list[GpioMirror]:
    """Pair each GPIO command with the GPIO state of the same name; set NaN GPIO states to 0.

    GPIOs have no physics: a state that has a same-named command repeats it, and the other GPIO states
    (inputs with nothing wired to them) read 0 rather than NaN unless they were given a value.
    """
    mirrors: list[GpioMirror] = []
    for gpio in info.gpios:
        for itf in gpio.command_interfaces:
            name = f"{gpio.name}/{itf.name}"
            if name in command_handles and name in state_handles:
                mirrors.append((command_handles[name].get_value, state_handles[name].set_value))
        for itf in gpio.state_interfaces:  # nothing is wired to the simulated inputs: they read 0, not NaN
            handle = state_handles.get(f"{gpio.name}/{itf.name}")
            value = handle.get_value() if handle is not None else None
            if isinstance(value, float) and math.isnan(value):
                handle.set_value(0.0)  # type: ignore[union-attr]
    return mirrors


def plan_command_writes(
    modes: Mapping[str, str | None], sim: MujocoModel, command_handles: Mapping[str, CommandInterface]
) -> list[CommandWrite]:
    """For each joint with a command mode, its command interface and the actuator of that mode.

    Args:
        modes: Joint name -> the command interface driving it, or None for a passive joint.
        sim: The compiled model with its actuator tables.
        command_handles: Full name -> exported command interface.
    """
    plan: list[CommandWrite] = []
    for joint, mode in modes.items():
        name = f"{joint}/{mode}"
        if mode is not None and name in command_handles:
            plan.append((command_handles[name], sim.joints[joint].actuators[mode]))
    return plan


def command_write_steps(plan: Sequence[CommandWrite]) -> list[tuple[list[Any], int, int]]:
    """``(store, slot, actuator)`` for each command of ``plan``: the flat list and index its value is in now.

    Build them again when the handles move (``handles.ADOPTIONS``).
    """
    return [(command._store, command._index, actuator) for command, actuator in plan]  # noqa: SLF001
