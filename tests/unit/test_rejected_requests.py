"""A rejected request changes nothing: partial hardware loads are undone, bad names and values raise clearly."""

from __future__ import annotations

import pytest
from core_helpers import TestSystem, load_configure, make_cm, make_info

from rrbot_workshop.exceptions import ControllerError, HardwareError
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State


class FailsInit(TestSystem):
    """A component whose on_init refuses its description."""

    __test__ = False

    def on_init(self, info):  # type: ignore[no-untyped-def]
        super().on_init(info)
        return CallbackReturn.ERROR


plugins.register("hardware", "test_hardware/FailsInit", FailsInit)


def test_failed_batch_load_leaves_no_component_behind() -> None:
    """If the second component fails on_init, the first one is unloaded again and its interfaces are gone."""
    rm = ResourceManager()
    with pytest.raises(HardwareError, match="broken"):
        rm.load_hardware_infos([
            make_info("fine", {"ja": (["position"], ["position"])}),
            make_info("broken", {"jb": (["position"], ["position"])}, plugin="test_hardware/FailsInit"),
        ])
    assert rm.get_components_status() == {}
    assert rm.state_interface_keys() == [] and rm.command_interface_keys() == []
    rm.load_hardware_infos([make_info("fine", {"ja": (["position"], ["position"])})])  # the name is free again
    assert list(rm.get_components_status()) == ["fine"]


def test_import_component_honours_initial_state_without_activate_all() -> None:
    """initial_states applies to import_component even when components are not activated by default."""
    rm = ResourceManager(activate_all=False, initial_states={"a": State.INACTIVE})
    rm.import_component(TestSystem(), make_info("a", {"ja": (["position"], ["position"])}))
    rm.import_component(TestSystem(), make_info("b", {"jb": (["position"], ["position"])}))
    status = rm.get_components_status()
    assert status["a"].state is State.INACTIVE and status["b"].state is State.UNCONFIGURED


def test_bad_fallback_controllers_value_is_rejected_before_on_init_and_leaves_no_topics() -> None:
    """fallback_controllers must be a list of names; the load fails and nothing of the controller remains."""
    cm = make_cm({"c": {"fallback_controllers": "other", "command_interfaces": ["joint1/position"]}})
    with pytest.raises(ControllerError, match="fallback_controllers"):
        cm.load_controller("c")
    assert cm.list_controllers() == []
    assert [t for t, _ in cm.bus.topic_names_and_types() if not t.startswith("/controller_manager/")] == []


def test_unknown_target_state_label_raises_controller_error_listing_the_states() -> None:
    """set_controller_state with a label that is not a lifecycle state names the valid ones."""
    cm = make_cm({"c": {"command_interfaces": ["joint1/position"]}})
    load_configure(cm, "c")
    with pytest.raises(ControllerError, match="valid: .*inactive"):
        cm.set_controller_state("c", "running")
    assert {c.name: c.state for c in cm.list_controllers()} == {"c": "inactive"}


@pytest.mark.parametrize("strictness", ["strict", "best_effort"])
def test_failed_activation_ends_unconfigured_and_the_error_says_a_controller_changed(strictness: str) -> None:
    """Jazzy: on_activate returning ERROR runs on_error, whose default (rclcpp_lifecycle's) returns SUCCESS, so the
    controller ends UNCONFIGURED, not FINALIZED; it can be configured and activated again. The switch error names it
    and does not claim that nothing changed. (ros2_control test_controller_manager.cpp, activation failure cases.)"""
    from rrbot_workshop.exceptions import SwitchError

    cm = make_cm({"c": {"command_interfaces": ["joint1/position"]}})
    load_configure(cm, "c")
    cm.get_controller("c").activate_result = CallbackReturn.ERROR  # type: ignore[attr-defined]
    with pytest.raises(SwitchError) as info:
        cm.switch_controllers(activate=["c"], strictness=strictness)
    assert info.value.partial and "no controller changed state" not in str(info.value)
    assert info.value.controllers == ["c"]
    assert {c.name: c.state for c in cm.list_controllers()} == {"c": "unconfigured"}
    cm.get_controller("c").activate_result = CallbackReturn.SUCCESS  # type: ignore[attr-defined]
    cm.configure_controller("c")
    cm.switch_controllers(activate=["c"], strictness="strict")
    assert {c.name: c.state for c in cm.list_controllers()} == {"c": "active"}
