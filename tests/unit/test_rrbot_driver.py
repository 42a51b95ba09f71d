"""The library's RRBot driver (controlko_hardware_interface/RRBotHardwareInterface, the task-7 reference) on the full
stack: every interface's value path, the lifecycle, one control mode for all joints, refusing incompatible
controllers with the reason, and the original solution's export bugs absent."""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.exceptions import HardwareError, SwitchError
from rrbot_workshop.hardware.rrbot import RRBotHardwareInterface, description_problems
from rrbot_workshop.hardware.rrbot_device import SENSOR_MAX, ControlMode
from rrbot_workshop.middleware import plugins
from rrbot_workshop.msgs import Float64MultiArray

ROOT = Path(__file__).resolve().parents[2]
CONTROLLERS = ROOT / "solutions" / "task07_hardware_interface" / "rrbot_controllers.yaml"
PLUGIN = "rrbot_workshop/RRBotHardwareInterface"
pytestmark = pytest.mark.skipif(not CONTROLLERS.is_file(), reason="this copy of the course has no solutions/")


@pytest.fixture(autouse=True)
def _quiet() -> Iterator[None]:
    logging.disable(logging.CRITICAL)
    yield
    logging.disable(logging.NOTSET)


def _urdf(**xacro_args: object) -> str:
    """RRBot on the library's driver, by its own name (the course name resolves to a learner's file per track)."""
    urdf = rw.description.process_xacro(ROOT / "descriptions/rrbot/urdf/rrbot.urdf.xacro", use_mock_hardware=False,
                                        **xacro_args)
    return urdf.replace("controlko_hardware_interface/RRBotHardwareInterface", PLUGIN)


@pytest.fixture
def system() -> Iterator[rw.System]:
    with rw.bringup(_urdf(), CONTROLLERS, spawn=["joint_state_broadcaster", "forward_position_controller"],
                    inactive=["forward_velocity_controller", "joint_trajectory_controller",
                              "incompatible_joint_trajectory_controller"], name="rrbot_driver_test") as s:
        s.spin_cycles(1)
        yield s


def _driver(system: rw.System) -> RRBotHardwareInterface:
    impl = system.resource_manager.get_component("rrbot").impl
    assert isinstance(impl, RRBotHardwareInterface)
    return impl


def _positions(system: rw.System) -> list[float]:
    return [round(p, 6) for p in system.latest("/joint_states").position]


def test_joints_start_at_the_devices_0_1_and_follow_position_commands_at_most_0_5_rad_per_s(system: rw.System) -> None:
    assert _positions(system) == [0.1, 0.1]
    system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.6, -0.4]))
    system.spin(0.5)
    moved = _positions(system)
    assert all(abs(q - 0.1) <= 0.5 * 0.5 + 1e-9 for q in moved) and moved != [0.1, 0.1]
    system.spin(1.0)
    assert _positions(system) == pytest.approx([0.6, -0.4])


def test_velocity_controller_switches_the_device_and_its_clamp_is_fixed(system: rw.System) -> None:
    driver = _driver(system)
    assert driver.device is not None and driver.device.get_control_mode() is ControlMode.POSITION
    system.controller_manager.switch_controllers(["forward_velocity_controller"], ["forward_position_controller"],
                                                 "strict")
    assert driver.device.get_control_mode() is ControlMode.VELOCITY
    system.publish("/forward_velocity_controller/commands", Float64MultiArray(data=[0.2, -1.0]))
    system.spin(1.0)
    assert system.latest("/joint_states").velocity == pytest.approx([0.2, -0.5])
    system.controller_manager.switch_controllers(["joint_trajectory_controller"], ["forward_velocity_controller"],
                                                 "strict")
    assert driver.device.get_control_mode() is ControlMode.POSITION


def test_a_controller_claiming_position_and_velocity_is_refused_and_nothing_changes(system: rw.System) -> None:
    before = [(c.name, c.state) for c in system.controller_manager.list_controllers()]
    with pytest.raises(SwitchError, match="runs all joints in one mode") as err:
        system.controller_manager.switch_controllers(["incompatible_joint_trajectory_controller"],
                                                     ["forward_position_controller"], "strict")
    assert "hardware component 'rrbot' rejected" in str(err.value)
    assert [(c.name, c.state) for c in system.controller_manager.list_controllers()] == before
    assert _driver(system).device.get_control_mode() is ControlMode.POSITION
    # a velocity controller next to a running position controller is refused too
    with pytest.raises(SwitchError, match="would be commanded in position"):
        system.controller_manager.switch_controllers(["forward_velocity_controller"], [], "strict")


def test_every_interface_carries_its_own_value(system: rw.System) -> None:
    """The original's solution exported effort on the acceleration buffer, swapped sensor and GPIO states and never
    exported the GPIO commands; here each has its own value."""
    system.publish("/forward_position_controller/commands", Float64MultiArray(data=[1.0, 1.0]))
    system.spin(0.2)
    dyn = system.latest("/dynamic_joint_states")
    by = {(g, n): x for g, group in zip(dyn.joint_names, dyn.interface_values, strict=True)
          for n, x in zip(group.interface_names, group.values, strict=True)}
    assert math.isnan(by[("joint1", "effort")]), "the device measures no torque: effort is NaN, not the acceleration"
    fts = [by[("tcp_fts_sensor", k)] for k in ("fx", "fy", "fz", "tx", "ty", "tz")]
    assert all(0.0 <= f <= SENSOR_MAX for f in fts) and len(set(fts)) > 1
    assert {by[("flange_gpios", "digital_in_1")], by[("flange_gpios", "digital_in_2")]} <= {0.0, 1.0}
    rm = system.resource_manager
    assert {"flange_gpios/digital_out_1", "flange_gpios/digital_out_2"} <= set(rm.available_command_interfaces())


def test_gpio_outputs_are_written_and_read_back(system: rw.System) -> None:
    cm = system.controller_manager
    cfg = rw.params.load_controllers_yaml(
        "controller_manager:\n  ros__parameters:\n    io:\n      type: gpio_controllers/GpioCommandController\n"
        "io:\n  ros__parameters:\n    gpios: [flange_gpios]\n    command_interfaces:\n      flange_gpios:\n"
        "        interfaces: [digital_out_1, digital_out_2]\n")
    cm.params.controller_types.update(cfg.controller_types)
    cm.params.controller_parameters.update(cfg.controller_parameters)
    system.spawn(["io"])
    system.publish("/io/commands", rw.msgs.DynamicInterfaceGroupValues(
        interface_groups=["flange_gpios"],
        interface_values=[rw.msgs.InterfaceValue(["digital_out_1", "digital_out_2"], [1.0, 0.0])]))
    system.spin(0.05)
    assert _driver(system).device.read_gpio()[1] == [True, False]
    dyn = system.latest("/dynamic_joint_states")
    group = dyn.interface_values[dyn.joint_names.index("flange_gpios")]
    readback = dict(zip(group.interface_names, group.values, strict=True))
    assert readback["digital_out_1"] == 1.0 and readback["digital_out_2"] == 0.0


def test_deactivated_hardware_freezes_and_reactivates_without_a_jump(system: rw.System) -> None:
    system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.5, 0.5]))
    system.spin(0.3)
    cm = system.controller_manager
    assert cm.set_hardware_component_state("rrbot", "inactive")
    system.spin_cycles(1)  # the broadcaster reports the last state the device reached
    frozen = _positions(system)
    system.spin(0.5)
    assert _positions(system) == frozen, "an inactive device must not move"
    assert cm.set_hardware_component_state("rrbot", "active")
    system.spin(0.02)
    assert _positions(system) == pytest.approx(frozen, abs=0.011), "activation seeds the commands from the states"


def test_two_runs_are_identical() -> None:
    runs = []
    for _ in range(2):
        with rw.bringup(_urdf(), CONTROLLERS, spawn=["joint_state_broadcaster", "forward_position_controller"],
                        name="rrbot_driver_repeat") as s:
            s.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.7, 0.2]))
            s.spin(1.5)
            dyn = s.latest("/dynamic_joint_states")
            runs.append((s.latest("/joint_states").position, [list(g.values) for g in dyn.interface_values]))
    assert str(runs[0]) == str(runs[1])


def test_a_description_the_device_cannot_serve_is_refused_at_init_naming_the_element() -> None:
    urdf = _urdf().replace('<command_interface name="velocity"/>', "", 1)
    infos = rw.description.parse_ros2_control(urdf)
    assert any("<joint name='joint1'> has command interfaces ['position']" in p for p in description_problems(infos[0]))
    with pytest.raises(HardwareError):
        rw.bringup(urdf, CONTROLLERS, name="rrbot_driver_bad")


def test_the_course_plugin_name_resolves_to_the_reference_without_a_learner_file(tmp_path: Path,
                                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    from rrbot_workshop.course import tracks

    monkeypatch.setenv(tracks.TASK_ROOT_ENV, str(tmp_path))  # a folder with no task-7 file
    cls = plugins.resolve("hardware", "controlko_hardware_interface/RRBotHardwareInterface")
    assert cls is RRBotHardwareInterface
