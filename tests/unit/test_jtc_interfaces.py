"""Tests of rrbot_workshop.controllers.jtc_interfaces.JointInterfaces (the JTC's sorted loans)."""

from __future__ import annotations

import math

import pytest

from rrbot_workshop.controllers.jtc_interfaces import JointInterfaces
from rrbot_workshop.hardware_interface.handles import (
    CommandInterface,
    LoanedCommandInterface,
    LoanedStateInterface,
    StateInterface,
)


def _loans(values: dict[str, float], cls: type) -> list:
    handle = CommandInterface if cls is LoanedCommandInterface else StateInterface
    out = []
    for name, value in values.items():
        prefix, _, interface = name.rpartition("/")
        out.append(cls(handle(prefix, interface, initial_value=value)))
    return out


def _io(commands: dict[str, float], states: dict[str, float], command_joints=("j1", "j2"), cmd_to_joint=(0, 1)):
    command_kinds = sorted({n.rpartition("/")[2] for n in commands})
    state_kinds = sorted({n.rpartition("/")[2] for n in states})
    cmd_loans = _loans(commands, LoanedCommandInterface)
    io = JointInterfaces(["j1", "j2"], list(command_joints), command_kinds, state_kinds, cmd_loans,
                         _loans(states, LoanedStateInterface), list(cmd_to_joint))
    return io, {loan.name: loan for loan in cmd_loans}


def test_missing_interface_raises_key_error_naming_it():
    with pytest.raises(KeyError, match="j2/position"):
        _io({"j1/position": 0.0}, {"j1/position": 0.0, "j2/position": 0.0})


def test_accelerations_are_read_only_with_velocities():
    io, _ = _io({"j1/position": 0.0, "j2/position": 0.0},
                {"j1/position": 1.0, "j2/position": 2.0, "j1/acceleration": 3.0, "j2/acceleration": 4.0})
    state = io.read_state()
    assert state.positions == [1.0, 2.0] and state.velocities == [] and state.accelerations == []


def test_joints_without_a_command_joint_get_the_fill_value():
    io, _ = _io({"j2/velocity": 5.0}, {"j1/position": 0.0, "j2/position": 0.0}, command_joints=("j2",),
                cmd_to_joint=(1,))
    values = io.command_values("velocity", math.nan)
    assert math.isnan(values[0]) and values[1] == 5.0


def test_state_from_commands_is_none_while_a_command_is_nan():
    io, loans = _io({"j1/position": math.nan, "j2/position": 0.5}, {"j1/position": 0.0, "j2/position": 0.0})
    assert io.state_from_commands() is None
    loans["j1/position"].set_value(0.25)
    assert io.state_from_commands().positions == [0.25, 0.5]  # type: ignore[union-attr]


def test_positions_to_hold_fall_back_to_the_measured_position():
    io, _ = _io({"j1/position": math.nan, "j2/position": 0.5}, {"j1/position": 1.5, "j2/position": 9.0})
    assert io.positions_to_hold() == [1.5, 0.5]


def test_write_ignores_a_field_shorter_than_the_joints():
    io, loans = _io({"j1/position": 0.0, "j2/position": 0.0}, {"j1/position": 0.0, "j2/position": 0.0})
    io.write("position", [1.0])
    assert [loans[n].get_value() for n in ("j1/position", "j2/position")] == [0.0, 0.0]
    io.write("position", [1.0, 2.0])
    assert [loans[n].get_value() for n in ("j1/position", "j2/position")] == [1.0, 2.0]


def test_stop_motion_zeroes_velocity_and_keeps_position():
    io, loans = _io({"j1/position": 0.7, "j2/position": 0.8, "j1/velocity": 1.0, "j2/velocity": 2.0},
                    {"j1/position": 0.0, "j2/position": 0.0})
    io.stop_motion()
    assert {n: loan.get_value() for n, loan in loans.items()} == {
        "j1/position": 0.7, "j2/position": 0.8, "j1/velocity": 0.0, "j2/velocity": 0.0}


def test_command_point_fills_only_the_commanded_fields():
    io, _ = _io({"j1/position": 0.1, "j2/position": 0.2}, {"j1/position": 0.0, "j2/position": 0.0})
    point = io.command_point()
    assert point.positions == [0.1, 0.2] and point.velocities == [] and point.effort == []
