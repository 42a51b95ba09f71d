"""``System.spawn`` / ``System.unspawn``: the spawner's semantics on a running system."""

from __future__ import annotations

import logging

import pytest

import rrbot_workshop as rw
from rrbot_workshop.exceptions import ControllerNotFound, ParameterError, SwitchError


@pytest.fixture
def system():  # noqa: ANN201
    s = rw.bringup(description="rrbot", controllers="rrbot_chained_controllers.yaml",
                   xacro_args={"calculate_dynamics": "true"}, spawn=[])
    yield s
    s.shutdown()


def _states(system) -> dict[str, str]:  # noqa: ANN001
    return {c.name: c.state for c in system.controller_manager.list_controllers()}


def test_spawn_loads_configures_and_activates_each(system) -> None:  # noqa: ANN001
    system.spawn(["joint_state_broadcaster", "forward_position_controller"])
    assert _states(system) == {"joint_state_broadcaster": "active", "forward_position_controller": "active"}


def test_spawn_inactive_and_load_only(system) -> None:  # noqa: ANN001
    system.spawn(["joint_state_broadcaster"], inactive=True)
    system.spawn(["forward_position_controller"], load_only=True)
    assert _states(system) == {"joint_state_broadcaster": "inactive", "forward_position_controller": "unconfigured"}


def test_chain_needs_activate_as_group_when_the_head_comes_first(system) -> None:  # noqa: ANN001
    """One by one, the JTC cannot activate before the PIDs it claims; as a group the chain starts together."""
    chain = ["joint_trajectory_controller", "pid_controller_joint1", "pid_controller_joint2"]
    with pytest.raises(SwitchError):
        system.spawn(chain)
    assert _states(system)["joint_trajectory_controller"] == "inactive"
    system.spawn(chain, activate_as_group=True)
    states = _states(system)
    assert all(states[name] == "active" for name in chain)
    assert system.controller_manager.get_controller("pid_controller_joint1").is_in_chained_mode()


def test_spawning_a_loaded_controller_warns_and_goes_on(system, caplog: pytest.LogCaptureFixture) -> None:  # noqa: ANN001
    system.spawn(["joint_state_broadcaster"], load_only=True)
    with caplog.at_level(logging.WARNING):
        system.spawn(["joint_state_broadcaster"])
    assert "already loaded, skipping load_controller" in caplog.text
    assert _states(system) == {"joint_state_broadcaster": "active"}


def test_undeclared_controller_is_refused_by_name(system) -> None:  # noqa: ANN001
    with pytest.raises(ControllerNotFound, match="no_such"):
        system.spawn(["no_such"])
    assert _states(system) == {}


def test_contradicting_options_are_refused(system) -> None:  # noqa: ANN001
    with pytest.raises(ParameterError, match="choose one"):
        system.spawn(["joint_state_broadcaster"], inactive=True, activate_as_group=True)
    assert _states(system) == {}


def test_unspawn_deactivates_then_unloads(system) -> None:  # noqa: ANN001
    system.spawn(["joint_state_broadcaster", "forward_position_controller"])
    system.unspawn(["forward_position_controller"])
    assert _states(system) == {"joint_state_broadcaster": "active"}


def test_unspawn_of_unknown_name_changes_nothing(system) -> None:  # noqa: ANN001
    system.spawn(["joint_state_broadcaster"])
    with pytest.raises(ControllerNotFound):
        system.unspawn(["joint_state_broadcaster", "nope"])
    assert _states(system) == {"joint_state_broadcaster": "active"}


def test_unspawning_a_chain_follower_alone_is_rejected_and_keeps_it(system) -> None:  # noqa: ANN001
    chain = ["pid_controller_joint1", "pid_controller_joint2", "joint_trajectory_controller"]
    system.spawn(chain, activate_as_group=True)
    with pytest.raises(SwitchError):
        system.unspawn(["pid_controller_joint1"])
    assert _states(system)["pid_controller_joint1"] == "active"
    system.unspawn(chain)
    assert _states(system) == {}
