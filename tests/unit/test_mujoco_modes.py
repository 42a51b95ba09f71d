"""Tests of rrbot_workshop.hardware.mujoco_modes.command_modes_after_switch (one mode per joint)."""

from __future__ import annotations

import pytest

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo
from rrbot_workshop.hardware.mujoco_modes import command_modes_after_switch


def _info() -> HardwareInfo:
    joint = ComponentInfo(name="joint1", type="joint",
                          command_interfaces=[InterfaceInfo(name="position"), InterfaceInfo(name="effort")])
    gpio = ComponentInfo(name="io", type="gpio", command_interfaces=[InterfaceInfo(name="out")])
    return HardwareInfo(name="arm", type="system", joints=[joint], gpios=[gpio])


def test_switch_returns_new_modes_and_leaves_the_current_ones():
    current = {"joint1": "position"}
    after = command_modes_after_switch(_info(), current, ["joint1/effort", "io/out"], ["joint1/position"])
    assert after == {"joint1": "effort"} and current == {"joint1": "position"}


def test_unknown_interface_raises_value_error_listing_the_valid_ones():
    with pytest.raises(ValueError, match="joint1/effort, joint1/position"):
        command_modes_after_switch(_info(), {"joint1": None}, ["joint1/velocity"], [])


def test_second_mode_without_stopping_the_first_raises_value_error():
    with pytest.raises(ValueError, match="already driven through 'position'"):
        command_modes_after_switch(_info(), {"joint1": "position"}, ["joint1/effort"], [])
