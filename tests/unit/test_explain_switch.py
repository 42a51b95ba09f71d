"""``cm.explain_switch`` / ``%control why``: the dry run names the same causes a real switch gives, and changes nothing.

For each way a switch can be rejected, the explanation is asked first, then the real switch is made with the same
strictness: the explanation's reasons must be the switch error's reasons, and the states, claims and chained modes
must be what they were before the explanation was asked.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest

import rrbot_workshop as rw
from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.exceptions import SwitchError

JSB, FWD, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"
PID1, PID2 = "pid_controller_joint1", "pid_controller_joint2"


@pytest.fixture
def cm() -> Iterator[ControllerManager]:
    """The chained RRBot on the mock: JSB and forward active, the PIDs and the trajectory controller inactive."""
    system = rw.bringup(
        "rrbot",
        "rrbot_chained_controllers.yaml",
        spawn=[JSB, FWD],
        inactive=[PID1, PID2, JTC],
        name="explain_switch_test",
    )
    try:
        yield system.controller_manager
    finally:
        system.shutdown()


def _snapshot(cm: ControllerManager) -> list[tuple[str, str, tuple[str, ...], bool]]:
    return [(c.name, c.state, tuple(c.claimed_interfaces), c.is_chained) for c in cm.list_controllers()]


def _hardware_inactive(cm: ControllerManager) -> None:
    cm.set_hardware_component_state("rrbot", "inactive")


def _pid_unloaded_for_fwd(cm: ControllerManager) -> None:
    cm.switch_controllers(deactivate=[FWD])


# name -> (set-up, activate, deactivate, strictness, words the reasons must contain, the fact that proves it)
CASES: dict[str, tuple[Callable[[ControllerManager], None] | None, list[str], list[str], str, str, str]] = {
    "unknown controller": (
        None,
        ["joint_trajectory_controler"],
        [],
        "strict",
        "is not loaded",
        "did you mean ['joint_trajectory_controller'",
    ),
    "already active": (None, [FWD], [], "strict", "is already active", f"controller '{FWD}': is 'active'"),
    "inactive hardware": (
        _hardware_inactive,
        [JTC, PID1, PID2],
        [FWD],
        "strict",
        "'rrbot' is inactive; its command",
        "hardware component 'rrbot': is 'inactive'",
    ),
    "inactive chain follower": (
        None,
        [JTC],
        [FWD],
        "strict",
        f"of controller '{PID1}', which is 'inactive'",
        f"controller '{PID1}': is 'inactive'",
    ),
    "deactivate a follower in use": (
        lambda cm: cm.switch_controllers([PID1, PID2, JTC], [FWD], "strict"),
        [],
        [PID1],
        "strict",
        f"preceding controller '{JTC}' stays active",
        f"controller '{JTC}': is 'active'",
    ),
    "deactivate an inactive controller": (
        None,
        [],
        [JTC],
        "strict",
        "is not active",
        f"controller '{JTC}': is 'inactive'",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_explanation_names_the_cause_the_real_switch_gives_and_changes_nothing(
    cm: ControllerManager, case: str
) -> None:
    setup, activate, deactivate, strictness, words, fact = CASES[case]
    if setup is not None:
        setup(cm)
    before = _snapshot(cm)
    answer = cm.explain_switch(activate, deactivate, strictness)
    assert _snapshot(cm) == before, "explain_switch changed the system"
    assert not answer.ok and not answer.strict.accepted
    assert any(words in r for r in answer.strict.reasons), answer.strict.reasons
    assert any(fact in f"{e.what}: {e.fact}" for e in answer.evidence), str(answer)
    with pytest.raises(SwitchError) as err:
        cm.switch_controllers(activate, deactivate, strictness)
    assert err.value.reasons == answer.strict.reasons
    assert _snapshot(cm) == before


def test_claimed_interface_names_its_holder_as_the_real_switch_does() -> None:
    system = rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB, FWD], inactive=[JTC], name="explain_claimed")
    try:
        cm = system.controller_manager
        before = _snapshot(cm)
        answer = cm.explain_switch([JTC])
        assert _snapshot(cm) == before
        assert any(f"'joint1/position' is already claimed by '{FWD}'" in r for r in answer.strict.reasons)
        assert any(
            f"{e.what}: {e.fact}" == f"interface 'joint1/position': is claimed by '{FWD}'" for e in answer.evidence
        ), str(answer)
        for strictness in ("strict", "best_effort"):
            with pytest.raises(SwitchError) as err:
                cm.switch_controllers([JTC], [], strictness)
            assert err.value.reasons == getattr(answer, strictness).reasons
        assert cm.explain_switch([JTC], [FWD]).ok
    finally:
        system.shutdown()


def test_missing_interface_names_the_closest_existing_ones(cm: ControllerManager) -> None:
    for pid in (PID1, PID2):
        cm.cleanup_controller(pid)
        cm.unload_controller(pid)
    answer = cm.explain_switch([JTC], [FWD])
    assert "pid_controller_joint1/joint1/position', which does not exist" in "\n".join(answer.strict.reasons)
    assert any(
        e.what == "interface 'pid_controller_joint1/joint1/position'" and "closest: ['joint1/position'" in e.fact
        for e in answer.evidence
    ), str(answer)
    with pytest.raises(SwitchError) as err:
        cm.switch_controllers([JTC], [FWD], "best_effort")
    assert err.value.reasons == answer.best_effort.reasons


def test_best_effort_part_that_would_go_through_is_listed_with_what_it_skips(cm: ControllerManager) -> None:
    # best effort drops the trajectory controller (its PIDs are not active) and still deactivates forward: the
    # explanation shows it before a learner is left with no controller commanding the arm
    answer = cm.explain_switch([JTC, "nonexistent"], [FWD])
    assert not answer.strict.accepted and answer.best_effort.accepted
    assert answer.best_effort.activate == [] and answer.best_effort.deactivate == [FWD]
    assert any(f"of controller '{PID1}', which is 'inactive'" in r for r in answer.best_effort.reasons)
    answer = cm.explain_switch([PID1, PID2, JTC, "nonexistent"], [FWD])
    assert not answer.strict.accepted and answer.best_effort.accepted
    assert sorted(answer.best_effort.activate) == sorted([PID1, PID2, JTC]) and answer.best_effort.deactivate == [FWD]
    assert any("'nonexistent' is not loaded" in r for r in answer.best_effort.reasons)
    result = cm.switch_controllers([PID1, PID2, JTC, "nonexistent"], [FWD])
    assert sorted(result.activated) == sorted(answer.best_effort.activate)


def test_a_switch_that_would_go_through_says_what_it_would_do_and_that_the_hardware_was_not_asked(
    cm: ControllerManager,
) -> None:
    answer = cm.explain_switch([PID1, PID2, JTC], [FWD], "strict")
    assert answer.ok and answer.best_effort.accepted and not answer.reasons
    assert "joint1/velocity" in answer.hardware_not_asked
    text = str(answer)
    assert "strict       would go through" in text and "prepare_command_mode_switch" in text
    assert cm.controllers[JTC].state.label == "inactive"


def test_explain_switch_refuses_a_string_and_a_bad_strictness(cm: ControllerManager) -> None:
    with pytest.raises(rw.exceptions.ControllerError, match="lists of controller names"):
        cm.explain_switch(JTC)  # type: ignore[arg-type]
    with pytest.raises(rw.exceptions.ControllerError, match="unknown strictness"):
        cm.explain_switch([JTC], strictness="sometimes")
