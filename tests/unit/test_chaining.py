"""Controller chaining through the manager.

Ports the key cases of ros2_control's test_controllers_chaining_with_controller_manager.cpp and
test_controller_manager_srvs.cpp (activate_chained_controllers_one_by_one / all_at_once): a preceding
controller claims the reference interfaces of a chainable one, which then runs in chained mode.
"""

from __future__ import annotations

import pytest
from core_helpers import load_configure, make_cm

from rrbot_workshop.exceptions import SwitchError
from rrbot_workshop.middleware.lifecycle import ReturnType, State

CHAIN = "test_controller/TestChainableController"


def _cm():  # noqa: ANN202
    cm = make_cm({
        "pre": {"command_interfaces": ["pid/joint1/position"]},
        "pid": {"type": CHAIN, "reference_interfaces": ["joint1/position"], "command_interfaces": ["joint1/position"]},
        "other": {"command_interfaces": ["joint2/position"]},
    })
    load_configure(cm, "pre", "pid", "other")
    return cm


def _chained(cm, name: str) -> bool:  # noqa: ANN001
    return cm.get_controller(name).is_in_chained_mode()


def test_reference_interfaces_exist_but_are_unavailable_until_activation() -> None:
    cm = _cm()
    rm = cm.resource_manager
    assert rm.command_interface_exists("pid/joint1/position")
    assert not rm.command_interface_is_available("pid/joint1/position")
    cm.switch_controllers(activate=["pid"])
    assert rm.command_interface_is_available("pid/joint1/position") and not _chained(cm, "pid")


def test_one_by_one_preceding_before_follower_is_rejected() -> None:
    cm = _cm()
    with pytest.raises(SwitchError, match="'pre' uses reference interface 'pid/joint1/position' of controller 'pid'"):
        cm.switch_controllers(activate=["pre"], strictness="strict")
    assert cm.controllers["pre"].state is State.INACTIVE


def test_one_by_one_follower_first_then_preceding_chains_it() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pid"], strictness="strict")
    cm.switch_controllers(activate=["pre"], strictness="strict")
    assert cm.controllers["pre"].state is State.ACTIVE and cm.controllers["pid"].state is State.ACTIVE
    assert _chained(cm, "pid")
    assert cm.resource_manager.command_interface_holder("pid/joint1/position") == "pre"


def test_all_at_once_activates_followers_first() -> None:
    cm = _cm()
    result = cm.switch_controllers(activate=["pre", "pid"], strictness="strict")
    assert result.activated == ["pid", "pre"] and _chained(cm, "pid")


def test_chained_values_flow_in_one_cycle() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pre", "pid"], strictness="strict")
    cm.get_controller("pre").command_value = 3.0
    cm.update(0.01, 0.01)
    rm = cm.resource_manager
    assert rm.get_interface_value("pid/joint1/position") == 3.0
    assert rm.get_interface_value("joint1/position", kind="command") == 6.0


def test_unchained_follower_takes_references_from_its_subscribers() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pid"])
    cm.update(0.01, 0.01)
    assert cm.resource_manager.get_interface_value("joint1/position", kind="command") == 1.0  # 2 * 0.5


def test_deactivating_follower_while_preceding_is_active_is_rejected() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pre", "pid"])
    with pytest.raises(SwitchError, match="preceding controller 'pre' stays active"):
        cm.switch_controllers(deactivate=["pid"], strictness="strict")
    assert cm.controllers["pid"].state is State.ACTIVE


def test_activating_preceding_while_deactivating_follower_is_rejected() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pid"])
    with pytest.raises(SwitchError):
        cm.switch_controllers(activate=["pre"], deactivate=["pid"], strictness="strict")
    assert cm.controllers["pid"].state is State.ACTIVE and cm.controllers["pre"].state is State.INACTIVE


def test_deactivating_preceding_restarts_follower_out_of_chained_mode() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pre", "pid"])
    result = cm.switch_controllers(deactivate=["pre"], strictness="strict")
    assert cm.controllers["pid"].state is State.ACTIVE and not _chained(cm, "pid")
    assert "pid" in result.deactivated and "pid" in result.activated  # restarted to change mode


def test_deactivating_the_whole_chain_at_once() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pre", "pid"])
    result = cm.switch_controllers(deactivate=["pid", "pre"], strictness="strict")
    assert result.deactivated == ["pre", "pid"]  # preceding first
    assert not cm.resource_manager.command_interface_is_available("pid/joint1/position")


def test_failure_in_a_chain_deactivates_the_chain_only() -> None:
    cm = _cm()
    cm.switch_controllers(activate=["pre", "pid", "other"])
    cm.get_controller("pid").update_result = ReturnType.ERROR
    cm.update(0.01, 0.01)
    assert [cm.controllers[n].state for n in ("pre", "pid", "other")] == [State.INACTIVE, State.INACTIVE, State.ACTIVE]


def test_reading_exported_state_does_not_chain() -> None:
    cm = make_cm({
        "est": {"type": CHAIN, "exported_state_interfaces": ["speed"], "state_interfaces": ["joint1/position"]},
        "reader": {"state_interfaces": ["est/speed"]},
    })
    load_configure(cm, "reader", "est")
    with pytest.raises(SwitchError, match="state interface 'est/speed' of controller 'est'"):
        cm.switch_controllers(activate=["reader"], strictness="strict")
    cm.switch_controllers(activate=["reader", "est"], strictness="strict")
    assert not _chained(cm, "est")
    cm.update(0.01, 0.01)
    assert cm.resource_manager.get_interface_value("est/speed") == 1.0


def test_cleanup_removes_exported_interfaces() -> None:
    cm = _cm()
    cm.cleanup_controller("pid")
    assert not cm.resource_manager.command_interface_exists("pid/joint1/position")
    assert cm.list_controllers()[0].name in ("pre", "other", "pid")


def test_a_broadcaster_reading_all_interfaces_is_not_a_preceding_controller() -> None:
    """The joint state broadcaster (ALL state interfaces) reads the PIDs' exported states but does not chain to them
    (Jazzy builds chains from the names a controller lists): the PIDs can stop while it keeps running."""
    from rrbot_workshop.bringup import bringup

    system = bringup("rrbot", "rrbot_sim_effort_controllers.yaml", xacro_args={"sim_mujoco": True},
                     spawn=["joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2"])
    try:
        cm = system.controller_manager
        system.spin(seconds=0.05)
        cm.switch_controllers(deactivate=["pid_controller_joint1", "pid_controller_joint2"], strictness="strict")
        states = {c.name: c.state for c in cm.list_controllers()}
        assert states == {"joint_state_broadcaster": "active", "pid_controller_joint1": "inactive",
                          "pid_controller_joint2": "inactive"}
    finally:
        system.shutdown()


def test_restarting_the_head_of_a_chain_keeps_its_followers_chained() -> None:
    """Deactivating and activating the JTC in one switch: the PIDs stay active and in chained mode, so their own
    ~/reference topic cannot override the trajectory (after any switch, a controller whose references an active
    controller claims is in chained mode)."""
    from rrbot_workshop.bringup import bringup

    system = bringup("rrbot", "rrbot_chained_controllers.yaml",
                     xacro_args={"use_mock_hardware": True, "calculate_dynamics": True}, spawn=["joint_state_broadcaster"])
    try:
        system.spawn(["pid_controller_joint1", "pid_controller_joint2", "joint_trajectory_controller"],
                     activate_as_group=True)
        cm = system.controller_manager
        for activate, deactivate in ((["joint_trajectory_controller"], ["joint_trajectory_controller"]),
                                     (["joint_trajectory_controller", "pid_controller_joint1"],
                                      ["joint_trajectory_controller", "pid_controller_joint1"])):
            cm.switch_controllers(activate=activate, deactivate=deactivate, strictness="strict")
            states = {c.name: (c.state, c.is_chained) for c in cm.list_controllers()}
            assert states["pid_controller_joint1"] == ("active", True), states
            assert states["pid_controller_joint2"] == ("active", True), states
        cm.switch_controllers(deactivate=["joint_trajectory_controller"], strictness="strict")
        assert not any(c.is_chained for c in cm.list_controllers())
    finally:
        system.shutdown()
