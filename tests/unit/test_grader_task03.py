"""Task 3's grader fails wrong answers: each mutation of the solution fails the checks it should, and only those.

A mutation appends a wrong definition of one answer to a copy of ``solutions/task03_components/answers.py``
(the later ``def`` wins), then grades the copy in a subprocess, as ``rrbot-workshop grade 3`` would.
"""

from __future__ import annotations

import shutil
import textwrap
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

MUTATIONS = {
    "update_order_lists_controllers_in_any_state": (
        """
        def update_order(system):
            return [c.name for c in system.controller_manager.list_controllers()]
        """,
        {"update_order"},
    ),
    "update_order_in_load_order": (
        """
        def update_order(system):
            cm = system.controller_manager
            return [name for name, spec in cm.controllers.items() if spec.state.label == "active"]
        """,
        {"update_order"},
    ),
    "inactive_controller_reads_its_required_state_interfaces": (
        """
        def state_interfaces_read_by(system, controller):
            entry = next(c for c in system.controller_manager.list_controllers() if c.name == controller)
            return sorted(entry.required_state_interfaces)
        """,
        {"state_interfaces_read_by"},
    ),
    "claimable_ignores_the_hardware_state": (
        """
        def claimable_command_interfaces(system):
            rm = system.resource_manager
            return [n for n in rm.available_command_interfaces() if not rm.command_interface_is_claimed(n)]
        """,
        {"claimable_command_interfaces"},
    ),
    "hard_coded_answers_of_one_system": (
        """
        def loop_rate(system):
            return 100

        def owner_of_interface(system, interface):
            return "rrbot"

        def reference_interfaces_of(system, controller):
            return []
        """,
        # the solution's claimable_command_interfaces asks owner_of_interface, so it fails along with it
        {"loop_rate", "owner_of_interface", "reference_interfaces_of", "claimable_command_interfaces"},
    ),
    "every_controller_runs_at_the_managers_rate": (
        """
        def controller_update_rates(system):
            rate = system.controller_manager.get_update_rate()
            return {c.name: rate for c in system.controller_manager.list_controllers()}
        """,
        {"controller_update_rates"},
    ),
    "unclaimed_interface_answers_an_empty_name": (
        """
        def claimant_of(system, interface):
            return system.resource_manager.command_interface_holder(interface) or ""
        """,
        {"claimant_of"},
    ),
    "reference_interfaces_without_the_controller_prefix": (
        """
        def reference_interfaces_of(system, controller):
            names = system.resource_manager.get_controller_reference_interface_names(controller)
            return sorted(n.split("/", 1)[1] for n in names)
        """,
        {"reference_interfaces_of"},
    ),
    "available_means_every_interface": (
        """
        def available_interfaces(system):
            listing = system.controller_manager.list_hardware_interfaces()
            return {"state": [i.name for i in listing.state_interfaces],
                    "command": [i.name for i in listing.command_interfaces]}
        """,
        # the solution's claimable_command_interfaces asks available_interfaces, so it fails along with it
        {"available_interfaces", "claimable_command_interfaces"},
    ),
    "every_component_assumed_active": (
        """
        def hardware_states(system):
            return {c.name: "active" for c in system.controller_manager.list_hardware_components()}
        """,
        # the solution's claimable_command_interfaces asks hardware_states, so it fails along with it
        {"hardware_states", "claimable_command_interfaces"},
    ),
    "owner_of_an_exported_interface_is_the_controller": (
        """
        def owner_of_interface(system, interface):
            rm = system.resource_manager
            return rm.hardware_of_interface(interface) or rm.controller_of_interface(interface)
        """,
        {"owner_of_interface"},
    ),
}


def _failed(rubric: Rubric) -> set[str]:
    return {c.name for c in rubric.checks if not c.passed}


@pytest.mark.parametrize("mutation", list(MUTATIONS))
def test_mutated_answer_fails_its_check(mutation: str, tmp_path: Path) -> None:
    """The mutated solution loses exactly the checks of the answers it breaks."""
    code, expected = MUTATIONS[mutation]
    source = tracks.task_dir(3, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    answers = copy / "answers.py"
    answers.write_text(answers.read_text() + "\n" + textwrap.dedent(code))
    rubric = grade(3, task_root=tmp_path)
    assert _failed(rubric) == expected, rubric.format()
