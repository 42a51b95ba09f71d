"""Controller manager: load/configure/unload, update order and rates, failures, introspection, services."""

from __future__ import annotations

import logging

import pytest
from core_helpers import TestSystem, load_configure, make_cm, make_info

from rrbot_workshop.exceptions import ControllerError, ControllerNotFound, HardwareError
from rrbot_workshop.middleware.lifecycle import ReturnType, State

J1 = {"command_interfaces": ["joint1/position"], "state_interfaces": ["joint1/position"]}
J2 = {"command_interfaces": ["joint2/position"]}
CHAIN = "test_controller/TestChainableController"


def _run(cm, cycles: int, start: int = 1) -> None:  # noqa: ANN001
    for k in range(start, start + cycles):
        cm.update(k / cm.update_rate, 1 / cm.update_rate)


def test_load_undeclared_controller_lists_declared_ones() -> None:
    cm = make_cm({"c1": J1})
    with pytest.raises(ControllerNotFound, match="'ghost'.*'c1'"):
        cm.load_controller("ghost")


def test_load_twice_raises() -> None:
    cm = make_cm({"c1": J1})
    cm.load_controller("c1")
    with pytest.raises(ControllerError, match="already loaded"):
        cm.load_controller("c1")


def test_load_unknown_type_names_controller_and_type() -> None:
    cm = make_cm({"c1": {"type": "nope/Nope"}})
    with pytest.raises(ControllerError, match="'c1'.*nope/Nope"):
        cm.load_controller("c1")
    assert "c1" not in cm.controllers


def test_load_with_explicit_type() -> None:
    cm = make_cm({})
    cm.load_controller("x", "test_controller/TestController")
    assert cm.controllers["x"].state is State.UNCONFIGURED


def test_configure_makes_controller_inactive() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    assert cm.controllers["c1"].state is State.INACTIVE


def test_configure_active_controller_raises() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    cm.switch_controllers(activate=["c1"])
    with pytest.raises(ControllerError, match="active"):
        cm.configure_controller("c1")


def test_reconfigure_inactive_controller_cleans_up_first() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    cm.configure_controller("c1")
    assert cm.controllers["c1"].state is State.INACTIVE


def test_chainable_controller_without_exports_fails_configure() -> None:
    cm = make_cm({"pid": {"type": CHAIN, "command_interfaces": ["joint1/position"]}})
    cm.load_controller("pid")
    with pytest.raises(ControllerError, match="exports neither"):
        cm.configure_controller("pid")
    assert cm.controllers["pid"].state is State.UNCONFIGURED


def test_unload_active_raises_and_unload_inactive_forgets() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    cm.switch_controllers(activate=["c1"])
    with pytest.raises(ControllerError, match="deactivate it first"):
        cm.unload_controller("c1")
    cm.switch_controllers(deactivate=["c1"])
    cm.unload_controller("c1")
    assert "c1" not in cm.controllers and cm.update_order() == []


def test_unload_unknown_raises() -> None:
    with pytest.raises(ControllerNotFound):
        make_cm({}).unload_controller("nope")


def test_cleanup_refuses_an_active_controller() -> None:
    """Jazzy's cleanup_controller_srv, variation 3: an active controller is not cleaned up (it stays active)."""
    cm = make_cm({"c1": J1})
    cm.load_controller("c1")
    cm.configure_controller("c1")
    cm.switch_controllers(activate=["c1"], strictness="strict")
    with pytest.raises(ControllerError, match="'active' and cannot be cleaned up"):
        cm.cleanup_controller("c1")
    assert cm.controllers["c1"].state.label == "active"


def test_set_controller_state_walks_the_lifecycle() -> None:
    cm = make_cm({"c1": J1})
    cm.load_controller("c1")
    for target in ("inactive", "active", "inactive", "unconfigured"):
        cm.set_controller_state("c1", target)
        assert cm.controllers["c1"].state.label == target


def test_set_controller_state_rejects_impossible_transitions() -> None:
    cm = make_cm({"c1": J1})
    cm.load_controller("c1")
    with pytest.raises(ControllerError, match="only an inactive"):
        cm.set_controller_state("c1", "active")
    with pytest.raises(ControllerError, match="valid"):
        cm.set_controller_state("c1", "finalized")


def test_update_order_puts_preceding_controllers_first() -> None:
    """Port of list_sorted_chained_controllers: loaded [c4, c1, c3, c5, c2, test] -> [test, c5, c4, c3, c2, c1]."""
    ctrls = {
        "c1": {"type": CHAIN, "reference_interfaces": ["joint1/position"], "command_interfaces": ["joint1/position"]},
        "test": {"command_interfaces": ["c5/joint1/position"]},
    }
    for k in range(2, 6):
        ctrls[f"c{k}"] = {
            "type": CHAIN, "reference_interfaces": ["joint1/position"], "command_interfaces": [f"c{k - 1}/joint1/position"],
        }
    cm = make_cm(ctrls)
    names = ["c4", "c1", "c3", "c5", "c2", "test"]
    for n in names:
        cm.load_controller(n)
    assert cm.update_order() == names
    for n in names:
        cm.configure_controller(n)
    assert cm.update_order() == ["test", "c5", "c4", "c3", "c2", "c1"]
    assert [c.name for c in cm.list_controllers()] == ["test", "c5", "c4", "c3", "c2", "c1"]


def test_reader_of_exported_state_runs_after_exporter() -> None:
    cm = make_cm({
        "reader": {"state_interfaces": ["est/joint1/position"]},
        "est": {"type": CHAIN, "exported_state_interfaces": ["joint1/position"], "state_interfaces": ["joint1/position"]},
    })
    load_configure(cm, "reader", "est")
    assert cm.update_order() == ["est", "reader"]


def test_controller_at_half_rate_updates_every_other_cycle() -> None:
    cm = make_cm({"slow": {**J1, "update_rate": 50}, "fast": J2})
    load_configure(cm, "slow", "fast")
    cm.switch_controllers(activate=["slow", "fast"])
    _run(cm, 10)
    slow = cm.get_controller("slow")
    assert len(slow.updates) == 5 and len(cm.get_controller("fast").updates) == 10
    assert [p for _, p in slow.updates[1:]] == pytest.approx([0.02] * 4)
    assert cm.list_controllers()[0].update_rate == 50


def test_non_divisor_rate_is_rounded_like_ros2_control() -> None:
    cm = make_cm({"c": {**J1, "update_rate": 30}})
    load_configure(cm, "c")
    assert cm.get_controller("c").get_update_rate() == 33


def test_controller_that_raises_is_deactivated_and_loop_goes_on(caplog: pytest.LogCaptureFixture) -> None:
    cm = make_cm({"bad": J1, "good": J2})
    load_configure(cm, "bad", "good")
    cm.switch_controllers(activate=["bad", "good"])
    cm.get_controller("bad").raise_in_update = True
    with caplog.at_level(logging.ERROR):
        _run(cm, 3)
    assert cm.controllers["bad"].state is State.INACTIVE
    assert cm.controllers["good"].state is State.ACTIVE and len(cm.get_controller("good").updates) == 3
    assert "learner bug in update" in caplog.text and "Traceback" in caplog.text
    assert not cm.resource_manager.command_interface_is_claimed("joint1/position")


def test_controller_returning_error_activates_its_fallback() -> None:
    cm = make_cm({"main": {**J1, "fallback_controllers": ["safe"]}, "safe": J1})
    load_configure(cm, "main", "safe")
    cm.switch_controllers(activate=["main"])
    cm.get_controller("main").update_result = ReturnType.ERROR
    _run(cm, 1)
    assert cm.controllers["main"].state is State.INACTIVE
    assert cm.controllers["safe"].state is State.ACTIVE
    assert cm.resource_manager.command_interface_holder("joint1/position") == "safe"


def test_exceptions_propagate_when_handle_exceptions_is_false() -> None:
    cm = make_cm({"bad": J1}, manager={"handle_exceptions": False})
    load_configure(cm, "bad")
    cm.switch_controllers(activate=["bad"])
    cm.get_controller("bad").raise_in_update = True
    with pytest.raises(ValueError, match="learner bug"):
        _run(cm, 1)


def _two_hw_cm():  # noqa: ANN202
    a, b = TestSystem(), TestSystem()
    hw = [(a, make_info("arm", {"joint1": (["position"], ["position"])})),
          (b, make_info("base", {"joint2": (["position"], ["position"])}))]
    cm = make_cm({"on_arm": J1, "on_base": J2}, hardware=hw)
    load_configure(cm, "on_arm", "on_base")
    cm.switch_controllers(activate=["on_arm", "on_base"])
    return cm, a, b


def test_hardware_read_error_deactivates_only_controllers_using_it() -> None:
    cm, arm, _ = _two_hw_cm()
    arm.read_result = ReturnType.ERROR
    _run(cm, 2)
    assert cm.controllers["on_arm"].state is State.INACTIVE
    assert cm.controllers["on_base"].state is State.ACTIVE
    assert cm.resource_manager.get_components_status()["arm"].state is State.UNCONFIGURED


def test_hardware_write_deactivate_stops_its_controllers() -> None:
    cm, _, base = _two_hw_cm()
    base.write_result = ReturnType.DEACTIVATE
    _run(cm, 1)
    assert cm.controllers["on_base"].state is State.INACTIVE
    assert cm.resource_manager.get_components_status()["base"].state is State.INACTIVE


def test_set_hardware_component_state_inactive_stops_writes() -> None:
    cm, arm, _ = _two_hw_cm()
    _run(cm, 1)
    assert cm.set_hardware_component_state("arm", "inactive")
    _run(cm, 3, start=2)
    assert arm.writes == 1 and arm.reads == 4
    assert cm.controllers["on_arm"].state is State.ACTIVE  # as in Jazzy: controllers are not touched


def test_set_hardware_component_state_bad_label_raises() -> None:
    cm, _, _ = _two_hw_cm()
    with pytest.raises(HardwareError, match="sleeping"):
        cm.set_hardware_component_state("arm", "sleeping")
    with pytest.raises(HardwareError, match="valid"):
        cm.set_hardware_component_state("nope", "active")


def test_cycle_runs_read_update_write_and_hooks_in_order() -> None:
    cm = make_cm({"c1": {**J1}})
    load_configure(cm, "c1")
    cm.switch_controllers(activate=["c1"])
    cm.get_controller("c1").command_value = 0.3
    seen: list[tuple[float, float]] = []
    remove = cm.add_cycle_hook(lambda t, p: seen.append((t, cm.resource_manager.get_interface_value("joint1/position"))))
    _run(cm, 2)
    assert seen == [(0.01, 0.3), (0.02, 0.3)]  # the write of the same cycle copied the command to the state
    remove()
    _run(cm, 1, start=3)
    assert len(seen) == 2


def test_list_controllers_fields() -> None:
    cm = make_cm({
        "pre": {"command_interfaces": ["pid/joint1/position"]},
        "pid": {"type": CHAIN, "reference_interfaces": ["joint1/position"], "command_interfaces": ["joint1/position"],
                "state_interfaces": ["joint1/position"]},
        "idle": J2,
    })
    load_configure(cm, "pre", "pid")
    cm.load_controller("idle")
    cm.switch_controllers(activate=["pid", "pre"])
    by_name = {c.name: c for c in cm.list_controllers()}
    pid, pre, idle = by_name["pid"], by_name["pre"], by_name["idle"]
    assert (pid.state, pid.type, pid.is_chainable, pid.is_chained) == ("active", CHAIN, True, True)
    assert pid.reference_interfaces == ["joint1/position"]  # prefix removed
    assert pid.claimed_interfaces == ["joint1/position"] and pid.required_state_interfaces == ["joint1/position"]
    assert pre.chain_connections[0].name == "pid"
    assert pre.chain_connections[0].reference_interfaces == ["pid/joint1/position"]
    assert idle.state == "unconfigured" and idle.required_command_interfaces == [] and idle.claimed_interfaces == []


def test_list_hardware_interfaces_sorted_with_claims() -> None:
    cm, _, _ = _two_hw_cm()
    itfs = cm.list_hardware_interfaces()
    assert [c.name for c in itfs.command_interfaces] == ["joint1/position", "joint2/position"]
    assert all(c.is_claimed and c.is_available for c in itfs.command_interfaces)
    assert not any(s.is_claimed for s in itfs.state_interfaces)


def test_list_hardware_components_fields() -> None:
    cm, _, _ = _two_hw_cm()
    arm = cm.list_hardware_components()[0]
    assert (arm.name, arm.type, arm.plugin_name, arm.state, arm.rw_rate) == (
        "arm", "system", "test_hardware/TestSystem", State.ACTIVE, 100)
    assert arm.command_interfaces[0].is_claimed


def test_list_controller_types_reports_base_classes() -> None:
    types = dict(make_cm({}).list_controller_types())
    assert types["test_controller/TestChainableController"] == "controller_interface::ChainableControllerInterface"
    assert types["test_controller/TestController"] == "controller_interface::ControllerInterface"


def test_view_controller_chains_draws_edges() -> None:
    cm = make_cm({
        "pre": {"command_interfaces": ["pid/joint1/position"]},
        "pid": {"type": CHAIN, "reference_interfaces": ["joint1/position"], "command_interfaces": ["joint1/position"]},
    })
    load_configure(cm, "pre", "pid")
    dot = cm.view_controller_chains()
    assert dot.startswith("digraph")
    assert '"pre":cmd_pid_joint1_position -> "pid":ref_pid_joint1_position;' in dot
    assert '"pid":cmd_joint1_position -> "hw_command_interfaces":hw_joint1_position;' in dot


def test_services_mirror_the_api() -> None:
    cm = make_cm({"c1": J1})
    assert cm.bus.call_service("/controller_manager/load_controller", {"name": "c1"}).ok
    assert cm.bus.call_service("/controller_manager/configure_controller", {"name": "c1"}).ok
    resp = cm.bus.call_service("/controller_manager/switch_controller", {"activate_controllers": ["c1"], "strictness": 2})
    assert resp.ok
    listed = cm.bus.call_service("/controller_manager/list_controllers", {}).controller
    assert [(c.name, c.state) for c in listed] == [("c1", "active")]
    bad = cm.bus.call_service("/controller_manager/unload_controller", {"name": "c1"})
    assert not bad.ok and "deactivate it first" in bad.message
    hw = cm.bus.call_service("/controller_manager/set_hardware_component_state", {"name": "sys", "target_state": "inactive"})
    assert hw.ok and hw.state is State.INACTIVE


def test_shutdown_unloads_everything() -> None:
    cm, _, _ = _two_hw_cm()
    cm.shutdown()
    assert cm.controllers == {} and not cm.resource_manager.command_interface_is_claimed("joint1/position")


def test_non_divisor_rate_uses_integer_division_like_ros2_control() -> None:
    """30 Hz on a 200 Hz loop: 200 // round(200 / 30) = 200 // 7 = 28 Hz (not 29)."""
    from rrbot_workshop.controller_interface.controller import _effective_rate

    assert _effective_rate(30, 200) == 28
    assert _effective_rate(0, 200) == 200
    assert _effective_rate(500, 200) == 200
