"""Tests for pid_controller/PidController; numbers from pid_controller/test/test_pid_controller.cpp."""

from __future__ import annotations

import logging
import math

import pytest

from rrbot_workshop.controller_interface.base import InterfaceConfigurationType
from rrbot_workshop.controllers.pid import PidController, shortest_angular_distance
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import ReturnType, State
from rrbot_workshop.msgs import MultiDOFCommand, MultiDOFStateStamped, SetBoolRequest
from rrbot_workshop.testing import ControllerHarness

NAME = "test_pid_controller"


def _params(**over):
    p = {
        "dof_names": ["joint1"],
        "command_interface": "acceleration",
        "reference_and_state_interfaces": ["position"],
        "set_current_state_as_first_setpoint": False,
        "gains": {"joint1": {"p": 1.0, "i": 2.0, "d": 3.0}},
    }
    p.update(over)
    return p


def _set_ref(h: ControllerHarness, name: str, value: float) -> None:
    """Write a reference interface, as a preceding controller would (exported states share its name)."""
    h.commands[f"{NAME}/{name}"].set_value(value)


def _harness(params=None, states=None, commands=None) -> ControllerHarness:
    return ControllerHarness(
        PidController(), NAME, params or _params(),
        state_values=states if states is not None else {"joint1/position": 1.1},
        command_values=commands if commands is not None else {"joint1/acceleration": 101.101},
    )


def _active(params=None, chained=False, **kw) -> ControllerHarness:
    h = _harness(params, **kw)
    assert h.configure() is State.INACTIVE
    if chained:
        assert h.set_chained_mode(True)
    assert h.activate() is State.ACTIVE
    return h


def test_interface_configuration_names():
    h = _harness(_params(dof_names=["joint1", "joint2"], reference_and_state_interfaces=["position", "velocity"],
                         gains={}), states={}, commands={})
    h.configure()
    c = h.controller
    assert c.command_interface_configuration().names == ["joint1/acceleration", "joint2/acceleration"]
    cfg = c.state_interface_configuration()
    assert cfg.type is InterfaceConfigurationType.INDIVIDUAL
    assert cfg.names == ["joint1/position", "joint2/position", "joint1/velocity", "joint2/velocity"]


def test_exported_reference_interfaces_are_prefixed_by_controller_and_nan():
    h = _harness()
    h.configure()
    refs = h.controller.reference_interfaces
    assert [r.name for r in refs] == [f"{NAME}/joint1/position"]
    assert refs[0].prefix_name == NAME and refs[0].interface_name == "joint1/position"
    assert math.isnan(refs[0].get_value())
    assert [s.name for s in h.controller.exported_state_interfaces] == [f"{NAME}/joint1/position"]


def test_reference_and_state_dof_names_default_to_dof_names():
    h = _harness()
    h.configure()
    assert h.controller.reference_and_state_dof_names == ["joint1"]


def test_reference_and_state_dof_names_size_mismatch_fails_configure(caplog):
    h = _harness(_params(reference_and_state_dof_names=["a", "b"]))
    with caplog.at_level(logging.ERROR):
        assert h.configure() is State.UNCONFIGURED
    assert "'reference_and_state_dof_names' has 2 entries but 'dof_names' has 1" in caplog.text


def test_three_interfaces_rejected_at_load():
    with pytest.raises(ParameterError, match="reference_and_state_interfaces"):
        _harness(_params(reference_and_state_interfaces=["position", "velocity", "acceleration"]))


def test_unknown_antiwindup_strategy_rejected_at_load():
    with pytest.raises(ParameterError, match=r"gains\.joint1\.antiwindup_strategy"):
        _harness(_params(gains={"joint1": {"antiwindup_strategy": "bogus"}}))


def test_invalid_gain_limits_fail_configure_naming_dof(caplog):
    h = _harness(_params(gains={"joint1": {"p": 1.0, "u_clamp_max": -1.0, "u_clamp_min": 1.0}}))
    with caplog.at_level(logging.ERROR):
        assert h.configure() is State.UNCONFIGURED
    assert "gains.joint1" in caplog.text and "u_clamp_min" in caplog.text


def test_references_nan_after_activate_without_first_setpoint():
    h = _active()
    assert math.isnan(h.value(f"{NAME}/joint1/position"))
    h.update()
    assert h.value("joint1/acceleration") == 101.101  # NaN reference: nothing written


def test_first_setpoint_is_current_state():
    h = _active(_params(set_current_state_as_first_setpoint=True))
    assert h.value(f"{NAME}/joint1/position") == 1.1
    h.update()
    assert h.value("joint1/acceleration") == 0.0  # zero error


def test_chained_update_uses_reference_interface():
    """p=1 i=2 d=3, ref 101.101, state 1.1, dt 0.01 -> 30102.30102 (no feed-forward): Jazzy's legacy integration adds
    i * dt * error = 2.00002 in the first cycle (ros2_controllers jazzy, test_pid_controller.cpp)."""
    h = _active(chained=True)
    _set_ref(h, "joint1/position", 101.101)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(30102.30102, rel=1e-12)


def test_chained_mode_ignores_topic():
    h = _active(chained=True)
    h.publish("~/reference", MultiDOFCommand(["joint1"], [0.45], [math.nan]))
    h.update()
    assert math.isnan(h.value(f"{NAME}/joint1/position"))


def test_topic_reference_reaches_reference_interface():
    h = _active()
    h.publish("~/reference", MultiDOFCommand(["joint1"], [0.45], [math.nan]))
    h.update()
    assert h.value(f"{NAME}/joint1/position") == 0.45
    msg = h.latest("~/controller_state")
    assert isinstance(msg, MultiDOFStateStamped)
    assert msg.dof_states[0].name == "joint1" and msg.dof_states[0].reference == 0.45
    assert msg.dof_states[0].output != 101.101


def test_feedforward_gain_single_interface():
    """ros2_controllers pid_controller/test/test_pid_controller.cpp, test_update_chained_feedforward_with_gain (jazzy):
    feed-forward switched on: p=0.5, ff=1.0, target 5.0, state 1.1 -> 0.5*3.9 + 5.0 = 6.95."""
    h = _active(_params(enable_feedforward=True, gains={"joint1": {"p": 0.5, "feedforward_gain": 1.0}}), chained=True)
    _set_ref(h, "joint1/position", 5.0)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(6.95)


def test_feedforward_is_off_by_default_even_with_a_gain():
    """ros2_controllers pid_controller/test/test_pid_controller.cpp, test_update_chained_feedforward_off_with_gain
    (jazzy): feed-forward is off unless switched on: 0.5 * (5.0 - 1.1) = 1.95."""
    h = _active(_params(gains={"joint1": {"p": 0.5, "feedforward_gain": 1.0}}), chained=True)
    assert h.controller.feedforward_mode_enabled is False
    _set_ref(h, "joint1/position", 5.0)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(1.95)


def test_feedforward_mode_service():
    """ros2_controllers pid_controller/test/test_pid_controller.cpp, test_feedforward_mode_service (jazzy): the mode is
    off after configure and activate; ~/set_feedforward_control (std_srvs/SetBool) turns it on, then off again."""
    h = _harness(_params(set_current_state_as_first_setpoint=True, gains={"joint1": {"p": 1.0, "i": 2.0, "d": 3.0}}))
    assert h.controller.feedforward_mode_enabled is False
    assert h.configure() is State.INACTIVE and h.activate() is State.ACTIVE
    assert h.controller.feedforward_mode_enabled is False
    response = h.bus.call_service(f"/{NAME}/set_feedforward_control", SetBoolRequest(data=True))
    assert response.success and h.controller.feedforward_mode_enabled is True
    response = h.bus.call_service(f"/{NAME}/set_feedforward_control", SetBoolRequest(data=False))
    assert response.success and h.controller.feedforward_mode_enabled is False


def test_set_feedforward_control_service_applies_the_gain():
    """The service's mode counts in the next update: test_update_chained_feedforward_with_gain's 6.95 (jazzy) with the
    mode switched by ~/set_feedforward_control instead of enable_feedforward."""
    h = _active(_params(gains={"joint1": {"p": 0.5, "feedforward_gain": 1.0}}), chained=True)
    h.bus.call_service(f"/{NAME}/set_feedforward_control", SetBoolRequest(data=True))
    _set_ref(h, "joint1/position", 5.0)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(6.95)


def test_set_feedforward_control_service_refuses_a_request_without_a_bool():
    """A request whose 'data' is not a bool is answered success=False and changes nothing."""
    h = _active(_params(gains={"joint1": {"p": 0.5, "feedforward_gain": 1.0}}), chained=True)
    response = h.bus.call_service(f"/{NAME}/set_feedforward_control", SetBoolRequest(data="yes"))  # type: ignore[arg-type]
    assert response.success is False and "bool" in response.message
    assert h.controller.feedforward_mode_enabled is False


def test_feedforward_mode_parameter():
    """ros2_controllers pid_controller/test/test_pid_controller.cpp, test_feedforward_mode_parameter (jazzy):
    enable_feedforward is read at configure (after a cleanup) and, once the controller runs, at the update after it is
    set."""
    h = _harness(_params(set_current_state_as_first_setpoint=True))
    c = h.controller
    assert c.feedforward_mode_enabled is False
    assert h.configure() is State.INACTIVE
    assert c.feedforward_mode_enabled is False

    assert c.cleanup() is State.UNCONFIGURED
    c.get_node().set_parameters({"enable_feedforward": True})
    assert h.configure() is State.INACTIVE
    assert c.feedforward_mode_enabled is True
    assert c.cleanup() is State.UNCONFIGURED
    c.get_node().set_parameters({"enable_feedforward": False})
    assert c.feedforward_mode_enabled is True  # not read before configure
    assert h.configure() is State.INACTIVE
    assert c.feedforward_mode_enabled is False

    assert h.activate() is State.ACTIVE
    assert c.feedforward_mode_enabled is False
    h.update()
    assert c.feedforward_mode_enabled is False
    c.get_node().set_parameters({"enable_feedforward": True})
    h.update()
    assert c.feedforward_mode_enabled is True
    c.get_node().set_parameters({"enable_feedforward": False})
    h.update()
    assert c.feedforward_mode_enabled is False


def test_a_mode_set_by_the_service_survives_reconfigure_with_unchanged_parameters():
    """Jazzy's update_parameters (pid_controller.cpp) writes the mode only from parameters it has not read: after the
    service turns it on, cleanup and configure keep it on; setting any parameter makes enable_feedforward count again."""
    h = _active()
    c = h.controller
    h.bus.call_service(f"/{NAME}/set_feedforward_control", SetBoolRequest(data=True))
    assert c.deactivate() is State.INACTIVE and c.cleanup() is State.UNCONFIGURED
    assert h.configure() is State.INACTIVE
    assert c.feedforward_mode_enabled is True
    c.get_node().set_parameters({"gains.joint1.p": 2.0})
    h.activate()
    h.update()
    assert c.feedforward_mode_enabled is False


def test_update_logic_feedforward_on_with_zero_feedforward_gain():
    """ros2_controllers pid_controller/test/test_pid_controller.cpp,
    test_update_logic_feedforward_on_with_zero_feedforward_gain (jazzy): feed-forward on with gain 0 adds nothing:
    ref 101.101, state 1.1, p=1 i=2 d=3 (antiwindup_strategy none), dt 0.01 -> 30100.301."""
    gains = {"joint1": {"p": 1.0, "i": 2.0, "d": 3.0, "antiwindup_strategy": "none"}}
    h = _active(_params(set_current_state_as_first_setpoint=True, gains=gains))
    h.controller.get_node().set_parameters({"enable_feedforward": True})
    h.publish("~/reference", MultiDOFCommand(["joint1"], [101.101], [math.nan]))
    h.update()
    assert h.controller.feedforward_mode_enabled is True
    assert round(h.value("joint1/acceleration"), 5) == pytest.approx(30100.301, abs=1e-5)


def test_update_logic_feedforward_off():
    """ros2_controllers pid_controller/test/test_pid_controller.cpp, test_update_logic_feedforward_off (jazzy): the same
    numbers with the mode off (the default) -> 30100.301."""
    gains = {"joint1": {"p": 1.0, "i": 2.0, "d": 3.0, "antiwindup_strategy": "none"}}
    h = _active(_params(set_current_state_as_first_setpoint=True, gains=gains))
    h.publish("~/reference", MultiDOFCommand(["joint1"], [101.101], [math.nan]))
    h.update()
    assert h.controller.feedforward_mode_enabled is False
    assert round(h.value("joint1/acceleration"), 5) == pytest.approx(30100.301, abs=1e-5)


def test_gains_set_while_running_take_effect_at_the_next_update():
    """Jazzy's update_parameters re-reads feedforward_gain and control_toolbox's PidROS takes new gains at once: with
    the mode on, p 0.5 -> 1.0 and feedforward_gain 1.0 -> 2.0 give 1.0 * 3.9 + 2.0 * 5.0 = 13.9."""
    h = _active(_params(enable_feedforward=True, gains={"joint1": {"p": 0.5, "feedforward_gain": 1.0}}), chained=True)
    _set_ref(h, "joint1/position", 5.0)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(6.95)
    h.controller.get_node().set_parameters({"gains.joint1.p": 1.0, "gains.joint1.feedforward_gain": 2.0})
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(13.9)


def test_invalid_gains_set_while_running_are_logged_and_the_old_ones_stay(caplog):
    """control_toolbox keeps the running gains when new ones are invalid (u_clamp_min above u_clamp_max)."""
    h = _active(_params(gains={"joint1": {"p": 0.5}}), chained=True)
    _set_ref(h, "joint1/position", 5.0)
    h.controller.get_node().set_parameters({"gains.joint1.u_clamp_min": 1.0, "gains.joint1.u_clamp_max": -1.0})
    with caplog.at_level(logging.ERROR):
        h.update()
    assert "u_clamp" in caplog.text
    assert h.value("joint1/acceleration") == pytest.approx(1.95)


def test_a_parameter_of_the_wrong_type_set_while_running_changes_nothing(caplog):
    """A value the declarations refuse is logged (naming the parameter) and the running parameters stay."""
    h = _active(_params(enable_feedforward=True, gains={"joint1": {"p": 0.5, "feedforward_gain": 1.0}}), chained=True)
    h.controller.get_node().set_parameters({"enable_feedforward": "maybe"})
    _set_ref(h, "joint1/position", 5.0)
    with caplog.at_level(logging.ERROR):
        h.update()
    assert "enable_feedforward" in caplog.text
    assert h.controller.feedforward_mode_enabled is True
    assert h.value("joint1/acceleration") == pytest.approx(6.95)


def test_interface_parameters_set_while_running_wait_for_configure(caplog):
    """dof_names and the interfaces are read-only in Jazzy's declarations: changed while running, they are not taken
    until the next configure (a warning says so) and the controller keeps commanding the same interfaces."""
    h = _active(_params(gains={"joint1": {"p": 0.5}}), chained=True)
    h.controller.get_node().set_parameters({"command_interface": "velocity"})
    _set_ref(h, "joint1/position", 5.0)
    with caplog.at_level(logging.WARNING):
        h.update()
    assert "command_interface" in caplog.text and "next configure" in caplog.text
    assert h.controller.command_interface_configuration().names == ["joint1/acceleration"]
    assert h.value("joint1/acceleration") == pytest.approx(1.95)


def test_dof_names_set_while_running_keep_the_configured_dofs_and_gains(caplog):
    """A new dof_names while running: the configured DOF keeps its PID and gains until the next configure."""
    h = _active(_params(gains={"joint1": {"p": 0.5}}), chained=True)
    h.controller.get_node().set_parameters({"dof_names": ["joint2"], "gains.joint2.p": 3.0})
    _set_ref(h, "joint1/position", 5.0)
    with caplog.at_level(logging.WARNING):
        assert h.update() is ReturnType.OK
    assert "dof_names" in caplog.text
    assert h.value("joint1/acceleration") == pytest.approx(1.95)


def test_chained_feedforward_with_gain_dual_interface():
    """ros2_controllers pid_controller/test/test_pid_controller_dual_interface.cpp,
    test_chained_feedforward_with_gain_dual_interface (jazzy): with two interfaces feed-forward acts on the reference's
    derivative: joint1 6.0 + 0.5*5 + 0.4*1 = 8.90, joint2 7.0 + 0.5*5 + 0.4*1 = 9.90."""
    gains = {j: {"p": 0.5, "i": 0.3, "d": 0.4, "feedforward_gain": 1.0, "antiwindup_strategy": "none"}
             for j in ("joint1", "joint2")}
    params = _params(dof_names=["joint1", "joint2"], command_interface="velocity",
                     reference_and_state_interfaces=["position", "velocity"], enable_feedforward=True,
                     set_current_state_as_first_setpoint=True, gains=gains)
    states = {"joint1/position": 10.0, "joint2/position": 11.0, "joint1/velocity": 5.0, "joint2/velocity": 6.0}
    h = _active(params, chained=True, states=states, commands={"joint1/velocity": 0.0, "joint2/velocity": 0.0})
    assert h.controller.feedforward_mode_enabled is True
    for name, value in (("joint1/position", 15.0), ("joint2/position", 16.0), ("joint1/velocity", 6.0),
                        ("joint2/velocity", 7.0)):
        _set_ref(h, name, value)
    h.update()
    assert h.value("joint1/velocity") == pytest.approx(8.90)
    assert h.value("joint2/velocity") == pytest.approx(9.90)


def test_dual_interface_uses_error_dot_and_feedforward_on_derivative():
    params = _params(reference_and_state_interfaces=["position", "velocity"], enable_feedforward=True,
                     gains={"joint1": {"p": 1.0, "d": 0.5, "feedforward_gain": 2.0}})
    h = _active(params, chained=True, states={"joint1/position": 1.0, "joint1/velocity": 0.2})
    _set_ref(h, "joint1/position", 2.0)
    _set_ref(h, "joint1/velocity", 1.0)
    h.update()
    # ff = 2*1.0, p*e = 1.0, d*(1.0-0.2) = 0.4
    assert h.value("joint1/acceleration") == pytest.approx(3.4)
    s = h.latest("~/controller_state").dof_states[0]
    assert s.feedback_dot == 0.2 and s.error_dot == pytest.approx(0.8)


def test_dual_interface_falls_back_to_error_only_when_derivative_is_nan():
    params = _params(reference_and_state_interfaces=["position", "velocity"], gains={"joint1": {"d": 1.0}})
    h = _active(params, chained=True, states={"joint1/position": 1.0, "joint1/velocity": 0.2})
    _set_ref(h, "joint1/position", 1.5)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(0.5 / 0.01)


def test_angle_wraparound_takes_shortest_way():
    params = _params(gains={"joint1": {"p": 1.0, "angle_wraparound": True}})
    h = _active(params, chained=True, states={"joint1/position": 3.0})
    _set_ref(h, "joint1/position", -3.0)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(2 * math.pi - 6.0)


def test_angle_wraparound_off_uses_plain_difference():
    h = _active(_params(gains={"joint1": {"p": 1.0}}), chained=True, states={"joint1/position": 3.0})
    _set_ref(h, "joint1/position", -3.0)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(-6.0)


def test_shortest_angular_distance():
    assert shortest_angular_distance(0.0, 0.5) == pytest.approx(0.5)
    assert shortest_angular_distance(3.0, -3.0) == pytest.approx(2 * math.pi - 6.0)
    assert shortest_angular_distance(-3.0, 3.0) == pytest.approx(6.0 - 2 * math.pi)


def _integral_after_reactivate(save: bool) -> float:
    h = _active(_params(gains={"joint1": {"i": 1.0, "save_i_term": save}}), chained=True,
                states={"joint1/position": 0.0})
    _set_ref(h, "joint1/position", 1.0)
    h.update(10)  # integral = 10 * 0.01 * 1.0
    h.deactivate()
    h.activate()
    return h.controller.pids[0].i_term


def test_save_i_term_keeps_integral_across_reactivation():
    assert _integral_after_reactivate(True) == pytest.approx(0.1)


def test_save_i_term_false_clears_integral():
    assert _integral_after_reactivate(False) == 0.0


def test_reference_message_reordered_by_name():
    params = _params(dof_names=["joint1", "joint2"], gains={})
    h = _active(params, states={"joint1/position": 0.0, "joint2/position": 0.0},
                commands={"joint1/acceleration": 0.0, "joint2/acceleration": 0.0})
    h.publish("~/reference", MultiDOFCommand(["joint2", "joint1"], [2.0, 1.0], []))
    h.update()
    assert h.values([f"{NAME}/joint1/position", f"{NAME}/joint2/position"]) == [1.0, 2.0]


def test_reference_without_names_assumes_order(caplog):
    h = _active()
    with caplog.at_level(logging.WARNING):
        h.publish("~/reference", MultiDOFCommand([], [0.3], []))
    h.update()
    assert h.value(f"{NAME}/joint1/position") == 0.3
    assert "no 'dof_names'" in caplog.text


def test_reference_with_unknown_dof_rejected(caplog):
    h = _active()
    with caplog.at_level(logging.ERROR):
        h.publish("~/reference", MultiDOFCommand(["jointX"], [0.3], []))
    h.update()
    assert math.isnan(h.value(f"{NAME}/joint1/position"))
    assert "field 'dof_names'" in caplog.text and "jointX" in caplog.text


def test_reference_with_wrong_size_rejected(caplog):
    h = _active()
    with caplog.at_level(logging.ERROR):
        h.publish("~/reference", MultiDOFCommand(["joint1"], [0.3, 0.4], []))
    assert "field 'values' has 2 entries, expected 1" in caplog.text


def test_reference_value_used_once_then_reference_holds():
    h = _active()
    h.publish("~/reference", MultiDOFCommand(["joint1"], [0.45], []))
    h.update()
    _set_ref(h, "joint1/position", 7.0)  # as if a later writer changed it
    h.update()
    assert h.value(f"{NAME}/joint1/position") == 7.0


def test_exported_state_interfaces_mirror_measured_state():
    h = _active()
    h.set("joint1/position", 0.7)
    h.update()
    assert h.controller.exported_state_interfaces[0].get_value() == 0.7


def test_external_measured_states_from_topic():
    h = _active(_params(use_external_measured_states=True), chained=True, states={})
    assert h.controller.state_interface_configuration().type is InterfaceConfigurationType.NONE
    h.publish("~/measured_state", MultiDOFCommand(["joint1"], [1.1], []))
    _set_ref(h, "joint1/position", 101.101)
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(30102.30102, rel=1e-12)


def test_external_measured_state_with_values_dot_needs_two_interfaces(caplog):
    h = _active(_params(use_external_measured_states=True), chained=True, states={})
    with caplog.at_level(logging.ERROR):
        h.publish("~/measured_state", MultiDOFCommand(["joint1"], [1.1], [0.0]))
    assert "'values_dot' needs two" in caplog.text


def test_controller_state_fields():
    h = _active(chained=True)
    _set_ref(h, "joint1/position", 101.101)
    h.update()
    s = h.latest("~/controller_state").dof_states[0]
    assert s.feedback == 1.1 and s.error == pytest.approx(100.001) and s.time_step == 0.01
    assert s.output == pytest.approx(30102.30102)
    assert h.latest("~/controller_state").header.stamp == pytest.approx(0.01)


def test_plugin_name_resolves():
    assert plugins.resolve("controller", "pid_controller/PidController") is PidController
