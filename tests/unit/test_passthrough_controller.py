"""PassthroughController: a chainable controller that forwards references to commands (the demos' example 12).

The chain forward command controller -> pass-through -> pass-through -> mock hardware is brought up from a
controllers YAML in the demos' layout (tests/unit/data/rrbot_passthrough_chain.yaml) and driven chained and not.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.controllers.passthrough import PassthroughController
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import Float64MultiArray
from rrbot_workshop.testing import ControllerHarness

CHAIN_YAML = Path(__file__).parent / "data" / "rrbot_passthrough_chain.yaml"
FIRST = ["shoulder_passthrough", "elbow_passthrough"]
WHOLE_CHAIN = ["joint_state_broadcaster", *FIRST, "arm_passthrough", "arm_commands"]


def _bringup(spawn: list[str]) -> rw.System:
    return rw.bringup("rrbot", CHAIN_YAML, xacro_args={"use_mock_hardware": True}, spawn=spawn)


def _joints(system: rw.System) -> list[float]:
    rm = system.resource_manager
    return [rm.get_interface_value("joint1/position"), rm.get_interface_value("joint2/position")]


def _harness(params: dict | None = None) -> ControllerHarness:
    return ControllerHarness(PassthroughController(), "pt", {"interfaces": ["j1/position", "j2/velocity"]}
                             if params is None else params, command_values={"j1/position": 0.0, "j2/velocity": 0.0})


# ----------------------------------------------------------------------------- registration and parameters


def test_registered_under_the_demo_name_and_the_library_name() -> None:
    assert plugins.resolve("controller", "passthrough_controller/PassthroughController") is PassthroughController
    assert plugins.resolve("controller", "rrbot_workshop/PassthroughController") is PassthroughController


@pytest.mark.parametrize("params", [{}, {"interfaces": []}, {"interfaces": ["j1/position", "j1/position"]}])
def test_bad_interfaces_are_refused_naming_the_parameter(params: dict) -> None:
    with pytest.raises(ParameterError, match="interfaces"):
        _harness(params)


def test_exports_one_reference_per_interface_prefixed_with_its_name() -> None:
    h = _harness()
    assert h.configure() is State.INACTIVE
    assert [r.name for r in h.controller.reference_interfaces] == ["pt/j1/position", "pt/j2/velocity"]
    assert all(math.isnan(r.get_value()) for r in h.controller.reference_interfaces)
    assert h.controller.command_interface_configuration().names == ["j1/position", "j2/velocity"]
    assert h.controller.state_interface_configuration().names == []


def test_chained_references_are_copied_and_nan_is_skipped() -> None:
    h = _harness()
    h.configure()
    assert h.set_chained_mode(True)
    h.activate()
    h.set("pt/j1/position", 0.7)
    h.update()
    assert h.values(["j1/position", "j2/velocity"]) == [0.7, 0.0]  # the NaN reference writes nothing


def test_unchained_takes_the_topic_and_drops_a_wrong_size(caplog: pytest.LogCaptureFixture) -> None:
    h = _harness()
    h.configure()
    h.activate()
    h.publish("/pt/commands", Float64MultiArray(data=[1.0, 2.0]))
    h.update()
    assert h.values(["j1/position", "j2/velocity"]) == [1.0, 2.0]
    with caplog.at_level(logging.ERROR):
        h.publish("/pt/commands", Float64MultiArray(data=[5.0]))
    assert "field 'data' has 1 values, expected 2" in caplog.text and "'interfaces'" in caplog.text
    h.publish("/pt/commands", Float64MultiArray(data=[3.0, math.nan]))  # not all finite: kept out
    h.update(2)
    assert h.values(["j1/position", "j2/velocity"]) == [1.0, 2.0]


def test_activation_forgets_a_command_received_before() -> None:
    h = _harness()
    h.configure()
    h.activate()
    h.publish("/pt/commands", Float64MultiArray(data=[1.0, 2.0]))
    h.deactivate()
    h.activate()
    h.update()
    assert h.values(["j1/position", "j2/velocity"]) == [0.0, 0.0]


# ----------------------------------------------------------------------------- the demo's chain, brought up


def test_two_levels_chained_move_the_robot_as_commanded() -> None:
    with _bringup(WHOLE_CHAIN) as system:
        states = {c.name: (c.state, c.is_chained) for c in system.controller_manager.list_controllers()}
        assert states == {"joint_state_broadcaster": ("active", False), "arm_commands": ("active", False),
                          "arm_passthrough": ("active", True), "shoulder_passthrough": ("active", True),
                          "elbow_passthrough": ("active", True)}
        order = system.controller_manager.update_order()
        assert order.index("arm_commands") < order.index("arm_passthrough") < order.index("shoulder_passthrough")
        rm = system.resource_manager
        for itf in ("shoulder_passthrough/joint1/position", "arm_passthrough/shoulder_passthrough/joint1/position"):
            assert rm.command_interface_exists(itf)
        system.publish("/arm_commands/commands", Float64MultiArray(data=[0.5, -0.25]))
        system.spin_cycles(2)
        assert _joints(system) == [0.5, -0.25]
        assert rm.get_interface_value("arm_passthrough/shoulder_passthrough/joint1/position", kind="command") == 0.5
        assert rm.get_interface_value("elbow_passthrough/joint2/position", kind="command") == -0.25
        system.publish("/arm_passthrough/commands", Float64MultiArray(data=[9.0, 9.0]))  # chained: topic unused
        system.spin_cycles(2)
        assert _joints(system) == [0.5, -0.25]
        js = system.latest("/joint_states")
        assert dict(zip(js.name, js.position, strict=True)) == {"joint1": 0.5, "joint2": -0.25}


def test_first_level_alone_takes_its_topics() -> None:
    with _bringup(["joint_state_broadcaster", *FIRST]) as system:
        assert not any(c.is_chained for c in system.controller_manager.list_controllers())
        system.publish("/shoulder_passthrough/commands", Float64MultiArray(data=[0.3]))
        system.publish("/elbow_passthrough/commands", Float64MultiArray(data=[-0.6]))
        system.spin_cycles(2)
        assert _joints(system) == [0.3, -0.6]


def test_second_level_unchained_drives_the_first_level() -> None:
    with _bringup(["joint_state_broadcaster", *FIRST, "arm_passthrough"]) as system:
        chained = {c.name: c.is_chained for c in system.controller_manager.list_controllers()}
        assert chained == {"joint_state_broadcaster": False, "shoulder_passthrough": True, "elbow_passthrough": True,
                           "arm_passthrough": False}
        system.publish("/arm_passthrough/commands", Float64MultiArray(data=[0.2, 0.4]))
        system.spin_cycles(2)
        assert _joints(system) == [0.2, 0.4]
        # leaving the chain: the first level goes back to its own topic
        system.controller_manager.switch_controllers(deactivate=["arm_passthrough"], strictness="strict")
        assert not any(c.is_chained for c in system.controller_manager.list_controllers())
        system.publish("/shoulder_passthrough/commands", Float64MultiArray(data=[-0.1]))
        system.spin_cycles(2)
        assert _joints(system) == [-0.1, 0.4]
