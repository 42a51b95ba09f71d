"""``rrbot-workshop lint`` on Jazzy's layouts: no false positive on a corpus of clean files, every seeded mistake found.

The corpus (tests/lint_corpus/, described by its manifest.yaml) holds controller files and descriptions written
for this project in the layouts the ros2_control demos use: types in the controller's own section or under the
manager, ``/**`` and namespaced keys, two controller managers in one file, ``$(var ...)`` launch arguments,
chains of PIDs under a diff drive, GPIO interfaces as a list of maps. Each mutated copy carries one known mistake.
The other tests pin the parts the corpus does not reach: node-key matching, launch-argument substitution, a
learner's unfinished controller and the CLI options.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from rrbot_workshop.cli import main
from rrbot_workshop.middleware import plugins
from rrbot_workshop.tools.lint import Finding, lint_controllers, lint_description
from rrbot_workshop.tools.lint.layout import key_matches, read_layout, read_sections, substitute

CORPUS = Path(__file__).resolve().parents[1] / "lint_corpus"
MANIFEST = yaml.safe_load((CORPUS / "manifest.yaml").read_text())


def _path(name: str) -> Path:
    for folder in ("clean", "mutations", "descriptions"):
        if (CORPUS / folder / name).is_file():
            return CORPUS / folder / name
    raise FileNotFoundError(name)


def _skip_without(case: dict[str, Any]) -> None:
    missing = [t for t in case.get("requires", []) if t not in plugins.available("controller")]
    if missing:
        pytest.skip(f"{case['file']} needs {', '.join(missing)}, which this library does not register yet")


def _lint(case: dict[str, Any], file: str | None = None) -> list[Finding]:
    path = _path(file or case["file"])
    xacro_args = case.get("xacro_args", {})
    if path.suffix == ".yaml":
        description = _path(case["description"]) if case.get("description") else None
        return lint_controllers(path, description, xacro_args, launch_args=case.get("launch_args", {}))
    return lint_description(path, xacro_args)


def _case_id(case: dict[str, Any]) -> str:
    extra = ",".join(f"{k}={v}" for k, v in sorted({**case.get("xacro_args", {}), **case.get("launch_args", {})}.items()))
    return f"{case['file']}[{extra}]" if extra else case["file"]


def _matches(finding: Finding, expected: dict[str, Any]) -> bool:
    return (finding.level == expected["level"] and finding.line == expected["line"]
            and finding.where == expected["where"] and expected["contains"] in finding.message)


def test_the_corpus_is_as_large_as_promised() -> None:
    yamls = {c["file"] for c in MANIFEST["clean"] if c["file"].endswith(".yaml")}
    assert len(yamls) >= 15 and len(MANIFEST["mutations"]) >= 15
    listed = {c["file"] for c in MANIFEST["clean"] + MANIFEST["mutations"]}
    on_disk = {p.name for folder in ("clean", "mutations") for p in (CORPUS / folder).iterdir()}
    assert on_disk <= listed, f"files without a manifest entry: {sorted(on_disk - listed)}"


@pytest.mark.parametrize("case", MANIFEST["clean"], ids=_case_id)
def test_a_clean_file_has_no_finding(case: dict[str, Any]) -> None:
    _skip_without(case)
    findings = _lint(case)
    notes = case.get("notes", [])
    unexpected = [str(f) for f in findings if not any(_matches(f, {"level": "note", **n}) for n in notes)]
    assert unexpected == []
    for note in notes:
        assert any(_matches(f, {"level": "note", **note}) for f in findings), (note, findings)


@pytest.mark.parametrize("case", MANIFEST["mutations"], ids=lambda c: c["file"] + ("@" + c["as_description_of"]
                                                                                    if "as_description_of" in c else ""))
def test_a_mutation_is_found_and_nothing_else(case: dict[str, Any]) -> None:
    _skip_without(case)
    if "as_description_of" in case:
        findings = lint_controllers(_path(case["as_description_of"]), _path(case["file"]))
    else:
        findings = _lint(case)
    for expected in case["expect"]:
        assert any(_matches(f, expected) for f in findings), (expected, [str(f) for f in findings])
    others = [str(f) for f in findings if not any(_matches(f, e) for e in case["expect"])]
    assert others == []


def test_a_finding_names_the_file_it_is_about() -> None:
    (finding,) = lint_controllers(_path("c07_pids_under_diff_drive.yaml"), _path("d01_fake_components.urdf.xacro"))
    assert finding.source.endswith("d01_fake_components.urdf.xacro")
    findings = lint_controllers(_path("m02_wrong_type.yaml"), _path("rover.urdf.xacro"))
    assert all(f.source.endswith("m02_wrong_type.yaml") for f in findings)


# ----------------------------------------------------------------------------------------------- node keys


@pytest.mark.parametrize(("key", "node", "applies"), [
    ("controller_manager", "/controller_manager", True),
    ("/controller_manager", "/controller_manager", True),
    ("controller_manager", "/arm/controller_manager", False),
    ("/**/controller_manager", "/controller_manager", True),
    ("/**/controller_manager", "/a/b/controller_manager", True),
    ("/**", "/a/any_node", True),
    ("/*/controller_manager", "/arm/controller_manager", True),
    ("/*/controller_manager", "/controller_manager", False),
    ("arm/controller_manager", "/arm/controller_manager", True),
    ("/arm/controller_manager", "/other/controller_manager", False),
    ("/**/controller_manager", "/arm/my_controller_manager", False),
])
def test_node_keys_apply_as_rclcpp_matches_them(key: str, node: str, applies: bool) -> None:
    assert key_matches(key, node) is applies


def test_each_namespaced_manager_gets_its_own_controllers_and_parameters() -> None:
    data = yaml.safe_load(_path("c05_two_managers.yaml").read_text())
    sections, problems = read_sections(data)
    layout = read_layout(sections)
    assert problems == [] and layout.unclaimed == []
    by_fqn = {m.fqn: m for m in layout.managers}
    assert sorted(by_fqn) == ["/left_arm/controller_manager", "/right_arm/controller_manager"]
    for ns in ("left_arm", "right_arm"):
        manager = by_fqn[f"/{ns}/controller_manager"]
        assert manager.parameters()["update_rate"] == 20
        commands = manager.controllers["arm_position_commands"]
        assert commands.type == "forward_command_controller/ForwardCommandController"
        assert commands.parameters()["joints"] == [f"{ns}_joint1", f"{ns}_joint2"]
        assert commands.parameters()["interface_name"] == "position"


def test_nested_namespace_keys_read_like_a_path() -> None:
    sections, _ = read_sections(yaml.safe_load(_path("c16_nested_namespace.yaml").read_text()))
    assert [s.key for s in sections] == ["left_arm/controller_manager", "left_arm/arm_position_commands"]
    (manager,) = read_layout(sections).managers
    assert manager.fqn == "/left_arm/controller_manager" and set(manager.controllers) == {
        "arm_state_broadcaster", "arm_position_commands"}


def test_a_list_of_maps_is_read_as_one_map() -> None:
    sections, _ = read_sections(yaml.safe_load(_path("c08_gpio_commands.yaml").read_text()))
    gpio = next(s for s in sections if s.name == "flange_io_controller")
    assert gpio.params["command_interfaces"] == {"flange_io": {"interfaces": ["analog_out", "suction"]}}


# ----------------------------------------------------------------------------------------------- launch arguments


def test_launch_arguments_are_substituted_in_the_text() -> None:
    text, missing = substitute("joints: [$(var p)j1, $( var p )j2]\nrate: $(var rate)\n", {"p": "arm_", "rate": "50"})
    assert text == "joints: [arm_j1, arm_j2]\nrate: 50\n" and missing == []
    text, missing = substitute("a: $(var x)\nb: $(var x)$(var y)\n", {})
    assert text == "a: $(var x)\nb: $(var x)$(var y)\n" and missing == ["x", "y"]


def test_an_argument_without_value_is_one_finding_not_a_cascade() -> None:
    findings = lint_controllers(_path("c06_launch_args.yaml"), _path("arm2.urdf.xacro"))
    (finding,) = findings
    assert finding.level == "error" and finding.line == 14 and finding.where == "$(var joint_prefix)"
    assert "--arg joint_prefix:=VALUE" in finding.message


def test_a_substituted_value_is_checked_with_its_yaml_type(tmp_path: Path) -> None:
    path = tmp_path / "rate.yaml"
    path.write_text("controller_manager:\n  ros__parameters:\n    update_rate: $(var rate)\n")
    assert lint_controllers(path, launch_args={"rate": "100"}) == []
    (finding,) = lint_controllers(path, launch_args={"rate": "fast"})
    assert finding.level == "error" and "must be of type integer" in finding.message and finding.line == 3


# ----------------------------------------------------------------------------------------------- learner's classes

_UNFINISHED = '''
from rrbot_workshop.controller_interface import ControllerInterface


class DisplacementController(ControllerInterface):
    PARAMETERS = """
displacement_controller:
  joints: {type: string_array, default_value: [], description: "Joints."}
  interface_name: {type: string, default_value: "", description: "Interface."}
"""

    def on_configure(self, previous_state):
        raise NotImplementedError("TODO(task 8.2): on_configure")

    def command_interface_configuration(self):
        raise NotImplementedError("TODO(task 8.2): command_interface_configuration")

    def state_interface_configuration(self):
        raise NotImplementedError("TODO(task 8.2): state_interface_configuration")
'''

_WORKSHOP_YAML = """\
controller_manager:
  ros__parameters:
    update_rate: 100
    displacement_controller:
      type: controlko_controllers/DisplacementController

displacement_controller:
  ros__parameters:
    joints: [joint1]
    interface_name: position
"""


@pytest.fixture
def learner_task8(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """An exercises folder whose task 8 file is the learner's, on the exercises track."""
    from rrbot_workshop.course import tracks

    folder = tmp_path / "exercises" / tracks.task_name(8)
    folder.mkdir(parents=True)
    monkeypatch.setenv("RRBOT_WORKSHOP_EXERCISES", str(tmp_path / "exercises"))
    monkeypatch.delenv("RRBOT_WORKSHOP_TASK_ROOT", raising=False)
    tracks.set_track("exercises")
    tracks.install()
    (tmp_path / "controllers.yaml").write_text(_WORKSHOP_YAML)
    yield folder
    tracks.set_track(None)


@pytest.mark.parametrize("with_description", [True, False])
def test_an_unfinished_exercise_is_one_finding_without_a_traceback(learner_task8: Path, with_description: bool) -> None:
    (learner_task8 / "displacement_controller.py").write_text(_UNFINISHED)
    description = _path("arm2.urdf.xacro") if with_description else None
    (finding,) = lint_controllers(learner_task8.parents[1] / "controllers.yaml", description)
    assert finding.level == "error" and finding.line == 5
    assert finding.where == "controller_manager.displacement_controller.type"
    assert finding.message.startswith("'controlko_controllers/DisplacementController' resolves to your unfinished ")
    assert "displacement_controller.py" in finding.message and "on_configure" in finding.message
    assert "NotImplementedError" in finding.message or "not written yet" in finding.message


def test_an_exercise_that_does_not_import_is_one_finding(learner_task8: Path) -> None:
    """Where the library refuses an unfinished class (UnfinishedExercise) it is an error; where it falls back to its
    reference implementation, a warning that says so."""
    from rrbot_workshop import exceptions

    (learner_task8 / "displacement_controller.py").write_text("class DisplacementController(:\n")
    (finding,) = lint_controllers(learner_task8.parents[1] / "controllers.yaml", _path("arm2.urdf.xacro"))
    assert finding.where == "controller_manager.displacement_controller.type" and finding.line == 5
    assert "resolves to your unfinished" in finding.message and "SyntaxError" in finding.message
    if hasattr(exceptions, "UnfinishedExercise"):
        assert finding.level == "error" and "displacement_controller.py" in finding.message
    else:
        assert finding.level == "warning" and "reference implementation" in finding.message


# ----------------------------------------------------------------------------------------------- CLI


def test_cli_takes_launch_arguments_and_package_paths(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    yaml_file, description = str(_path("c06_launch_args.yaml")), str(_path("arm2.urdf.xacro"))
    status = main(["lint", yaml_file, "--description", description, "--arg", "joint_prefix:=tool_",
                   "--xacro-arg", "prefix:=tool_", "--package-path", str(tmp_path)])
    assert status == 0 and capsys.readouterr().out.strip() == "no problems found"
    status = main(["lint", yaml_file, "--description", description])
    out = capsys.readouterr().out
    assert status != 0 and f"{yaml_file}:14: error: $(var joint_prefix):" in out and "1 error(s)" in out


def test_cli_refuses_a_launch_argument_without_value_separator(capsys: pytest.CaptureFixture[str]) -> None:
    status = main(["lint", str(_path("c06_launch_args.yaml")), "--arg", "joint_prefix"])
    err = capsys.readouterr().err
    assert status == 2 and "--arg 'joint_prefix' must be NAME:=VALUE" in err


def test_cli_prints_notes_and_counts_them(capsys: pytest.CaptureFixture[str]) -> None:
    status = main(["lint", str(_path("c11_diff_drive_limits.yaml"))])
    out = capsys.readouterr().out
    assert status == 0 and ":20: note: rover_base.linear.x.min_acceleration:" in out
    assert out.rstrip().endswith("no problems found, 1 note(s)")


def test_cli_arg_reaches_the_yaml_and_the_xacro(capsys: pytest.CaptureFixture[str]) -> None:
    """``--arg`` means what it means for bringup and in a launch file: $(var NAME) in the YAML and a xacro argument of
    the description (here joint_prefix for the YAML, prefix for the xacro)."""
    status = main(["lint", str(_path("c06_launch_args.yaml")), "--description", str(_path("arm2.urdf.xacro")),
                   "--arg", "joint_prefix:=tool_", "--arg", "prefix:=tool_"])
    assert status == 0 and capsys.readouterr().out.strip() == "no problems found"


def test_cli_xacro_arg_wins_over_arg_for_the_xacro_only(capsys: pytest.CaptureFixture[str]) -> None:
    """``--xacro-arg prefix:=`` overrides ``--arg prefix:=tool_`` in the description: its joints lose the prefix the
    YAML's joints have."""
    status = main(["lint", str(_path("c06_launch_args.yaml")), "--description", str(_path("arm2.urdf.xacro")),
                   "--arg", "joint_prefix:=tool_", "--arg", "prefix:=tool_", "--xacro-arg", "prefix:="])
    out = capsys.readouterr().out
    assert status == 1 and "claims command interface 'tool_joint1/position'" in out


def _arm_urdfs(tmp_path: Path) -> tuple[Path, Path]:
    from rrbot_workshop.description import process_xacro

    left, right = tmp_path / "left.urdf", tmp_path / "right.urdf"
    left.write_text(process_xacro(_path("arm2.urdf.xacro"), prefix="left_arm_"))
    right.write_text(process_xacro(_path("arm2.urdf.xacro"), prefix="right_arm_"))
    return left, right


@pytest.mark.parametrize("options", [
    ["--description", "/left_arm={left}", "--description", "/right_arm={right}"],
    ["--description", "/left_arm/controller_manager={left}", "--description", "/right_arm/={right}"],
    ["--description", "{right}", "--description", "/left_arm={left}"],
])
def test_cli_checks_each_manager_against_the_description_given_for_it(
        options: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Two managers, two robots: NS=URDF (a namespace or a manager's full name) gives each its own; a plain URDF is
    for every manager not named."""
    left, right = _arm_urdfs(tmp_path)
    options = [o.format(left=left, right=right) for o in options]
    assert main(["lint", str(_path("c05_two_managers.yaml")), *options]) == 0
    assert capsys.readouterr().out.strip() == "no problems found"


def test_one_robot_for_two_managers_finds_the_other_arms_joints(tmp_path: Path) -> None:
    """The left arm's description given for both managers: the right arm's controller claims joints it lacks."""
    left, _ = _arm_urdfs(tmp_path)
    findings = lint_controllers(_path("c05_two_managers.yaml"), left)
    assert {(f.level, f.where) for f in findings} == {("error", "/right_arm/arm_position_commands")}
    assert all("'right_arm_joint" in f.message for f in findings) and len(findings) == 2


def test_a_manager_without_a_description_gets_its_parameters_checked_only(tmp_path: Path) -> None:
    """A description for /left_arm alone: the right arm's interfaces are not judged (no robot given for it)."""
    left, _ = _arm_urdfs(tmp_path)
    assert lint_controllers(_path("c05_two_managers.yaml"), {"/left_arm": left}) == []


@pytest.mark.parametrize(("options", "says"), [
    (["--description", "/left_arm="], "names no file"),
    (["--description", "a.urdf", "--description", "b.urdf"], "given twice for every manager"),
    (["--description", "/left_arm=a.urdf", "--description", "/left_arm/=b.urdf"], "given twice for the managers of "
                                                                                  "'/left_arm'"),
    (["--description", "/left arm=a.urdf"], None),
    (["--namespace", "/left arm"], "is not a ROS namespace"),
])
def test_cli_refuses_a_description_or_namespace_it_cannot_use(
        options: list[str], says: str | None, capsys: pytest.CaptureFixture[str]) -> None:
    """Usage errors exit 2 with a sentence naming the option; a value that is no namespace is a file name."""
    status = main(["lint", str(_path("c05_two_managers.yaml")), *options])
    err = capsys.readouterr()
    if says is None:  # '/left arm' is not a namespace: the whole value is the file, which does not exist
        assert status == 1 and "/left arm=a.urdf: error: description: /left arm=a.urdf: xacro file not found" in err.out
        return
    assert status == 2 and says in err.err


def test_read_layout_in_given_namespaces_takes_the_sections_that_apply_there() -> None:
    """With the namespace a launch file gives ros2_control_node: that manager only; the other namespace's sections
    are another launch's, not unclaimed; a namespace the file does not name gets the '/**' sections."""
    sections, _ = read_sections(yaml.safe_load(_path("c05_two_managers.yaml").read_text()))
    left = read_layout(sections, ["left_arm"])
    assert [m.fqn for m in left.managers] == ["/left_arm/controller_manager"] and left.unclaimed == []
    assert left.managers[0].controllers["arm_position_commands"].parameters()["joints"] == ["left_arm_joint1",
                                                                                            "left_arm_joint2"]
    (third,) = read_layout(sections, ["/third/"]).managers
    assert third.fqn == "/third/controller_manager"
    assert third.controllers["arm_position_commands"].parameters() == {
        "type": "forward_command_controller/ForwardCommandController", "interface_name": "position"}


@pytest.mark.parametrize(("value", "expected"), [
    ("/rrbot_1=rrbot.urdf.xacro", ("/rrbot_1", "rrbot.urdf.xacro")),
    ("/rrbot_1/controller_manager=a=b.urdf", ("/rrbot_1/controller_manager", "a=b.urdf")),
    ("/=root.urdf", ("/", "root.urdf")),
    ("rrbot.urdf.xacro", ("", "rrbot.urdf.xacro")),
    ("a=b.urdf", ("", "a=b.urdf")),
])
def test_split_description_option(value: str, expected: tuple[str, str]) -> None:
    """``[NS=]URDF``: NS is '/' or a '/'-path of ROS names; anything else is part of the file name."""
    from rrbot_workshop.tools.lint.descriptions import split_description_option

    assert split_description_option(value) == expected


def test_split_description_option_keeps_an_existing_file_whole(tmp_path: Path) -> None:
    """A file that exists is a file, even when its path looks like NS=FILE."""
    from rrbot_workshop.tools.lint.descriptions import split_description_option

    (tmp_path / "x=y.urdf").write_text("<robot name='r'/>")
    path = str(tmp_path / "x=y.urdf")
    assert split_description_option(path) == ("", path)


def test_manager_descriptions_parse_refuses_a_key_without_a_description() -> None:
    """``ManagerDescriptions.parse`` of a namespace no description is given for raises KeyError."""
    from rrbot_workshop.tools.lint.descriptions import ManagerDescriptions

    descriptions = ManagerDescriptions({"/left_arm": _path("arm2.urdf.xacro")}, {}, ())
    assert descriptions.keys() == ["/left_arm"]
    with pytest.raises(KeyError):
        descriptions.parse("/right_arm")
