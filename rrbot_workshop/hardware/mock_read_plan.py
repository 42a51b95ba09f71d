"""The mock's prepared read: what ``read`` does without ``calculate_dynamics``, worked out once.

Without dynamics, the read of ``mock_components/GenericSystem`` is the same copies in every cycle: each finite position
command to its state (plus the offset), each other joint command to the state of the same name, mimic joints from
their source, and sensor and GPIO commands to their states when the mock is asked to. :func:`build_read_steps` lists
these copies once, in the order of the general path; :func:`runs_of_one_kind` groups consecutive steps of one kind and
gives each handle as its flat list and index; :func:`run_read_plan` then only moves numbers.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware_interface.handles import CommandInterface, StateInterface
from rrbot_workshop.middleware.lifecycle import ReturnType

_log = logging.getLogger("rrbot_workshop.hardware.mock")

__all__ = ["FOLLOW", "MIRROR_FLOAT", "MIRROR_BOOL", "MIMIC", "build_read_steps", "runs_of_one_kind", "run_read_plan"]

POSITION = "position"
_MODES = ("position", "velocity", "acceleration")
_FLOAT_TYPES = ("double", "float32")
#: The kinds of steps: follow a command (with an offset), mirror a float or a bool command, follow a mimicked joint.
FOLLOW, MIRROR_FLOAT, MIRROR_BOOL, MIMIC = range(4)


def build_read_steps(
    info: HardwareInfo,
    states: Mapping[str, StateInterface],
    commands: Mapping[str, CommandInterface],
    offset: float,
    custom: str,
    custom_offset: float,
    mock_sensor_commands: bool,
    mock_gpio_commands: bool,
) -> list[tuple[int, Any, Any, float, float]]:
    """The steps of a read without ``calculate_dynamics``, in the order of the general path, with the handles
    looked up once: the cycle then only moves numbers.

    Args:
        info: The component's ``<ros2_control>`` tag.
        states: Its state handles by full name.
        commands: Its command handles by full name.
        offset: What a position command adds to the position state (``position_state_following_offset``, unless
            ``custom_interface_with_following_offset`` takes it).
        custom: ``custom_interface_with_following_offset`` ("" for none).
        custom_offset: ``position_state_following_offset``.
        mock_sensor_commands: Sensor states mirror their commands.
        mock_gpio_commands: Every GPIO state mirrors a command.
    """
    plan: list[tuple[int, Any, Any, float, float]] = []
    joints = info.joints

    def mirror(name: str) -> None:
        kind = states[name].data_type
        if kind in _FLOAT_TYPES:
            plan.append((MIRROR_FLOAT, commands[name], states[name], 0.0, 1.0))
        elif kind == "bool":
            plan.append((MIRROR_BOOL, commands[name], states[name], 0.0, 1.0))

    for joint in joints:
        key = f"{joint.name}/{POSITION}"
        if key in commands and key in states:
            plan.append((FOLLOW, commands[key], states[key], offset, 1.0))
    for joint in joints:
        for itf in joint.state_interfaces:
            name = f"{joint.name}/{itf.name}"
            if itf.name == POSITION or name not in states:
                continue
            if name in commands:
                mirror(name)
            position_cmd = f"{joint.name}/{POSITION}"
            if custom and itf.name == custom and position_cmd in commands:
                plan.append((FOLLOW, commands[position_cmd], states[name], custom_offset, 1.0))
    for mimic in info.mimic_joints:
        follower, source = joints[mimic.joint_index].name, joints[mimic.mimicked_joint_index].name
        for mode in _MODES:
            dst, src = f"{follower}/{mode}", f"{source}/{mode}"
            if dst in states and src in states:
                plan.append((MIMIC, states[src], states[dst], mimic.offset if mode == POSITION else 0.0,
                             mimic.multiplier))
    groups = [(info.sensors, True)] if mock_sensor_commands else []
    groups.append((info.gpios, mock_gpio_commands))
    for components, every_state in groups:
        for comp in components:
            for itf in comp.state_interfaces if every_state else comp.command_interfaces:
                name = f"{comp.name}/{itf.name}"
                if name in commands and name in states:
                    mirror(name)
    return plan


def runs_of_one_kind(
    plan: list[tuple[int, Any, Any, float, float]],
) -> list[tuple[int, list[tuple[list[Any], int, list[Any], int, float, float]]]]:
    """The plan's steps grouped into consecutive runs of one kind, in their order, each handle given as its flat
    list and index."""
    runs: list[tuple[int, list[tuple[list[Any], int, list[Any], int, float, float]]]] = []
    for kind, source, target, offset, gain in plan:
        if not runs or runs[-1][0] != kind:
            runs.append((kind, []))
        runs[-1][1].append((source._store, source._index, target._store, target._index, offset, gain))
    return runs


def run_read_plan(runs: list[tuple[int, list[tuple[list[Any], int, list[Any], int, float, float]]]]) -> ReturnType:
    """Run the prepared read; ERROR if a mirrored float command is infinite, or holds something that is not a
    number (None written by a controller, a string): said in one line, not a traceback."""
    try:
        return _run(runs)
    except TypeError:
        _log.error("mock hardware: a command interface holds a value that is not a number; the read fails "
                   "(write floats to double interfaces)")
        return ReturnType.ERROR


def _run(runs: list[tuple[int, list[tuple[list[Any], int, list[Any], int, float, float]]]]) -> ReturnType:
    # the handles are the component's own: their values are read and written in their flat lists directly, a
    # run of steps of one kind at a time (the order of the steps is kept: a mimic joint reads what the steps
    # before it wrote)
    for kind, steps in runs:
        if kind == 0:  # follow a command, when it is finite (v - v is 0.0 exactly for finite numbers)
            for src, i, dst, j, offset, _gain in steps:
                value = src[i]
                if value - value == 0.0:
                    dst[j] = value + offset
        elif kind == 1:  # mirror a float command; an infinite one is an error, NaN leaves the state
            for src, i, dst, j, _offset, _gain in steps:
                value = src[i]
                if value == value:
                    if value - value != 0.0:
                        return ReturnType.ERROR
                    dst[j] = value
        elif kind == 2:
            for src, i, dst, j, _offset, _gain in steps:
                dst[j] = bool(src[i])
        else:  # a mimic joint
            for src, i, dst, j, offset, gain in steps:
                dst[j] = offset + gain * src[i]
    return ReturnType.OK
