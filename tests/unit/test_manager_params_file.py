"""The manager's ``<controller>.params_file`` parameter, as Jazzy's ``ControllerManager::load_controller`` reads it.

Ported from ros2_control (jazzy) ``controller_manager/test/test_spawner_unspawner.cpp``,
``spawner_test_with_params_file_string_parameter``: the manager's ``ctrl.type`` and ``ctrl.params_file`` are set, the
controller is loaded by name, and it starts with the file's ``joint_names`` and ``interface_name``. The variations:
a list of files (the string-array form of the same parameter, as ``spawner_test_parsing_multiple_params_file`` sets
it), the file's wildcard and namespaced keys (as ``test_controller_spawner_with_type.yaml`` writes them), and every
place a controller is loaded: ``bringup(spawn=...)``, ``System.spawn``, ``%control load_controller``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from test_namespaces import arm_urdf

import rrbot_workshop as rw
from rrbot_workshop.course.magics import control
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.controllers_yaml import load_controllers_yaml
from rrbot_workshop.msgs import Float64MultiArray

FWD = "forward_position_controller"
FWD_TYPE = "forward_command_controller/ForwardCommandController"

#: The file the manager names: ``joints`` and ``interface_name`` for the controller, as upstream's
#: test_controller_spawner_with_type.yaml gives ``joint_names`` and ``interface_name``.
OWN_FILE = f"""\
{FWD}:
  ros__parameters:
    type: {FWD_TYPE}
    joints: [j2]
    interface_name: position
"""


def manager_yaml(params_file: object, namespace_key: str = "controller_manager") -> str:
    """A controllers YAML whose manager declares the forward controller with ``params_file`` set to ``params_file``."""
    return f"""\
{namespace_key}:
  ros__parameters:
    update_rate: 50
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    {FWD}:
      type: {FWD_TYPE}
      params_file: {params_file!r}
"""


@pytest.fixture
def own_file(tmp_path: Path) -> Path:
    path = tmp_path / "fwd_params.yaml"
    path.write_text(OWN_FILE)
    return path


def test_the_managers_params_file_string_gives_the_controller_its_parameters(own_file: Path) -> None:
    """spawner_test_with_params_file_string_parameter: with ``<name>.type`` and ``<name>.params_file`` (a string)
    on the manager, the controller loads unconfigured, of that type, with the file recorded for it and the file's
    parameters on its node."""
    system = rw.bringup(arm_urdf(""), manager_yaml(str(own_file)))
    try:
        cm = system.controller_manager
        ctrl = cm.load_controller(FWD)
        spec = cm.controllers[FWD]
        assert (spec.type, spec.state.label) == (FWD_TYPE, "unconfigured")
        assert cm.params.param_files[FWD] == [str(own_file)]
        assert ctrl.get_node().get_parameter("joints") == ["j2"]
        assert ctrl.get_node().get_parameter("interface_name") == "position"
        assert ctrl.get_node().get_parameter("params_file") is None, "params_file is the manager's, not the controller's"
    finally:
        system.shutdown()


def test_a_list_of_files_is_read_in_order_the_later_winning(own_file: Path, tmp_path: Path) -> None:
    """The string-array form of ``<name>.params_file``: every file gives its section, a later file overriding an
    earlier one parameter by parameter."""
    later = tmp_path / "later.yaml"
    later.write_text(f"/**:\n  {FWD}:\n    ros__parameters:\n      joints: [j1]\n")
    system = rw.bringup(arm_urdf(""), manager_yaml([str(own_file), str(later)]))
    try:
        node = system.controller_manager.load_controller(FWD).get_node()
        assert node.get_parameter("joints") == ["j1"]  # the later file's
        assert node.get_parameter("interface_name") == "position"  # the earlier file's, kept
        assert system.controller_manager.params.param_files[FWD] == [str(own_file), str(later)]
    finally:
        system.shutdown()


def test_the_file_overrides_the_controllers_yaml_and_the_managers_type_wins(tmp_path: Path) -> None:
    """The file is the controller node's own ``--params-file``: it overrides the controllers YAML's section; the
    plugin is the manager's ``<name>.type``, the file's ``type`` is only a parameter."""
    path = tmp_path / "fwd.yaml"
    path.write_text(f"{FWD}:\n  ros__parameters:\n    type: position_controllers/JointGroupPositionController\n"
                    "    interface_name: position\n")
    yaml = manager_yaml(str(path)) + f"{FWD}:\n  ros__parameters:\n    joints: [j1, j2]\n    interface_name: velocity\n"
    system = rw.bringup(arm_urdf(""), yaml)
    try:
        node = system.controller_manager.load_controller(FWD).get_node()
        assert system.controller_manager.controllers[FWD].type == FWD_TYPE
        assert (node.get_parameter("joints"), node.get_parameter("interface_name")) == (["j1", "j2"], "position")
    finally:
        system.shutdown()


def test_a_namespaced_manager_reads_the_namespaced_and_wildcard_keys(tmp_path: Path) -> None:
    """As test_controller_spawner_with_type.yaml writes them: ``/foo_namespace/<name>`` reaches the controller in
    that namespace, ``/**`` every controller."""
    path = tmp_path / "ns.yaml"
    path.write_text(f"/**:\n  ros__parameters:\n    interface_name: position\n"
                    f"/arm_a/{FWD}:\n  ros__parameters:\n    joints: [arm_a_j1]\n")
    system = rw.bringup(arm_urdf("arm_a_"), manager_yaml(str(path), "/**/controller_manager"), namespace="/arm_a",
                        spawn=[FWD])
    try:
        node = system.controller_manager.get_controller(FWD).get_node()
        assert node.get_fully_qualified_name() == f"/arm_a/{FWD}"
        assert (node.get_parameter("joints"), node.get_parameter("interface_name")) == (["arm_a_j1"], "position")
    finally:
        system.shutdown()


def test_bringup_spawn_uses_the_file_and_the_controller_commands(own_file: Path) -> None:
    """``bringup(..., spawn=[...])`` loads through the manager: the controller runs with the file's joints."""
    system = rw.bringup(arm_urdf(""), manager_yaml(str(own_file)), spawn=["joint_state_broadcaster", FWD])
    try:
        assert system.controller_manager.controllers[FWD].state.label == "active"
        system.publish(f"/{FWD}/commands", Float64MultiArray(data=[0.4]))
        system.spin(0.2)
        assert list(system.latest("/joint_states").position) == pytest.approx([0.0, 0.4])
    finally:
        system.shutdown()


def test_system_spawn_and_the_magic_use_the_file(own_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``System.spawn`` and ``%control load_controller NAME`` load with the manager's file as well."""
    system = rw.bringup(arm_urdf(""), manager_yaml(str(own_file)))
    try:
        system.spawn([FWD], inactive=True)
        assert system.controller_manager.get_controller(FWD).get_node().get_parameter("joints") == ["j2"]
        system.controller_manager.unload_controller(FWD)
        control(f"load_controller {FWD}")
        assert f"Successfully loaded controller {FWD}" in capsys.readouterr().out
        assert system.controller_manager.get_controller(FWD).get_node().get_parameter("joints") == ["j2"]
        assert system.controller_manager.params.param_files[FWD] == [str(own_file)], "read once, not again"
    finally:
        system.shutdown()


def test_a_missing_file_is_an_error_naming_the_file_and_the_controller(tmp_path: Path) -> None:
    """A ``params_file`` that does not exist: ParameterError naming the parameter, the file and the controller;
    nothing is loaded."""
    missing = tmp_path / "nowhere.yaml"
    system = rw.bringup(arm_urdf(""), manager_yaml(str(missing)))
    try:
        with pytest.raises(ParameterError, match=rf"'{FWD}.params_file'.*{missing}.*controller '{FWD}'") as info:
            system.controller_manager.load_controller(FWD)
        assert info.value.owner == "controller_manager"
        assert FWD not in system.controller_manager.controllers
    finally:
        system.shutdown()


def test_a_file_without_a_section_for_the_controller_is_an_error(tmp_path: Path) -> None:
    """A file with no section that reaches the controller: ParameterError naming the file, the controller and the
    keys that would; nothing is loaded."""
    other = tmp_path / "other.yaml"
    other.write_text("someone_else:\n  ros__parameters:\n    joints: [j1]\n")
    system = rw.bringup(arm_urdf(""), manager_yaml(str(other)))
    try:
        with pytest.raises(ParameterError, match=rf"{other} has no section for controller '{FWD}'.*'/\*\*/{FWD}:'"):
            system.spawn([FWD])
        assert FWD not in system.controller_manager.controllers
    finally:
        system.shutdown()


@pytest.mark.parametrize("value", [3, [], ["a.yaml", 2]])
def test_a_params_file_that_is_not_a_string_or_list_of_strings_is_refused(value: object) -> None:
    """Jazzy takes a string or a string array only; anything else is a ParameterError naming the parameter."""
    cfg = load_controllers_yaml(manager_yaml(value))
    with pytest.raises(ParameterError, match=rf"'{FWD}.params_file'.*string or a list of strings"):
        cfg.params_files_of(FWD)


def test_the_dotted_and_typeless_forms_are_the_managers_parameter() -> None:
    """``<name>.params_file: f`` and ``<name>: {params_file: f}`` (no type) in the manager's section set the same
    parameter; neither reaches the controller's own parameters."""
    cfg = load_controllers_yaml("controller_manager:\n  ros__parameters:\n    a.params_file: /x/a.yaml\n"
                                "    b:\n      params_file: [/x/b.yaml]\n")
    assert (cfg.params_files_of("a"), cfg.params_files_of("b"), cfg.params_files_of("c")) == (["/x/a.yaml"],
                                                                                             ["/x/b.yaml"], [])
    assert "params_file" not in cfg.parameters_for("b") and "b" not in cfg.manager_parameters


# ---------------------------------------------------------------------------------- lint


def _lint(tmp_path: Path, params_file: object, namespace_key: str = "controller_manager") -> list:
    from rrbot_workshop.tools.lint import lint_controllers

    yaml = tmp_path / "controllers.yaml"
    yaml.write_text(manager_yaml(params_file, namespace_key))
    return [f for f in lint_controllers(yaml) if "params_file" in f.where or "joints" in f.where]


def test_lint_accepts_a_file_with_the_controllers_section_and_checks_its_parameters(own_file: Path,
                                                                                   tmp_path: Path) -> None:
    """The file exists and names the controller: no finding, and the file's ``joints`` count (the controllers YAML
    alone has none, which lint reports as missing)."""
    assert _lint(tmp_path, str(own_file)) == []
    without = tmp_path / "controllers_without.yaml"
    without.write_text(manager_yaml(str(own_file)).replace(f"      params_file: {str(own_file)!r}\n", ""))
    from rrbot_workshop.tools.lint import lint_controllers

    assert any("joints" in f.where and f.level == "error" for f in lint_controllers(without)), "the control case"


def test_lint_reports_a_missing_file(tmp_path: Path) -> None:
    missing = tmp_path / "nowhere.yaml"
    (finding,) = [f for f in _lint(tmp_path, str(missing)) if "params_file" in f.where]
    assert (finding.level, finding.where) == ("error", f"controller_manager.{FWD}.params_file")
    assert str(missing) in finding.message and f"controller '{FWD}'" in finding.message
    assert finding.line > 0


def test_lint_reports_a_file_without_the_controllers_section(tmp_path: Path) -> None:
    other = tmp_path / "other.yaml"
    other.write_text("someone_else:\n  ros__parameters:\n    joints: [j1]\n    interface_name: position\n")
    findings = [f for f in _lint(tmp_path, str(other)) if "params_file" in f.where]
    assert [(f.level, f.message.split(";")[0]) for f in findings] == [
        ("error", f"{other} has no section for controller '{FWD}'")]


def test_lint_reports_a_value_of_the_wrong_type(tmp_path: Path) -> None:
    (finding,) = [f for f in _lint(tmp_path, 7) if "params_file" in f.where]
    assert finding.level == "error" and "string or a list of strings" in finding.message


def test_lint_matches_the_file_to_a_namespaced_manager(tmp_path: Path) -> None:
    """A namespaced manager's controller is matched by its fully qualified name, as at load."""
    path = tmp_path / "ns.yaml"
    path.write_text(f"/arm_a/{FWD}:\n  ros__parameters:\n    joints: [arm_a_j1]\n    interface_name: position\n")
    assert _lint(tmp_path, str(path), "/arm_a/controller_manager") == []
    assert [f.level for f in _lint(tmp_path, str(path), "/arm_b/controller_manager")
            if "params_file" in f.where] == ["error"]
