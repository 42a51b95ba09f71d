"""Task 3's grader: wrong answers written as learners would lose points; correct ones written differently do not.

A wrong or alternative answer is appended to a copy of ``solutions/task03_components/answers.py`` (the later ``def``
wins) and the copy is graded in a subprocess, as ``rrbot-workshop grade 3`` would.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

FILE = "answers.py"
SOLUTION = (tracks.task_dir(3, "solutions") / FILE).read_text() if HAS_SOLUTIONS else ""


def appended(code: str) -> dict[str, str]:
    """The solution with ``code`` appended: its later definitions replace the solution's."""
    return {FILE: SOLUTION + "\n\n" + textwrap.dedent(code)}


#: The generated sequences compare every answer: a slip in one may show there too (after its own check).
SEQUENCES = "any_sequence_matches_the_controller_manager"
#: Variants with several slips at once.
MANY_SLIPS = {"hard_coded_answers_of_one_system"}

WRONG = [
    Variant("update_order_lists_controllers_in_any_state", appended("""
        def update_order(system):
            return [c.name for c in system.controller_manager.list_controllers()]
        """), fails={"update_order", SEQUENCES}),
    Variant("update_order_in_load_order", appended("""
        def update_order(system):
            cm = system.controller_manager
            return [name for name, spec in cm.controllers.items() if spec.state.label == "active"]
        """), fails={"update_order"}, only=True),
    Variant("update_order_sorted_by_name", appended("""
        def update_order(system):
            return sorted(c.name for c in system.controller_manager.list_controllers() if c.state == "active")
        """), fails={"update_order"}, only=True),
    Variant("inactive_controller_reads_its_required_state_interfaces", appended("""
        def state_interfaces_read_by(system, controller):
            entry = next(c for c in system.controller_manager.list_controllers() if c.name == controller)
            return sorted(entry.required_state_interfaces)
        """), fails={"state_interfaces_read_by", SEQUENCES}),
    Variant("claimable_ignores_the_hardware_state", appended("""
        def claimable_command_interfaces(system):
            rm = system.resource_manager
            return [n for n in rm.available_command_interfaces() if not rm.command_interface_is_claimed(n)]
        """), fails={"claimable_command_interfaces", SEQUENCES}),
    Variant("claimable_ignores_availability", appended("""
        def claimable_command_interfaces(system):
            states = hardware_states(system)
            out = []
            for itf in system.controller_manager.list_hardware_interfaces().command_interfaces:
                owner = owner_of_interface(system, itf.name)
                if not itf.is_claimed and (owner is None or states[owner] == "active"):
                    out.append(itf.name)
            return sorted(out)
        """), fails={"claimable_command_interfaces", SEQUENCES}),
    Variant("claimable_keeps_claimed_interfaces", appended("""
        def claimable_command_interfaces(system):
            states = hardware_states(system)
            return [n for n in available_interfaces(system)["command"]
                    if owner_of_interface(system, n) is None or states[owner_of_interface(system, n)] == "active"]
        """), fails={"claimable_command_interfaces", SEQUENCES}),
    Variant("hard_coded_answers_of_one_system", appended("""
        def loop_rate(system):
            return 100

        def owner_of_interface(system, interface):
            return "rrbot"

        def reference_interfaces_of(system, controller):
            return []
        """), fails={"loop_rate", "owner_of_interface", "reference_interfaces_of", SEQUENCES}),
    Variant("every_controller_runs_at_the_managers_rate", appended("""
        def controller_update_rates(system):
            rate = system.controller_manager.get_update_rate()
            return {c.name: rate for c in system.controller_manager.list_controllers()}
        """), fails={"controller_update_rates", SEQUENCES}),
    Variant("controller_rates_of_active_controllers_only", appended("""
        def controller_update_rates(system):
            return {c.name: c.update_rate for c in system.controller_manager.list_controllers() if c.state == "active"}
        """), fails={"controller_update_rates", SEQUENCES}),
    Variant("unclaimed_interface_answers_an_empty_name", appended("""
        def claimant_of(system, interface):
            return system.resource_manager.command_interface_holder(interface) or ""
        """), fails={"claimant_of", SEQUENCES}),
    Variant("reference_interfaces_without_the_controller_prefix", appended("""
        def reference_interfaces_of(system, controller):
            names = system.resource_manager.get_controller_reference_interface_names(controller)
            return sorted(n.split("/", 1)[1] for n in names)
        """), fails={"reference_interfaces_of", SEQUENCES}),
    Variant("available_means_every_interface", appended("""
        def available_interfaces(system):
            listing = system.controller_manager.list_hardware_interfaces()
            return {"state": sorted(i.name for i in listing.state_interfaces),
                    "command": sorted(i.name for i in listing.command_interfaces)}
        """), fails={"available_interfaces", SEQUENCES}),
    Variant("every_component_assumed_active", appended("""
        def hardware_states(system):
            return {c.name: "active" for c in system.controller_manager.list_hardware_components()}
        """), fails={"hardware_states", SEQUENCES}),
    Variant("hardware_state_object_not_its_label", appended("""
        def hardware_states(system):
            return {c.name: c.state for c in system.controller_manager.list_hardware_components()}
        """), fails={"hardware_states", SEQUENCES}),
    Variant("owner_of_an_exported_interface_is_the_controller", appended("""
        def owner_of_interface(system, interface):
            rm = system.resource_manager
            return rm.hardware_of_interface(interface) or rm.controller_of_interface(interface)
        """), fails={"owner_of_interface"}, only=True),
    Variant("hardware_states_remembered_from_the_first_call", appended("""
        _FIRST = {}

        def hardware_states(system):
            if id(system) not in _FIRST:
                _FIRST[id(system)] = {c.name: c.state.label for c in system.controller_manager.list_hardware_components()}
            return dict(_FIRST[id(system)])
        """), fails={"hardware_states", SEQUENCES}),
]

WRONG += [
    Variant("loop_rate_of_the_fastest_controller", appended("""
        def loop_rate(system):
            return max(c.update_rate for c in system.controller_manager.list_controllers())
        """), fails={"loop_rate"}, only=True, says={"loop_rate": "all run slower"}),
    Variant("state_interfaces_in_the_order_of_the_joints", appended("""
        def state_interfaces_read_by(system, controller):
            entry = next(c for c in system.controller_manager.list_controllers() if c.name == controller)
            return list(entry.required_state_interfaces) if entry.state == "active" else []
        """), fails={"state_interfaces_read_by"}, only=True, says={"state_interfaces_read_by": "sorted"}),
    Variant("reference_interfaces_remembered", appended("""
        _SEEN = {}

        def reference_interfaces_of(system, controller):
            key = (id(system), controller)
            if key not in _SEEN:
                _SEEN[key] = sorted(system.resource_manager.get_controller_reference_interface_names(controller))
            return list(_SEEN[key])
        """), fails={"reference_interfaces_of", SEQUENCES}, says={"reference_interfaces_of": "cleaned up"}),
    Variant("claimant_among_the_controllers_that_need_it", appended("""
        def claimant_of(system, interface):
            for entry in system.controller_manager.list_controllers():
                if interface in entry.required_command_interfaces:
                    return entry.name
            return None
        """), fails={"claimant_of", SEQUENCES}),
    Variant("claimable_built_on_a_wrong_owner", appended("""
        def owner_of_interface(system, interface):
            return interface.split("/")[0]
        """), fails={"owner_of_interface"}, only=True),
]

RIGHT = [
    Variant("only_the_introspection_lists", appended("""
        def claimant_of(system, interface):
            for entry in system.controller_manager.list_controllers():
                if interface in entry.claimed_interfaces:
                    return entry.name
            return None


        def state_interfaces_read_by(system, controller):
            for entry in system.controller_manager.list_controllers():
                if entry.name == controller:
                    return sorted(entry.required_state_interfaces) if entry.state == "active" else []
            return []


        def reference_interfaces_of(system, controller):
            entry = [c for c in system.controller_manager.list_controllers() if c.name == controller][0]
            return sorted(controller + "/" + ref for ref in entry.reference_interfaces)


        def owner_of_interface(system, interface):
            for comp in system.controller_manager.list_hardware_components():
                names = {i.name for i in comp.command_interfaces} | {i.name for i in comp.state_interfaces}
                if interface in names:
                    return comp.name
            return None


        def available_interfaces(system):
            listing = system.controller_manager.list_hardware_interfaces()
            state = [i.name for i in listing.state_interfaces if i.is_available]
            command = [i.name for i in listing.command_interfaces if i.is_available]
            state.sort()
            command.sort()
            return dict(command=command, state=state)
        """)),
    Variant("sets_and_a_filter", appended("""
        def claimable_command_interfaces(system):
            listing = system.controller_manager.list_hardware_interfaces()
            active = {c.name for c in system.controller_manager.list_hardware_components()
                      if c.state.label == "active"}

            def usable(itf):
                owner = owner_of_interface(system, itf.name)
                return itf.is_available and not itf.is_claimed and (owner is None or owner in active)

            return sorted({itf.name for itf in filter(usable, listing.command_interfaces)})


        def update_order(system):
            order = []
            for c in system.controller_manager.list_controllers():
                if c.state != "active":
                    continue
                order.append(c.name)
            return order
        """)),
    Variant("loops_tuples_and_str_labels", appended("""
        def hardware_states(system):
            out = {}
            for comp in system.controller_manager.list_hardware_components():
                out[comp.name] = str(comp.state.label)
            return out


        def controller_update_rates(system):
            return dict((c.name, int(c.update_rate)) for c in system.controller_manager.list_controllers())


        def loop_rate(system):
            return int(system.controller_manager.get_update_rate())


        def state_interfaces_read_by(system, controller):
            loans = system.controller_manager.get_controller(controller).state_interfaces
            return sorted({loan.name for loan in loans})
        """)),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    return grade_variants(3, WRONG + RIGHT, Path(tmp_path_factory.mktemp("task03")))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


def test_enough_variants() -> None:
    """The issue asks for at least 12 wrong and 3 alternative solutions per task."""
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


@pytest.mark.parametrize("variant", [v for v in WRONG if v.name not in MANY_SLIPS], ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(3), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(3))
