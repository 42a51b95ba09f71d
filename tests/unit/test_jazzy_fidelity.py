"""Cases ported from the Jazzy test suites of ros2_control, ros2_controllers and control_toolbox (issue 23).

Each test's docstring names its source: repository, file and test name, on the jazzy branch. The setups are our
own (the course's test controllers and hardware); the behaviour asserted is Jazzy's.
"""

from __future__ import annotations

import pytest
from core_helpers import load_configure, make_cm

from rrbot_workshop.exceptions import SwitchError
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State

CHAIN = "test_controller/TestChainableController"


def _fail_activation(cm, name: str) -> None:  # noqa: ANN001
    cm.get_controller(name).on_activate = lambda previous_state: CallbackReturn.ERROR


def _heal(cm, name: str) -> None:  # noqa: ANN001
    del cm.get_controller(name).on_activate


def _states(cm, *names: str) -> list[State]:  # noqa: ANN001
    return [cm.controllers[n].state for n in names]


def test_chainable_controller_that_failed_activation_can_be_configured_and_activated_again() -> None:
    """ros2_control controller_manager/test/test_controller_manager.cpp,
    test_chainable_controllers_failed_activation_and_then_reconfiguring_it (jazzy)."""
    cm = make_cm({"chain": {"type": CHAIN, "reference_interfaces": ["modified_joint1/position"],
                            "exported_state_interfaces": ["modified_joint2/position"],
                            "command_interfaces": ["joint1/position"], "state_interfaces": ["joint2/position"]}})
    load_configure(cm, "chain")
    _fail_activation(cm, "chain")
    with pytest.raises(SwitchError, match="failed to activate"):
        cm.switch_controllers(activate=["chain"], strictness="strict")
    assert _states(cm, "chain") == [State.UNCONFIGURED]
    _heal(cm, "chain")
    cm.configure_controller("chain")
    assert _states(cm, "chain") == [State.INACTIVE]
    cm.switch_controllers(activate=["chain"], strictness="strict")
    assert _states(cm, "chain") == [State.ACTIVE]
    assert cm.resource_manager.command_interface_is_available("chain/modified_joint1/position")


def test_chainable_controller_that_failed_activation_can_be_unloaded_and_loaded_again() -> None:
    """The same as above after an unload and a reload (issue 23 reproduced it so)."""
    cm = make_cm({"chain": {"type": CHAIN, "reference_interfaces": ["ref"], "command_interfaces": ["joint1/position"]}})
    load_configure(cm, "chain")
    _fail_activation(cm, "chain")
    with pytest.raises(SwitchError):
        cm.switch_controllers(activate=["chain"], strictness="strict")
    cm.unload_controller("chain")
    assert not cm.resource_manager.command_interface_exists("chain/ref")
    load_configure(cm, "chain")
    cm.switch_controllers(activate=["chain"], strictness="strict")
    assert _states(cm, "chain") == [State.ACTIVE]


def test_chainable_controller_failed_activation_stops_all_list() -> None:
    """ros2_control controller_manager/test/test_controller_manager.cpp,
    test_chainable_controllers_failed_activation_stops_all_list (jazzy)."""
    cm = make_cm({
        "chain1": {"type": CHAIN, "reference_interfaces": ["modified_joint1/position"],
                   "command_interfaces": ["joint1/position"]},
        "chain2": {"type": CHAIN, "reference_interfaces": ["modified_joint2/position"],
                   "command_interfaces": ["joint2/position"]},
        "user": {"command_interfaces": ["chain1/modified_joint1/position"]},
    })
    names = ("chain1", "chain2", "user")
    load_configure(cm, *names)
    cm.switch_controllers(activate=list(names), strictness="strict")
    assert _states(cm, *names) == [State.ACTIVE] * 3
    cm.switch_controllers(deactivate=list(names), strictness="strict")
    assert _states(cm, *names) == [State.INACTIVE] * 3

    _fail_activation(cm, "chain1")
    with pytest.raises(SwitchError):
        cm.switch_controllers(activate=list(names), strictness="strict")
    assert _states(cm, *names) == [State.UNCONFIGURED, State.INACTIVE, State.INACTIVE]

    cm.configure_controller("chain1")
    assert _states(cm, "chain1") == [State.INACTIVE]
    with pytest.raises(SwitchError):
        cm.switch_controllers(activate=list(names), strictness="best_effort")
    assert _states(cm, *names) == [State.UNCONFIGURED, State.ACTIVE, State.INACTIVE]


def _raising_system_cm(handle_exceptions: bool, where: str):  # noqa: ANN202
    from core_helpers import TestSystem, make_info

    class Raising(TestSystem):
        __test__ = False

        def write(self, time: float, period: float):  # noqa: ANN201
            if where == "write":
                raise RuntimeError("bus fault in write")
            return super().write(time, period)

    hw = Raising()
    hw.raise_in_read = where == "read"
    return make_cm({}, hardware=[(hw, make_info("sys", {"joint1": (["position"], ["position"])}))],
                   manager={"handle_exceptions": handle_exceptions})


@pytest.mark.parametrize("where", ["read", "write"])
def test_hardware_exception_propagates_without_handle_exceptions(where: str) -> None:
    """ros2_control hardware_interface_testing/test/test_resource_manager.cpp,
    handle_read_exception_without_handle_exceptions and handle_write_exception_without_handle_exceptions (jazzy)."""
    cm = _raising_system_cm(False, where)
    rm = cm.resource_manager
    with pytest.raises(RuntimeError):
        getattr(rm, where)(0.0, 0.01)
    with pytest.raises(RuntimeError):
        cm.update(0.01, 0.01)


@pytest.mark.parametrize("where", ["read", "write"])
def test_hardware_exception_is_an_error_with_handle_exceptions(where: str) -> None:
    """ros2_control hardware_interface_testing/test/test_resource_manager.cpp,
    handle_read_exception_with_handle_exceptions and handle_write_exception_with_handle_exceptions (jazzy)."""
    cm = _raising_system_cm(True, where)
    status = getattr(cm.resource_manager, where)(0.0, 0.01)
    assert not status.ok and status.failed_hardware_names == ["sys"]


def _diff_drive_over_two_pids():  # noqa: ANN202
    cm = make_cm({
        "diff_drive": {"command_interfaces": ["pid_left/joint1/position", "pid_right/joint2/position"]},
        "pid_left": {"type": CHAIN, "reference_interfaces": ["joint1/position"], "command_interfaces": ["joint1/position"]},
        "pid_right": {"type": CHAIN, "reference_interfaces": ["joint2/position"],
                      "command_interfaces": ["joint2/position"]},
    })
    load_configure(cm, "diff_drive", "pid_left", "pid_right")
    cm.switch_controllers(activate=["pid_left", "pid_right"], strictness="strict")
    return cm


def test_best_effort_activating_a_preceding_controller_while_deactivating_its_followers() -> None:
    """ros2_control controller_manager/test/test_controllers_chaining_with_controller_manager.cpp,
    test_chained_controllers_deactivation_error_handling, Test Case 6, BEST_EFFORT (jazzy): the preceding controller
    cannot start (its followers stop), so it is dropped and the followers are deactivated."""
    cm = _diff_drive_over_two_pids()
    result = cm.switch_controllers(activate=["diff_drive"], deactivate=["pid_left", "pid_right"],
                                   strictness="best_effort")
    assert sorted(result.deactivated) == ["pid_left", "pid_right"] and result.activated == []
    assert _states(cm, "diff_drive", "pid_left", "pid_right") == [State.INACTIVE] * 3


def test_strict_activating_a_preceding_controller_while_deactivating_its_followers_changes_nothing() -> None:
    """The same, Test Case 6, STRICT (jazzy): an error, and the followers stay active."""
    cm = _diff_drive_over_two_pids()
    with pytest.raises(SwitchError):
        cm.switch_controllers(activate=["diff_drive"], deactivate=["pid_left", "pid_right"], strictness="strict")
    assert _states(cm, "diff_drive", "pid_left", "pid_right") == [State.INACTIVE, State.ACTIVE, State.ACTIVE]


def test_spawner_takes_the_type_from_the_wildcard_entry() -> None:
    """ros2_control controller_manager/test/test_spawner_unspawner.cpp,
    spawner_test_with_wildcard_entries_with_no_ctrl_name (jazzy): '/**' gives the type and shared parameters; a
    controller's own section adds to them; each named controller is spawned active."""
    import rrbot_workshop as rw

    yaml_text = """
controller_manager:
  ros__parameters:
    update_rate: 100
/**:
  ros__parameters:
    type: forward_command_controller/ForwardCommandController
    joints: [joint1]
    interface_name: position
wildcard_ctrl_3:
  ros__parameters:
    joints: [joint2]
"""
    names = ["wildcard_ctrl_1", "wildcard_ctrl_3"]
    system = rw.bringup(description="rrbot", controllers=yaml_text, spawn=names[:1])
    try:
        system.spawn(names[1:])
        cm = system.controller_manager
        assert [(c.name, c.type, c.state) for c in cm.list_controllers()] == [
            (n, "forward_command_controller/ForwardCommandController", "active") for n in names]
        assert cm.get_controller("wildcard_ctrl_3").get_node().get_parameter("joints") == ["joint2"]
    finally:
        system.shutdown()


def test_on_init_returning_none_is_a_clear_controller_error() -> None:
    """A learner's on_init without `return`: one ControllerError saying what to return, nothing loaded."""
    from core_helpers import TestController

    from rrbot_workshop.exceptions import ControllerError
    from rrbot_workshop.middleware import plugins

    class NoReturn(TestController):
        __test__ = False

        def on_init(self):  # noqa: ANN201
            pass

    plugins.register("controller", "test_controller/NoReturnOnInit", NoReturn)
    cm = make_cm({"c": {"type": "test_controller/NoReturnOnInit"}})
    with pytest.raises(ControllerError, match=r"on_init returned None \(did it forget to `return"):
        cm.load_controller("c")
    assert "c" not in cm.controllers


def test_on_deactivate_error_is_logged(caplog: pytest.LogCaptureFixture) -> None:
    """ros2_control controller_manager deactivate_controllers (jazzy) logs a controller that is not inactive after
    deactivation."""
    cm = make_cm({"c": {"command_interfaces": ["joint1/position"]}})
    load_configure(cm, "c")
    cm.switch_controllers(activate=["c"], strictness="strict")
    cm.get_controller("c").on_deactivate = lambda previous_state: CallbackReturn.ERROR
    with caplog.at_level("ERROR"):
        cm.switch_controllers(deactivate=["c"], strictness="best_effort")
    assert "'c' failed to deactivate (on_deactivate returned ERROR)" in caplog.text
    assert _states(cm, "c") == [State.UNCONFIGURED]


@pytest.mark.parametrize("result", [CallbackReturn.FAILURE, CallbackReturn.ERROR])
def test_on_cleanup_that_does_not_succeed_is_an_error(result: CallbackReturn,
                                                      caplog: pytest.LogCaptureFixture) -> None:
    """ros2_control controller_manager cleanup_controller (jazzy): FAILURE leaves it inactive (with its exports),
    'is not cleaned-up properly' is logged and the request fails; ERROR runs on_error (unconfigured), logged."""
    from rrbot_workshop.exceptions import ControllerError

    cm = make_cm({"chain": {"type": CHAIN, "reference_interfaces": ["ref"], "command_interfaces": ["joint1/position"]}})
    load_configure(cm, "chain")
    cm.get_controller("chain").on_cleanup = lambda previous_state: result
    with caplog.at_level("ERROR"):
        if result is CallbackReturn.FAILURE:
            with pytest.raises(ControllerError, match="was not cleaned up"):
                cm.cleanup_controller("chain")
            assert "not cleaned up properly" in caplog.text
        else:
            cm.cleanup_controller("chain")
            assert "on_cleanup of 'chain' did not succeed (ERROR)" in caplog.text
    expected = State.INACTIVE if result is CallbackReturn.FAILURE else State.UNCONFIGURED
    assert _states(cm, "chain") == [expected]
    assert cm.resource_manager.command_interface_exists("chain/ref") is (result is CallbackReturn.FAILURE)


@pytest.mark.parametrize("result", [CallbackReturn.FAILURE, CallbackReturn.ERROR])
def test_hardware_on_cleanup_that_does_not_succeed_is_logged(result: CallbackReturn,
                                                             caplog: pytest.LogCaptureFixture) -> None:
    """ros2_control's resource manager (jazzy) logs a component transition that fails."""
    cm = make_cm({})
    rm = cm.resource_manager
    rm.set_component_state("sys", State.INACTIVE)
    rm.get_component("sys")._impl.on_cleanup = lambda previous_state: result  # noqa: SLF001
    with caplog.at_level("ERROR"):
        rm.set_component_state("sys", State.UNCONFIGURED)
    assert f"on_cleanup returned {result.value.upper()} in 'inactive'" in caplog.text
