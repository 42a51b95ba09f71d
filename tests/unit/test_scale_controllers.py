"""Many controllers: loading, listing, ordering and linting stay right at a few hundred or thousand controllers.

The speed is measured in ``benchmarks/bench_scale_controllers.py``; these tests check the behaviour the faster paths
keep (the same order, the same activity message, the same findings).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from core_helpers import load_configure, make_cm

import rrbot_workshop as rw
from rrbot_workshop.controller_manager.activity import ACTIVITY_TOPIC
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.params import ParameterSchema
from rrbot_workshop.tools.lint import lint_controllers
from rrbot_workshop.tools.lint.parameters import closest

CHAIN = "test_controller/TestChainableController"
FORWARD = "forward_command_controller/ForwardCommandController"


def _controllers_yaml(n: int) -> str:
    lines = ["controller_manager:", "  ros__parameters:", "    update_rate: 100"]
    for i in range(n):
        lines += [f"    fwd_{i}:", f"      type: {FORWARD}"]
    for i in range(n):
        lines += [f"fwd_{i}:", "  ros__parameters:", "    joints: [joint1, joint2]", "    interface_name: position"]
    return "\n".join(lines) + "\n"


def test_two_hundred_controllers_load_configure_and_list_in_load_order(tmp_path: Path) -> None:
    path = tmp_path / "many.yaml"
    path.write_text(_controllers_yaml(200))
    names = [f"fwd_{i}" for i in range(200)]
    with rw.bringup("rrbot", path, inactive=names) as system:
        cm = system.controller_manager
        listed = cm.list_controllers()
        assert [c.name for c in listed] == names
        assert {c.state for c in listed} == {"inactive"}
        assert cm.update_order() == names
        activity = system.bus.latest(ACTIVITY_TOPIC)
        assert [(c.name, c.state.label) for c in activity.controllers] == [(n, "inactive") for n in names]
        cm.switch_controllers(activate=["fwd_7"], strictness="strict")
        assert cm.controllers["fwd_7"].state is State.ACTIVE
        assert system.bus.latest(ACTIVITY_TOPIC).controllers[7].state.label == "active"
        cm.switch_controllers(deactivate=["fwd_7"], strictness="strict")
        for name in names[::2]:
            cm.unload_controller(name)
        assert cm.update_order() == names[1::2]
        assert [c.name for c in system.bus.latest(ACTIVITY_TOPIC).controllers] == names[1::2]
        assert system.bus.subscription_count("/fwd_0/commands") == 0
        assert system.bus.subscription_count("/fwd_1/commands") == 1


def test_activity_is_published_once_per_change_and_not_for_a_request_that_changes_nothing() -> None:
    cm = make_cm({f"c{i}": {} for i in range(30)})
    load_configure(cm, *[f"c{i}" for i in range(30)])
    before = len(cm.bus.history(ACTIVITY_TOPIC))
    with pytest.raises(Exception):  # noqa: B017 - any refusal: the point is that nothing changed
        cm.cleanup_controller("c99")
    cm.switch_controllers(activate=[], deactivate=[])
    assert len(cm.bus.history(ACTIVITY_TOPIC)) == before
    cm.cleanup_controller("c3")
    history = cm.bus.history(ACTIVITY_TOPIC)
    assert len(history) == before + 1
    assert history[-1].controllers[3].state.label == "unconfigured"


def test_chain_order_among_many_unchained_controllers_puts_preceding_ones_first() -> None:
    """A chain configured among a hundred unchained controllers: the chain is sorted, the others keep load order."""
    ctrls: dict[str, dict] = {f"plain_{i}": {} for i in range(100)}
    ctrls["follower"] = {"type": CHAIN, "reference_interfaces": ["joint1/position"], "command_interfaces": ["joint1/position"]}
    ctrls["leader"] = {"command_interfaces": ["follower/joint1/position"]}
    cm = make_cm(ctrls)
    names = [*(f"plain_{i}" for i in range(50)), "follower", *(f"plain_{i}" for i in range(50, 100)), "leader"]
    load_configure(cm, *names)
    order = cm.update_order()
    assert order.index("leader") < order.index("follower")
    assert [n for n in order if n.startswith("plain_")] == [n for n in names if n.startswith("plain_")]
    # the first ready controller in load order goes next: 'follower' waits for 'leader', loaded last
    assert order == [*(f"plain_{i}" for i in range(100)), "leader", "follower"]


def test_lint_of_two_thousand_controllers_reports_exactly_the_seeded_mistakes(tmp_path: Path) -> None:
    text = _controllers_yaml(2000)
    text = text.replace(f"    fwd_17:\n      type: {FORWARD}", "    fwd_17:\n      type: forward_command_controller/ForwardComandController")
    text = text.replace("fwd_1200:\n  ros__parameters:\n    joints: [joint1, joint2]\n",
                        "fwd_1200:\n  ros__parameters:\n    joint: [joint1, joint2]\n")
    text = text.replace("fwd_1999:\n  ros__parameters:\n    joints: [joint1, joint2]\n    interface_name: position\n",
                        "fwd_1999:\n  ros__parameters:\n    joints: [joint1, joint2]\n    interface_name: 7\n")
    text += "fwd_12345:\n  ros__parameters:\n    joints: [joint1]\n"
    path = tmp_path / "many.yaml"
    path.write_text(text)
    findings = lint_controllers(path)
    seen = sorted((f.level, f.where) for f in findings)
    assert seen == sorted([
        ("error", "controller_manager.fwd_17.type"),
        ("warning", "fwd_1200.joint"),
        ("error", "fwd_1200.joints"),
        ("error", "fwd_1999.interface_name"),
        ("warning", "fwd_12345"),
    ]), findings
    by_where = {f.where: f for f in findings}
    assert "did you mean 'forward_command_controller/ForwardCommandController'" in by_where["controller_manager.fwd_17.type"].message
    assert "did you mean 'joints'" in by_where["fwd_1200.joint"].message
    stray = by_where["fwd_12345"]
    # the same suggestion as difflib's over all the names (ties go to the greater name, as get_close_matches has it)
    assert stray.message.endswith(closest("fwd_12345", [f"fwd_{i}" for i in range(2000)]))
    assert "did you mean 'fwd_1345'" in stray.message
    assert stray.line == text.splitlines().index("fwd_12345:") + 1


def test_schemas_from_the_same_text_have_their_own_declaration_lists() -> None:
    text = "ns:\n  a: {type: int, default_value: 1}\n  b: {type: string_array}\n"
    one, two = ParameterSchema(text), ParameterSchema(text)
    assert [d.path for d in one.declarations] == [("a",), ("b",)]
    one.declarations.pop()
    assert [d.path for d in two.declarations] == [("a",), ("b",)]
    assert [d.path for d in ParameterSchema(text).declarations] == [("a",), ("b",)]
