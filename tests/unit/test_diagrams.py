"""Tests of the SVG diagrams: controller chains, architecture, lifecycle states."""

from __future__ import annotations

import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.controller_manager.spec import ControllerState, HardwareComponentState, HardwareInterface
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.viz.diagrams import architecture, chain_ranks, controller_chains, lifecycle_states
from rrbot_workshop.viz.snapshot import take_snapshot
from rrbot_workshop.viz.svg import SvgDiagram

_SVG = "{http://www.w3.org/2000/svg}"


def _chain():
    """JTC -> one PID per joint -> effort commands (task 9), plus JSB and two idle controllers.

    As ``list_controllers`` reports them: an active controller's ``claimed_interfaces`` are its required
    command interfaces; the inactive forward controller requires two but claims none.
    """
    states = ["joint1/position", "joint1/velocity", "joint2/position", "joint2/velocity"]
    controllers = [
        ControllerState("joint_state_broadcaster", "active", "joint_state_broadcaster/JointStateBroadcaster",
                        required_state_interfaces=states),
        ControllerState("joint_trajectory_controller", "active",
                        "joint_trajectory_controller/JointTrajectoryController",
                        required_command_interfaces=["pid_controller_joint1/joint1/position",
                                                     "pid_controller_joint2/joint2/position"],
                        claimed_interfaces=["pid_controller_joint1/joint1/position",
                                            "pid_controller_joint2/joint2/position"],
                        required_state_interfaces=["joint1/position", "joint2/position"]),
        *(
            ControllerState(f"pid_controller_{j}", "active", "pid_controller/PidController", is_chainable=True,
                            is_chained=True, required_command_interfaces=[f"{j}/effort"],
                            claimed_interfaces=[f"{j}/effort"],
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


def _styled(diagram: SvgDiagram, color: str) -> list[ET.Element]:
    """The arrows of one colour (legend samples included)."""
    return [e for e in _edges(diagram) if e.get("stroke") == color]


_CLAIMED, _REQUIRED, _READ = "#455a64", "#9e9e9e", "#8e24aa"
_REQUIRED_LEGEND = "required (not claimed: controller inactive)"


@pytest.fixture
def rrbot():
    """RRBot as at the end of task 2: broadcaster and forward controller active, trajectory controller inactive."""
    system = rw.bringup("rrbot", "rrbot_controllers.yaml",
                        spawn=["joint_state_broadcaster", "forward_position_controller"],
                        inactive=["joint_trajectory_controller"], name="rrbot_diagrams")
    yield system
    system.shutdown()


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


def test_chains_draw_one_arrow_per_claim_requirement_and_read():
    chain = _chain()
    claims = sum(len(c.claimed_interfaces) for c in chain["controllers"])
    required = sum(len(c.required_command_interfaces) for c in chain["controllers"] if c.state == "inactive")
    reads = sum(len(c.required_state_interfaces) for c in chain["controllers"])
    edges = _edges(controller_chains(**chain))
    legend = 3
    assert len(edges) == claims + required + reads + legend
    assert sum(1 for e in edges if e.get("stroke-dasharray")) == required + reads + 2


def test_chains_draw_claimed_interfaces_solid():
    diagram = controller_chains(**_chain())
    claimed = _styled(diagram, _CLAIMED)
    assert len(claimed) == 4 + 1  # JTC -> 2 references, PIDs -> 2 efforts, legend
    assert all(e.get("stroke-dasharray") is None and e.get("marker-end") == "url(#arrow)" for e in claimed)


def test_chains_draw_inactive_controllers_requirements_grey_dashed():
    diagram = controller_chains(**_chain())
    required = _styled(diagram, _REQUIRED)
    assert len(required) == 2 + 1  # the inactive forward controller's two positions, legend
    assert all(e.get("stroke-dasharray") and e.get("marker-end") == "url(#arrow-9e9e9e)" for e in required)
    assert _REQUIRED_LEGEND in _texts(diagram)
    assert 'id="arrow-9e9e9e"' in diagram.svg  # its arrowhead is defined


def test_chains_draw_an_active_controllers_claims_not_its_requirements():
    """Only ``claimed_interfaces`` of an active controller become solid arrows."""
    chain = _chain()
    chain["controllers"] = [ControllerState("forward_position_controller", "active", "fcc",
                                            required_command_interfaces=["joint1/position", "joint2/position"],
                                            claimed_interfaces=["joint1/position"])]
    diagram = controller_chains(**chain)
    assert len(_styled(diagram, _CLAIMED)) == 1 + 1
    assert _styled(diagram, _REQUIRED) == []


def test_chains_without_inactive_requirements_have_no_required_legend():
    chain = _chain()
    chain["controllers"] = [c for c in chain["controllers"] if c.state != "inactive"]
    diagram = controller_chains(**chain)
    assert _REQUIRED_LEGEND not in _texts(diagram)
    assert _styled(diagram, _REQUIRED) == []
    assert "arrow-9e9e9e" not in diagram.svg


def test_chains_of_running_rrbot_separate_claims_from_requirements(rrbot):
    """Forward controller's two claims are solid; the inactive trajectory controller's two are grey dashed."""
    diagram = controller_chains(rrbot)
    assert len(_styled(diagram, _CLAIMED)) == 2 + 1
    assert len(_styled(diagram, _REQUIRED)) == 2 + 1
    assert all(e.get("stroke-dasharray") is None for e in _styled(diagram, _CLAIMED))
    assert all(e.get("stroke-dasharray") for e in _styled(diagram, _REQUIRED))


def test_chains_of_running_rrbot_are_deterministic(rrbot):
    assert controller_chains(rrbot).svg == controller_chains(rrbot).svg


def test_chains_draw_the_state_interfaces_an_active_controller_holds():
    """The broadcaster (ALL) activated before the PIDs holds no PID export, although list_controllers lists them."""
    chain = rw.bringup("rrbot", "rrbot_chained_controllers.yaml", xacro_args={"calculate_dynamics": True},
                       spawn=["joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2",
                              "joint_trajectory_controller"], name="rrbot_diagrams_chain")
    try:
        listed = {c.name: c for c in chain.controller_manager.list_controllers()}
        export = "pid_controller_joint1/joint1/position"
        assert export in listed["joint_state_broadcaster"].required_state_interfaces
        loans = chain.controller_manager.get_controller("joint_state_broadcaster").state_interfaces
        assert export not in [loan.name for loan in loans]
        texts = _texts(controller_chains(chain))
        assert f"{export} (exp state)" not in texts  # not a row of the broadcaster
        assert "joint1/position (exp state)" in texts  # still exported by the PID
        assert len(_styled(controller_chains(chain), _READ)) == len(loans) + 4 + 2 + 1  # + JTC, PIDs, legend
    finally:
        chain.shutdown()


def test_chains_from_given_lists_draw_required_state_interfaces():
    """Without a running system the listed ``required_state_interfaces`` are all there is to draw."""
    chain = _chain()
    reads = sum(len(c.required_state_interfaces) for c in chain["controllers"])
    assert len(_styled(controller_chains(**chain), _READ)) == reads + 1


def test_architecture_draws_inactive_controllers_requirements_grey_dashed(rrbot):
    diagram = architecture(rrbot)
    required = _styled(diagram, _REQUIRED)
    assert len(required) == 1 + 1  # trajectory controller -> rrbot, legend
    assert all(e.get("stroke-dasharray") for e in required)
    assert len(_styled(diagram, _CLAIMED)) == 1 + 1  # forward controller -> rrbot, legend
    assert _REQUIRED_LEGEND in _texts(diagram)


def test_architecture_without_inactive_controllers_has_no_required_legend():
    chain = _chain()
    chain["controllers"] = [c for c in chain["controllers"] if c.state != "inactive"]
    diagram = architecture(**chain)
    assert _REQUIRED_LEGEND not in _texts(diagram)
    assert _styled(diagram, _REQUIRED) == []


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


# ------------------------------------------------------------------------------------------ fit the cell
def test_wide_diagrams_scale_to_the_cell_width_keeping_their_proportions():
    diagram = controller_chains(**_chain())
    root = ET.fromstring(diagram.svg)
    width, height = float(root.get("width")), float(root.get("height"))
    assert width > 900  # wider than a notebook cell on a laptop
    assert root.get("viewBox") == f"0 0 {root.get('width')} {root.get('height')}"
    style = {k.strip(): v.strip() for k, v in (p.split(":") for p in root.get("style").split(";"))}
    assert style == {"max-width": "100%", "height": "auto"}
    assert height > 0


@pytest.mark.browser
@pytest.mark.skipif(shutil.which("chromium") is None, reason="headless Chromium not installed")
def test_wide_diagram_fits_a_narrow_cell_in_a_browser(tmp_path: Path):
    diagram = controller_chains(**_chain())
    root = ET.fromstring(diagram.svg)
    natural_w, natural_h = float(root.get("width")), float(root.get("height"))
    page = tmp_path / "cell.html"
    page.write_text(
        "<!DOCTYPE html><html><body style='margin:0'><div id='cell' style='width:500px'>" + diagram.svg + "</div>"
        "<script>const r = document.querySelector('#cell svg').getBoundingClientRect();"
        "document.title = 'size ' + r.width + ' ' + r.height;</script></body></html>",
        encoding="utf-8",
    )
    out = subprocess.run(
        [shutil.which("chromium"), "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         f"--user-data-dir={tmp_path / 'profile'}", "--dump-dom", page.as_uri()],
        capture_output=True, text=True, timeout=120, check=False,
    ).stdout
    match = re.search(r"<title>size ([\d.]+) ([\d.]+)</title>", out)
    assert match, out[-500:]
    shown_w, shown_h = float(match.group(1)), float(match.group(2))
    assert shown_w == pytest.approx(500, abs=1)
    assert shown_h == pytest.approx(natural_h * 500 / natural_w, rel=0.02)
