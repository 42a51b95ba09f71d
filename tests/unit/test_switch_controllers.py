"""switch_controllers: strictness, conflicts, interface availability, hardware veto, rollback.

Ports the key cases of ros2_control's test_controller_manager_srvs.cpp and test_release_interfaces.cpp.
"""

from __future__ import annotations

import pytest
from core_helpers import TestSystem, load_configure, make_cm, make_info

from rrbot_workshop.exceptions import ControllerError, SwitchError
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

J1 = {"command_interfaces": ["joint1/position"]}
J2 = {"command_interfaces": ["joint2/position"]}


def _states(cm) -> dict[str, str]:  # noqa: ANN001
    return {n: s.state.label for n, s in cm.controllers.items()}


def test_unknown_controller_strict_rejects_everything() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    with pytest.raises(SwitchError, match="'ghost' is not loaded"):
        cm.switch_controllers(activate=["c1", "ghost"], strictness="strict")
    assert _states(cm) == {"c1": "inactive"}


def test_unknown_controller_best_effort_activates_the_known_ones() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    result = cm.switch_controllers(activate=["c1", "ghost"], strictness="best_effort")
    assert _states(cm) == {"c1": "active"}
    assert result.activated == ["c1"] and "ghost" in result.skipped[0]


def test_best_effort_with_only_unknown_names_is_an_error() -> None:
    cm = make_cm({"c1": J1})
    with pytest.raises(SwitchError, match="ghost"):
        cm.switch_controllers(activate=["ghost"], strictness="best_effort")


def test_empty_request_does_nothing() -> None:
    result = make_cm({}).switch_controllers()
    assert result.activated == [] and result.deactivated == []


def test_default_strictness_is_best_effort_as_in_jazzy() -> None:
    cm = make_cm({"c1": J1, "c2": J2})
    load_configure(cm, "c1")
    cm.load_controller("c2")
    result = cm.switch_controllers(activate=["c1", "c2"])
    assert _states(cm) == {"c1": "active", "c2": "unconfigured"}
    assert "unconfigured" in result.skipped[0]


def test_integer_strictness_constants_are_accepted() -> None:
    cm = make_cm({"c1": J1})
    with pytest.raises(SwitchError):
        cm.switch_controllers(activate=["c1", "ghost"], strictness=2)


def test_unknown_strictness_raises() -> None:
    with pytest.raises(ControllerError, match="strictness"):
        make_cm({}).switch_controllers(activate=["x"], strictness="sloppy")


def test_single_string_instead_of_list_raises() -> None:
    with pytest.raises(ControllerError, match="lists"):
        make_cm({}).switch_controllers(activate="c1")  # type: ignore[arg-type]


def test_activating_unconfigured_controller_strict_fails_and_changes_nothing() -> None:
    cm = make_cm({"c1": J1, "c2": J2})
    load_configure(cm, "c1")
    cm.load_controller("c2")
    with pytest.raises(SwitchError, match="'c2' is unconfigured"):
        cm.switch_controllers(activate=["c1", "c2"], strictness="strict")
    assert _states(cm) == {"c1": "inactive", "c2": "unconfigured"}


def test_activating_active_controller_strict_fails() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    cm.switch_controllers(activate=["c1"])
    with pytest.raises(SwitchError, match="already active"):
        cm.switch_controllers(activate=["c1"], strictness="strict")


def test_deactivating_inactive_controller_strict_fails() -> None:
    cm = make_cm({"c1": J1})
    load_configure(cm, "c1")
    with pytest.raises(SwitchError, match="not active"):
        cm.switch_controllers(deactivate=["c1"], strictness="strict")


def test_two_controllers_on_the_same_interface_name_both_and_the_interface() -> None:
    """Port of switch_controller_test_two_controllers_using_same_interface: ERROR, whatever the strictness."""
    cm = make_cm({"a": J1, "b": J1})
    load_configure(cm, "a", "b")
    for strictness in ("strict", "best_effort"):
        with pytest.raises(SwitchError) as err:
            cm.switch_controllers(activate=["a", "b"], strictness=strictness)
        text = str(err.value)
        assert "'a'" in text and "'b'" in text and "'joint1/position'" in text
        assert _states(cm) == {"a": "inactive", "b": "inactive"}


def test_interface_claimed_by_active_controller_names_the_holder() -> None:
    cm = make_cm({"a": J1, "b": J1})
    load_configure(cm, "a", "b")
    cm.switch_controllers(activate=["a"])
    with pytest.raises(SwitchError, match="already claimed by 'a'"):
        cm.switch_controllers(activate=["b"])
    assert _states(cm) == {"a": "active", "b": "inactive"}


def test_swapping_controllers_in_one_switch_moves_the_claim() -> None:
    cm = make_cm({"a": J1, "b": J1})
    load_configure(cm, "a", "b")
    cm.switch_controllers(activate=["a"])
    result = cm.switch_controllers(activate=["b"], deactivate=["a"], strictness="strict")
    assert _states(cm) == {"a": "inactive", "b": "active"}
    assert result.deactivated == ["a"] and result.activated == ["b"]
    assert cm.resource_manager.command_interface_holder("joint1/position") == "b"


def test_missing_interface_is_an_error_even_in_best_effort() -> None:
    cm = make_cm({"c": {"command_interfaces": ["joint7/position"]}})
    load_configure(cm, "c")
    with pytest.raises(SwitchError, match="'joint7/position', which does not exist"):
        cm.switch_controllers(activate=["c"], strictness="best_effort")


def test_unavailable_state_interface_names_the_hardware_state() -> None:
    cm = make_cm({"c": {"state_interfaces": ["joint1/position"]}})
    load_configure(cm, "c")
    cm.set_hardware_component_state("sys", "unconfigured")
    with pytest.raises(SwitchError, match="hardware component 'sys' is 'unconfigured'"):
        cm.switch_controllers(activate=["c"])


def test_command_interfaces_of_inactive_hardware_cannot_be_claimed() -> None:
    cm = make_cm({"c": J1, "broadcaster": {"state_interfaces": ["joint1/position"]}})
    load_configure(cm, "c", "broadcaster")
    cm.set_hardware_component_state("sys", "inactive")
    with pytest.raises(SwitchError, match="hardware rejected"):
        cm.switch_controllers(activate=["c"])
    cm.switch_controllers(activate=["broadcaster"], strictness="strict")  # state-only controllers may
    assert cm.controllers["broadcaster"].state is State.ACTIVE


def test_hardware_veto_rejects_the_switch_and_changes_nothing() -> None:
    impl = TestSystem()
    impl.prepare_result = ReturnType.ERROR
    hw = [(impl, make_info("sys", {"joint1": (["position"], ["position"])}))]
    cm = make_cm({"c": J1}, hardware=hw)
    load_configure(cm, "c")
    with pytest.raises(SwitchError, match="hardware rejected the command mode switch"):
        cm.switch_controllers(activate=["c"])
    assert cm.controllers["c"].state is State.INACTIVE and impl.performed == []


def test_hardware_is_told_which_interfaces_start_and_stop() -> None:
    impl = TestSystem()
    hw = [(impl, make_info("sys", {"joint1": (["position"], ["position"])}))]
    cm = make_cm({"a": J1, "b": J1}, hardware=hw)
    load_configure(cm, "a", "b")
    cm.switch_controllers(activate=["a"])
    cm.switch_controllers(activate=["b"], deactivate=["a"])
    assert impl.prepared[-1] == (["joint1/position"], ["joint1/position"])
    assert impl.performed[-1] == (["joint1/position"], ["joint1/position"])


def test_failed_activation_strict_rolls_back_the_whole_switch() -> None:
    cm = make_cm({"a": J1, "b": J2, "old": {"command_interfaces": ["joint1/position"]}})
    load_configure(cm, "a", "b", "old")
    cm.switch_controllers(activate=["old"])
    cm.get_controller("b").activate_result = CallbackReturn.FAILURE
    with pytest.raises(SwitchError, match="'b' failed to activate") as err:
        cm.switch_controllers(activate=["a", "b"], deactivate=["old"], strictness="strict")
    assert not err.value.partial
    assert _states(cm) == {"a": "inactive", "b": "inactive", "old": "active"}
    assert cm.resource_manager.command_interface_holder("joint1/position") == "old"


def test_failed_activation_best_effort_keeps_the_others_and_says_partial() -> None:
    cm = make_cm({"a": J1, "b": J2})
    load_configure(cm, "a", "b")
    cm.get_controller("b").activate_result = CallbackReturn.FAILURE
    with pytest.raises(SwitchError, match="partly failed") as err:
        cm.switch_controllers(activate=["a", "b"], strictness="best_effort")
    assert err.value.partial and _states(cm) == {"a": "active", "b": "inactive"}
    assert not cm.resource_manager.command_interface_is_claimed("joint2/position")


def test_every_reason_is_listed() -> None:
    cm = make_cm({"a": J1, "b": J1, "c": {"command_interfaces": ["nope/x"]}})
    load_configure(cm, "a", "b", "c")
    with pytest.raises(SwitchError) as err:
        cm.switch_controllers(activate=["a", "b", "c"], strictness="strict")
    assert len(err.value.reasons) == 2
    assert any("nope/x" in r for r in err.value.reasons) and any("both claim" in r for r in err.value.reasons)


def test_best_effort_with_a_list_of_unknown_names_changes_nothing() -> None:
    """Best effort forgives unknown names per list: `--deactivate a --activate typo` is rejected as a whole (a running
    controller is not stopped for a replacement that does not exist); `--activate real typo` activates `real`."""
    from core_helpers import load_configure, make_cm

    from rrbot_workshop.exceptions import SwitchError

    cm = make_cm({"a": {"command_interfaces": ["joint1/position"]}, "b": {"command_interfaces": ["joint2/position"]}})
    load_configure(cm, "a", "b")
    cm.switch_controllers(activate=["a"], strictness="strict")
    with pytest.raises(SwitchError, match="no controller of the activate list exists") as info:
        cm.switch_controllers(activate=["a_typo"], deactivate=["a"], strictness="best_effort")
    assert info.value.controllers == ["a_typo"]
    assert {c.name: c.state for c in cm.list_controllers()} == {"a": "active", "b": "inactive"}
    cm.switch_controllers(activate=["b", "b_typo"], strictness="best_effort")
    assert {c.name: c.state for c in cm.list_controllers()} == {"a": "active", "b": "active"}
