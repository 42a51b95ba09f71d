"""Tests of the SVG diagrams: controller chains, architecture, lifecycle states."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.controller_spec import ControllerState, HardwareComponentState, HardwareInterface
from rrbot_workshop.lifecycle import State
from rrbot_workshop.viz.diagrams import architecture, chain_ranks, controller_chains, lifecycle_states
from rrbot_workshop.viz.snapshot import take_snapshot
from rrbot_workshop.viz.svg import SvgDiagram

_SVG = "{http://www.w3.org/2000/svg}"


def _chain():
    """JTC -> one PID per joint -> effort commands (task 9), plus JSB and two idle controllers."""
    states = ["joint1/position", "joint1/velocity", "joint2/position", "joint2/velocity"]
    controllers = [
        ControllerState("joint_state_broadcaster", "active", "joint_state_broadcaster/JointStateBroadcaster",
                        required_state_interfaces=states),
        ControllerState("joint_trajectory_controller", "active",
                        "joint_trajectory_controller/JointTrajectoryController",
                        required_command_interfaces=["pid_controller_joint1/joint1/position",
                                                     "pid_controller_joint2/joint2/position"],
                        required_state_interfaces=["joint1/position", "joint2/position"]),
        *(
            ControllerState(f"pid_controller_{j}", "active", "pid_controller/PidController", is_chainable=True,
                            is_chained=True, required_command_interfaces=[f"{j}/effort"],
                            required_state_interfaces=[f"{j}/position", f"{j}/velocity"],
                            reference_interfaces=[f"{j}/position"])
            for j in ("joint1", "joint2")
        ),
        ControllerState("forward_position_controller", "inactive", "forward_command_controller/ForwardCommandController",
                        required_command_interfaces=["joint1/position", "joint2/position"]),
        ControllerState("displacement_controller", "unconfigured", "controlko_controllers/DisplacementController"),
    ]
    components = [
        HardwareComponentState(
            "RRBot", "system", False, 100, "mock_components/GenericSystem", State.ACTIVE,
            command_interfaces=[HardwareInterface(n, is_claimed=n.endswith("effort"))
                                for n in ("joint1/position", "joint1/effort", "joint2/position", "joint2/effort")],
            state_interfaces=[HardwareInterface(n) for n in states],
        ),
        HardwareComponentState("FTS", "sensor", False, 100, "mock_components/GenericSystem", State.INACTIVE,
                               state_interfaces=[HardwareInterface("tcp_fts_sensor/force.x")]),
    ]
    return {"controllers": controllers, "components": components}


def _texts(diagram: SvgDiagram) -> list[str]:
    root = ET.fromstring(diagram.svg)
    return [t.text or "" for t in root.iter(f"{_SVG}text")]


def _edges(diagram: SvgDiagram) -> list[ET.Element]:
    root = ET.fromstring(diagram.svg)
    return [p for p in root.iter(f"{_SVG}path") if p.get("marker-end")]


def test_chain_ranks_put_preceding_controllers_first():
    ranks = chain_ranks(take_snapshot(**_chain()))
    assert ranks["joint_trajectory_controller"] == 0
    assert ranks["pid_controller_joint1"] == ranks["pid_controller_joint2"] == 1


def test_chains_show_every_controller_and_interface():
    texts = _texts(controller_chains(**_chain()))
    for name in ("joint_trajectory_controller", "pid_controller_joint1", "displacement_controller"):
        assert name in texts
    assert "joint1/position (ref)" in texts
    assert "pid_controller_joint1/joint1/position (cmd)" in texts
    assert "joint1/effort" in texts  # hardware command interface
    assert "tcp_fts_sensor/force.x" in texts  # hardware state interface


def test_chains_draw_one_arrow_per_claim_and_read():
    chain = _chain()
    claims = sum(len(c.required_command_interfaces) for c in chain["controllers"])
    reads = sum(len(c.required_state_interfaces) for c in chain["controllers"])
    edges = _edges(controller_chains(**chain))
    legend = 2
    assert len(edges) == claims + reads + legend
    assert sum(1 for e in edges if e.get("stroke-dasharray")) == reads + 1


def test_architecture_shows_managers_components_and_claims():
    texts = _texts(architecture(**_chain()))
    assert "controller_manager" in texts and "resource_manager" in texts
    assert "RRBot" in texts and "FTS" in texts
    assert "● joint1/effort (cmd)" in texts and "○ joint1/position (cmd)" in texts
    assert "reference" in texts  # the JTC -> PID chain


def test_lifecycle_places_each_controller_and_component_in_its_state():
    diagram = lifecycle_states(**_chain())
    texts = _texts(diagram)
    assert "[ctrl] displacement_controller" in texts
    assert "[hw]   FTS" in texts
    for transition in ("configure", "activate", "deactivate", "cleanup", "shutdown"):
        assert transition in texts


def test_diagrams_of_a_running_system(tmp_path: Path):
    system = rw.bringup("rrbot", controllers="rrbot_controllers.yaml",
                        spawn=["joint_state_broadcaster", "forward_position_controller"],
                        inactive=["joint_trajectory_controller"])
    try:
        for make in (controller_chains, architecture, lifecycle_states):
            diagram = make(system)
            assert any(t.endswith("forward_position_controller") for t in _texts(diagram))
            path = diagram.save(tmp_path / f"{make.__name__}.svg")
            ET.parse(path)  # well-formed XML
    finally:
        system.shutdown()


def test_diagram_displays_inline_and_is_deterministic():
    first, second = controller_chains(**_chain()), controller_chains(**_chain())
    assert first._repr_svg_() == second._repr_svg_()
    assert first.svg.startswith("<svg")


def test_without_source_or_lists_raises_type_error():
    with pytest.raises(TypeError, match="controllers="):
        controller_chains(controllers=[])
