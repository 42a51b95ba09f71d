"""Controller names follow the ROS node name rule (rmw_validate_node_name, as rcl applies it to every node):
refused at load with the reason and the rule, nothing loaded."""

from __future__ import annotations

import pytest
from core_helpers import make_cm

from rrbot_workshop.exceptions import ControllerError
from rrbot_workshop.middleware.names import NODE_NAME_MAX_LENGTH, check_node_name, node_name_problem

HOSTILE = [
    "", " ", "a-b", "a b", " a", "a ", "a\nb", "a\tb", "1abc", "0", "a.b", "a/b", "/a", "~/a", "a:b", "ä",
    "contrôleur", "名前", "a\x00b", "a\"b", "a'b", "a\\b", "a\"\"\"b", "a' + str(__import__('os')) + 'b", "$a",
    "a" * (NODE_NAME_MAX_LENGTH + 1),
]
VALID = ["a", "_a", "A_1", "joint_state_broadcaster", "pid_controller_joint1", "_", "a" * NODE_NAME_MAX_LENGTH]


def test_there_are_26_hostile_names() -> None:
    assert len(HOSTILE) == 26 and len(set(HOSTILE)) == 26


@pytest.mark.parametrize("name", HOSTILE, ids=repr)
def test_a_hostile_name_is_not_a_node_name(name: str) -> None:
    assert node_name_problem(name)


@pytest.mark.parametrize("name", VALID)
def test_valid_node_names(name: str) -> None:
    assert node_name_problem(name) == "" and check_node_name(name) == name


@pytest.mark.parametrize(("name", "reason"), [
    ("", "it is empty"), ("a-b", "it contains '-' at index 1"), ("1abc", "it starts with a digit"),
    ("a" * 256, "it has 256 characters, more than 255"), (3, "it is a int, not a string"),
])
def test_the_reason_is_given(name: object, reason: str) -> None:
    assert node_name_problem(name) == reason


@pytest.mark.parametrize("name", HOSTILE, ids=repr)
def test_load_refuses_a_hostile_name_and_gives_the_rule(name: str) -> None:
    cm = make_cm({})
    with pytest.raises(ControllerError, match=r"not a valid ROS node name: .*ASCII letters, digits and underscores"):
        cm.load_controller(name, "test_controller/TestController")
    assert cm.controllers == {}


@pytest.mark.parametrize("name", [None, 3, b"abc", ["a"]], ids=repr)
def test_load_refuses_a_name_that_is_not_a_string(name: object) -> None:
    cm = make_cm({})
    with pytest.raises(ControllerError, match="not a string"):
        cm.load_controller(name, "test_controller/TestController")  # type: ignore[arg-type]
    assert cm.controllers == {}


def test_a_wrong_typed_type_is_refused_clearly() -> None:
    cm = make_cm({})
    with pytest.raises(ControllerError, match="the type must be a string"):
        cm.load_controller("c", 42)  # type: ignore[arg-type]
    assert cm.controllers == {}
