"""Command modes of ``rrbot_workshop/MujocoSystem``: at most one of position, velocity, effort per joint.

A simulated joint has one actuator per declared command interface, and only one of them may drive it at a
time. :func:`command_modes_after_switch` applies a controller switch (the interfaces about to be claimed and
released) to the current mode of each joint and refuses a switch that would leave a joint with two modes;
the component calls it both to prepare and to perform the switch. GPIO command interfaces have no mode.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware.mujoco_model import COMMAND_MODES

__all__ = ["command_modes_after_switch"]


def command_modes_after_switch(
    info: HardwareInfo, modes: Mapping[str, str | None], start: Sequence[str], stop: Sequence[str]
) -> dict[str, str | None]:
    """The mode of every joint once ``stop`` is released and ``start`` is claimed.

    Args:
        info: The component's ``<ros2_control>`` tag.
        modes: Joint name -> the command interface driving it now, or None for a passive joint.
        start: Full names of the command interfaces about to be claimed.
        stop: Full names of the command interfaces about to be released.

    Returns:
        Joint name -> command interface name or None (a new dict; ``modes`` is not changed).

    Raises:
        ValueError: For an interface the component does not have, two modes started for one joint, or a mode
            started on a joint whose current mode is not stopped in the same switch.
    """
    declared = {itf.name for joint in info.joints for itf in joint.command_interfaces}
    declared_full = {f"{joint.name}/{itf.name}" for joint in info.joints for itf in joint.command_interfaces}
    gpio_full = {f"{gpio.name}/{itf.name}" for gpio in info.gpios for itf in gpio.command_interfaces}
    after = dict(modes)
    for key in stop:
        if key in declared_full:
            joint, _, interface = key.rpartition("/")
            if after.get(joint) == interface:
                after[joint] = None
    started: dict[str, list[str]] = {}
    for key in start:
        if key in gpio_full:
            continue
        if key not in declared_full:
            valid = sorted(declared_full | gpio_full)
            raise ValueError(f"unknown command interface '{key}' (valid: {', '.join(valid)})")
        joint, _, interface = key.rpartition("/")
        started.setdefault(joint, []).append(interface)
    for joint, interfaces in started.items():
        if len(interfaces) > 1:
            raise ValueError(
                f"joint '{joint}' cannot be driven through {' and '.join(sorted(interfaces))} at once; "
                f"choose one of {', '.join(m for m in COMMAND_MODES if m in declared)}"
            )
        if after[joint] is not None and after[joint] != interfaces[0]:
            raise ValueError(
                f"joint '{joint}' is already driven through '{after[joint]}'; stop '{joint}/{after[joint]}' "
                f"in the same switch to start '{joint}/{interfaces[0]}'"
            )
        after[joint] = interfaces[0]
    return after
