"""The controller manager's Jazzy parameters read from the controllers YAML, a slower controller's first period, and
a component that deactivates itself from ``write``.

Jazzy sources: ``controller_manager/src/controller_manager_parameters.yaml`` (names, types, defaults),
``controller_manager.cpp`` (``write``: self-deactivated hardware; ``update``: a controller's first period).
"""

from __future__ import annotations

import logging
from typing import Any

import pytest
from core_helpers import TestSystem, load_configure, make_cm, make_info

from rrbot_workshop.exceptions import ParameterError, SwitchError
from rrbot_workshop.middleware.lifecycle import ReturnType, State


@pytest.fixture(autouse=True)
def _quiet() -> Any:
    logging.disable(logging.CRITICAL)
    yield
    logging.disable(logging.NOTSET)


def _two_controllers(manager: dict[str, Any] | None = None) -> Any:
    cm = make_cm({"a": {"command_interfaces": ["joint1/position"]}, "b": {"command_interfaces": ["joint1/position"]}},
                 manager=manager)
    load_configure(cm, "a", "b")
    cm.switch_controllers(activate=["a"], strictness="strict")
    return cm


def test_jazzy_defaults_when_the_yaml_says_nothing() -> None:
    cm = _two_controllers()
    assert cm.default_strictness == "best_effort"
    assert cm.deactivate_controllers_on_hardware_self_deactivate is True
    assert cm.resource_manager.allow_controller_activation_with_inactive_hardware is False
    assert cm.enforce_command_limits is False


@pytest.mark.parametrize("spelling", ["nested", "dotted"])
def test_default_strictness_from_the_yaml_is_used_for_strictness_none_and_zero(spelling: str) -> None:
    manager = ({"defaults": {"switch_controller": {"strictness": "strict"}}} if spelling == "nested"
               else {"defaults.switch_controller.strictness": "strict"})
    cm = _two_controllers(manager)
    assert cm.default_strictness == "strict"
    for strictness in (None, 0):
        with pytest.raises(SwitchError):  # strict: the unknown name rejects the whole request
            cm.switch_controllers(activate=["b", "nope"], deactivate=["a"], strictness=strictness)
        assert cm.controllers["a"].state is State.ACTIVE
    # the same request under Jazzy's default drops the unknown name and switches
    best = _two_controllers()
    best.switch_controllers(activate=["b", "nope"], deactivate=["a"])
    assert best.controllers["b"].state is State.ACTIVE


@pytest.mark.parametrize(("key", "value", "words"), [
    ("defaults.switch_controller.strictness", "sometimes", "must be 'strict' or 'best_effort'"),
    ("defaults.deactivate_controllers_on_hardware_self_deactivate", "yes", "must be true or false"),
    ("defaults.allow_controller_activation_with_inactive_hardware", 1, "must be true or false"),
    ("enforce_command_limits", "false", "must be true or false"),
])
def test_a_wrong_value_names_the_parameter(key: str, value: object, words: str) -> None:
    with pytest.raises(ParameterError, match=words) as err:
        make_cm({}, manager={key: value})
    assert err.value.parameter == key and err.value.owner == "controller_manager"


def test_allow_activation_with_inactive_hardware_from_the_yaml() -> None:
    for allowed in (False, True):
        cm = make_cm({"a": {"command_interfaces": ["joint1/position"]}},
                     manager={"defaults": {"allow_controller_activation_with_inactive_hardware": allowed}})
        load_configure(cm, "a")
        cm.set_hardware_component_state("sys", "inactive")
        if allowed:
            cm.switch_controllers(activate=["a"], strictness="strict")
            assert cm.controllers["a"].state is State.ACTIVE
        else:
            with pytest.raises(SwitchError, match="is inactive; its command interfaces"):
                cm.switch_controllers(activate=["a"], strictness="strict")


def _self_deactivating(flag: bool | None) -> tuple[Any, TestSystem]:
    hw = TestSystem()
    manager = {} if flag is None else {"defaults": {"deactivate_controllers_on_hardware_self_deactivate": flag}}
    cm = make_cm({"commander": {"command_interfaces": ["joint1/position"]},
                  "reader": {"state_interfaces": ["joint1/position"]}},
                 hardware=[(hw, make_info("arm", {"joint1": (["position"], ["position"])}))], manager=manager)
    load_configure(cm, "commander", "reader")
    cm.switch_controllers(activate=["commander", "reader"], strictness="strict")
    hw.write_result = ReturnType.DEACTIVATE
    cm.update(0.0, 0.01)
    return cm, hw


def test_hardware_that_deactivates_itself_stops_only_its_commanders() -> None:
    cm, hw = _self_deactivating(None)
    assert cm.resource_manager.get_component("arm").get_lifecycle_state() is State.INACTIVE
    assert cm.controllers["commander"].state is State.INACTIVE
    assert cm.controllers["reader"].state is State.ACTIVE, "a state reader of inactive hardware keeps running"
    hw.write_result = ReturnType.OK
    reads = hw.reads
    cm.update(0.01, 0.01)
    assert hw.reads == reads + 1 and cm.controllers["reader"].state is State.ACTIVE


def test_self_deactivated_hardware_keeps_its_controllers_when_the_parameter_is_false() -> None:
    cm, _hw = _self_deactivating(False)
    assert cm.resource_manager.get_component("arm").get_lifecycle_state() is State.INACTIVE
    assert cm.controllers["commander"].state is State.ACTIVE
    assert cm.controllers["reader"].state is State.ACTIVE


def test_hardware_write_error_still_stops_readers_too() -> None:
    hw = TestSystem()
    cm = make_cm({"commander": {"command_interfaces": ["joint1/position"]},
                  "reader": {"state_interfaces": ["joint1/position"]}},
                 hardware=[(hw, make_info("arm", {"joint1": (["position"], ["position"])}))])
    load_configure(cm, "commander", "reader")
    cm.switch_controllers(activate=["commander", "reader"], strictness="strict")
    hw.write_result = ReturnType.ERROR
    cm.update(0.0, 0.01)
    assert cm.controllers["commander"].state is State.INACTIVE and cm.controllers["reader"].state is State.INACTIVE


def test_a_slower_controllers_first_period_is_its_own_nominal_period() -> None:
    """Jazzy: a controller at 20 Hz under a 100 Hz manager gets 1/20 s as its first period, then the time since its
    last update (the manager's period only for controllers as fast as the manager)."""
    cm = make_cm({"slow": {"command_interfaces": ["joint1/position"], "update_rate": 20},
                  "fast": {"command_interfaces": ["joint2/position"]}}, update_rate=100)
    load_configure(cm, "slow", "fast")
    cm.switch_controllers(activate=["slow", "fast"], strictness="strict")
    for k in range(12):
        cm.update(k * 0.01, 0.01)
    slow = cm.controllers["slow"].controller.updates
    fast = cm.controllers["fast"].controller.updates
    assert slow[0][1] == pytest.approx(0.05)
    assert [p for _, p in slow[1:]] == pytest.approx([0.05] * (len(slow) - 1))
    assert len(slow) == 3 and all(p == pytest.approx(0.01) for _, p in fast)


def test_a_controller_naming_itself_as_fallback_fails_to_load_and_nothing_is_left() -> None:
    from rrbot_workshop.exceptions import ControllerError

    cm = make_cm({"a": {"command_interfaces": ["joint1/position"], "fallback_controllers": ["b", "a"]}})
    with pytest.raises(ControllerError, match="names itself in 'fallback_controllers'"):
        cm.load_controller("a")
    assert "a" not in cm.controllers


def test_a_type_declared_only_in_the_all_nodes_section_loads() -> None:
    """ROS 2 applies '/**' to every node, the controller manager too: '<name>.type' there declares a controller."""
    from rrbot_workshop.controller_manager.manager import ControllerManager
    from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
    from rrbot_workshop.middleware.params import load_controllers_yaml

    cfg = load_controllers_yaml(
        "/**:\n  ros__parameters:\n    use_sim_time: true\n    a:\n      type: test_controller/TestController\n"
        "a:\n  ros__parameters:\n    command_interfaces: [joint1/position]\n"
    )
    assert cfg.controller_types == {"a": "test_controller/TestController"}
    assert cfg.parameters_for("a") == {"use_sim_time": True, "command_interfaces": ["joint1/position"]}
    rm = ResourceManager()
    hw = TestSystem()
    rm.import_component(hw, make_info("sys", {"joint1": (["position"], ["position"])}))
    cm = ControllerManager(rm, params=cfg)
    load_configure(cm, "a")
    cm.switch_controllers(activate=["a"], strictness="strict")
    assert cm.controllers["a"].state is State.ACTIVE
