"""lifecycle.py: primary states, result codes and allowed transition sources."""

from __future__ import annotations

import pytest

from rrbot_workshop.middleware.lifecycle import TRANSITION_SOURCES, CallbackReturn, ReturnType, State


def test_states_carry_the_ros_labels_and_ids() -> None:
    """lifecycle_msgs/msg/State: 0 unknown, 1 unconfigured, 2 inactive, 3 active, 4 finalized."""
    assert [(s.label, s.id) for s in State] == [
        ("unknown", 0), ("unconfigured", 1), ("inactive", 2), ("active", 3), ("finalized", 4),
    ]


def test_state_prints_as_its_label() -> None:
    assert str(State.ACTIVE) == "active" and f"{State.INACTIVE}" == "inactive"


@pytest.mark.parametrize("label", ["active", "ACTIVE", " Active "])
def test_from_label_accepts_any_letter_case(label: str) -> None:
    assert State.from_label(label) is State.ACTIVE


def test_from_label_rejects_unknown_labels_and_lists_the_valid_ones() -> None:
    with pytest.raises(ValueError, match="unconfigured") as info:
        State.from_label("running")
    assert "running" in str(info.value)


def test_result_codes() -> None:
    assert {r.value for r in CallbackReturn} == {"success", "failure", "error"}
    assert {r.value for r in ReturnType} == {"ok", "error", "deactivate"}


def test_transition_sources_follow_the_managed_node_state_machine() -> None:
    assert TRANSITION_SOURCES == {
        "configure": (State.UNCONFIGURED,),
        "cleanup": (State.INACTIVE,),
        "activate": (State.INACTIVE,),
        "deactivate": (State.ACTIVE,),
        "shutdown": (State.UNCONFIGURED, State.INACTIVE, State.ACTIVE),
    }


def test_hardware_component_uses_the_same_transition_sources() -> None:
    """The wrapper's allowed states agree with the shared table (error() aside, which is hardware-only)."""
    from rrbot_workshop.hardware_interface.component_interface import SystemInterface
    from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent

    for transition, sources in TRANSITION_SOURCES.items():
        for state in (State.UNCONFIGURED, State.INACTIVE, State.ACTIVE):
            comp = HardwareComponent(SystemInterface())
            comp._set_state(state)
            changed = getattr(comp, transition)() is not state
            assert changed == (state in sources), (transition, state)
