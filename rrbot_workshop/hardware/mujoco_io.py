"""Where the interfaces of ``rrbot_workshop/MujocoSystem`` meet MuJoCo's arrays, worked out once.

``read`` and ``write`` run every control cycle, so the component does not look names up there. At configure time
:func:`plan_state_reads` makes a function that fills every joint and force-torque state from ``MjData`` (see
:func:`state_reader`); :func:`plan_gpio_mirrors` pairs each GPIO command with the same-named GPIO
state; and whenever the command modes change :func:`plan_command_writes` lists which command feeds which actuator
control (:func:`command_write_steps` gives the flat list and index of each command's value).
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
    "StateSource",
    "state_reader",
    "GpioMirror",
    "CommandWrite",
    "plan_state_reads",
    "plan_gpio_mirrors",
    "plan_command_writes",
    "command_write_steps",
]

#: ``(array, index, sign, handle)``: the state in ``handle`` becomes ``sign * array[index] + 0.0``.
StateSource = tuple[np.ndarray, int, float, StateInterface]
#: ``(command_store, command_slot, state_store, state_slot)``: the state repeats the command (flat lists and indices
#: of the two handles, as when the mirror was planned).
GpioMirror = tuple[list[Any], int, list[Any], int]
#: ``(command, actuator)``: the command's value becomes ``data.ctrl[actuator]``.
CommandWrite = tuple[CommandInterface, int]


def state_reader(sources: Sequence[StateSource]) -> Callable[[], None]:
    """A function that fills the states of ``sources`` from their ``MjData`` arrays.

    Every state gets ``sign * array[index] + 0.0`` (the ``+ 0.0`` turns -0.0 into 0.0) as a Python float: each array
    is converted once per call (``tolist``), and each value goes straight to its handle's slot in its flat list. The
    slots are captured here: make a new reader when the handles move (``handles.ADOPTIONS``).

    (Gathering every value with one numpy ``take`` over a strided view of ``MjData``'s buffer was measured ~0.13 µs
    faster per cycle on RRBot: not worth reading memory between MuJoCo's arrays.)

    Args:
        sources: Where each state comes from, see :data:`StateSource`.

    Raises:
        IndexError: If an index is outside its array.
        ValueError: If a sign is not 1.0 or -1.0.
    """
    per_array: dict[int, tuple[np.ndarray, list[tuple[list[Any], int, int, float]]]] = {}
    for array, index, sign, handle in sources:
        if not 0 <= index < array.size:
            raise IndexError(f"'{handle.name}' would read element {index} of an array of {array.size}")
        if sign not in (1.0, -1.0):
            raise ValueError(f"'{handle.name}' has sign {sign}; a state's sign is 1.0 or -1.0")
        reads = per_array.setdefault(id(array), (array, []))[1]
        reads.append((handle._store, handle._index, index, sign))  # noqa: SLF001 - the component's own handles
    plan = list(per_array.values())

    def read_states() -> None:
        for array, reads in plan:
            values = array.tolist()  # Python floats, one conversion per array
            for store, slot, index, sign in reads:
                store[slot] = sign * values[index] + 0.0

    return read_states


def plan_state_reads(
    info: HardwareInfo, sim: MujocoModel, data: mujoco.MjData, state_handles: Mapping[str, StateInterface]
) -> Callable[[], None]:
    """Where each joint and force-torque state interface is read from, as a ready :func:`state_reader`.

    Joint ``position`` comes from ``qpos``, ``velocity`` from ``qvel``, ``acceleration`` from ``qacc`` and
    ``effort`` from ``qfrc_actuator``; a force-torque sensor's ``fx`` ... ``tz`` from ``sensordata``, negated
    (MuJoCo reports the force the parent side applies to the child side; the component reports the load's).

    Args:
        info: The component's ``<ros2_control>`` tag.
        sim: The compiled model with its joint and sensor tables.
        data: The live data whose arrays are read.
        state_handles: Full name -> exported state interface; interfaces missing here are left out.
    """
    sources: list[StateSource] = []
    arrays = {"position": (data.qpos, "q"), "velocity": (data.qvel, "v"), "acceleration": (data.qacc, "v"),
              "effort": (data.qfrc_actuator, "v")}  # one view each (each attribute access makes a new one)
    for joint in info.joints:
        binding = sim.joints[joint.name]
        for itf in joint.state_interfaces:
            handle = state_handles.get(f"{joint.name}/{itf.name}")
            if handle is not None:
                array, kind = arrays[itf.name]
                sources.append((array, binding.qpos_adr if kind == "q" else binding.dof_adr, 1.0, handle))
    sensordata = data.sensordata
    for sensor in info.sensors:
        ft = sim.force_torque_sensors[sensor.name]
        for itf in sensor.state_interfaces:
            handle = state_handles.get(f"{sensor.name}/{itf.name}")
            if handle is not None:
                k = FORCE_TORQUE_INTERFACES.index(itf.name)
                sources.append((sensordata, ft.force_adr + k if k < 3 else ft.torque_adr + k - 3, -1.0, handle))
    return state_reader(sources)


def plan_gpio_mirrors(
    info: HardwareInfo, state_handles: Mapping[str, StateInterface], command_handles: Mapping[str, CommandInterface]
) -> list[GpioMirror]:
    """Pair each GPIO command with the GPIO state of the same name; set NaN GPIO states to 0.

    GPIOs have no physics: a state that has a same-named command repeats it, and the other GPIO states
    (inputs with nothing wired to them) read 0 rather than NaN unless they were given a value. The mirrors hold the
    handles' flat lists and indices: plan them again when the handles move (``handles.ADOPTIONS``).
    """
    mirrors: list[GpioMirror] = []
    for gpio in info.gpios:
        for itf in gpio.command_interfaces:
            name = f"{gpio.name}/{itf.name}"
            if name in command_handles and name in state_handles:
                command, state = command_handles[name], state_handles[name]
                mirrors.append((command._store, command._index, state._store, state._index))  # noqa: SLF001
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
