"""Where the interfaces of ``rrbot_workshop/MujocoSystem`` meet MuJoCo's arrays, worked out once.

``read`` and ``write`` run every control cycle, so the component does not look names up there. At configure time
:func:`plan_state_reads` makes a function that fills every joint and force-torque state from ``MjData`` with a few
numpy calls (see :func:`state_reader`); :func:`plan_gpio_mirrors` pairs each GPIO command with the same-named GPIO
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


def state_reader(sources: Sequence[StateSource], buffer_bytes: int) -> Callable[[], None]:
    """A function that fills the states of ``sources`` from their ``MjData`` arrays in a few numpy calls.

    Every state gets ``sign * array[index] + 0.0`` (the ``+ 0.0`` turns -0.0 into 0.0) as a Python float. numpy
    computes it with one subtraction ``a - b``: ``value - (-0.0)`` where the sign is +1 and ``0.0 - value`` where it
    is -1, the same IEEE results bit for bit (signed zeros and NaNs included). The gathered values and the constant
    zeros sit in one array laid out so that ``b`` and ``a`` are its two halves::

        [-0.0 per kept sign | values of the negated states | values of the kept ones | 0.0 per negated]
         \\__________________ b __________________/\\__________________ a __________________/

    ``qpos``, ``qvel``, ``qacc``, ``qfrc_actuator`` and ``sensordata`` are all slices of the one buffer ``MjData``
    allocates, so a strided view starting at the lowest of them reaches every element read and one ``take``
    gathers them all (only those elements are ever read). Should the arrays not lie within ``buffer_bytes`` of each
    other, they are first copied into one array of the reader's own (same values, a few more calls). The handles'
    flat lists and indices are captured here: make a new reader when the handles move (``handles.ADOPTIONS``).

    Args:
        sources: Where each state comes from, see :data:`StateSource`.
        buffer_bytes: Size of the buffer the arrays are expected to share (``MjData.nbuffer``).

    Raises:
        IndexError: If an index is outside its array.
        ValueError: If a sign is not 1.0 or -1.0.
    """
    for array, index, sign, handle in sources:
        if not 0 <= index < array.size:
            raise IndexError(f"'{handle.name}' would read element {index} of an array of {array.size}")
        if sign not in (1.0, -1.0):
            raise ValueError(f"'{handle.name}' has sign {sign}; a state's sign is 1.0 or -1.0")
    arrays = list({id(array): array for array, _, _, _ in sources}.values())
    source, offsets = _shared_view(arrays, buffer_bytes)
    copies: list[tuple[np.ndarray, np.ndarray]] = []  # (target, array), copied before each gather
    if source is None:
        source, start = np.empty(sum(array.size for array in arrays)), 0
        for array in arrays:
            offsets[id(array)] = start
            copies.append((source[start:start + array.size], array))
            start += array.size
    stores: dict[int, int] = {}
    for _, _, _, handle in sources:
        stores.setdefault(id(handle._store), len(stores))  # noqa: SLF001
    # Kept signs first, each group by flat list and index: neighbouring slots become one slice assignment.
    order = sorted(sources, key=lambda s: (s[2] < 0.0, stores[id(s[3]._store)], s[3]._index))  # noqa: SLF001
    n, kept = len(order), sum(1 for _, _, sign, _ in order if sign > 0.0)
    halves = np.concatenate([np.full(kept, -0.0), np.empty(n), np.zeros(n - kept)])
    b, a, gathered = halves[:n], halves[n:], halves[kept:kept + n]
    indices = np.array([offsets[id(array)] + index for array, index, _, _ in order[kept:] + order[:kept]], np.intp)
    result = np.empty(n)
    take, subtract = source.take, np.subtract
    runs: list[tuple[list[Any], int, int, int, int]] = []  # store[first_slot:end_slot] = values[first:end]
    for position, (_, _, _, handle) in enumerate(order):
        store, slot = handle._store, handle._index  # noqa: SLF001
        if runs and runs[-1][0] is store and runs[-1][2] == slot:
            runs[-1] = (store, runs[-1][1], slot + 1, runs[-1][3], position + 1)
        else:
            runs.append((store, slot, slot + 1, position, position + 1))

    if not copies and len(runs) == 1:  # the usual case: the resource manager's flat list, neighbouring slots
        store, first_slot, end_slot, _, _ = runs[0]

        def read_states() -> None:
            take(indices, None, gathered, "clip")  # "clip": no bounds pass (the indices were checked)
            subtract(a, b, result)
            store[first_slot:end_slot] = result.tolist()

        return read_states

    # Handles in lists of their own (a component used without a resource manager) make runs of one: set those
    # one by one, cheaper than a slice each.
    singles = [(store, slot, first) for store, slot, end_slot, first, _ in runs if end_slot == slot + 1]
    runs = [run for run in runs if run[2] > run[1] + 1]

    def read_states_in_runs() -> None:
        for target, array in copies:
            np.copyto(target, array)
        take(indices, None, gathered, "clip")
        subtract(a, b, result)
        values = result.tolist()
        for store, first_slot, end_slot, first, end in runs:
            store[first_slot:end_slot] = values[first:end]
        for store, slot, position in singles:
            store[slot] = values[position]

    return read_states_in_runs


def _shared_view(arrays: Sequence[np.ndarray], buffer_bytes: int) -> tuple[np.ndarray | None, dict[int, int]]:
    """A read-only 1-D view reaching every element of ``arrays``, and each array's offset in it (by ``id``).

    Returns ``(None, {})`` unless the arrays are 1-D float64 arrays with unit stride, lying within ``buffer_bytes``
    of each other at whole-element distances.
    """
    if not arrays or any(a.dtype != np.float64 or a.ndim != 1 or a.strides[0] != 8 for a in arrays):
        return None, {}
    addresses = {id(a): a.__array_interface__["data"][0] for a in arrays}
    base = min(arrays, key=lambda a: addresses[id(a)])
    distances = {key: address - addresses[id(base)] for key, address in addresses.items()}
    end = max(distances[id(a)] + 8 * a.size for a in arrays)
    if end > buffer_bytes or any(d % 8 for d in distances.values()):
        return None, {}
    view = np.lib.stride_tricks.as_strided(base, shape=(end // 8,), strides=(8,), writeable=False)
    return view, {key: d // 8 for key, d in distances.items()}


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
    return state_reader(sources, data.nbuffer)


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
