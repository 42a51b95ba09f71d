"""mock_components/GenericSystem, held against ros2_control's test_generic_system.cpp.

The scenarios and numbers follow the upstream test; the descriptions are built as HardwareInfo objects
(what the parser would produce for the upstream XML snippets) and driven through HardwareComponent, as
the resource manager does. Period 0.1 s and tolerance 1e-4 as upstream.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import pytest

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo, MimicJoint
from rrbot_workshop.hardware.mock import GenericSystem
from rrbot_workshop.hardware_interface.handles import Handle
from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import ReturnType, State

TIME = 0.0
PERIOD = 0.1
DELTA = 1e-4

Spec = str | tuple[str, str] | tuple[str, str, str]  # name | (name, initial) | (name, initial, data_type)


# ----------------------------------------------------------------- description helpers
def _itfs(specs: Iterable[Spec]) -> list[InterfaceInfo]:
    out = []
    for spec in specs:
        name, initial, data_type = (spec, "", "double") if isinstance(spec, str) else (*spec, "double")[:3]
        params = {"initial_value": initial} if initial else {}
        out.append(InterfaceInfo(name=name, initial_value=initial, data_type=data_type, parameters=params))
    return out


def joint(name: str, commands: Iterable[Spec] = (), states: Iterable[Spec] = ()) -> ComponentInfo:
    return ComponentInfo(name=name, type="joint", command_interfaces=_itfs(commands), state_interfaces=_itfs(states))


def sensor(name: str, states: Iterable[Spec]) -> ComponentInfo:
    return ComponentInfo(name=name, type="sensor", state_interfaces=_itfs(states))


def gpio(name: str, commands: Iterable[Spec] = (), states: Iterable[Spec] = ()) -> ComponentInfo:
    return ComponentInfo(name=name, type="gpio", command_interfaces=_itfs(commands), state_interfaces=_itfs(states))


def system_info(
    joints: Sequence[ComponentInfo] = (),
    sensors: Sequence[ComponentInfo] = (),
    gpios: Sequence[ComponentInfo] = (),
    params: dict[str, str] | None = None,
    mimic: Sequence[MimicJoint] = (),
) -> HardwareInfo:
    return HardwareInfo(
        name="MockHardwareSystem",
        type="system",
        hardware_plugin_name="mock_components/GenericSystem",
        hardware_parameters=dict(params or {}),
        joints=list(joints),
        sensors=list(sensors),
        gpios=list(gpios),
        mimic_joints=list(mimic),
    )


class Mock:
    """A GenericSystem in its wrapper, with its handles by name (what the resource manager would hold)."""

    def __init__(self, info: HardwareInfo, activate: bool = True) -> None:
        self.component = HardwareComponent(GenericSystem())
        assert self.component.initialize(info) is State.UNCONFIGURED
        self.states: dict[str, Handle] = {h.name: h for h in self.component.export_state_interfaces()}
        self.commands: dict[str, Handle] = {h.name: h for h in self.component.export_command_interfaces()}
        if activate:
            assert self.component.configure() is State.INACTIVE
            assert self.component.activate() is State.ACTIVE

    @property
    def impl(self) -> GenericSystem:
        assert isinstance(self.component.impl, GenericSystem)
        return self.component.impl

    def s(self, name: str) -> float:
        return self.states[name].get_value()

    def c(self, name: str) -> float:
        return self.commands[name].get_value()

    def set(self, **values: float) -> None:
        for key, value in values.items():
            self.commands[key.replace("__", "/")].set_value(value)

    def read(self) -> ReturnType:
        return self.component.read(TIME, PERIOD)

    def write(self) -> ReturnType:
        return self.component.write(TIME, PERIOD)


# ----------------------------------------------------------------- the upstream descriptions
def two_dof() -> HardwareInfo:
    return system_info([
        joint("joint1", ["position"], [("position", "1.57")]),
        joint("joint2", ["position"], [("position", "0.7854")]),
    ])


def two_dof_asymmetric() -> HardwareInfo:
    return system_info([
        joint("joint1", ["position"], [("velocity", "1.57")]),
        joint("joint2", ["acceleration"], [("position", "0.7854")]),
    ])


def standard_joints(j1: str = "3.45", j2: str = "2.78", extra_states: Sequence[str] = ()) -> list[ComponentInfo]:
    return [
        joint("joint1", ["position", "velocity"], [("position", j1), "velocity", *extra_states]),
        joint("joint2", ["position", "velocity"], [("position", j2), "velocity", *extra_states]),
    ]


def standard(params: dict[str, str] | None = None, gpios: Sequence[ComponentInfo] = ()) -> HardwareInfo:
    return system_info(standard_joints(), gpios=gpios, params=params)


def with_other_interface() -> HardwareInfo:
    return system_info(
        [
            joint("joint1", ["position", "velocity"], [("position", "1.55"), ("velocity", "0.1")]),
            joint("joint2", ["position", "velocity"], [("position", "0.65"), ("velocity", "0.2")]),
        ],
        gpios=[gpio("voltage_output", ["voltage"], [("voltage", "0.5")])],
    )


def with_sensor(params: dict[str, str] | None = None) -> HardwareInfo:
    plain = [
        joint("joint1", ["position", "velocity"], ["position", "velocity"]),
        joint("joint2", ["position", "velocity"], ["position", "velocity"]),
    ]
    return system_info(plain, sensors=[sensor("tcp_force_sensor", ["fx", "fy", "tx", "ty"])], params=params)


ROBOT_GPIOS = [
    gpio("flange_analog_IOs", ["analog_output1"], ["analog_output1", "analog_input1", "analog_input2"]),
    gpio("flange_vacuum", ["vacuum"], ["vacuum"]),
]


def with_mimic(offset: float = 0.0) -> HardwareInfo:
    return system_info(
        [
            joint("joint1", ["position", "velocity"], [("position", "1.57"), "velocity"]),
            joint("joint2", [], ["position", "velocity"]),
        ],
        mimic=[MimicJoint(joint_index=1, mimicked_joint_index=0, multiplier=-2.0, offset=offset)],
    )


def different_control_modes() -> HardwareInfo:
    """joint1 offers position+velocity, joint2 velocity+acceleration (upstream also repeats joint2's position state)."""
    return system_info(
        [
            joint("joint1", ["position", "velocity"], [("position", "3.45"), "velocity", "acceleration"]),
            joint("joint2", ["velocity", "acceleration"], [("position", "2.78"), "velocity", "acceleration"]),
        ],
        gpios=[gpio("flange_vacuum", ["vacuum"], ["vacuum"])],
        params={"calculate_dynamics": "true"},
    )


def valid_different_control_modes() -> HardwareInfo:
    return system_info(
        [
            joint("joint1", ["position"], [("position", "3.45"), "velocity", "acceleration"]),
            joint("joint2", ["velocity"], [("position", "2.78"), "velocity", "acceleration"]),
            joint("joint3", ["acceleration"], [("position", "2.78"), "velocity", "acceleration"]),
        ],
        gpios=[gpio("flange_vacuum", ["vacuum"], ["vacuum"])],
        params={"calculate_dynamics": "true"},
    )


# ----------------------------------------------------------------- plugin and interfaces
def test_plugin_name_resolves_to_generic_system() -> None:
    assert plugins.resolve("hardware", "mock_components/GenericSystem") is GenericSystem


def test_symmetric_interfaces_start_from_initial_values_and_nan_commands() -> None:
    m = Mock(two_dof())
    assert sorted(m.states) == ["joint1/position", "joint2/position"]
    assert sorted(m.commands) == ["joint1/position", "joint2/position"]
    assert (m.s("joint1/position"), m.s("joint2/position")) == (1.57, 0.7854)
    assert math.isnan(m.c("joint1/position")) and math.isnan(m.c("joint2/position"))


def test_asymmetric_interfaces_export_exactly_what_is_declared() -> None:
    m = Mock(two_dof_asymmetric())
    assert sorted(m.states) == ["joint1/velocity", "joint2/position"]
    assert sorted(m.commands) == ["joint1/position", "joint2/acceleration"]
    assert (m.s("joint1/velocity"), m.s("joint2/position")) == (1.57, 0.7854)
    assert math.isnan(m.c("joint1/position")) and math.isnan(m.c("joint2/acceleration"))


def _functional_check(m: Mock, offset: float, initial_offset: float | None = None) -> None:
    """Upstream generic_system_functional_test: write changes nothing, read mirrors commands (+ offset)."""
    start = offset if initial_offset is None else initial_offset
    assert m.s("joint1/position") == pytest.approx(3.45 + start)
    assert m.s("joint2/position") == pytest.approx(2.78 + start)
    assert m.s("joint1/velocity") == 0.0 and m.s("joint2/velocity") == 0.0  # no initial value -> 0
    assert all(math.isnan(m.c(k)) for k in m.commands if k.startswith("joint"))

    m.set(joint1__position=0.11, joint1__velocity=0.22, joint2__position=0.33, joint2__velocity=0.44)
    assert m.s("joint1/position") == pytest.approx(3.45 + start)  # commands alone change nothing
    assert m.write() is ReturnType.OK
    assert m.s("joint1/position") == pytest.approx(3.45 + start) and m.s("joint1/velocity") == 0.0

    assert m.read() is ReturnType.OK
    assert m.s("joint1/position") == pytest.approx(0.11 + offset)
    assert m.s("joint1/velocity") == 0.22
    assert m.s("joint2/position") == pytest.approx(0.33 + offset)
    assert m.s("joint2/velocity") == 0.44
    assert (m.c("joint1/position"), m.c("joint2/velocity")) == (0.11, 0.44)  # read leaves commands alone

    m.set(joint1__position=0.55, joint1__velocity=0.66, joint2__position=0.77, joint2__velocity=0.88)
    assert m.s("joint1/position") == pytest.approx(0.11 + offset) and m.s("joint2/velocity") == 0.44
    assert m.component.deactivate() is State.INACTIVE


def test_functional_read_mirrors_commands_to_states() -> None:
    _functional_check(Mock(standard()), offset=0.0)


def test_offset_minus_three_follows_position_and_is_added_at_configure() -> None:
    """Offset -3: position state = command - 3; configure already shifts the initial position by -3."""
    _functional_check(Mock(standard({"position_state_following_offset": "-3"})), offset=-3.0)


def test_offset_with_missing_custom_interface_is_not_applied() -> None:
    params = {"position_state_following_offset": "-3", "custom_interface_with_following_offset": "actual_position"}
    _functional_check(Mock(standard(params)), offset=0.0)


def test_offset_on_custom_interface_leaves_position_unshifted() -> None:
    params = {"position_state_following_offset": "-3", "custom_interface_with_following_offset": "actual_position"}
    m = Mock(system_info(standard_joints(extra_states=["actual_position"]), params=params))
    assert (m.s("joint1/position"), m.s("joint2/position")) == (3.45, 2.78)
    assert m.s("joint1/actual_position") == 0.0  # NaN joint states become 0 at configure
    m.set(joint1__position=0.11, joint1__velocity=0.22, joint2__position=0.33, joint2__velocity=0.44)
    assert m.read() is ReturnType.OK
    assert (m.s("joint1/position"), m.s("joint2/position")) == (0.11, 0.33)
    assert m.s("joint1/actual_position") == pytest.approx(0.11 - 3)
    assert m.s("joint2/actual_position") == pytest.approx(0.33 - 3)
    assert (m.s("joint1/velocity"), m.s("joint2/velocity")) == (0.22, 0.44)


def test_other_interfaces_and_gpio_are_mirrored() -> None:
    m = Mock(with_other_interface())
    assert len(m.states) == 5 and len(m.commands) == 5
    assert [m.s(k) for k in ("joint1/position", "joint1/velocity", "joint2/position", "joint2/velocity")] == [
        1.55, 0.1, 0.65, 0.2,
    ]
    assert m.s("voltage_output/voltage") == 0.5
    m.set(joint1__position=0.11, joint2__position=0.33, voltage_output__voltage=0.99)
    assert m.write() is ReturnType.OK and m.s("voltage_output/voltage") == 0.5
    assert m.read() is ReturnType.OK
    assert (m.s("joint1/position"), m.s("joint2/position"), m.s("voltage_output/voltage")) == (0.11, 0.33, 0.99)
    assert (m.s("joint1/velocity"), m.s("joint2/velocity")) == (0.1, 0.2)  # NaN velocity commands are skipped


def test_sensor_states_have_no_commands_and_stay_nan() -> None:
    m = Mock(with_sensor())
    assert len(m.states) == 8 and len(m.commands) == 4
    assert not any(k.startswith("tcp_force_sensor") for k in m.commands)
    m.set(joint1__position=0.11, joint2__position=0.33)
    assert m.read() is ReturnType.OK
    assert (m.s("joint1/position"), m.s("joint2/position")) == (0.11, 0.33)
    assert all(math.isnan(m.s(f"tcp_force_sensor/{i}")) for i in ("fx", "fy", "tx", "ty"))


@pytest.mark.parametrize("flag", ["true", "True"])
def test_mock_sensor_commands_mirror_to_sensor_states(flag: str) -> None:
    m = Mock(with_sensor({"mock_sensor_commands": flag}))
    assert len(m.states) == 8 and len(m.commands) == 8
    assert all(math.isnan(m.c(f"tcp_force_sensor/{i}")) for i in ("fx", "fy", "tx", "ty"))
    m.set(joint1__position=0.11, joint2__position=0.33)
    m.set(tcp_force_sensor__fx=1.11, tcp_force_sensor__fy=2.22, tcp_force_sensor__tx=3.33, tcp_force_sensor__ty=4.44)
    assert m.write() is ReturnType.OK and math.isnan(m.s("tcp_force_sensor/fx"))
    assert m.read() is ReturnType.OK
    assert [m.s(f"tcp_force_sensor/{i}") for i in ("fx", "fy", "tx", "ty")] == [1.11, 2.22, 3.33, 4.44]
    assert (m.s("joint1/position"), m.s("joint1/velocity")) == (0.11, 0.0)


def test_mimic_joint_follows_with_multiplier_minus_two() -> None:
    m = Mock(with_mimic())
    assert len(m.states) == 4 and sorted(m.commands) == ["joint1/position", "joint1/velocity"]
    assert (m.s("joint1/position"), m.s("joint2/position")) == (1.57, 0.0)
    m.set(joint1__position=0.11, joint1__velocity=0.05)
    assert m.write() is ReturnType.OK and m.s("joint2/position") == 0.0
    assert m.read() is ReturnType.OK
    assert (m.s("joint1/position"), m.s("joint1/velocity")) == (0.11, 0.05)
    assert m.s("joint2/position") == pytest.approx(-0.22)
    assert m.s("joint2/velocity") == pytest.approx(-0.1)


def test_mimic_offset_applies_to_position_only() -> None:
    m = Mock(with_mimic(offset=0.5))
    m.set(joint1__position=0.11, joint1__velocity=0.05)
    m.read()
    assert m.s("joint2/position") == pytest.approx(0.5 - 0.22)
    assert m.s("joint2/velocity") == pytest.approx(-0.1)


def test_gpio_commands_mirror_only_to_same_named_states() -> None:
    m = Mock(standard(gpios=ROBOT_GPIOS))
    assert len(m.states) == 8 and len(m.commands) == 6
    assert math.isnan(m.s("flange_analog_IOs/analog_output1")) and math.isnan(m.s("flange_vacuum/vacuum"))
    m.set(flange_analog_IOs__analog_output1=0.111, flange_vacuum__vacuum=0.222)
    assert m.write() is ReturnType.OK and math.isnan(m.s("flange_vacuum/vacuum"))
    assert m.read() is ReturnType.OK
    assert (m.s("flange_analog_IOs/analog_output1"), m.s("flange_vacuum/vacuum")) == (0.111, 0.222)
    assert math.isnan(m.s("flange_analog_IOs/analog_input1"))
    m.set(flange_analog_IOs__analog_output1=0.333, flange_vacuum__vacuum=0.444)
    assert m.s("flange_analog_IOs/analog_output1") == 0.111  # until the next read


@pytest.mark.parametrize("flag", ["true", "True"])
def test_mock_gpio_commands_add_a_command_for_every_gpio_state(flag: str) -> None:
    m = Mock(standard({"mock_gpio_commands": flag}, gpios=ROBOT_GPIOS))
    assert len(m.states) == 8 and len(m.commands) == 8
    names = ["flange_analog_IOs/analog_output1", "flange_analog_IOs/analog_input1", "flange_analog_IOs/analog_input2",
             "flange_vacuum/vacuum"]
    assert all(math.isnan(m.c(n)) and math.isnan(m.s(n)) for n in names)
    for name, value in zip(names, (0.11, 0.33, 1.11, 2.22), strict=True):
        m.commands[name].set_value(value)
    assert m.write() is ReturnType.OK and math.isnan(m.s(names[0]))
    assert m.read() is ReturnType.OK
    assert [m.s(n) for n in names] == [0.11, 0.33, 1.11, 2.22]


def test_sensor_and_gpio_initial_values_are_kept() -> None:
    m = Mock(system_info(sensors=[sensor("force_sensor", [("force.x", "0.0"), ("force.y", "0.0"), ("force.z", "0.0")])]))
    assert [m.s(f"force_sensor/force.{a}") for a in "xyz"] == [0.0, 0.0, 0.0]
    g = Mock(system_info(gpios=[gpio("sample_io", [], [("output_1", "1")])]))
    assert list(g.states) == ["sample_io/output_1"] and g.s("sample_io/output_1") == 1.0


def test_disable_commands_keeps_states_unchanged() -> None:
    m = Mock(system_info([joint("joint1", ["position", "velocity"], [("position", "3.45"), "velocity"])],
                         params={"disable_commands": "True"}))
    assert len(m.states) == 2 and len(m.commands) == 2
    m.set(joint1__position=0.11)
    assert m.write() is ReturnType.OK
    assert m.read() is ReturnType.OK
    assert (m.s("joint1/position"), m.s("joint1/velocity"), m.c("joint1/position")) == (3.45, 0.0, 0.11)


# ----------------------------------------------------------------- commands that are events, not errors
def test_nan_command_is_skipped() -> None:
    m = Mock(standard())
    m.set(joint1__position=0.11, joint1__velocity=0.22)
    m.read()
    m.set(joint1__position=math.nan, joint1__velocity=math.nan)
    assert m.read() is ReturnType.OK
    assert (m.s("joint1/position"), m.s("joint1/velocity")) == (0.11, 0.22)


@pytest.mark.parametrize("value", [math.inf, -math.inf])
def test_infinite_mirrored_command_makes_read_error_and_component_leaves(value: float) -> None:
    """±inf on a mirrored command: read returns ERROR, error() runs, and on_error's default (SUCCESS, as
    rclcpp_lifecycle's) leaves the component UNCONFIGURED: it can be configured and activated again (Jazzy)."""
    m = Mock(standard())
    m.set(joint1__velocity=value)
    assert m.impl.read(TIME, PERIOD) is ReturnType.ERROR
    assert m.read() is ReturnType.ERROR
    assert m.component.get_lifecycle_state() is State.UNCONFIGURED
    m.set(joint1__velocity=0.0)
    assert m.component.configure() is State.INACTIVE
    assert m.component.activate() is State.ACTIVE
    assert m.read() is ReturnType.OK


def test_infinite_position_command_is_ignored_without_dynamics() -> None:
    """Position is not mirrored but followed, and only finite commands are followed (upstream)."""
    m = Mock(standard())
    m.set(joint1__position=math.inf)
    assert m.read() is ReturnType.OK
    assert m.s("joint1/position") == 3.45


def test_bool_gpio_command_is_copied() -> None:
    m = Mock(system_info(gpios=[gpio("gripper", [("close", "", "bool")], [("close", "", "bool")])]))
    assert m.s("gripper/close") is False
    m.set(gripper__close=True)
    assert m.read() is ReturnType.OK
    assert m.s("gripper/close") is True


@pytest.mark.parametrize(
    "params",
    [{"calculate_dynamics": "yes"}, {"mock_gpio_commands": "1.0"}, {"position_state_following_offset": "minus three"}],
)
def test_malformed_hardware_parameter_fails_initialisation(params: dict[str, str]) -> None:
    component = HardwareComponent(GenericSystem())
    assert component.initialize(standard(params)) is State.FINALIZED


# ----------------------------------------------------------------- dynamics
def test_dynamics_in_position_acceleration_and_velocity_modes() -> None:
    """Upstream simple_dynamics_pos_vel_acc_control_modes_interfaces, with today's implicit Euler update."""
    m = Mock(different_control_modes())
    assert len(m.states) == 7 and len(m.commands) == 5
    s = m.s
    assert [s("joint1/position"), s("joint1/velocity"), s("joint1/acceleration")] == [3.45, 0.0, 0.0]
    assert [s("joint2/position"), s("joint2/velocity"), s("joint2/acceleration")] == [2.78, 0.0, 0.0]
    sw = m.component
    assert sw.prepare_command_mode_switch(["joint1/position", "joint2/effort"], []) is ReturnType.ERROR
    assert sw.prepare_command_mode_switch(["joint1/position", "joint1/acceleration"], []) is ReturnType.ERROR
    start = ["joint1/position", "joint2/acceleration", "flange_vacuum/vacuum"]  # the GPIO key is ignored
    assert sw.prepare_command_mode_switch(start, []) is ReturnType.OK
    assert sw.perform_command_mode_switch(start, []) is ReturnType.OK

    m.set(joint1__position=0.11, joint2__acceleration=3.5)
    assert m.write() is ReturnType.OK and s("joint1/position") == 3.45 and s("joint2/acceleration") == 0.0

    def expect(j1: tuple[float, float, float], j2: tuple[float, float, float]) -> None:
        got = [s(f"{j}/{i}") for j in ("joint1", "joint2") for i in ("position", "velocity", "acceleration")]
        assert got == pytest.approx([*j1, *j2], abs=DELTA)

    m.read()
    expect((0.11, -33.4, -334.0), (2.815, 0.35, 3.5))
    m.read()
    expect((0.11, 0.0, 334.0), (2.885, 0.7, 3.5))
    m.read()
    expect((0.11, 0.0, 0.0), (2.99, 1.05, 3.5))

    assert sw.prepare_command_mode_switch(["joint1/velocity", "joint2/velocity"], []) is ReturnType.OK
    assert sw.perform_command_mode_switch(["joint1/velocity", "joint2/velocity"], []) is ReturnType.OK
    m.set(joint1__velocity=0.5, joint2__velocity=2.0)
    m.write()
    expect((0.11, 0.0, 0.0), (2.99, 1.05, 3.5))
    m.read()
    expect((0.16, 0.5, 5.0), (3.19, 2.0, 9.5))
    m.read()
    expect((0.21, 0.5, 0.0), (3.39, 2.0, 0.0))
    assert (m.c("joint1/position"), m.c("joint2/acceleration")) == (0.11, 3.5)  # commands untouched


def test_velocity_command_integrates_into_position_only_state() -> None:
    """A joint with a velocity command and only a position state still moves (ros2_control#2694)."""
    m = Mock(system_info([joint("j", ["velocity"], [("position", "1.0")])], params={"calculate_dynamics": "true"}))
    m.component.perform_command_mode_switch(["j/velocity"], [])
    m.set(j__velocity=2.0)
    m.read()
    m.read()
    assert m.s("j/position") == pytest.approx(1.4, abs=DELTA)


def test_zero_period_does_not_divide_by_zero() -> None:
    m = Mock(different_control_modes())
    m.set(joint1__position=0.11)
    assert m.component.read(TIME, 0.0) is ReturnType.OK
    assert (m.s("joint1/position"), m.s("joint1/velocity")) == (0.11, 0.0)  # the undefined rate is not stored


@pytest.mark.parametrize(("quirk", "expected"), [(False, [0.0, 0.0]), (True, [-3.0, -6.0])])
def test_offset_in_velocity_mode_with_unknown_velocity(quirk: bool, expected: list[float]) -> None:
    """Jazzy adds the offset on each cycle without a finite velocity; we do not unless asked to."""
    info = system_info([joint("j", ["velocity"], ["position"])],
                       params={"calculate_dynamics": "true", "position_state_following_offset": "-3"})
    component = HardwareComponent(GenericSystem())
    assert isinstance(component.impl, GenericSystem)
    component.impl.jazzy_offset_quirk = quirk
    component.initialize(info)
    states = {h.name: h for h in component.export_state_interfaces()}
    component.configure(); component.activate()  # noqa: E702
    assert states["j/position"].get_value() == -3.0  # 0 + offset at configure
    component.perform_command_mode_switch(["j/velocity"], [])
    got = []
    for _ in range(2):
        component.read(TIME, PERIOD)  # velocity command still NaN, no velocity state
        got.append(states["j/position"].get_value() + 3.0)
    assert got == expected


# ----------------------------------------------------------------- mode switch checks
ALL_EXAMPLES = {
    "two_dof": two_dof,
    "asymmetric": two_dof_asymmetric,
    "standard": standard,
    "other_interface": with_other_interface,
    "sensor": with_sensor,
    "sensor_mock": lambda: with_sensor({"mock_sensor_commands": "true"}),
    "mimic": with_mimic,
    "offset": lambda: standard({"position_state_following_offset": "-3"}),
    "gpio": lambda: standard(gpios=ROBOT_GPIOS),
    "gpio_mock": lambda: standard({"mock_gpio_commands": "true"}, gpios=ROBOT_GPIOS),
    "disabled": lambda: standard({"disable_commands": "true"}),
    "valid_control_modes": valid_different_control_modes,
    "different_control_modes": different_control_modes,
}


@pytest.mark.parametrize("example", sorted(ALL_EXAMPLES))
def test_prepare_switch_with_every_command_interface(example: str) -> None:
    """Starting all command interfaces is accepted, except a dynamics joint offering two modes."""
    m = Mock(ALL_EXAMPLES[example]())
    expected = ReturnType.ERROR if example == "different_control_modes" else ReturnType.OK
    assert m.component.prepare_command_mode_switch(sorted(m.commands), []) is expected


def test_without_dynamics_any_combination_is_accepted() -> None:
    m = Mock(standard())
    assert m.component.prepare_command_mode_switch(["joint1/position", "joint1/velocity"], []) is ReturnType.OK


def test_joint_names_that_prefix_each_other_are_told_apart() -> None:
    """Upstream matches joints by substring ("joint1" in "joint10/velocity"); we match exactly."""
    m = Mock(system_info(
        [joint("joint1", ["position", "velocity"], ["position", "velocity"]),
         joint("joint10", ["position", "velocity"], ["position", "velocity"])],
        params={"calculate_dynamics": "true"},
    ))
    start = ["joint1/position", "joint10/velocity"]
    assert m.component.prepare_command_mode_switch(start, []) is ReturnType.OK
    m.component.perform_command_mode_switch(start, [])
    m.set(joint1__position=1.0, joint10__velocity=1.0)
    m.read()
    assert m.s("joint1/position") == 1.0
    assert m.s("joint10/position") == pytest.approx(0.1)


def test_configure_resets_every_joint_to_position_mode() -> None:
    m = Mock(different_control_modes())
    m.component.perform_command_mode_switch(["joint2/velocity"], [])
    m.component.deactivate(); m.component.cleanup(); m.component.configure()  # noqa: E702
    m.set(joint2__velocity=1.0)
    m.read()
    assert m.s("joint2/velocity") == 0.0  # position mode with no position command: nothing moves


# ----------------------------------------------------------------- through the parser
_MIMIC_URDF = """
<?xml version="1.0"?>
<robot name="mimic_test">
  <link name="base"/><link name="link1"/><link name="link2"/>
  <joint name="joint1" type="revolute">
    <parent link="base"/><child link="link1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="joint2" type="revolute">
    <parent link="link1"/><child link="link2"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
    <mimic joint="joint1" multiplier="-2"/>
  </joint>
  <ros2_control name="MockHardwareSystem" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="joint1">
      <command_interface name="position"/>
      <command_interface name="velocity"/>
      <state_interface name="position"><param name="initial_value">1.57</param></state_interface>
      <state_interface name="velocity"/>
    </joint>
    <joint name="joint2" mimic="true">
      <state_interface name="position"/>
      <state_interface name="velocity"/>
    </joint>
  </ros2_control>
</robot>
"""


def test_mimic_joint_from_urdf_description() -> None:
    """The upstream mimic snippet, parsed from URDF text: joint2 = -2 * joint1."""
    from rrbot_workshop.description import parse_ros2_control

    (info,) = parse_ros2_control(_MIMIC_URDF)
    m = Mock(info)
    assert sorted(m.commands) == ["joint1/position", "joint1/velocity"]
    m.set(joint1__position=0.11, joint1__velocity=0.05)
    assert m.read() is ReturnType.OK
    assert (m.s("joint2/position"), m.s("joint2/velocity")) == pytest.approx((-0.22, -0.1))
