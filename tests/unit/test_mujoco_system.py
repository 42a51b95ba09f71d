"""Tests of rrbot_workshop.hardware.mujoco_system.MujocoSystem on a tiny inline pendulum."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo
from rrbot_workshop.hardware.mujoco_system import MujocoSystem
from rrbot_workshop.hardware_interface.handles import adopt
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

_INERTIA = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'

# world -> base_link (fixed, 1 m up) -> joint1 (about y) -> link1 (1 kg, horizontal at q = 0, COM 0.5 m out)
#   -> ft_frame (fixed, 1 m out, z up at q = 0) -> load (fixed, 2 kg at the sensor's origin).
_PENDULUM = f"""<?xml version="1.0"?>
<robot name="pendulum">
  <link name="world"/>
  <joint name="base_joint" type="fixed"><parent link="world"/><child link="base_link"/><origin xyz="0 0 1"/></joint>
  <link name="base_link"><inertial><mass value="1"/>{_INERTIA}</inertial></link>
  <joint name="joint1" type="revolute"><parent link="base_link"/><child link="link1"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="5" effort="200"/></joint>
  <link name="link1"><inertial><origin xyz="0.5 0 0"/><mass value="1"/>{_INERTIA}</inertial></link>
  <joint name="ft_joint" type="fixed"><parent link="link1"/><child link="ft_frame"/><origin xyz="1 0 0"/></joint>
  <link name="ft_frame"/>
  <joint name="load_joint" type="fixed"><parent link="ft_frame"/><child link="load"/></joint>
  <link name="load"><inertial><mass value="2"/>{_INERTIA}</inertial></link>
</robot>
"""

_LOAD_WEIGHT = 2.0 * 9.81  # [N]
_GRAVITY_TORQUE = 9.81 * (1.0 * 0.5 + 2.0 * 1.0)  # [N m] about joint1 at q = 0


def _itfs(*names: str, **initial: str) -> list[InterfaceInfo]:
    return [InterfaceInfo(name=n, initial_value=initial.get(n, "")) for n in names]


def _info(
    commands: tuple[str, ...] = ("position", "velocity", "effort"),
    hardware: dict[str, str] | None = None,
    joint_params: dict[str, str] | None = None,
    initial_position: str = "",
) -> HardwareInfo:
    initial = {"position": initial_position} if initial_position else {}
    joint = ComponentInfo(
        name="joint1",
        type="joint",
        command_interfaces=_itfs(*commands),
        state_interfaces=_itfs("position", "velocity", "acceleration", "effort", **initial),
        parameters=dict(joint_params or {}),
    )
    sensor = ComponentInfo(
        name="tcp_fts_sensor",
        type="sensor",
        state_interfaces=_itfs("fx", "fy", "fz", "tx", "ty", "tz"),
        parameters={"frame_id": "ft_frame"},
    )
    gpio = ComponentInfo(
        name="flange_gpios",
        type="gpio",
        command_interfaces=_itfs("digital_out_1"),
        state_interfaces=_itfs("digital_in_1", "digital_out_1"),
    )
    return HardwareInfo(
        name="pendulum",
        type="system",
        hardware_plugin_name="rrbot_workshop/MujocoSystem",
        hardware_parameters={"position_kp": "5000", "position_kv": "200", **(hardware or {})},
        joints=[joint],
        sensors=[sensor],
        gpios=[gpio],
        robot_description=_PENDULUM,
    )


def _system(info: HardwareInfo | None = None, activate: bool = True) -> MujocoSystem:
    system = MujocoSystem()
    assert system.on_init(info or _info()) is CallbackReturn.SUCCESS
    system._register_handles(system.export_state_interfaces(), system.export_command_interfaces())
    assert system.on_configure(State.UNCONFIGURED) is CallbackReturn.SUCCESS
    if activate:
        assert system.on_activate(State.INACTIVE) is CallbackReturn.SUCCESS
    return system


def _switch(system: MujocoSystem, start: list[str], stop: list[str] = ()) -> ReturnType:  # type: ignore[assignment]
    result = system.prepare_command_mode_switch(start, list(stop))
    if result is ReturnType.OK:
        result = system.perform_command_mode_switch(start, list(stop))
    return result


def _run(system: MujocoSystem, seconds: float, period: float = 0.01) -> None:
    for _ in range(round(seconds / period)):
        system.read(0.0, period)
        system.write(0.0, period)


# --------------------------------------------------------------------------- on_init
@pytest.mark.parametrize(
    "change",
    [
        lambda i: setattr(i, "robot_description", ""),
        lambda i: i.hardware_parameters.update(timestep="fast"),
        lambda i: i.hardware_parameters.update(gravity="down"),
        lambda i: i.joints[0].state_interfaces.append(InterfaceInfo(name="temperature")),
        lambda i: i.joints[0].command_interfaces.append(InterfaceInfo(name="acceleration")),
        lambda i: i.sensors[0].parameters.pop("frame_id"),
        lambda i: i.sensors[0].state_interfaces.append(InterfaceInfo(name="orientation.x")),
    ],
    ids=["no-urdf", "bad-timestep", "bad-gravity", "joint-state", "joint-command", "no-frame-id", "imu-sensor"],
)
def test_on_init_rejects_what_cannot_be_simulated(change, caplog: pytest.LogCaptureFixture) -> None:  # type: ignore[no-untyped-def]
    """on_init returns ERROR and logs the reason for descriptions it cannot simulate."""
    info = _info()
    change(info)
    with caplog.at_level(logging.ERROR):
        assert MujocoSystem().on_init(info) is CallbackReturn.ERROR
    assert "pendulum" in caplog.text


def test_urdf_may_come_from_original_xml() -> None:
    """With no robot_description, a whole <robot> document in original_xml is used."""
    info = _info()
    info.original_xml, info.robot_description = info.robot_description, ""
    assert MujocoSystem().on_init(info) is CallbackReturn.SUCCESS


def test_joint_parameters_reach_the_model() -> None:
    """Joint <param>s damping and friction become MuJoCo dof damping and friction loss."""
    system = _system(_info(joint_params={"damping": "1.5", "friction": "0.25"}), activate=False)
    model = system.get_model()
    assert model.dof_damping[0] == 1.5 and model.dof_frictionloss[0] == 0.25


# --------------------------------------------------------------------------- physics
def test_unclaimed_joint_is_passive_and_gravity_moves_it() -> None:
    """With no command mode, joint1 swings under gravity (positive direction for this pendulum)."""
    system = _system()
    _run(system, 0.3)
    assert system.get_state("joint1/position") > 0.1
    assert system.command_modes == {"joint1": None}


def test_position_mode_holds_against_gravity() -> None:
    """After a switch to position mode the joint holds where it was within 0.01 rad, its effort ~ gravity."""
    system = _system()
    assert _switch(system, ["joint1/position"]) is ReturnType.OK
    assert system.get_command("joint1/position") == 0.0
    _run(system, 2.0)
    assert abs(system.get_state("joint1/position")) < 0.01
    assert system.get_state("joint1/effort") == pytest.approx(-_GRAVITY_TORQUE, rel=0.02)


def test_position_mode_tracks_a_command() -> None:
    """A position command of 0.5 rad is reached within 0.01 rad."""
    system = _system()
    _switch(system, ["joint1/position"])
    system.set_command("joint1/position", 0.5)
    _run(system, 2.0)
    assert system.get_state("joint1/position") == pytest.approx(0.5, abs=0.01)


def test_velocity_mode_tracks_a_command_without_gravity() -> None:
    """In velocity mode with gravity off, the joint turns at the commanded 0.5 rad/s."""
    system = _system(_info(hardware={"gravity": "false"}))
    _switch(system, ["joint1/velocity"])
    assert system.get_command("joint1/velocity") == 0.0
    system.set_command("joint1/velocity", 0.5)
    _run(system, 1.0)
    assert system.get_state("joint1/velocity") == pytest.approx(0.5, abs=0.01)
    assert system.get_state("joint1/position") == pytest.approx(0.5, abs=0.05)


def test_effort_mode_is_seeded_with_the_torque_that_holds_the_joint() -> None:
    """Switching to effort seeds the command with the gravity torque; the effort state follows the command."""
    system = _system()
    _switch(system, ["joint1/effort"])
    assert system.get_command("joint1/effort") == pytest.approx(-_GRAVITY_TORQUE, rel=1e-6)
    _run(system, 0.2)
    assert abs(system.get_state("joint1/position")) < 0.01
    system.set_command("joint1/effort", 0.0)
    _run(system, 0.2)
    assert system.get_state("joint1/effort") == 0.0 and system.get_state("joint1/position") > 0.05


def test_nan_command_keeps_the_last_control() -> None:
    """A NaN position command is ignored: the joint keeps holding the previous target."""
    system = _system()
    _switch(system, ["joint1/position"])
    system.set_command("joint1/position", 0.3)
    _run(system, 1.0)
    system.set_command("joint1/position", math.nan)
    assert system.write(0.0, 0.01) is ReturnType.OK
    _run(system, 1.0)
    assert system.get_state("joint1/position") == pytest.approx(0.3, abs=0.01)


def test_acceleration_state_is_reported() -> None:
    """A passive joint released at rest accelerates at about torque / inertia."""
    system = _system()
    system.read(0.0, 0.001)
    assert system.get_state("joint1/acceleration") > 1.0


def test_force_torque_sensor_reads_the_hanging_load() -> None:
    """Held still, the sensor reads the 2 kg load pulling down (fz = -19.62 N) and no side force."""
    system = _system()
    _switch(system, ["joint1/position"])
    _run(system, 1.0)
    assert system.get_state("tcp_fts_sensor/fz") == pytest.approx(-_LOAD_WEIGHT, rel=0.02)
    assert abs(system.get_state("tcp_fts_sensor/fx")) < 0.5 and abs(system.get_state("tcp_fts_sensor/fy")) < 1e-6
    assert abs(system.get_state("tcp_fts_sensor/ty")) < 0.1


def test_gpio_states_mirror_commands() -> None:
    """flange_gpios/digital_out_1 state follows its command; digital_in_1, with nothing wired, reads 0."""
    system = _system()
    system.set_command("flange_gpios/digital_out_1", 1.0)
    system.read(0.0, 0.01)
    assert system.get_state("flange_gpios/digital_out_1") == 1.0
    assert system.get_state("flange_gpios/digital_in_1") == 0.0


# --------------------------------------------------------------------------- time
def test_simulated_time_follows_the_periods_in_lockstep() -> None:
    """100 reads of 0.01 s advance the simulation by exactly 1 s (1000 steps of 1 ms)."""
    system = _system()
    _run(system, 1.0)
    assert system.sim_time == pytest.approx(1.0, abs=1e-9)


def test_fractional_periods_are_carried_over() -> None:
    """Periods of 1.5 ms with 1 ms steps: after 10 reads 15 steps were taken."""
    system = _system()
    for _ in range(10):
        system.read(0.0, 0.0015)
    assert system.sim_time == pytest.approx(0.015, abs=1e-9)


def test_zero_period_does_not_step() -> None:
    """A read with period 0 (the first cycle) leaves the time at 0."""
    system = _system()
    system.read(0.0, 0.0)
    assert system.sim_time == 0.0


# --------------------------------------------------------------------------- initial state and reset
def test_initial_value_sets_the_start_position() -> None:
    """The position state interface's initial_value (0.4) is where the simulation starts."""
    system = _system(_info(initial_position="0.4"), activate=False)
    assert system.get_state("joint1/position") == pytest.approx(0.4)
    assert system.get_data().qpos[0] == pytest.approx(0.4)


def test_reset_restores_the_initial_state() -> None:
    """reset() puts the joint back to its initial value and time back to 0; overrides are honoured."""
    system = _system(_info(initial_position="0.4"))
    _run(system, 0.5)
    system.reset()
    assert system.get_state("joint1/position") == pytest.approx(0.4) and system.sim_time == 0.0
    system.reset(positions={"joint1": -0.2})
    assert system.get_state("joint1/position") == pytest.approx(-0.2)


def test_reset_rejects_unknown_joints() -> None:
    """reset() raises KeyError naming the valid joints."""
    with pytest.raises(KeyError, match="joint1"):
        _system().reset(positions={"joint7": 0.0})


# --------------------------------------------------------------------------- mode switching
def test_two_modes_for_one_joint_are_rejected() -> None:
    """Starting position and velocity on joint1 together returns ERROR and changes nothing."""
    system = _system()
    assert system.prepare_command_mode_switch(["joint1/position", "joint1/velocity"], []) is ReturnType.ERROR
    assert "joint1" in system.mode_switch_rejection
    assert system.command_modes == {"joint1": None}


def test_unknown_interface_is_rejected() -> None:
    """An interface the component does not have returns ERROR naming the valid ones."""
    system = _system(_info(commands=("position",)))
    assert system.prepare_command_mode_switch(["joint1/effort"], []) is ReturnType.ERROR
    assert "joint1/position" in system.mode_switch_rejection


def test_starting_a_second_mode_needs_the_first_stopped() -> None:
    """With joint1 in position mode, starting velocity alone is rejected; stopping position too is accepted."""
    system = _system()
    _switch(system, ["joint1/position"])
    assert system.prepare_command_mode_switch(["joint1/velocity"], []) is ReturnType.ERROR
    assert _switch(system, ["joint1/velocity"], ["joint1/position"]) is ReturnType.OK
    assert system.command_modes == {"joint1": "velocity"}


def test_gpio_interfaces_pass_the_mode_check() -> None:
    """GPIO command interfaces are not joint modes and are accepted."""
    assert _system().prepare_command_mode_switch(["flange_gpios/digital_out_1"], []) is ReturnType.OK


def test_stopping_a_mode_makes_the_joint_passive() -> None:
    """After position is stopped, gravity moves the joint again."""
    system = _system()
    _switch(system, ["joint1/position"])
    _run(system, 0.2)
    _switch(system, [], ["joint1/position"])
    _run(system, 0.3)
    assert system.get_state("joint1/position") > 0.1


def test_deactivate_turns_the_motors_off_and_activate_holds_again() -> None:
    """Inactive hardware is passive (read still steps); activation re-enables the remembered mode."""
    system = _system()
    _switch(system, ["joint1/position"])
    system.on_deactivate(State.ACTIVE)
    for _ in range(30):
        system.read(0.0, 0.01)
    moved = system.get_state("joint1/position")
    assert moved > 0.1
    system.on_activate(State.INACTIVE)
    assert system.get_command("joint1/position") == pytest.approx(moved)
    _run(system, 1.0)
    assert system.get_state("joint1/position") == pytest.approx(moved, abs=0.02)


# --------------------------------------------------------------------------- prepared reads and writes
def test_reads_writes_and_mirrors_follow_the_handles_when_they_move() -> None:
    """Once the resource manager adopts the handles into its flat list, states, commands and GPIOs still flow."""
    system = _system()
    _switch(system, ["joint1/position"])
    _run(system, 0.2)
    store: list[object] = []
    adopt([*system._state_handles.values(), *system._command_handles.values()], store)  # noqa: SLF001
    system.set_command("joint1/position", 0.4)
    system.set_command("flange_gpios/digital_out_1", 1.0)
    _run(system, 1.0)
    assert system.get_state("joint1/position") == pytest.approx(0.4, abs=0.01)
    assert system.get_state("joint1/position") == float(system.get_data().qpos[0]) + 0.0
    fz = system.simulation.force_torque_sensors["tcp_fts_sensor"].force_adr + 2
    assert system.get_state("tcp_fts_sensor/fz") == -float(system.get_data().sensordata[fz]) + 0.0
    assert system.get_state("flange_gpios/digital_out_1") == 1.0


@pytest.mark.parametrize("command", [math.nan, math.inf, -math.inf])
def test_a_non_finite_command_keeps_the_last_control(command: float) -> None:
    system = _system()
    _switch(system, ["joint1/position"])
    system.set_command("joint1/position", 0.3)
    system.write(0.0, 0.01)
    system.set_command("joint1/position", command)
    system.write(0.0, 0.01)
    assert system.get_data().ctrl[system.simulation.joints["joint1"].actuators["position"]] == 0.3


@pytest.mark.parametrize(
    ("command", "mirrored"),
    [(True, True), (3, True), (-0.5, True), (math.nan, False), (np.float64("nan"), False), (np.float32("nan"), True)],
)
def test_gpio_states_mirror_any_command_but_a_float_nan(command: object, mirrored: bool) -> None:
    """Only a NaN that is a Python float (or subclass) counts as "no command"; anything else is copied as it is."""
    system = _system()
    system.set_state("flange_gpios/digital_out_1", 7.0)
    system.set_command("flange_gpios/digital_out_1", command)
    system.read(0.0, 0.01)
    value = system.get_state("flange_gpios/digital_out_1")
    assert (value is command) if mirrored else value == 7.0


def test_read_and_write_before_init_fail_as_before() -> None:
    system = MujocoSystem()
    with pytest.raises(AssertionError):
        system.read(0.0, 0.01)
    with pytest.raises(AssertionError):
        system.write(0.0, 0.01)
